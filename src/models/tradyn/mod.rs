//! TRADYN (thesis chapter 5): the context model of Explore the Context on the unicycle's observation, with the
//! terrain features under the robot as a third GRU input that is read from the map at every predicted position
//! (eq. 5.11/5.12). Its ablation ("−T") is the same network without that input, predicting the terrain features
//! as part of the state. Both train through `models::context_net`, the network they share; this module adds what is specific to the robot:
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
use crate::models::context_net::fast::LocalFeatures;
use crate::models::context_net::{
    self, ContextConfig, ContextDetails, ContextSummary, ContextTrainer, LoadedModel, StateSpace,
};
use crate::train::run_dir::Field;
use crate::train::{open_run, Accept, Method, Prepared, Request, RunRecord, Trained};

pub const METHOD: &str = "tradyn";

/// The model's state: the unicycle's observation; with `terrain_lookup` its terrain features are input read
/// from the map, without it they are predicted like the rest (the −T ablation).
pub fn state_space(terrain_lookup: bool) -> StateSpace {
    StateSpace::Observation {
        names: OBSERVATION_NAMES.iter().map(|s| s.to_string()).collect(),
        local_dim: if terrain_lookup { TERRAIN_FEATURES } else { 0 },
    }
}

/// TRADYN as the training job drives it: the context network on the unicycle's observation; its variant is
/// whether the terrain is looked up (+T) or predicted (−T).
pub struct Tradyn;

impl Method for Tradyn {
    const NAME: &'static str = METHOD;
    const TITLE: &'static str = "TRADYN";
    type Config = ContextConfig;
    type Variant = bool;
    type Details = ContextDetails;
    type Trainer = ContextTrainer;

    fn prepare(request: &Request<Self>) -> Result<Prepared<Self>> {
        context_net::prepare_model(request, &state_space(request.variant))
    }

    fn variant_of(record: &RunRecord<Self>) -> Result<bool> {
        Ok(record.details.model.local_dim > 0)
    }

    fn check_record(record: &RunRecord<Self>) -> Result<()> {
        context_net::check_details(&record.details, &record.data)?;
        let spec = &record.details.model;
        let names_fit = spec.observations && spec.state_names.iter().map(String::as_str).eq(OBSERVATION_NAMES);
        if !names_fit || spec.action_dim != 2 || ![0, TERRAIN_FEATURES].contains(&spec.local_dim) {
            return Err(Error::config(format!(
                "model: a TRADYN model reads the unicycle's observation ({}) and 2 actions, with 0 or {TERRAIN_FEATURES} \
                 features read from the map",
                OBSERVATION_NAMES.join(", ")
            )));
        }
        Ok(())
    }

    /// The lookup is no config field: the model records it as the size of the terrain features it reads.
    fn fixed_fields(request: &Request<Self>) -> Vec<Field> {
        let lookup = if request.variant { serde_json::Value::from(TERRAIN_FEATURES) } else { serde_json::Value::Null };
        vec![Field {
            show: |v| if v.is_null() { "off (--no-terrain)".into() } else { "on".into() },
            ..Field::new("the terrain lookup", "/model/local_dim", lookup)
        }]
    }
}

/// What `mbrl train tradyn` reports of a finished run.
pub fn summary(trained: &Trained<Tradyn>, dir: &Path) -> ContextSummary {
    let lookup = if trained.record.details.model.local_dim > 0 {
        "with terrain lookup"
    } else {
        "without terrain lookup (−T: terrain predicted)"
    };
    ContextSummary::of(format!("a TRADYN model {lookup}"), trained, dir)
}

/// A trained TRADYN checkpoint.
#[derive(Clone)]
pub struct TradynModel {
    pub loaded: LoadedModel,
}

impl TradynModel {
    /// A TRADYN run, finished or (when `accept` takes it) still training: then its best-validation weights.
    pub fn load(dir: &Path, accept: Accept) -> Result<Self> {
        let (opened, run) = open_run::<Tradyn>(dir, accept)?;
        let loaded = context_net::model_from(&opened, run.retag(), &EnvName::Unicycle(None))?;
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
