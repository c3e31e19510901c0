//! A bounded (x, value) history for one metric, x being the step or, for a history whose steps rewind,
//! the sample index.

/// Points kept visible per series; older ones are dropped so a week-long run cannot exhaust memory.
pub(crate) const SERIES_CAP: usize = 10_000;

/// Extra points allowed to accumulate before trimming, so the front of the vector is shifted once per
/// `TRIM_SLACK` pushes instead of on every push.
const TRIM_SLACK: usize = SERIES_CAP / 10;

#[derive(Clone, Debug, Default)]
pub(crate) struct Series {
    /// Finite points only, as the chart wants them: a NaN would poison the axis bounds.
    points: Vec<(f64, f64)>,
    /// Tracked apart from `points` because a non-finite value still counts as "the last step seen".
    last_step: Option<u64>,
    /// The raw last value, NaN included: a diverging loss is exactly what the user needs to see.
    last_value: Option<f64>,
    /// Whether a rewinding step switches x from the step to the sample index (see `indexed_on_rewind`).
    index_on_rewind: bool,
    /// Whether x is the sample index rather than the step.
    by_sample: bool,
    /// Finite points pushed so far, trimmed ones included: the sample index of the next point.
    samples: u64,
}

impl Series {
    /// A series for a metric's whole history. Its x is the step until a step fails to increase (a
    /// metric counted per planner call or per episode, such as CEM's iteration): from then on x is the
    /// sample index, so the repeats are drawn one after another instead of on top of each other.
    pub(crate) fn indexed_on_rewind() -> Self {
        Series { index_on_rewind: true, ..Series::default() }
    }

    pub(crate) fn push(&mut self, step: u64, value: f64) {
        let rewound = self.last_step.is_some_and(|last| step <= last);
        if rewound && self.index_on_rewind && !self.by_sample {
            self.switch_to_samples();
        }
        self.last_step = Some(step);
        self.last_value = Some(value);
        if !value.is_finite() {
            return;
        }
        let x = if self.by_sample { self.samples as f64 } else { step as f64 };
        self.samples += 1;
        self.points.push((x, value));
        if self.points.len() >= SERIES_CAP + TRIM_SLACK {
            let excess = self.points.len() - SERIES_CAP;
            self.points.drain(..excess);
        }
    }

    /// Re-labels the kept points with their sample index: they are the newest `points.len()` of the
    /// `samples` finite points pushed so far.
    fn switch_to_samples(&mut self) {
        let first = self.samples - self.points.len() as u64;
        for (i, point) in self.points.iter_mut().enumerate() {
            point.0 = (first + i as u64) as f64;
        }
        self.by_sample = true;
    }

    /// The newest `SERIES_CAP` finite points, oldest first.
    pub(crate) fn points(&self) -> &[(f64, f64)] {
        let start = self.points.len().saturating_sub(SERIES_CAP);
        &self.points[start..]
    }

    /// What x measures: `step`, or `sample` once a rewind switched it to the sample index.
    pub(crate) fn x_label(&self) -> &'static str {
        if self.by_sample {
            "sample"
        } else {
            "step"
        }
    }

    pub(crate) fn last_step(&self) -> Option<u64> {
        self.last_step
    }

    pub(crate) fn last_value(&self) -> Option<f64> {
        self.last_value
    }

    /// Forgets every point; a series indexed on rewind stays so, starting again on steps.
    pub(crate) fn clear(&mut self) {
        *self = Series { index_on_rewind: self.index_on_rewind, ..Series::default() };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cap_keeps_only_the_newest_points() {
        let mut s = Series::default();
        let extra = 3 * TRIM_SLACK + 7;
        for step in 0..(SERIES_CAP + extra) as u64 {
            s.push(step, step as f64);
            assert!(s.points().len() <= SERIES_CAP);
            assert!(s.points.len() < SERIES_CAP + TRIM_SLACK);
        }
        let points = s.points();
        assert_eq!(points.len(), SERIES_CAP);
        assert_eq!(points[0].0, extra as f64);
        assert_eq!(points[SERIES_CAP - 1].0, (SERIES_CAP + extra - 1) as f64);
    }

    #[test]
    fn non_finite_values_are_not_plotted_but_reported() {
        let mut s = Series::default();
        s.push(1, 2.0);
        s.push(2, f64::NAN);
        s.push(3, f64::INFINITY);
        assert_eq!(s.points(), &[(1.0, 2.0)]);
        assert_eq!(s.last_step(), Some(3));
        assert_eq!(s.last_value(), Some(f64::INFINITY));
    }

    #[test]
    fn plain_series_keep_the_step_after_a_rewind() {
        let mut s = Series::default();
        s.push(5, 1.0);
        s.push(0, 2.0);
        assert_eq!(s.points(), &[(5.0, 1.0), (0.0, 2.0)]);
        assert_eq!(s.x_label(), "step");
    }

    #[test]
    fn monotone_history_keeps_the_step() {
        let mut s = Series::indexed_on_rewind();
        for step in [3, 7, 8] {
            s.push(step, 1.0);
        }
        assert_eq!(s.points().iter().map(|p| p.0).collect::<Vec<_>>(), vec![3.0, 7.0, 8.0]);
        assert_eq!(s.x_label(), "step");
    }

    #[test]
    fn rewinding_history_switches_to_the_sample_index() {
        let mut s = Series::indexed_on_rewind();
        s.push(0, 1.0);
        s.push(1, f64::NAN);
        s.push(2, 3.0);
        s.push(0, 4.0);
        s.push(1, 5.0);
        assert_eq!(s.points(), &[(0.0, 1.0), (1.0, 3.0), (2.0, 4.0), (3.0, 5.0)]);
        assert_eq!(s.x_label(), "sample");
        assert_eq!(s.last_step(), Some(1));
        // Once switched, even increasing steps keep counting samples.
        s.push(100, 6.0);
        assert_eq!(s.points().last(), Some(&(4.0, 6.0)));
    }

    #[test]
    fn sample_index_survives_trimming() {
        let mut s = Series::indexed_on_rewind();
        let total = SERIES_CAP + 2 * TRIM_SLACK + 3;
        for i in 0..total {
            s.push((i % 10) as u64, i as f64);
        }
        let points = s.points();
        assert_eq!(points.len(), SERIES_CAP);
        assert!(points.windows(2).all(|w| w[1].0 == w[0].0 + 1.0));
        assert!(points.iter().all(|&(x, value)| x == value), "x is the sample index of every point");

        // Switching after trimming has started labels the kept points by their true index.
        let mut s = Series::indexed_on_rewind();
        for i in 0..total {
            s.push(i as u64, i as f64);
        }
        s.push(0, total as f64);
        assert!(s.points().iter().all(|&(x, value)| x == value));
        assert_eq!(s.x_label(), "sample");
    }

    #[test]
    fn clear_forgets_points_and_last_step() {
        let mut s = Series::default();
        s.push(5, 1.0);
        s.clear();
        assert!(s.points().is_empty());
        assert_eq!(s.last_step(), None);
    }
}
