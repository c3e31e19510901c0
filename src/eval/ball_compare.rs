//! A learned EKF against the black-box baseline at every horizon and pose set the ball protocol scored, paired
//! per shot: the comparison of thesis Figs. 6.4 (1 s, default and unseen poses) and 6.6 (0.1-1.0 s).

use std::collections::HashMap;

use serde::{Deserialize, Serialize};

use super::ball::BallEvalSummary;
use super::num;
use super::stats::{wilcoxon_signed_rank, Alternative};

/// One horizon and pose set: medians as the ball report gives them, and the paired test that the EKF's error
/// is lower.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct HorizonComparison {
    pub group: String,
    pub horizon_s: f64,
    /// Shots both methods were scored on.
    pub n: usize,
    #[serde(with = "num::real")]
    pub ekf_median: f64,
    #[serde(with = "num::real")]
    pub baseline_median: f64,
    #[serde(with = "num::opt")]
    pub oracle_median: Option<f64>,
    /// One-sided paired Wilcoxon signed-rank p that the EKF's per-shot error is lower; None when every pair ties.
    #[serde(with = "num::opt")]
    pub p_value: Option<f64>,
}

impl HorizonComparison {
    pub fn ekf_lower(&self) -> bool {
        self.ekf_median < self.baseline_median
    }
}

/// A failed prediction is infinitely wrong; the rank test only needs it to rank last, which a finite stand-in
/// far beyond any table does without making the differences overflow.
const FAILED_M: f64 = 1e6;

/// `ekf` against `baseline` at every horizon of every pose set of `summary` (pose sets in report order, then
/// horizons ascending); `oracle` rides along for reference.
pub fn compare(summary: &BallEvalSummary, ekf: &str, baseline: &str, oracle: &str) -> Vec<HorizonComparison> {
    let mut out = Vec::new();
    let mut horizons: Vec<f64> = summary.rows.iter().map(|r| r.horizon_s).collect();
    horizons.sort_by(f64::total_cmp);
    horizons.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
    for group in &summary.groups {
        for &h in &horizons {
            // A pose set pools several launcher poses whose shots are numbered from 0 each, so a shot is its id
            // and how often that id came before it; every method scores the shots in the same order.
            let per_shot = |method: &str| -> HashMap<(&str, usize), f64> {
                let mut seen: HashMap<&str, usize> = HashMap::new();
                summary
                    .errors
                    .iter()
                    .filter(|e| e.method == method && &e.group == group && (e.horizon_s - h).abs() < 1e-9)
                    .map(|e| {
                        let k = seen.entry(e.trajectory.as_str()).or_insert(0);
                        *k += 1;
                        ((e.trajectory.as_str(), *k), if e.error_m.is_finite() { e.error_m } else { FAILED_M })
                    })
                    .collect()
            };
            let (a, b) = (per_shot(ekf), per_shot(baseline));
            let mut shots: Vec<(&str, usize)> = a.keys().filter(|k| b.contains_key(*k)).copied().collect();
            shots.sort_unstable();
            let (Some(ekf_median), Some(baseline_median)) =
                (summary.median_at(ekf, group, h), summary.median_at(baseline, group, h))
            else {
                continue;
            };
            let xs: Vec<f64> = shots.iter().map(|s| a[s]).collect();
            let ys: Vec<f64> = shots.iter().map(|s| b[s]).collect();
            let p_value = wilcoxon_signed_rank(&xs, &ys, Alternative::Less).ok().map(|t| t.p_value);
            out.push(HorizonComparison {
                group: group.clone(),
                horizon_s: h,
                n: shots.len(),
                ekf_median,
                baseline_median,
                oracle_median: summary.median_at(oracle, group, h),
                p_value,
            });
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::ball::{BallEvalSettings, ErrorSummary, TrajectoryError};
    use crate::eval::stats::quantile_counting_failures;
    use crate::run::dir::Provenance;

    /// `ids[i]` names shot i (the unseen pose set repeats ids, one run of them per pose).
    fn summary_with_ids(ekf: &[f64], ridge: &[f64], ids: &[usize]) -> BallEvalSummary {
        let mut errors = Vec::new();
        let mut rows = Vec::new();
        for (method, errs) in [("ekf", ekf), ("ridge", ridge)] {
            for (i, &e) in errs.iter().enumerate() {
                errors.push(TrajectoryError {
                    method: method.into(),
                    group: "unseen".into(),
                    horizon_s: 1.0,
                    trajectory: ids[i].to_string(),
                    error_m: e,
                });
            }
            let q = |p| quantile_counting_failures(errs, p);
            rows.push(ErrorSummary {
                method: method.into(),
                group: "unseen".into(),
                horizon_s: 1.0,
                count: errs.len(),
                failed: errs.iter().filter(|e| e.is_infinite()).count(),
                too_short: 0,
                q10: q(0.1),
                median: q(0.5),
                q90: q(0.9),
            });
        }
        BallEvalSummary {
            provenance: Provenance {
                mbrl_version: String::new(),
                command_line: String::new(),
                seed: 0,
                threads: 1,
                extended_by: Vec::new(),
            },
            settings: BallEvalSettings::default(),
            methods: Vec::new(),
            groups: vec!["unseen".into()],
            errors,
            rows,
            side_view: Vec::new(),
        }
    }

    fn summary(ekf: &[f64], ridge: &[f64]) -> BallEvalSummary {
        summary_with_ids(ekf, ridge, &(0..ekf.len()).collect::<Vec<_>>())
    }

    #[test]
    fn shots_of_different_poses_with_the_same_id_stay_separate_pairs() {
        let ekf = [0.10, 0.11, 0.12, 0.13, 0.14, 0.15];
        let ridge = [0.20, 0.22, 0.25, 0.29, 0.34, 0.40];
        // Three poses of two shots each: ids 0, 1, 0, 1, 0, 1.
        let c = compare(&summary_with_ids(&ekf, &ridge, &[0, 1, 0, 1, 0, 1]), "ekf", "ridge", "oracle");
        assert_eq!(c[0].n, 6);
        assert_eq!(c[0].p_value, Some(1.0 / 64.0));
    }

    #[test]
    fn the_pairs_are_tested_shot_by_shot_and_a_failure_ranks_last() {
        let ekf = [0.10, 0.11, 0.12, 0.13, 0.14, 0.15];
        // Distinct gaps, so that the exact null distribution applies (tied gaps take the normal approximation).
        let ridge = [0.20, 0.22, 0.25, 0.29, 0.34, f64::INFINITY];
        let c = compare(&summary(&ekf, &ridge), "ekf", "ridge", "oracle");
        assert_eq!(c.len(), 1);
        assert_eq!(c[0].n, 6);
        assert!(c[0].ekf_lower());
        // Every difference negative: the exact one-sided p is 2⁻⁶.
        assert_eq!(c[0].p_value, Some(1.0 / 64.0));
        assert_eq!(c[0].oracle_median, None);
        // The other way round the EKF is never lower.
        let c = compare(&summary(&ridge, &ekf), "ekf", "ridge", "oracle");
        assert!(!c[0].ekf_lower());
        assert_eq!(c[0].p_value, Some(1.0));
    }
}
