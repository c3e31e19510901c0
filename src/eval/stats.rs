//! Small summary statistics and a paired significance test for reports.

use statrs::distribution::{ContinuousCDF, Normal};

use crate::error::{Error, Result};

/// Linear-interpolated quantile (numpy's default) of finite values; `None` when there are none.
pub fn quantile(values: &[f64], q: f64) -> Option<f64> {
    interpolated_quantile(values.iter().copied().filter(|x| x.is_finite()).collect(), q)
}

/// Quantile of errors where a failure counts as +∞: failures take the top ranks, so a method that fails
/// on a third of the trajectories has an infinite 90 % quantile rather than a flattering finite one.
/// NaN values are not errors and are ignored; `None` when nothing is left.
pub fn quantile_counting_failures(values: &[f64], q: f64) -> Option<f64> {
    interpolated_quantile(values.iter().copied().filter(|x| !x.is_nan()).collect(), q)
}

/// numpy's linear interpolation between the ranks around `q` of `values` (no NaN).
fn interpolated_quantile(mut values: Vec<f64>, q: f64) -> Option<f64> {
    if values.is_empty() {
        return None;
    }
    values.sort_by(f64::total_cmp);
    let pos = q.clamp(0.0, 1.0) * (values.len() - 1) as f64;
    let (lo, hi) = (pos.floor() as usize, pos.ceil() as usize);
    let frac = pos - lo as f64;
    // Interpolating towards an infinite neighbour is infinite only if the neighbour carries weight (and
    // ∞ − ∞ must not turn two failures into NaN).
    Some(if frac == 0.0 || values[lo].is_infinite() {
        values[lo]
    } else {
        values[lo] + (values[hi] - values[lo]) * frac
    })
}

pub fn mean(values: &[f64]) -> Option<f64> {
    (!values.is_empty()).then(|| values.iter().sum::<f64>() / values.len() as f64)
}

/// Which shift of the paired differences `a − b` the test looks for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Alternative {
    /// `a − b` is shifted away from zero in either direction.
    TwoSided,
    /// `a − b` is shifted below zero, i.e. `a` tends to be smaller ("A's error is lower than B's").
    Less,
    /// `a − b` is shifted above zero.
    Greater,
}

/// How the p-value of [`wilcoxon_signed_rank`] was obtained.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WilcoxonMethod {
    /// The exact null distribution of W+; used up to [`WILCOXON_EXACT_MAX_N`] non-zero differences without ties.
    Exact,
    /// The normal approximation with tie correction and no continuity correction.
    NormalApprox,
}

/// Largest number of non-zero differences for which the exact null distribution is used (scipy's "auto" cut-off).
/// It also bounds the exact table: rank sums up to 50·51/2 = 1275, and counts up to 2^50, which stay exact in a `u64`.
pub const WILCOXON_EXACT_MAX_N: usize = 50;

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WilcoxonResult {
    /// Number of non-zero differences, i.e. the pairs the test actually used.
    pub n: usize,
    /// W+, the sum of the (average) ranks of `|a − b|` over the pairs with `a > b`, for every alternative.
    /// scipy reports min(W+, W−) for the two-sided test instead; that drops the direction, and W− = n(n+1)/2 − W+.
    pub statistic: f64,
    pub p_value: f64,
    pub method: WilcoxonMethod,
}

/// Paired Wilcoxon signed-rank test on the differences `a[i] − b[i]`, matching `scipy.stats.wilcoxon` with
/// `zero_method="wilcox"` and `correction=False`: zero differences are dropped, tied `|a − b|` get average ranks.
///
/// The exact null distribution is used when at most [`WILCOXON_EXACT_MAX_N`] differences are non-zero and their
/// absolute values are all distinct, otherwise the normal approximation with tie correction. Two deliberate
/// departures from scipy 1.17's `method="auto"`, both only when zeros or ties are present: with zero differences
/// scipy falls back to the normal approximation (or a permutation test up to 13 pairs) where this stays exact on the
/// non-zero ones, and with ties among at most 13 pairs scipy runs a permutation test where this uses the normal
/// approximation.
pub fn wilcoxon_signed_rank(a: &[f64], b: &[f64], alternative: Alternative) -> Result<WilcoxonResult> {
    if a.len() != b.len() {
        return Err(Error::data(format!(
            "Wilcoxon signed-rank test needs paired samples, got {} values in a and {} in b",
            a.len(),
            b.len()
        )));
    }
    let mut diffs = Vec::with_capacity(a.len());
    for (i, (&x, &y)) in a.iter().zip(b).enumerate() {
        if !x.is_finite() || !y.is_finite() {
            return Err(Error::data(format!("Wilcoxon signed-rank test needs finite values, pair {i} is ({x}, {y})")));
        }
        let d = x - y;
        // Finite inputs near f64::MAX can still overflow when subtracted.
        if !d.is_finite() {
            return Err(Error::data(format!(
                "Wilcoxon signed-rank test: the difference of pair {i} ({x} − {y}) overflows"
            )));
        }
        if d != 0.0 {
            diffs.push(d);
        }
    }
    let n = diffs.len();
    if n == 0 {
        return Err(Error::data(format!(
            "Wilcoxon signed-rank test needs at least one non-zero difference, all {} pairs are equal",
            a.len()
        )));
    }

    let ranked = signed_ranks(&diffs);
    let w_plus = ranked.w_plus;
    if n <= WILCOXON_EXACT_MAX_N && !ranked.has_ties {
        // Without ties every rank is an integer, so W+ is one too and indexes the exact table.
        let w = w_plus.round() as usize;
        let counts = signed_rank_sum_counts(n);
        let lower: u64 = counts[..=w].iter().sum();
        let upper: u64 = counts[w..].iter().sum();
        // Summing integer counts and dividing by 2^n once avoids the cancellation of computing one tail as 1 − other.
        let total = 2f64.powi(n as i32);
        let (p_le, p_ge) = (lower as f64 / total, upper as f64 / total);
        let p_value = match alternative {
            Alternative::Less => p_le,
            Alternative::Greater => p_ge,
            Alternative::TwoSided => (2.0 * p_le.min(p_ge)).min(1.0),
        };
        return Ok(WilcoxonResult { n, statistic: w_plus, p_value, method: WilcoxonMethod::Exact });
    }

    let nf = n as f64;
    let mean = nf * (nf + 1.0) / 4.0;
    // Ties shrink the variance of W+: each group of t tied ranks removes (t³ − t)/48. It stays positive for n ≥ 1.
    let variance = (nf * (nf + 1.0) * (2.0 * nf + 1.0) - ranked.tie_term / 2.0) / 24.0;
    let z = (w_plus - mean) / variance.sqrt();
    let normal = Normal::standard();
    // Tails via the survival function rather than 1 − cdf, so small p-values keep their precision.
    let p_value = match alternative {
        Alternative::Less => normal.cdf(z),
        Alternative::Greater => normal.sf(z),
        Alternative::TwoSided => (2.0 * normal.sf(z.abs())).min(1.0),
    };
    Ok(WilcoxonResult { n, statistic: w_plus, p_value, method: WilcoxonMethod::NormalApprox })
}

struct SignedRanks {
    w_plus: f64,
    has_ties: bool,
    /// Σ (t³ − t) over the groups of t equal `|d|`.
    tie_term: f64,
}

/// Average ranks of `|d|` (1-based), summed over the positive `d`; `diffs` must be finite and non-zero.
fn signed_ranks(diffs: &[f64]) -> SignedRanks {
    let mut order: Vec<usize> = (0..diffs.len()).collect();
    order.sort_by(|&i, &j| diffs[i].abs().total_cmp(&diffs[j].abs()));
    let (mut w_plus, mut has_ties, mut tie_term) = (0.0, false, 0.0);
    let mut start = 0;
    while start < order.len() {
        let value = diffs[order[start]].abs();
        let end = start + order[start..].iter().take_while(|&&i| diffs[i].abs() == value).count();
        let t = (end - start) as f64;
        // Positions start..end hold ranks start+1..=end, whose mean is this.
        let rank = (start + end + 1) as f64 / 2.0;
        w_plus += rank * order[start..end].iter().filter(|&&i| diffs[i] > 0.0).count() as f64;
        if end - start > 1 {
            has_ties = true;
            tie_term += t * t * t - t;
        }
        start = end;
    }
    SignedRanks { w_plus, has_ties, tie_term }
}

/// `counts[s]` = number of subsets of the ranks {1, …, n} that sum to `s`, i.e. of sign patterns giving W+ = s;
/// under the null every one of the 2^n patterns is equally likely.
fn signed_rank_sum_counts(n: usize) -> Vec<u64> {
    // The cut-off keeps every tail count (at most 2^n) exact even after its conversion to f64, whose mantissa has 53 bits.
    assert!(n <= WILCOXON_EXACT_MAX_N, "exact Wilcoxon table requested for n = {n}");
    let max_sum = n * (n + 1) / 2;
    let mut counts = vec![0u64; max_sum + 1];
    counts[0] = 1;
    for rank in 1..=n {
        let reachable = rank * (rank + 1) / 2;
        // Descending, so each rank joins a subset at most once (0/1 knapsack).
        for s in (rank..=reachable).rev() {
            counts[s] += counts[s - rank];
        }
    }
    counts
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn failures_take_the_top_ranks_of_the_quantiles() {
        let errors = [0.1, 0.2, f64::INFINITY, 0.3, f64::INFINITY];
        assert_eq!(quantile_counting_failures(&errors, 0.5), Some(0.3));
        assert_eq!(quantile_counting_failures(&errors, 0.9), Some(f64::INFINITY));
        assert_eq!(quantile_counting_failures(&errors, 0.0), Some(0.1));
        // The finite-only quantile would have said 0.2 for the median.
        assert_eq!(quantile(&errors, 0.5), Some(0.2));
        assert_eq!(quantile_counting_failures(&[f64::NAN], 0.5), None);
        assert_eq!(quantile_counting_failures(&[1.0, f64::INFINITY, f64::INFINITY], 0.9), Some(f64::INFINITY));
    }

    #[test]
    fn quantiles_interpolate_like_numpy() {
        let v = [4.0, 1.0, 3.0, 2.0];
        assert_eq!(quantile(&v, 0.5), Some(2.5));
        assert_eq!(quantile(&v, 0.0), Some(1.0));
        assert_eq!(quantile(&v, 1.0), Some(4.0));
        assert!((quantile(&v, 0.1).unwrap() - 1.3).abs() < 1e-12);
        assert_eq!(quantile(&[f64::NAN], 0.5), None);
        assert_eq!(mean(&[1.0, 2.0]), Some(1.5));
    }

    // Reference values from scipy 1.17.1 (numpy 2.4.6): scipy.stats.wilcoxon(a, b, alternative=...), whose
    // defaults are zero_method="wilcox", correction=False, method="auto". W+ is its statistic for "greater".

    fn check(a: &[f64], b: &[f64], method: WilcoxonMethod, n: usize, w_plus: f64, p: [f64; 3], tol: f64) {
        let alts = [Alternative::TwoSided, Alternative::Less, Alternative::Greater];
        for (alt, expected) in alts.into_iter().zip(p) {
            let r = wilcoxon_signed_rank(a, b, alt).unwrap();
            assert_eq!((r.method, r.n, r.statistic), (method, n, w_plus), "{alt:?}");
            assert!((r.p_value - expected).abs() < tol, "{alt:?}: p = {} but scipy gives {expected}", r.p_value);
        }
    }

    /// The pair of vectors used for the n = 50 and n = 60 cases; multiples of 1/64, so `a − b` is exact in both
    /// languages (numpy: `((i * 7919) % 1000) / 64.0` and `((i * 104729 + 13) % 1000) / 64.0 + shift`).
    fn generated(len: usize, shift: f64) -> (Vec<f64>, Vec<f64>) {
        let a = (0..len).map(|i| ((i * 7919) % 1000) as f64 / 64.0).collect();
        let b = (0..len).map(|i| ((i * 104729 + 13) % 1000) as f64 / 64.0 + shift).collect();
        (a, b)
    }

    #[test]
    #[allow(clippy::approx_constant)] // 3.14 is a data value (scipy's example), not π
    fn wilcoxon_small_sample_is_exact_like_scipy() {
        let a = [1.83, 0.50, 1.62, 2.48, 1.68, 1.88, 1.55, 3.06, 1.30, 0.27];
        let b = [0.878, 0.647, 0.598, 2.05, 1.06, 1.29, 1.06, 3.14, 1.29, 0.45];
        check(&a, &b, WilcoxonMethod::Exact, 10, 46.0, [0.064453125, 0.9755859375, 0.0322265625], 1e-9);
    }

    #[test]
    fn wilcoxon_drops_zero_differences() {
        // scipy method="exact" and "auto" (a permutation test at this size) agree here.
        let a = [3.0, 1.25, 2.5, 4.0, 0.5, 2.0, 7.0, 1.0, 6.5];
        let b = [3.0, 2.0, 1.0, 4.0, 0.25, 4.5, 1.0, 1.0, 0.0];
        check(&a, &b, WilcoxonMethod::Exact, 6, 15.0, [0.4375, 0.84375, 0.21875], 1e-9);
    }

    #[test]
    fn wilcoxon_exact_at_the_size_limit() {
        let (a, b) = generated(50, 1.5);
        let p = [0.07082612042920822, 0.03541306021460411, 0.9653491846641531];
        check(&a, &b, WilcoxonMethod::Exact, 50, 450.0, p, 1e-9);
    }

    #[test]
    fn wilcoxon_ties_use_the_corrected_normal_approximation() {
        let a = [1.5, 2.0, 3.0, 0.5, 4.0, 2.5, 1.0, 3.5, 2.0, 5.0, 1.0, 0.0, 2.5, 3.0, 4.5, 1.5, 2.0, 3.0];
        let b = [1.0, 3.0, 2.0, 0.0, 2.0, 1.5, 2.0, 1.5, 1.0, 3.0, 0.5, 1.0, 0.5, 2.0, 2.5, 2.0, 2.0, 1.0];
        let p = [0.01634522670548517, 0.9918273866472574, 0.008172613352742586];
        check(&a, &b, WilcoxonMethod::NormalApprox, 17, 126.5, p, 1e-6);
    }

    #[test]
    fn wilcoxon_large_sample_uses_the_normal_approximation() {
        let (a, b) = generated(60, 0.75);
        let p = [0.49357801242517574, 0.24678900621258787, 0.7532109937874121];
        check(&a, &b, WilcoxonMethod::NormalApprox, 60, 822.0, p, 1e-6);
    }

    #[test]
    fn wilcoxon_exact_edge_cases() {
        check(&[2.0], &[1.0], WilcoxonMethod::Exact, 1, 1.0, [1.0, 1.0, 0.5], 1e-12);
        // All 20 differences negative: only the empty sign pattern is as extreme, p = 2^-20 one-sided.
        let a: Vec<f64> = (1..=20).map(f64::from).collect();
        let b: Vec<f64> = a.iter().map(|x| 2.0 * x).collect();
        let one = 2f64.powi(-20);
        check(&a, &b, WilcoxonMethod::Exact, 20, 0.0, [2.0 * one, one, 1.0], 1e-15);
    }

    #[test]
    fn wilcoxon_exact_table_sums_to_all_sign_patterns() {
        for n in [1, 2, 13, WILCOXON_EXACT_MAX_N] {
            let counts = signed_rank_sum_counts(n);
            assert_eq!(counts.len(), n * (n + 1) / 2 + 1);
            assert_eq!(counts.iter().sum::<u64>(), 1u64 << n);
            // W+ and W− = n(n+1)/2 − W+ have the same null distribution.
            assert!(counts.iter().eq(counts.iter().rev()));
        }
    }

    #[test]
    fn wilcoxon_rejects_unusable_input() {
        let err = |a: &[f64], b: &[f64]| wilcoxon_signed_rank(a, b, Alternative::TwoSided).unwrap_err().to_string();
        assert!(err(&[1.0, 2.0], &[1.0]).contains("2 values in a and 1 in b"));
        assert!(err(&[1.0, f64::NAN], &[0.0, 0.0]).contains("pair 1 is (NaN, 0)"));
        assert!(err(&[1.0], &[f64::NEG_INFINITY]).contains("finite"));
        assert!(err(&[f64::MAX], &[-f64::MAX]).contains("overflows"));
        assert!(err(&[1.0, 2.0], &[1.0, 2.0]).contains("all 2 pairs are equal"));
        assert!(err(&[], &[]).contains("at least one non-zero difference"));
        for msg in [err(&[1.0], &[]), err(&[0.0], &[0.0])] {
            assert!(!msg.contains('\n'));
        }
    }
}

/// How the p-value of [`mann_whitney_u`] was obtained.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MannWhitneyMethod {
    /// The exact null distribution of U (no ties and a sample of at most [`MANN_WHITNEY_EXACT_MAX_N`]).
    Exact,
    /// The normal approximation with tie and continuity correction.
    NormalApprox,
}

/// scipy's `method="auto"` cut-off: exact when the smaller sample has at most this many values and nothing ties.
pub const MANN_WHITNEY_EXACT_MAX_N: usize = 8;
/// Samples beyond this are a flag typo, not seeds of an experiment (the exact table would be n1·n2 wide).
const MANN_WHITNEY_MAX_N: usize = 100_000;

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MannWhitneyResult {
    /// U of the first sample: the number of pairs (a_i, b_j) with a_i > b_j, ties counted one half.
    pub statistic: f64,
    pub p_value: f64,
    pub method: MannWhitneyMethod,
}

/// The Mann-Whitney U test of independent samples `a` and `b`, matching `scipy.stats.mannwhitneyu` with its
/// defaults (`use_continuity=True`, `method="auto"`). `Greater`: `a` tends to be larger than `b` (the
/// one-sided test of an ablation against the full method over trained seeds).
pub fn mann_whitney_u(a: &[f64], b: &[f64], alternative: Alternative) -> Result<MannWhitneyResult> {
    let (n1, n2) = (a.len(), b.len());
    if n1 == 0 || n2 == 0 || n1 > MANN_WHITNEY_MAX_N || n2 > MANN_WHITNEY_MAX_N {
        return Err(Error::data(format!(
            "Mann-Whitney U test needs 1..={MANN_WHITNEY_MAX_N} values in each sample, got {n1} and {n2}"
        )));
    }
    if let Some(x) = a.iter().chain(b).find(|x| !x.is_finite()) {
        return Err(Error::data(format!("Mann-Whitney U test needs finite values, got {x}")));
    }
    // Average ranks of the pooled sample.
    let mut pooled: Vec<(f64, bool)> = a.iter().map(|&x| (x, true)).chain(b.iter().map(|&x| (x, false))).collect();
    pooled.sort_by(|x, y| x.0.total_cmp(&y.0));
    let (mut rank_sum_a, mut tie_term, mut has_ties) = (0.0, 0.0, false);
    let mut i = 0;
    while i < pooled.len() {
        let mut j = i;
        while j + 1 < pooled.len() && pooled[j + 1].0 == pooled[i].0 {
            j += 1;
        }
        let t = (j - i + 1) as f64;
        let rank = (i + j) as f64 / 2.0 + 1.0;
        rank_sum_a += rank * pooled[i..=j].iter().filter(|p| p.1).count() as f64;
        if t > 1.0 {
            has_ties = true;
            tie_term += t * t * t - t;
        }
        i = j + 1;
    }
    let (f1, f2) = (n1 as f64, n2 as f64);
    let u = rank_sum_a - f1 * (f1 + 1.0) / 2.0;
    if !has_ties && n1.min(n2) <= MANN_WHITNEY_EXACT_MAX_N {
        let counts = u_counts(n1, n2);
        let total: f64 = counts.iter().sum();
        let k = u.round() as usize;
        let p_le = counts[..=k].iter().sum::<f64>() / total;
        let p_ge = counts[k..].iter().sum::<f64>() / total;
        let p_value = match alternative {
            Alternative::Greater => p_ge,
            Alternative::Less => p_le,
            Alternative::TwoSided => (2.0 * p_le.min(p_ge)).min(1.0),
        };
        return Ok(MannWhitneyResult { statistic: u, p_value, method: MannWhitneyMethod::Exact });
    }
    let n = f1 + f2;
    let mean = f1 * f2 / 2.0;
    let variance = f1 * f2 / 12.0 * ((n + 1.0) - tie_term / (n * (n - 1.0)));
    let normal = Normal::standard();
    let sd = variance.sqrt();
    let p_value = if sd == 0.0 {
        1.0
    } else {
        match alternative {
            Alternative::Greater => normal.sf((u - mean - 0.5) / sd),
            Alternative::Less => normal.cdf((u - mean + 0.5) / sd),
            Alternative::TwoSided => (2.0 * normal.sf((u.max(f1 * f2 - u) - mean - 0.5) / sd)).min(1.0),
        }
    };
    Ok(MannWhitneyResult { statistic: u, p_value, method: MannWhitneyMethod::NormalApprox })
}

/// Number of arrangements of n1 + n2 distinct values giving each U = 0..=n1·n2, by the recursion over whether
/// the largest value belongs to the first sample. Small: the exact path runs only for min(n1, n2) ≤ 8.
fn u_counts(n1: usize, n2: usize) -> Vec<f64> {
    // table[j][u] for the current i: first sample of size i, second of size j.
    let max_u = n1 * n2;
    let mut prev: Vec<Vec<f64>> = (0..=n2).map(|_| vec![0.0; max_u + 1]).collect();
    for row in prev.iter_mut() {
        row[0] = 1.0;
    }
    for i in 1..=n1 {
        let mut cur: Vec<Vec<f64>> = (0..=n2).map(|_| vec![0.0; max_u + 1]).collect();
        cur[0][0] = 1.0;
        for j in 1..=n2 {
            for u in 0..=i * j {
                // Largest value in the first sample: it beats all j of the second.
                let from_first = if u >= j { prev[j][u - j] } else { 0.0 };
                cur[j][u] = from_first + cur[j - 1][u];
            }
        }
        prev = cur;
    }
    prev.swap_remove(n2)
}

#[cfg(test)]
mod mann_whitney_tests {
    use super::*;

    /// Reference values from scipy 1.17.1 `mannwhitneyu(a, b, alternative=…)`.
    #[test]
    fn matches_scipy() {
        type Case<'a> = (&'a [f64], &'a [f64], Alternative, f64, f64);
        let cases: [Case; 6] = [
            (&[0.9, 0.95, 1.0], &[0.5, 0.6, 0.7], Alternative::Greater, 9.0, 0.05),
            (&[1.0, 0.98, 0.99, 0.97], &[0.9, 0.99, 0.85, 0.8], Alternative::Greater, 13.5, 0.07324459196760427),
            (
                &[3.0, 5.0, 7.0, 9.0, 11.0, 13.0, 15.0, 17.0, 19.0],
                &[2.0, 4.0, 6.0, 8.0, 10.0, 12.0, 14.0, 16.0, 18.0],
                Alternative::Greater,
                45.0,
                0.36196601980698784,
            ),
            (&[1.0, 2.0, 2.0, 3.0], &[2.0, 3.0, 4.0, 4.0, 5.0], Alternative::Less, 2.5, 0.039272925475595334),
            (&[1.0, 1.0, 1.0], &[0.9, 1.0, 0.8], Alternative::Greater, 7.5, 0.09835280122947343),
            (
                &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0],
                &[1.5, 2.5, 3.5, 4.5, 5.5, 6.5, 7.5, 8.5],
                Alternative::TwoSided,
                28.0,
                0.7209013209013208,
            ),
        ];
        for (a, b, alternative, u, p) in cases {
            let r = mann_whitney_u(a, b, alternative).unwrap();
            assert_eq!(r.statistic, u, "{a:?} {b:?}");
            assert!((r.p_value - p).abs() < 1e-9, "{a:?} {b:?}: p {} vs scipy {p}", r.p_value);
        }
    }

    #[test]
    fn bad_samples_are_errors() {
        assert!(mann_whitney_u(&[], &[1.0], Alternative::Greater).is_err());
        assert!(mann_whitney_u(&[f64::NAN], &[1.0], Alternative::Greater).is_err());
    }
}
