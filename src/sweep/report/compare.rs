//! The spec's `[[compare]]` tests: two cells of a stage, one scalar, Mann-Whitney U over the runs or
//! Wilcoxon signed rank over the seeds both cells ran.

use std::collections::BTreeMap;

use super::collect::StageRuns;
use crate::error::{Error, Result};
use crate::eval::stats::{mann_whitney_u, wilcoxon_signed_rank, Alternative, MannWhitneyMethod, WilcoxonMethod};
use crate::sweep::plan::JobPlan;
use crate::sweep::spec::{CompareSpec, Direction, GridValue, TestKind};

/// How many names an error lists before it says how many more there are.
const LISTED: usize = 12;

pub struct Comparison {
    pub index: usize,
    pub spec: CompareSpec,
    pub cell_a: String,
    pub cell_b: String,
    /// Finished runs with a finite value of the metric, in each cell.
    pub n_a: usize,
    pub n_b: usize,
    /// Seeds in both cells (Wilcoxon only).
    pub pairs: Option<usize>,
    pub outcome: Outcome,
}

pub enum Outcome {
    Tested {
        statistic: f64,
        p_value: f64,
        method: String,
    },
    /// Why there is no result (no finished runs yet, all differences zero, …).
    NotRun(String),
}

impl Comparison {
    pub fn test_name(&self) -> &'static str {
        match self.spec.test {
            TestKind::MannWhitney => "mann-whitney",
            TestKind::Wilcoxon => "wilcoxon",
        }
    }

    pub fn alternative_name(&self) -> &'static str {
        match self.spec.alternative {
            Direction::Less => "less",
            Direction::Greater => "greater",
            Direction::TwoSided => "two-sided",
        }
    }
}

/// Runs comparison `index` on its stage. A metric no run has, or a cell no job matches, is a spec error.
pub fn compare(index: usize, spec: &CompareSpec, stage: &StageRuns) -> Result<Comparison> {
    let at = format!("compare[{index}]");
    if !stage.runs.is_empty() && !stage.scalar_names.contains(&spec.metric) {
        let names: Vec<&str> = stage.scalar_names.iter().map(String::as_str).collect();
        return Err(Error::config(format!(
            "{at}.metric: '{}' is no scalar of stage '{}'{}; expected one of: {}",
            spec.metric,
            stage.stage.name,
            crate::util::suggest::did_you_mean(&spec.metric, names.iter().copied()),
            listed(&names)
        )));
    }
    let cell_a = matching_cell(&at, "a", &spec.a, stage)?;
    let cell_b = matching_cell(&at, "b", &spec.b, stage)?;
    let values = |cell: &str| -> BTreeMap<usize, (Option<u64>, f64)> {
        stage
            .runs
            .iter()
            .enumerate()
            .filter(|(_, r)| r.job.cell_label() == cell)
            .filter_map(|(i, r)| r.scalar(&spec.metric).filter(|v| v.is_finite()).map(|v| (i, (r.job.seed, v))))
            .collect()
    };
    let (a, b) = (values(&cell_a), values(&cell_b));
    let alternative = match spec.alternative {
        Direction::Less => Alternative::Less,
        Direction::Greater => Alternative::Greater,
        Direction::TwoSided => Alternative::TwoSided,
    };
    let mut comparison = Comparison {
        index,
        spec: spec.clone(),
        cell_a,
        cell_b,
        n_a: a.len(),
        n_b: b.len(),
        pairs: None,
        outcome: Outcome::NotRun(String::new()),
    };
    comparison.outcome = if a.is_empty() || b.is_empty() {
        Outcome::NotRun(format!(
            "no finished run with a finite {} in cell {}",
            spec.metric,
            if a.is_empty() { "a" } else { "b" }
        ))
    } else {
        match spec.test {
            TestKind::MannWhitney => {
                let xs: Vec<f64> = a.values().map(|p| p.1).collect();
                let ys: Vec<f64> = b.values().map(|p| p.1).collect();
                match mann_whitney_u(&xs, &ys, alternative) {
                    Ok(r) => Outcome::Tested {
                        statistic: r.statistic,
                        p_value: r.p_value,
                        method: mann_whitney_method(r.method).to_string(),
                    },
                    Err(e) => Outcome::NotRun(e.to_string()),
                }
            }
            TestKind::Wilcoxon => {
                let by_seed = |m: &BTreeMap<usize, (Option<u64>, f64)>| -> BTreeMap<u64, f64> {
                    m.values().filter_map(|&(seed, v)| seed.map(|s| (s, v))).collect()
                };
                let (sa, sb) = (by_seed(&a), by_seed(&b));
                let (xs, ys): (Vec<f64>, Vec<f64>) =
                    sa.iter().filter_map(|(seed, &x)| sb.get(seed).map(|&y| (x, y))).unzip();
                comparison.pairs = Some(xs.len());
                if xs.is_empty() {
                    Outcome::NotRun("the cells share no seed to pair by".to_string())
                } else {
                    match wilcoxon_signed_rank(&xs, &ys, alternative) {
                        Ok(r) => Outcome::Tested {
                            statistic: r.statistic,
                            p_value: r.p_value,
                            method: format!("{}, {} non-zero differences", wilcoxon_method(r.method), r.n),
                        },
                        Err(e) => Outcome::NotRun(e.to_string()),
                    }
                }
            }
        }
    };
    Ok(comparison)
}

/// The one cell whose jobs carry every given value (keys without their leading dashes).
fn matching_cell(at: &str, side: &str, given: &BTreeMap<String, GridValue>, stage: &StageRuns) -> Result<String> {
    let matches = |job: &JobPlan| {
        given.iter().all(|(key, value)| {
            let key = key.trim_start_matches('-');
            let value = value.render();
            job.cell.iter().any(|(k, v)| k.trim_start_matches('-') == key && *v == value)
        })
    };
    let cells: Vec<&str> =
        stage.cells.iter().filter(|(_, jobs)| jobs.iter().any(|j| matches(j))).map(|(l, _)| l.as_str()).collect();
    let wanted = || given.iter().map(|(k, v)| format!("{k} = {}", v.render())).collect::<Vec<_>>().join(", ");
    match cells.as_slice() {
        [one] => Ok(one.to_string()),
        [] => {
            let all: Vec<&str> = stage.cells.iter().map(|(l, _)| l.as_str()).collect();
            Err(Error::config(format!(
                "{at}.{side}: {{{}}} matches no run of stage '{}'; its cells are: {}",
                wanted(),
                stage.stage.name,
                listed(&all)
            )))
        }
        many => Err(Error::config(format!(
            "{at}.{side}: {{{}}} matches {} cells of stage '{}' ({}); give a value for every axis that varies",
            wanted(),
            many.len(),
            stage.stage.name,
            listed(many)
        ))),
    }
}

fn mann_whitney_method(method: MannWhitneyMethod) -> &'static str {
    match method {
        MannWhitneyMethod::Exact => "exact",
        MannWhitneyMethod::NormalApprox => "normal approximation",
    }
}

fn wilcoxon_method(method: WilcoxonMethod) -> &'static str {
    match method {
        WilcoxonMethod::Exact => "exact",
        WilcoxonMethod::NormalApprox => "normal approximation",
    }
}

pub fn listed(names: &[&str]) -> String {
    if names.is_empty() {
        return "none".to_string();
    }
    let shown = names.iter().take(LISTED).copied().collect::<Vec<_>>().join(", ");
    match names.len().saturating_sub(LISTED) {
        0 => shown,
        more => format!("{shown} and {more} more"),
    }
}
