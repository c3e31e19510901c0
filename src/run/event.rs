//! The events a long-running job reports. One stream feeds the console, the TUI and `metrics.jsonl`,
//! so everything a user can see live can also be replayed later by `mbrl watch`.

use serde::{Deserialize, Serialize};

/// One line of `metrics.jsonl`, tagged by `kind`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Event {
    /// Sent once at the start: names the job and the method-specific panels the TUI should draw.
    Layout { title: String, panels: Vec<PanelSpec> },
    /// A scalar metric at a step. Names are slash-separated paths such as `cem/best_cost`.
    Scalar {
        name: String,
        step: u64,
        #[serde(deserialize_with = "null_as_nan")]
        value: f64,
    },
    /// Progress of the current phase: `done` of `total` units.
    Progress { phase: String, done: u64, total: u64 },
    /// A human-readable note (a result line, a warning).
    Message { text: String },
    /// A block of preformatted text for a method panel (a board, a plan), replacing that panel's previous text.
    Text { panel: String, text: String },
    /// The job ended; `ok` is false when it failed.
    Finished { ok: bool },
}

/// JSON has no NaN: serde_json writes a NaN (or infinite) metric as `null`, and a diverged loss must still
/// read back, as the value it stands for, not as a broken line.
fn null_as_nan<'de, D: serde::Deserializer<'de>>(deserializer: D) -> Result<f64, D::Error> {
    Ok(Option::<f64>::deserialize(deserializer)?.unwrap_or(f64::NAN))
}

/// A method-specific plot: several scalar series drawn against their step.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PanelSpec {
    pub title: String,
    pub x_label: String,
    /// Metric names drawn in this panel.
    pub series: Vec<String>,
    /// When true, a step not larger than the last one starts the series afresh (a new episode or a new
    /// planner call), so the panel shows the latest episode instead of overdrawing all of them.
    #[serde(default)]
    pub restart_on_rewind: bool,
    /// Set for a panel that draws its first two series against each other on a fixed plane (an
    /// effector's path over a board) instead of against their step.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub path: Option<PathView>,
}

/// The plane of a path panel.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PathView {
    pub x: [f64; 2],
    pub y: [f64; 2],
    /// Cells per side of a grid drawn under the path; 0 draws none.
    pub grid: u32,
    /// Whether y grows downwards, as the rows of a board printed as text do.
    pub y_down: bool,
    /// Colours under the path (a terrain map), coarse enough to send in a layout.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub background: Option<Background>,
}

/// An n × n grid of colours over a path panel's plane: cell (i, j), at `rgb[3 (i n + j)..]`, covers the i-th
/// slice of the plane's x range and the j-th of its y range.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Background {
    pub cells: u32,
    pub rgb: Vec<u8>,
}

impl Background {
    /// The colour at fractions (u, v) ∈ [0, 1]² of the plane's x and y ranges; `None` for a grid whose bytes do
    /// not match its size (a corrupt replayed file).
    pub fn color_at(&self, u: f64, v: f64) -> Option<[u8; 3]> {
        let n = self.cells as usize;
        if n == 0 || self.rgb.len() != n.checked_mul(n)?.checked_mul(3)? {
            return None;
        }
        let index = |f: f64| ((f.clamp(0.0, 1.0) * n as f64) as usize).min(n - 1);
        let at = (index(u) * n + index(v)) * 3;
        Some([self.rgb[at], self.rgb[at + 1], self.rgb[at + 2]])
    }
}

impl Event {
    pub fn scalar(name: impl Into<String>, step: u64, value: f64) -> Self {
        Event::Scalar { name: name.into(), step, value }
    }

    pub fn progress(phase: impl Into<String>, done: u64, total: u64) -> Self {
        Event::Progress { phase: phase.into(), done, total }
    }

    pub fn message(text: impl Into<String>) -> Self {
        Event::Message { text: text.into() }
    }

    pub fn text(panel: impl Into<String>, text: impl Into<String>) -> Self {
        Event::Text { panel: panel.into(), text: text.into() }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_round_trips_through_json() {
        let event = Event::text("board", "■ · ■\n· ■ ·\nplan: push (0, 1)\n");
        let line = serde_json::to_string(&event).expect("serialize");
        assert!(line.starts_with(r#"{"kind":"text","panel":"board","#), "{line}");
        assert_eq!(serde_json::from_str::<Event>(&line).expect("deserialize"), event);
    }

    #[test]
    fn a_nan_metric_is_written_as_null_and_read_back_as_nan() {
        let line = serde_json::to_string(&Event::scalar("train/loss", 3, f64::NAN)).expect("serialize");
        assert!(line.contains(r#""value":null"#), "{line}");
        match serde_json::from_str::<Event>(&line).expect("deserialize") {
            Event::Scalar { step: 3, value, .. } => assert!(value.is_nan()),
            other => panic!("{other:?}"),
        }
        assert!(serde_json::from_str::<Event>(r#"{"kind":"scalar","name":"a","step":1}"#).is_err());
    }

    #[test]
    fn every_kind_round_trips_through_json() {
        let events = [
            Event::Layout {
                title: "t".into(),
                panels: vec![PanelSpec {
                    title: "p".into(),
                    x_label: "x".into(),
                    series: vec!["a".into()],
                    restart_on_rewind: true,
                    path: None,
                }],
            },
            Event::Layout {
                title: "board".into(),
                panels: vec![PanelSpec {
                    title: "effector".into(),
                    x_label: "x".into(),
                    series: vec!["effector/x".into(), "effector/y".into()],
                    restart_on_rewind: false,
                    path: Some(PathView {
                        x: [0.0, 1.0],
                        y: [0.0, 1.0],
                        grid: 5,
                        y_down: true,
                        background: Some(Background { cells: 1, rgb: vec![1, 2, 3] }),
                    }),
                }],
            },
            Event::scalar("loss", 3, 0.5),
            Event::progress("train", 1, 2),
            Event::message("hello"),
            Event::text("plan", ""),
            Event::Finished { ok: true },
        ];
        for event in events {
            let line = serde_json::to_string(&event).expect("serialize");
            assert_eq!(serde_json::from_str::<Event>(&line).expect("deserialize"), event, "{line}");
        }
    }
}
