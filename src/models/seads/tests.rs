use rand::SeedableRng;

use super::collect::Starts;
use super::*;
use crate::envs::boards::TileSwap;
use crate::train::TrainingMethod;

fn tiny(skills: usize) -> SeadsConfig {
    let mut c = SeadsConfig::preset(Preset::Small, skills, Embodiment::Cursor);
    c.episodes_per_epoch = 16;
    c.sampled_episodes = 32;
    c.episode_memory = 64;
    c.model_hidden = 16;
    c.sac_hidden = vec![16, 16];
    c.sac_batch = 32;
    c.sac_updates = 2;
    c.env_steps = 2_000;
    c
}

#[test]
fn parses_embodied_games() {
    let g = EmbodiedGame::parse("tileswap:cursor").unwrap();
    assert_eq!((g.game, g.embodiment, g.moves()), (GameSpec::TileSwap, Embodiment::Cursor, 12));
    assert_eq!(EmbodiedGame::parse("lightsout:reacher").unwrap().name(), "lightsout:reacher");
    for bad in ["lightsout", "tileswap:arm", "chess:cursor"] {
        assert!(EmbodiedGame::parse(bad).unwrap_err().to_string().contains("lightsout:cursor"), "{bad}");
    }
    assert!(EmbodiedGame::parse("lightsout:7x7:cursor").unwrap_err().to_string().contains("not supported"));
}

#[test]
fn epochs_fill_the_memory_then_train_and_resume_bit_for_bit() {
    let game = TileSwap::new();
    let mut a = SeadsTrainer::new(tiny(12), game.clone(), Embodiment::Cursor, 4).unwrap();
    for epoch in 1..=3 {
        let loss = a.step(epoch).unwrap();
        assert!(loss.is_finite() && loss > 0.0, "epoch {epoch}: {loss}");
    }
    // Updates began once 32 episodes were in memory.
    assert!(a.last.critic_loss.is_some() && a.last.mean_final_reward.is_some());
    let floor = reward::reward_floor(12);
    assert!(a.last.mean_final_reward.unwrap() >= floor);
    assert!(a.env_steps() > 0 && a.env_steps() <= 3 * 16 * 10);

    let mut b = SeadsTrainer::new(tiny(12), game, Embodiment::Cursor, 4).unwrap();
    b.restore(&a.state()).unwrap();
    a.step(4).unwrap();
    b.step(4).unwrap();
    assert_eq!(a.state(), b.state(), "a restored trainer must continue exactly as the original");
}

#[test]
fn deterministic_collection_from_given_boards() {
    let game = TileSwap::new();
    let mut t = SeadsTrainer::new(tiny(12), game.clone(), Embodiment::Cursor, 1).unwrap();
    let boards = vec![game.goal(); 3];
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(9);
    let episodes = t.collect(&[0, 5, 11], Starts::Boards(&boards), true, &mut rng);
    assert_eq!(episodes.len(), 3);
    let layout = t.layout();
    for e in &episodes {
        let steps = layout.steps(e);
        assert!((1..=10).contains(&steps));
        assert_eq!(e.obs.len(), (steps + 1) * layout.obs_dim);
        assert_eq!(layout.changed(e), e.performed.is_some());
    }
}

#[test]
fn search_through_a_model_that_knows_the_rules_finds_optimal_plans() {
    use super::forward_model::lightsout_rules_model;
    use super::planner::plan_with_model;
    use crate::envs::boards::{gf2, BoardGame, LightsOut};
    use crate::planning::bfs::SearchLimits;
    let game = LightsOut::new(5).unwrap();
    let model = lightsout_rules_model(&game, 32).unwrap();
    for presses in [vec![3], vec![0, 12], vec![1, 7, 19], vec![2, 8, 14, 20]] {
        let board = game.pressed(&presses);
        let optimal = gf2::solve(&game, board).unwrap().len();
        for bidirectional in [false, true] {
            let (result, used_bidirectional) =
                plan_with_model(&game, &model, board, bidirectional, &SearchLimits::default()).unwrap();
            let plan = result.plan.unwrap();
            assert_eq!(plan.len(), optimal);
            assert_eq!(plan.iter().fold(board, |b, &m| game.apply(b, m)), game.goal());
            assert_eq!(used_bidirectional, bidirectional, "the exact model is self-inverse everywhere");
        }
    }
}

#[cfg(feature = "mujoco")]
#[test]
fn jaco_episodes_do_not_depend_on_how_many_threads_step_them() {
    use super::boards::BoardPool;
    use super::collect::Collector;
    use crate::envs::embodiments::Embodiment;
    use rand::Rng;
    use rand_chacha::ChaCha8Rng;

    let game = TileSwap::new();
    let pool = BoardPool::new(&game, 3, crate::envs::boards::split::Split::Train).unwrap();
    let collect = |threads: usize| {
        let pool_of_threads = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool_of_threads.install(|| {
            let mut collector = Collector::new(&game, Embodiment::Jaco, 4, 12).unwrap();
            let (low, high) = collector.action_bounds();
            let mut rng = ChaCha8Rng::seed_from_u64(9);
            collector.collect(&[0, 3, 7, 11], Starts::Pool(&pool), &mut rng, |_, rows, rng| {
                (0..rows)
                    .flat_map(|_| {
                        low.iter().zip(&high).map(|(l, h)| rng.random_range(*l..*h) as f32).collect::<Vec<_>>()
                    })
                    .collect()
            })
        })
    };
    let (one, two) = (collect(1), collect(2));
    assert_eq!(one, two);
    assert!(one.iter().all(|e| !e.actions.is_empty()));
}
