//! What a small run may say about a thesis claim. Each claim is split into parts; a part is a one-sided test in
//! the thesis' direction (a rate the thesis reports as 100 %, or a paired Wilcoxon test), an exact check (a
//! count computed in full), or nothing the run can test (a scripted controller stands in for the learned agent).
//!
//! The rule, stated once for every report that uses it:
//! - a part *fails* when it can be tested (its smallest attainable p is below [`ALPHA`]) and the run's numbers
//!   do not point the thesis' way with p < [`ALPHA`], or when an exact check does not hold;
//! - a part is *underpowered* when even the most extreme outcome of its n could not reach p < [`ALPHA`] (one
//!   run per setting, four tasks), or when the slice does not run the thesis' method at all;
//! - the verdict is "not at this scale" if any part fails, else "smoke test only" if any part is underpowered,
//!   else "reproduced".
//!
//! A failure outranks an underpowered part so that a clear miss is never hidden behind a small sibling test.

use serde::{Deserialize, Serialize};

use super::num;

/// The significance level every verdict uses.
pub const ALPHA: f64 = 0.05;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Verdict {
    #[serde(rename = "reproduced")]
    Reproduced,
    #[serde(rename = "not at this scale")]
    NotAtThisScale,
    #[serde(rename = "smoke test only")]
    SmokeTestOnly,
}

impl std::fmt::Display for Verdict {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str(match self {
            Verdict::Reproduced => "reproduced",
            Verdict::NotAtThisScale => "not at this scale",
            Verdict::SmokeTestOnly => "smoke test only",
        })
    }
}

/// One part of a claim, as the run's numbers bear on it.
#[derive(Clone, Debug, PartialEq)]
pub enum Part {
    /// A one-sided test: `n` pairs or trials, the smallest p any outcome of that n could give, the observed p
    /// (None when the test could not run, e.g. every pair tied), and whether the effect points the thesis' way.
    Test { n: usize, min_p: f64, p: Option<f64>, thesis_direction: bool },
    /// A quantity computed in full (no sampling), compared with the thesis.
    Check { holds: bool },
    /// The slice runs something else than the thesis' method (a scripted controller), so it tests no claim.
    Untested,
}

impl Part {
    /// A success rate the thesis reports as 100 %: `k` of `n` against a coin flip, one-sided exact binomial.
    pub fn full_success(k: usize, n: usize) -> Part {
        Part::Test { n, min_p: 0.5f64.powi(n as i32), p: Some(binomial_tail_half(k, n)), thesis_direction: k == n }
    }

    /// A one-sided paired Wilcoxon signed-rank test over `n` pairs; its smallest p (every difference one way,
    /// exact null) is 2⁻ⁿ.
    pub fn wilcoxon(n: usize, p: Option<f64>, thesis_direction: bool) -> Part {
        Part::Test { n, min_p: 0.5f64.powi(n as i32), p, thesis_direction }
    }

    fn outcome(&self) -> Outcome {
        match *self {
            Part::Check { holds: true } => Outcome::Pass,
            Part::Check { holds: false } => Outcome::Fail,
            Part::Untested => Outcome::Underpowered,
            Part::Test { min_p, .. } if min_p >= ALPHA => Outcome::Underpowered,
            Part::Test { p: Some(p), thesis_direction: true, .. } if p < ALPHA => Outcome::Pass,
            Part::Test { .. } => Outcome::Fail,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Outcome {
    Pass,
    Fail,
    Underpowered,
}

/// The verdict of a claim made of `parts` (see the module's rule); no parts tests nothing.
pub fn verdict(parts: &[Part]) -> Verdict {
    let outcomes: Vec<Outcome> = parts.iter().map(Part::outcome).collect();
    if outcomes.contains(&Outcome::Fail) {
        Verdict::NotAtThisScale
    } else if outcomes.is_empty() || outcomes.contains(&Outcome::Underpowered) {
        Verdict::SmokeTestOnly
    } else {
        Verdict::Reproduced
    }
}

/// A part of a claim with what it states, in the run's terms ("5/5 episodes swung up").
#[derive(Clone, Debug, PartialEq)]
pub struct Evidence {
    pub label: String,
    pub part: Part,
}

impl Evidence {
    pub fn new(label: impl Into<String>, part: Part) -> Evidence {
        Evidence { label: label.into(), part }
    }
}

/// Parts a reason names one by one; more are counted.
const MAX_LISTED: usize = 3;

/// The verdict on `parts` with the reason that decided it (the failing parts, else the underpowered ones, else
/// all), the smallest n and the largest p of its tests.
pub fn judge(parts: &[Evidence]) -> (Verdict, String, Option<usize>, Option<f64>) {
    let bare: Vec<Part> = parts.iter().map(|e| e.part.clone()).collect();
    let verdict = verdict(&bare);
    let wanted = match verdict {
        Verdict::NotAtThisScale => Outcome::Fail,
        Verdict::SmokeTestOnly => Outcome::Underpowered,
        Verdict::Reproduced => Outcome::Pass,
    };
    let mut deciding: Vec<String> =
        parts.iter().filter(|e| e.part.outcome() == wanted).map(|e| describe(e, wanted)).collect();
    let tests = parts.iter().filter_map(|e| match e.part {
        Part::Test { n, p, .. } => Some((n, p)),
        _ => None,
    });
    let n = tests.clone().map(|(n, _)| n).min();
    let p = tests.filter_map(|(_, p)| p).reduce(f64::max);
    // A claim of many comparisons (the ball's eleven) is summed up, so that a printed line stays readable.
    if deciding.len() > MAX_LISTED {
        let more = deciding.len() - MAX_LISTED;
        if verdict == Verdict::Reproduced {
            deciding = vec![format!(
                "all {} comparisons ({}, n ≥ {})",
                deciding.len(),
                format_p(p).replace('=', "≤"),
                n.unwrap_or(0)
            )];
        } else {
            deciding.truncate(MAX_LISTED);
            deciding.push(format!("{more} more"));
        }
    }
    let untested = parts.iter().any(|e| e.part == Part::Untested);
    let reason = match verdict {
        Verdict::NotAtThisScale => format!("misses: {}", deciding.join("; ")),
        Verdict::SmokeTestOnly if deciding.is_empty() => "nothing to test".to_string(),
        Verdict::SmokeTestOnly if untested => deciding.join("; "),
        Verdict::SmokeTestOnly => format!("too small to test: {}", shared_bound(parts, deciding)),
        Verdict::Reproduced => deciding.join("; "),
    };
    (verdict, reason, n, p)
}

/// The underpowered parts' labels, with their bound said once when every part has the same n.
fn shared_bound(parts: &[Evidence], deciding: Vec<String>) -> String {
    let bounds: Vec<(usize, f64)> = parts
        .iter()
        .filter_map(|e| match e.part {
            Part::Test { n, min_p, .. } if min_p >= ALPHA => Some((n, min_p)),
            _ => None,
        })
        .collect();
    match bounds.first() {
        Some(&(n, min_p)) if bounds.len() > 1 && bounds.iter().all(|b| b.0 == n) => {
            let labels: Vec<&str> = parts
                .iter()
                .filter(|e| matches!(e.part, Part::Test { min_p, .. } if min_p >= ALPHA))
                .map(|e| e.label.as_str())
                .collect();
            format!("{}; n = {n}: even the best outcome gives p = {min_p:.3} ≥ {ALPHA}", labels.join(", "))
        }
        _ => deciding.join("; "),
    }
}

fn describe(e: &Evidence, outcome: Outcome) -> String {
    match (&e.part, outcome) {
        (Part::Test { n, min_p, .. }, Outcome::Underpowered) => {
            format!("{}; n = {n}: even the best outcome gives p = {min_p:.3} ≥ {ALPHA}", e.label)
        }
        (Part::Test { n, p, thesis_direction: false, .. }, _) => {
            format!("{}: against the thesis' direction, {}, n = {n}", e.label, format_p(*p))
        }
        (Part::Test { n, p, .. }, _) => format!("{}: {}, n = {n}", e.label, format_p(*p)),
        (Part::Check { .. } | Part::Untested, _) => e.label.clone(),
    }
}

/// P(X ≥ k) for X ~ Binomial(n, ½): the one-sided p of k successes in n trials against a coin flip.
pub fn binomial_tail_half(k: usize, n: usize) -> f64 {
    if k == 0 {
        return 1.0;
    }
    // Terms C(n, i)/2ⁿ from i = n down, each from the next by one multiplication, so no factorial overflows.
    let mut term = 0.5f64.powi(n as i32);
    let mut sum = 0.0;
    for i in (k..=n).rev() {
        sum += term;
        term *= i as f64 / (n - i + 1) as f64;
    }
    sum.min(1.0)
}

/// What a slice of a report reproduces, as summary.json records it for a results page: the thesis' figure or
/// table, what the thesis reports there, what this run found, the verdict and how it was reached.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Claim {
    /// The thesis' figures, tables or sections ("Table 7.1, Table 7.2").
    pub target: String,
    /// What the thesis reports there, with its number where it has one.
    pub thesis: String,
    /// This run's key figure, in the same terms.
    pub ours: String,
    /// The run's scale next to the thesis' (episodes, tasks, training steps).
    pub scale: String,
    pub verdict: Verdict,
    /// Why this verdict: the rule applied to this run's numbers.
    pub reason: String,
    /// The sample size of the deciding test (pairs, episodes, boards); None for an exact check.
    pub n: Option<usize>,
    /// The test used, None for an exact check.
    pub test: Option<String>,
    /// The deciding p-value (the largest of the parts' when several must all hold).
    #[serde(with = "num::opt")]
    pub p_value: Option<f64>,
}

impl Claim {
    /// The compact tail of a printed line: "target: …; verdict: … (…)".
    pub fn tail(&self) -> String {
        format!("target: {}; verdict: {} ({})", self.target, self.verdict, self.reason)
    }
}

/// "p = 3.1e-2" or "p = –" for a p-value in a sentence.
pub fn format_p(p: Option<f64>) -> String {
    match p {
        Some(p) if p >= 0.001 => format!("p = {p:.3}"),
        Some(p) => format!("p = {p:.1e}"),
        None => "p = –".into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn binomial_tail_matches_hand_counts() {
        assert_eq!(binomial_tail_half(5, 5), 1.0 / 32.0);
        // P(X ≥ 4 | 5) = (5 + 1)/32.
        assert!((binomial_tail_half(4, 5) - 6.0 / 32.0).abs() < 1e-15);
        assert_eq!(binomial_tail_half(0, 7), 1.0);
        // Symmetry: P(X ≥ 11 | 20) = (1 − P(X = 10 | 20))/2.
        let p10 = 184_756.0 / 1_048_576.0;
        assert!((binomial_tail_half(11, 20) - (1.0 - p10) / 2.0).abs() < 1e-12);
    }

    #[test]
    fn five_of_five_reproduces_a_full_success_rate_but_three_of_three_is_too_few_to_tell() {
        assert_eq!(verdict(&[Part::full_success(5, 5)]), Verdict::Reproduced);
        assert_eq!(verdict(&[Part::full_success(3, 3)]), Verdict::SmokeTestOnly);
        // One run per setting can never reproduce, whatever it shows.
        assert_eq!(verdict(&[Part::full_success(1, 1)]), Verdict::SmokeTestOnly);
        assert_eq!(verdict(&[Part::full_success(0, 1)]), Verdict::SmokeTestOnly);
    }

    #[test]
    fn a_failure_in_a_testable_sample_is_not_at_this_scale() {
        // 24 of 25 is significant against a coin flip but misses the thesis' 100 %.
        assert_eq!(verdict(&[Part::full_success(24, 25)]), Verdict::NotAtThisScale);
        assert_eq!(verdict(&[Part::wilcoxon(30, Some(0.2), true)]), Verdict::NotAtThisScale);
        // Significant, but the other way round.
        assert_eq!(verdict(&[Part::wilcoxon(30, Some(1e-4), false)]), Verdict::NotAtThisScale);
        assert_eq!(verdict(&[Part::wilcoxon(30, None, true)]), Verdict::NotAtThisScale);
        assert_eq!(verdict(&[Part::wilcoxon(30, Some(1e-4), true)]), Verdict::Reproduced);
    }

    #[test]
    fn four_pairs_cannot_reach_five_percent_and_five_can() {
        assert_eq!(verdict(&[Part::wilcoxon(4, Some(0.0625), true)]), Verdict::SmokeTestOnly);
        assert_eq!(verdict(&[Part::wilcoxon(5, Some(1.0 / 32.0), true)]), Verdict::Reproduced);
    }

    #[test]
    fn a_clear_miss_outranks_an_underpowered_sibling_and_every_part_must_hold() {
        let small = Part::full_success(2, 2);
        let miss = Part::Check { holds: false };
        assert_eq!(verdict(&[small.clone(), miss]), Verdict::NotAtThisScale);
        assert_eq!(verdict(&[small, Part::Check { holds: true }]), Verdict::SmokeTestOnly);
        let pass = Part::wilcoxon(30, Some(1e-3), true);
        assert_eq!(verdict(&[pass.clone(), Part::Check { holds: true }]), Verdict::Reproduced);
        assert_eq!(verdict(&[pass.clone(), Part::Check { holds: false }]), Verdict::NotAtThisScale);
        assert_eq!(verdict(&[pass, Part::Untested]), Verdict::SmokeTestOnly);
        assert_eq!(verdict(&[]), Verdict::SmokeTestOnly);
    }

    #[test]
    fn the_reason_names_the_deciding_parts_and_the_extremes_of_the_tests() {
        let parts = [
            Evidence::new("lower at 0.5 s", Part::wilcoxon(30, Some(1e-4), true)),
            Evidence::new("lower at 1.0 s", Part::wilcoxon(24, Some(0.31), true)),
            Evidence::new("moves found", Part::Check { holds: true }),
        ];
        let (verdict, reason, n, p) = judge(&parts);
        assert_eq!(verdict, Verdict::NotAtThisScale);
        assert_eq!(reason, "misses: lower at 1.0 s: p = 0.310, n = 24");
        assert_eq!((n, p), (Some(24), Some(0.31)));
        let (verdict, reason, ..) = judge(&[Evidence::new("1/1 swung up", Part::full_success(1, 1))]);
        assert_eq!(verdict, Verdict::SmokeTestOnly);
        assert_eq!(reason, "too small to test: 1/1 swung up; n = 1: even the best outcome gives p = 0.500 ≥ 0.05");
        let four = Part::wilcoxon(4, Some(0.0625), true);
        let (_, reason, ..) = judge(&[Evidence::new("a", four.clone()), Evidence::new("b", four)]);
        assert_eq!(reason, "too small to test: a, b; n = 4: even the best outcome gives p = 0.062 ≥ 0.05");
        let (verdict, reason, ..) = judge(&[Evidence::new("scripted", Part::Untested)]);
        assert_eq!((verdict, reason.as_str()), (Verdict::SmokeTestOnly, "scripted"));
    }

    #[test]
    fn verdicts_are_written_as_they_read() {
        let json = serde_json::to_string(&[Verdict::Reproduced, Verdict::NotAtThisScale, Verdict::SmokeTestOnly]);
        assert_eq!(json.unwrap(), r#"["reproduced","not at this scale","smoke test only"]"#);
    }
}
