//! Planning time for LightsOut 5×5 and TileSwap boards with the true rules used as a successor model
//! (every node expanded through the model, as a learned model would be; no GF(2) shortcut).
//! Thesis figures on a 2.2 GHz Xeon: 2.02 s (LightsOut depth 5), 301.8 s (depth 9). Aim: depth 9 < 1 s.

use criterion::{criterion_group, criterion_main, Criterion};
use mbrl::envs::boards::depth::DepthTable;
use mbrl::envs::boards::sets::boards_at;
use mbrl::envs::boards::{BoardGame, LightsOut, TileSwap};
use mbrl::planning::bfs::{bidirectional, breadth_first, GameRules, SearchLimits};

// The binary runs on mimalloc (cmd/main.rs) and these figures are meant to be its: the library no longer
// chooses the process allocator, so each benchmark declares the same one.
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn first_board_at<G: mbrl::envs::boards::depth::DenseIndex>(game: &G, depth: u8) -> G::State {
    let table = DepthTable::build(game).unwrap();
    boards_at(game, &table, depth, None)[0]
}

fn plan<G: BoardGame>(c: &mut Criterion, game: &G, name: &str, board: G::State, unidirectional: bool) {
    let limits = SearchLimits::default();
    let goal = game.goal();
    if unidirectional {
        c.bench_function(&format!("{name}/bfs"), |b| {
            b.iter(|| breadth_first(&GameRules(game), board, |s| *s == goal, &limits, |_| {}).unwrap())
        });
    }
    c.bench_function(&format!("{name}/bidirectional"), |b| {
        b.iter(|| bidirectional(&GameRules(game), board, goal, &limits, |_| {}).unwrap())
    });
}

fn boards(c: &mut Criterion) {
    let lightsout = LightsOut::new(5).unwrap();
    for depth in [5, 9, 12] {
        plan(c, &lightsout, &format!("lightsout_depth_{depth}"), first_board_at(&lightsout, depth), depth <= 9);
    }
    let tileswap = TileSwap::new();
    for depth in [10, 16] {
        plan(c, &tileswap, &format!("tileswap_depth_{depth}"), first_board_at(&tileswap, depth), true);
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10);
    targets = boards
}
criterion_main!(benches);
