//! A method panel: its own copies of a few series, so that restarting them on a rewind (a new episode,
//! a new planner call) never loses the full history the Curves panel draws.

use super::series::Series;
use crate::run::PanelSpec;

#[derive(Clone, Debug)]
pub(crate) struct Panel {
    spec: PanelSpec,
    /// Parallel to `spec.series`.
    series: Vec<Series>,
}

impl Panel {
    pub(crate) fn new(spec: PanelSpec) -> Self {
        let series = vec![Series::default(); spec.series.len()];
        Panel { spec, series }
    }

    pub(crate) fn record(&mut self, name: &str, step: u64, value: f64) {
        for (series_name, series) in self.spec.series.iter().zip(&mut self.series) {
            if series_name != name {
                continue;
            }
            let rewound = series.last_step().is_some_and(|last| step <= last);
            if self.spec.restart_on_rewind && rewound {
                series.clear();
            }
            series.push(step, value);
        }
    }

    /// Whether the panel draws the whole history of `name`, as the Curves panel would. A panel that
    /// restarts on a rewind shows only the latest episode or planner call, so the Curves panel still
    /// has the history to add.
    pub(crate) fn draws_full_history(&self, name: &str) -> bool {
        !self.spec.restart_on_rewind && self.spec.series.iter().any(|s| s == name)
    }

    pub(crate) fn spec(&self) -> &PanelSpec {
        &self.spec
    }

    /// Each series with its metric name, in the order the spec lists them.
    pub(crate) fn series(&self) -> impl Iterator<Item = (&str, &Series)> {
        self.spec.series.iter().map(String::as_str).zip(&self.series)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec(restart_on_rewind: bool) -> PanelSpec {
        PanelSpec {
            title: "pendulum".into(),
            x_label: "t".into(),
            series: vec!["pendulum/angle".into(), "pendulum/action".into()],
            restart_on_rewind,
            path: None,
        }
    }

    fn steps(panel: &Panel, name: &str) -> Vec<f64> {
        let (_, series) = panel.series().find(|(n, _)| *n == name).expect("series in panel");
        series.points().iter().map(|p| p.0).collect()
    }

    #[test]
    fn rewind_restarts_only_the_rewound_series() {
        let mut panel = Panel::new(spec(true));
        for step in 0..3 {
            panel.record("pendulum/angle", step, 1.0);
            panel.record("pendulum/action", step, 0.5);
        }
        panel.record("pendulum/angle", 0, 2.0);
        assert_eq!(steps(&panel, "pendulum/angle"), vec![0.0]);
        assert_eq!(steps(&panel, "pendulum/action"), vec![0.0, 1.0, 2.0]);
    }

    #[test]
    fn equal_step_counts_as_rewind() {
        let mut panel = Panel::new(spec(true));
        panel.record("pendulum/angle", 4, 1.0);
        panel.record("pendulum/angle", 4, 2.0);
        assert_eq!(steps(&panel, "pendulum/angle"), vec![4.0]);
    }

    #[test]
    fn without_restart_a_rewind_appends() {
        let mut panel = Panel::new(spec(false));
        panel.record("pendulum/angle", 5, 1.0);
        panel.record("pendulum/angle", 0, 2.0);
        assert_eq!(steps(&panel, "pendulum/angle"), vec![5.0, 0.0]);
    }

    #[test]
    fn other_metrics_are_ignored() {
        let mut panel = Panel::new(spec(true));
        panel.record("cem/best_cost", 1, 3.0);
        assert!(panel.series().all(|(_, s)| s.points().is_empty()));
    }
}
