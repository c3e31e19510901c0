//! TRADYN (thesis chapter 5): the context model of Explore the Context on the unicycle's observation, with the
//! terrain features under the robot as a third GRU input that is read from the map at every predicted position
//! (eq. 5.11/5.12). Its ablation ("−T") is the same network without that input, predicting the terrain features
//! as part of the state. Both train through `models::context`; this module adds what is specific to the robot:
//! the map lookup, the learned model as a planner's dynamics, and navigation (eq. 5.13).

pub mod dynamics;
pub mod navigation;
pub mod options;

use std::path::Path;
use std::sync::Arc;

pub use dynamics::TradynDynamics;

use crate::envs::terrain::TerrainMap;
use crate::envs::unicycle::{OBSERVATION_NAMES, TERRAIN_FEATURES};
use crate::envs::EnvName;
use crate::error::{Error, Result};
use crate::models::context::fast::LocalFeatures;
use crate::models::context::{self, LoadedModel, StateSpace};
use crate::train::Accept;

pub const METHOD: &str = "tradyn";

/// The model's state: the unicycle's observation; with `terrain_lookup` its terrain features are input read
/// from the map, without it they are predicted like the rest (the −T ablation).
pub fn state_space(terrain_lookup: bool) -> StateSpace {
    StateSpace::Observation {
        names: OBSERVATION_NAMES.iter().map(|s| s.to_string()).collect(),
        local_dim: if terrain_lookup { TERRAIN_FEATURES } else { 0 },
    }
}

/// A trained TRADYN checkpoint.
#[derive(Clone)]
pub struct TradynModel {
    pub loaded: LoadedModel,
}

impl TradynModel {
    pub fn load(dir: &Path) -> Result<Self> {
        Self::load_accepting(dir, Accept::Finished)
    }

    /// Also a run still in training when `accept` takes it (its best-validation weights so far).
    pub fn load_accepting(dir: &Path, accept: Accept) -> Result<Self> {
        let loaded = context::load_method_accepting(dir, &EnvName::Unicycle(None), METHOD, accept)?;
        let spec = &loaded.run.model;
        let names_fit = spec.observations && spec.state_names.iter().map(String::as_str).eq(OBSERVATION_NAMES);
        if !names_fit || spec.action_dim != 2 || ![0, TERRAIN_FEATURES].contains(&spec.local_dim) {
            return Err(Error::bad_file(
                &dir.join("config.json"),
                format!(
                    "model: a TRADYN model reads the unicycle's observation ({}) and 2 actions, with 0 or {TERRAIN_FEATURES} \
                     features read from the map",
                    OBSERVATION_NAMES.join(", ")
                ),
            ));
        }
        Ok(TradynModel { loaded })
    }

    /// Whether the model reads terrain at predicted positions (+T) or predicts it (−T).
    pub fn terrain_lookup(&self) -> bool {
        self.loaded.fast.local_dim > 0
    }

    pub fn variant_name(&self) -> &'static str {
        if self.terrain_lookup() {
            "+T (terrain lookup)"
        } else {
            "−T (terrain predicted)"
        }
    }
}

/// Reads τ from a map at the predicted position (x, y are the first two predicted features; positions off the
/// map read its edge, as the simulator clips them there).
pub struct MapLookup(pub Arc<TerrainMap>);

impl LocalFeatures for MapLookup {
    fn at(&self, predicted: &[f32], out: &mut [f32]) {
        let tau = self.0.feature_at(predicted[0] as f64, predicted[1] as f64);
        for (o, t) in out.iter_mut().zip(tau) {
            *o = t as f32;
        }
    }
}

#[cfg(test)]
mod tests;
