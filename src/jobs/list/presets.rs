//! `mbrl list presets`: what each method's `--preset` sets, read from the method's own preset constructor, and
//! its cost: the work it does (derived from the preset) and, for the small presets, a measured wall time.

use super::Table;
use crate::envs::embodiments::Embodiment;
use crate::jobs::train::PetsPreset;
use crate::models::ball::learn::TrainSettings;
use crate::models::context_net::{ContextConfig, EnvFamily, Preset as ContextPreset};
use crate::models::dlgpd::config::{DlgpdConfig, Preset as DlgpdPreset};
use crate::models::pets::{PetsConfig, Preset as PetsEnginePreset};
use crate::models::seads::{Preset as SeadsPreset, SeadsConfig};

/// Wall times of `mbrl train METHOD --preset small`, measured once on a 2-core machine (release build of commit
/// 6d7a81e, other builds running beside it) on the datasets of the README's examples. Remeasure when a preset
/// or the training step changes; the WORK column is the cost that follows from the preset alone.
fn measured(method: &str, preset: &str, family: &str) -> &'static str {
    match (method, preset, family) {
        ("pets", "small", _) => "17.7 s (pendulum, 5400 transitions)",
        ("context", "small", "toy") => "11.0 s (toy:inner, 1000 pairs)",
        ("dlgpd", "small", _) => "67.1 s (pendulum, 500 rollouts)",
        _ => "",
    }
}

pub fn table() -> Table {
    let header = ["METHOD", "PRESET", "FOR", "NETWORK", "STEPS", "BATCH", "WORK", "MEASURED (2 cores)"];
    let mut table = Table::new(&header);
    let mut add =
        |method: &str, preset: &str, family: &str, network: String, steps: String, batch: String, work: String| {
            let cells = [method, preset, family, &network, &steps, &batch, &work, measured(method, preset, family)];
            table.row(cells.map(String::from).to_vec());
        };
    for (preset, name) in [(PetsPreset::Small, "small"), (PetsPreset::Medium, "medium")] {
        let c = PetsConfig::preset(match preset {
            PetsPreset::Small => PetsEnginePreset::Small,
            PetsPreset::Medium => PetsEnginePreset::Medium,
        });
        let network = format!("{} × MLP {}×{} {}", c.ensemble, c.hidden_layers, c.hidden_units, c.activation.name());
        let work = format!("{} transitions", si(c.steps * (c.batch_size * c.ensemble) as u64));
        add("pets", name, "any", network, c.steps.to_string(), c.batch_size.to_string(), work);
    }
    for (preset, name) in scale_presets() {
        let engine = match preset {
            Scale::Small => ContextPreset::Small,
            Scale::Medium => ContextPreset::Medium,
            Scale::Paper => ContextPreset::Paper,
        };
        for (family, label) in [(EnvFamily::Toy, "toy"), (EnvFamily::Control, "control")] {
            let c = ContextConfig::preset(engine, family);
            let network = format!("GRU {}, MLPs {}, D_β {}", c.embedding, c.hidden_units, c.latent_dim);
            let transitions = c.steps * (c.batch_size * (c.chunk_states - 1)) as u64;
            let batch = format!("{} × {} states", c.batch_size, c.chunk_states);
            let family = if label == "toy" { "toy" } else { label };
            add(
                "context",
                name,
                family,
                network,
                c.steps.to_string(),
                batch,
                format!("{} transitions", si(transitions)),
            );
        }
    }
    for (preset, name) in scale_presets() {
        let c = DlgpdConfig::preset(match preset {
            Scale::Small => DlgpdPreset::Small,
            Scale::Medium => DlgpdPreset::Medium,
            Scale::Paper => DlgpdPreset::Paper,
        });
        let network = match c.images {
            true => format!("conv VAE on 64×64 frames, latent {}", c.latent_dim),
            false => format!("MLP VAE {} on (cos θ, sin θ), latent {}", c.hidden_units, c.latent_dim),
        };
        let work = format!("{} transitions", si(c.steps * c.batch_size as u64));
        add("dlgpd", name, "pendulum", network, c.steps.to_string(), c.batch_size.to_string(), work);
    }
    for (preset, name) in scale_presets() {
        let engine = match preset {
            Scale::Small => SeadsPreset::Small,
            Scale::Medium => SeadsPreset::Medium,
            Scale::Paper => SeadsPreset::Paper,
        };
        for (embodiment, family) in [
            (Embodiment::Cursor, "<game>:cursor"),
            (Embodiment::Reacher, "<game>:reacher"),
            (Embodiment::Jaco, "<game>:jaco"),
        ] {
            // The skill count (the game's moves) changes no size listed here.
            let c = SeadsConfig::preset(engine, 12, embodiment);
            let sac = c.sac_hidden.iter().map(usize::to_string).collect::<Vec<_>>().join("×");
            let network = format!("SAC {sac}, model {}", c.model_hidden);
            let batch = format!("SAC {}, model {}", c.sac_batch, c.model_batch);
            let work = format!("{} env steps", si(c.env_steps));
            add("seads", name, family, network, "—".into(), batch, work);
        }
    }
    let ball = TrainSettings::default();
    let work = format!("{} frames", si(ball.steps * (ball.batch_size * ball.chunk_len) as u64));
    let batch = format!("{} × {} frames", ball.batch_size, ball.chunk_len);
    add("ball-ekf", "(none)", "ball", "gray-box EKF".into(), ball.steps.to_string(), batch, work);
    table.note("");
    table.note(
        "WORK = steps × batch (× ensemble members for pets): the samples a run processes, from the preset alone.",
    );
    table.note("control = pendulum, mountaincar and unicycle; tradyn trains the context model with these rows.");
    table.note("dlgpd fits its GPs on the batch's points every step; seads steps until its env-step budget is spent.");
    table.note("Measured: release build, 2-core machine with other builds running; the dataset is in brackets.");
    table
}

/// The three scales every method but PETS offers (each method's own `--preset` enum names them alike).
#[derive(Clone, Copy)]
enum Scale {
    Small,
    Medium,
    Paper,
}

fn scale_presets() -> [(Scale, &'static str); 3] {
    [(Scale::Small, "small"), (Scale::Medium, "medium"), (Scale::Paper, "paper")]
}

/// 2560000 → "2.56M": counts to three significant digits.
fn si(n: u64) -> String {
    let (value, suffix) = match n {
        0..1_000 => return n.to_string(),
        1_000..1_000_000 => (n as f64 / 1e3, "k"),
        1_000_000..1_000_000_000 => (n as f64 / 1e6, "M"),
        _ => (n as f64 / 1e9, "G"),
    };
    let digits = if value >= 100.0 {
        0
    } else if value >= 10.0 {
        1
    } else {
        2
    };
    format!("{value:.digits$}{suffix}")
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::ValueEnum;

    #[test]
    fn every_preset_a_method_takes_is_listed_with_its_own_settings() {
        let table = table();
        let listed = |method: &str| -> Vec<String> {
            table.rows().iter().filter(|r| r[0] == method).map(|r| r[1].clone()).collect()
        };
        fn names<E: ValueEnum>() -> Vec<String> {
            E::value_variants().iter().map(|v| v.to_possible_value().unwrap().get_name().to_string()).collect()
        }
        let methods = [
            ("context", names::<crate::jobs::train::ContextPreset>()),
            ("dlgpd", names::<crate::jobs::train::DlgpdPresetChoice>()),
            ("seads", names::<crate::jobs::train::SeadsPreset>()),
        ];
        for (method, presets) in methods {
            for name in presets {
                assert!(listed(method).contains(&name), "{method} {name}");
            }
        }
        assert_eq!(listed("pets"), ["small", "medium"]);
        let pets_small = &table.rows()[0];
        assert_eq!(pets_small[3..7], ["5 × MLP 3×64 silu", "2000", "256", "2.56M transitions"]);
    }

    #[test]
    fn counts_read_in_three_digits() {
        assert_eq!(si(999), "999");
        assert_eq!(si(2_560_000), "2.56M");
        assert_eq!(si(60_000), "60.0k");
        assert_eq!(si(10_000_000), "10.0M");
        assert_eq!(si(512_000_000), "512M");
    }
}
