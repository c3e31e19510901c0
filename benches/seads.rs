//! SEADS: breadth-first search through a forward model of the paper's shape (256 hidden units; weights that
//! encode LightsOut's rules, so the search meets every reachable board as a perfectly trained model would and
//! each query costs what a trained model's does), environment steps of episode collection, and one training
//! epoch at paper sizes. Thesis: 2.02 s (depth 5) and 301.8 s (depth 9) per search. Aim: depth 9 one-sided
//! under 30 s, bidirectional under 1 s.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use mbrl::envs::boards::{gf2, BoardGame, LightsOut};
use mbrl::envs::embodiments::Embodiment;
use mbrl::models::seads::boards::BoardPool;
use mbrl::models::seads::collect::{Collector, Starts};
use mbrl::models::seads::forward_model::lightsout_rules_model;
use mbrl::models::seads::planner::LearnedSuccessors;
use mbrl::models::seads::{Preset, SeadsConfig, SeadsTrainer};
use mbrl::planning::bfs::{bidirectional, breadth_first, SearchLimits};
use mbrl::train::TrainingMethod;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

// The binary runs on mimalloc (cmd/main.rs) and these figures are meant to be its: the library no longer
// chooses the process allocator, so each benchmark declares the same one.
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

/// A board whose shortest solution has `depth` presses (distinct presses up to 11 are always optimal on 5×5:
/// the quiet patterns that would allow a shorter solution have 12 or more lights).
fn board_at(game: &LightsOut, depth: usize) -> <LightsOut as BoardGame>::State {
    let presses: Vec<usize> = (0..depth).map(|i| (i * 7) % 25).collect();
    let board = game.pressed(&presses);
    assert_eq!(gf2::solve(game, board).unwrap().len(), depth);
    board
}

fn search(c: &mut Criterion) {
    let game = LightsOut::new(5).unwrap();
    let model = lightsout_rules_model(&game, 256).unwrap();
    let limits = SearchLimits::default();
    let goal = game.goal();
    let mut group = c.benchmark_group("seads_bfs_lightsout_learned_model_256");
    group.sample_size(10);
    for depth in [5, 9] {
        let board = board_at(&game, depth);
        if depth == 5 {
            let one_sided = LearnedSuccessors::new(&game, &model, false);
            group.bench_function(format!("depth_{depth}/bfs"), |b| {
                b.iter(|| breadth_first(&one_sided, board, |s| *s == goal, &limits, |_| {}).unwrap())
            });
        }
        let checked = LearnedSuccessors::new(&game, &model, true);
        group.bench_function(format!("depth_{depth}/bidirectional_verified"), |b| {
            b.iter(|| bidirectional(&checked, board, goal, &limits, |_| {}).unwrap())
        });
    }
    group.finish();
}

/// One-sided depth 9 takes tens of seconds: timed once, outside criterion's ten samples.
fn search_depth9_once(_: &mut Criterion) {
    let game = LightsOut::new(5).unwrap();
    let model = lightsout_rules_model(&game, 256).unwrap();
    let one_sided = LearnedSuccessors::new(&game, &model, false);
    let goal = game.goal();
    let started = std::time::Instant::now();
    let result =
        breadth_first(&one_sided, board_at(&game, 9), |s| *s == goal, &SearchLimits::default(), |_| {}).unwrap();
    println!(
        "seads_bfs_lightsout_learned_model_256/depth_9/bfs (one run): {:.1} s, {} states expanded, plan of {}",
        started.elapsed().as_secs_f64(),
        result.stats.expanded,
        result.plan.map_or(0, |p| p.len())
    );
}

fn collection(c: &mut Criterion) {
    let game = LightsOut::new(5).unwrap();
    let pool = BoardPool::new(&game, 5, mbrl::envs::boards::Split::Train).unwrap();
    let mut collector = Collector::new(&game, Embodiment::Cursor, 32, 25).unwrap();
    let labels: Vec<usize> = (0..32).collect::<Vec<_>>().iter().map(|k| k % 25).collect();
    let mut group = c.benchmark_group("seads_collect_lightsout_cursor");
    group.sample_size(20);
    // Random actions: the episodes run to the step limit unless a push lands, as early in training.
    group.throughput(Throughput::Elements(32 * 10));
    group.bench_function("32_episodes_random_policy", |b| {
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        b.iter(|| {
            collector.collect(&labels, Starts::Pool(&pool), &mut rng, |_, rows, rng| {
                (0..rows * 3).map(|_| rng.random_range(-1.0f32..1.0)).collect()
            })
        })
    });
    group.finish();
}

fn epoch(c: &mut Criterion) {
    let game = LightsOut::new(5).unwrap();
    let config = SeadsConfig::preset(Preset::Paper, 25, Embodiment::Cursor);
    let mut trainer = SeadsTrainer::new(config, game, Embodiment::Cursor, 0).unwrap();
    // Fill the memory so that every timed epoch updates the model and SAC.
    let mut epoch = 0;
    while epoch < 8 {
        epoch += 1;
        trainer.step(epoch).unwrap();
    }
    let mut group = c.benchmark_group("seads_epoch_lightsout_cursor_paper");
    group.sample_size(10);
    group.bench_function("collect_32_relabel_512_model_4_sac_16", |b| {
        b.iter(|| {
            epoch += 1;
            trainer.step(epoch).unwrap()
        })
    });
    group.finish();
}

criterion_group!(benches, search, search_depth9_once, collection, epoch);
criterion_main!(benches);
