//! A bounded (step, value) history for one metric.

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
}

impl Series {
    pub(crate) fn push(&mut self, step: u64, value: f64) {
        self.last_step = Some(step);
        self.last_value = Some(value);
        if !value.is_finite() {
            return;
        }
        self.points.push((step as f64, value));
        if self.points.len() >= SERIES_CAP + TRIM_SLACK {
            let excess = self.points.len() - SERIES_CAP;
            self.points.drain(..excess);
        }
    }

    /// The newest `SERIES_CAP` finite points, oldest first.
    pub(crate) fn points(&self) -> &[(f64, f64)] {
        let start = self.points.len().saturating_sub(SERIES_CAP);
        &self.points[start..]
    }

    pub(crate) fn last_step(&self) -> Option<u64> {
        self.last_step
    }

    pub(crate) fn last_value(&self) -> Option<f64> {
        self.last_value
    }

    pub(crate) fn clear(&mut self) {
        *self = Series::default();
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
    fn clear_forgets_points_and_last_step() {
        let mut s = Series::default();
        s.push(5, 1.0);
        s.clear();
        assert!(s.points().is_empty());
        assert_eq!(s.last_step(), None);
    }
}
