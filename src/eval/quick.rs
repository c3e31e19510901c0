//! `mbrl eval quick`: a small reproduction of every method, the README's first command. Each method adds
//! its slice here; the whole job stays around a minute on two cores.

use std::path::Path;

use super::swingup::{self, SwingupSettings};
use crate::envs::pendulum::PendulumVariant;
use crate::error::{Error, Result};
use crate::run::atomic::write_atomic;
use crate::run::dir::Provenance;
use crate::run::Monitor;

pub const SWINGUP_EPISODES: usize = 5;

pub struct QuickSummary {
    pub lines: Vec<String>,
}

pub fn run_quick(provenance: &Provenance, out_dir: &Path, monitor: &dyn Monitor) -> Result<QuickSummary> {
    std::fs::create_dir_all(out_dir).map_err(|e| Error::io(out_dir, e))?;
    let settings = SwingupSettings::thesis(PendulumVariant::Standard);
    let swing = swingup::evaluate(&settings, SWINGUP_EPISODES, provenance, &out_dir.join("pendulum-swingup"), monitor)?;
    let lines = vec![format!(
        "pendulum swing-up (ground-truth model, CEM {}×{}×{}): {}/{} episodes succeeded; see pendulum-swingup/report.md",
        settings.cem.candidates, settings.cem.horizon, settings.cem.iterations, swing.successes, swing.episodes
    )];
    let mut md = String::from("# mbrl quick reproduction\n\nSmall-scale runs of each implemented method.\n\n");
    for line in &lines {
        md.push_str(&format!("- {line}\n"));
    }
    let path = out_dir.join("report.md");
    write_atomic(&path, |w| w.write_all(md.as_bytes()).map_err(|e| Error::io(&path, e)))?;
    Ok(QuickSummary { lines })
}
