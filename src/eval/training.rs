//! The loss curve of a training run, beside its checkpoint: losses.csv and loss.png. It lives with the reports
//! rather than in `train/` because it draws with `eval::plot`, and `train/` sits below `eval/`.

use std::collections::BTreeMap;
use std::path::Path;

use super::plot::{line_panels, line_plot, Panel, Series};
use crate::error::Result;
use crate::models::registry::LossPlot;
use crate::run::dir::METRICS_FILE;
use crate::train::data_file::scalar_history;
use crate::train::loss_history;
use crate::util::table::write_csv;

/// Writes losses.csv and loss.png of the run in `dir` from its metrics log (so a resumed run gets the whole
/// curve): the batch loss of every step and, where the method validates, the held-out loss at each validation
/// (the curve that shows overfitting and which snapshot was kept as the best). Returns the batch losses.
pub fn write_loss_report(dir: &Path, plot: LossPlot) -> Result<Vec<(u64, f64)>> {
    let metrics = dir.join(METRICS_FILE);
    let losses = loss_history(&metrics)?;
    let validation: BTreeMap<u64, f64> = scalar_history(&metrics, "valid/loss")?.into_iter().collect();
    let rows: Vec<Vec<String>> = losses
        .iter()
        .map(|(k, l)| {
            vec![k.to_string(), format!("{l:.6}"), validation.get(k).map_or(String::new(), |v| format!("{v:.6}"))]
        })
        .collect();
    let validation_column = plot.separate_validation.map_or("validation_loss", |(column, _)| column);
    write_csv(&dir.join("losses.csv"), &["step", "loss", validation_column], &rows)?;
    let loss = Series { name: "batch loss".into(), points: losses.iter().map(|(k, l)| (*k as f64, *l)).collect() };
    let held_out = |name: &str| Series {
        name: name.to_string(),
        points: validation.iter().map(|(k, v)| (*k as f64, *v)).collect(),
    };
    let path = dir.join("loss.png");
    match plot.separate_validation {
        Some((_, label)) if !validation.is_empty() => {
            let panel =
                |y_label: &str, series| Panel { y_label: y_label.to_string(), series: vec![series], y_range: None };
            let panels = [panel(plot.y_label, loss), panel(label, held_out(label))];
            line_panels(&path, plot.title, "step", &panels)?;
        }
        _ => {
            let mut curves = vec![loss];
            if !validation.is_empty() {
                curves.push(held_out("validation loss (held out)"));
            }
            line_plot(&path, plot.title, "step", plot.y_label, &curves)?;
        }
    }
    Ok(losses)
}
