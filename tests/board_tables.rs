//! Thesis Table 7.1 (boards per solution depth) and Table 7.2 (train/test split per depth), recomputed.

use mbrl::envs::boards::depth::{DenseIndex, DepthTable};
use mbrl::envs::boards::{split_of, LightsOut, Split, TileSwap};

// BoardGame brings canonical_string into scope.

const LIGHTSOUT_TABLE_7_1: [u64; 16] =
    [1, 25, 300, 2300, 12650, 53130, 176176, 467104, 982335, 1596279, 1935294, 1684446, 1004934, 383670, 82614, 7350];
const TILESWAP_TABLE_7_1: [u64; 17] =
    [1, 12, 88, 470, 1978, 6658, 18081, 38936, 65246, 83000, 76688, 48316, 18975, 4024, 382, 24, 1];

/// (train, test) for depths 1-5.
const LIGHTSOUT_TABLE_7_2: [(u64, u64); 5] = [(7, 18), (99, 201), (785, 1515), (4200, 8450), (17849, 35281)];
const TILESWAP_TABLE_7_2: [(u64, u64); 5] = [(7, 5), (31, 57), (179, 291), (683, 1295), (2237, 4421)];

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
