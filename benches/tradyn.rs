//! TRADYN's planning cost: one navigation MPC step on a learned model at the thesis' CEM size (1000 candidates ×
//! horizon 30 × 20 iterations, colored noise) with the terrain read from the map at every predicted position,
//! for the thesis' network (200 units) and the small preset's (64). The simulator's own speed is
//! `benches/unicycle.rs`.

use std::sync::Arc;

use criterion::{criterion_group, criterion_main, Criterion};
use mbrl::data::collect::{collect_instance_pairs, InstancePairSettings};
use mbrl::data::write_dataset;
use mbrl::envs::terrain::generate_map;
use mbrl::envs::unicycle::UnicycleTerrain;
use mbrl::envs::EnvName;
use mbrl::models::context::{ContextConfig, EnvFamily, Preset};
use mbrl::models::tradyn::navigation::{NavigationObjective, NavigationSettings};
use mbrl::models::tradyn::{self, TradynDynamics, TradynModel};
use mbrl::planning::{Cem, CemConfig};
use mbrl::run::dir::Provenance;
use mbrl::run::NullMonitor;
use mbrl::train::job::start;
use mbrl::train::{Accept, Request};

// The binary runs on mimalloc (cmd/main.rs) and these figures are meant to be its: the library no longer
// chooses the process allocator, so each benchmark declares the same one.
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

/// A one-step-trained checkpoint of `width` units (+T), loaded as the CLI loads it.
fn model(dir: &std::path::Path, width: usize) -> TradynModel {
    let map = generate_map(0, 0);
    let env = EnvName::Unicycle(Some(Arc::new(UnicycleTerrain::new(vec![map]))));
    let data = dir.join("pairs.mcap");
    let collect = InstancePairSettings { env, instances: 20, steps: 60, seed: 1, command_line: String::new() };
    write_dataset(&data, &collect_instance_pairs(&collect, &NullMonitor).unwrap()).unwrap();
    let mut config = ContextConfig::preset(Preset::Paper, EnvFamily::Control);
    (config.embedding, config.hidden_units, config.steps, config.batch_size) = (width, width, 1, 8);
    let out = dir.join(format!("model-{width}"));
    let request = Request::<tradyn::Tradyn> {
        env: None,
        data: vec![data],
        seed: 0,
        config,
        variant: true,
        provenance: Provenance::new(String::new(), 0, 1),
    };
    start(&out, &request, &NullMonitor).unwrap();
    TradynModel::load(&out, Accept::Finished).unwrap()
}

fn planning_step(c: &mut Criterion) {
    let dir = tempfile::tempdir().unwrap();
    let map = Arc::new(generate_map(0, 1));
    let init = [0.3, 0.4, 0.0, 1.0];
    let mut group = c.benchmark_group("tradyn_planning_step_1000x30x20");
    group.sample_size(10);
    for width in [200, 64] {
        let trained = model(dir.path(), width);
        let rows = 10 * trained.loaded.fast.transition_dim();
        let context: Vec<f32> = (0..rows).map(|i| ((i % 7) as f32 - 3.0) * 0.1).collect();
        let dynamics = TradynDynamics::new(trained, map.clone(), &context);
        let objective = NavigationObjective { dynamics: &dynamics, init: &init, goal: [0.7, 0.6] };
        let config: CemConfig = NavigationSettings::thesis().cem;
        let mut cem = Cem::new(config, 0).unwrap();
        group.bench_function(format!("{width}_units"), |b| b.iter(|| cem.plan(&objective, |_| {})));
    }
    group.finish();
}

criterion_group!(benches, planning_step);
criterion_main!(benches);
