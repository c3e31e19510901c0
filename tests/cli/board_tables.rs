//! Thesis Table 7.1 (boards per solution depth) and Table 7.2 (train/test split per depth), recomputed.

use mbrl::envs::boards::depth::{DenseIndex, DepthTable};
use mbrl::envs::boards::{split_of, LightsOut, Split, TileSwap};

// BoardGame brings canonical_string into scope.

use mbrl::eval::boards::{LIGHTSOUT_TABLE_7_1, LIGHTSOUT_TABLE_7_2, TILESWAP_TABLE_7_1, TILESWAP_TABLE_7_2};

fn split_counts<G: DenseIndex>(game: &G, table: &DepthTable, depth: u8) -> (u64, u64) {
    let mut counts = (0, 0);
    for index in table.indices_at(depth) {
        match split_of(&game.canonical_string(game.state_at(index))) {
            Split::Train => counts.0 += 1,
            Split::Test => counts.1 += 1,
        }
    }
    counts
}

#[test]
fn lightsout_5x5_depths_and_splits_match_the_thesis() {
    let game = LightsOut::new(5).unwrap();
    let table = DepthTable::build(&game).unwrap();
    assert_eq!(table.counts(), LIGHTSOUT_TABLE_7_1.to_vec());
    assert_eq!(table.max_depth(), 15, "no 5×5 board deeper than 15");
    for (d, expected) in LIGHTSOUT_TABLE_7_2.iter().enumerate() {
        assert_eq!(split_counts(&game, &table, d as u8 + 1), *expected, "depth {}", d + 1);
    }
}

#[test]
fn tileswap_depths_and_splits_match_the_thesis() {
    let game = TileSwap::new();
    let table = DepthTable::build(&game).unwrap();
    assert_eq!(table.counts(), TILESWAP_TABLE_7_1.to_vec());
    for (d, expected) in TILESWAP_TABLE_7_2.iter().enumerate() {
        assert_eq!(split_counts(&game, &table, d as u8 + 1), *expected, "depth {}", d + 1);
    }
}
