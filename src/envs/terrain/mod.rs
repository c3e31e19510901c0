//! Terrain maps for TRADYN (thesis 5.5.1): images over [0, 1]² whose colour is the ground's friction
//! coefficient and whose inverted colour the robot observes.

pub mod generate;
pub mod map;

use serde::{Deserialize, Serialize};

pub use generate::generate_map;
pub use map::{friction_of_color, TerrainMap, MAP_SIZE, MU_MAX, MU_MIN};

/// Which half of a map set: models train on one and are tested on the other.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TerrainSplit {
    Train,
    Test,
}

impl TerrainSplit {
    pub fn name(self) -> &'static str {
        match self {
            TerrainSplit::Train => "train",
            TerrainSplit::Test => "test",
        }
    }
}
