//! Relabelling (thesis 7.3.4): the skill labels of a set of episodes are redistributed among them so that the
//! total clipped log q(k | z_0, z_T) is largest, keeping the multiset of labels (each skill keeps its share of
//! the data). A linear sum assignment, solved with `lsap` (scipy's algorithm, which the authors called).

use crate::error::{Error, Result};

/// `clipped_posteriors[e][k]` = clipped log q(k | z_0, z_T) of episode e; `labels[e]` its current label. Returns
/// the new label of every episode.
pub fn relabel_by_assignment(clipped_posteriors: &[Vec<f64>], labels: &[usize]) -> Result<Vec<usize>> {
    let n = labels.len();
    if clipped_posteriors.len() != n {
        return Err(Error::config(format!("relabelling: {} episodes but {n} labels", clipped_posteriors.len())));
    }
    if n == 0 {
        return Ok(Vec::new());
    }
    // Row r stands for label labels[r]; column c for episode c.
    let mut cost = Vec::with_capacity(n * n);
    for &label in labels {
        for posterior in clipped_posteriors {
            let value = *posterior.get(label).ok_or_else(|| {
                Error::config(format!("relabelling: label {label} beyond the {} skills", posterior.len()))
            })?;
            if !value.is_finite() {
                return Err(Error::config("relabelling: a non-finite skill log-probability"));
            }
            cost.push(-value);
        }
    }
    let (rows, cols) =
        lsap::solve(n, n, &cost, false).map_err(|e| Error::config(format!("relabelling assignment failed: {e:?}")))?;
    let mut relabelled = vec![usize::MAX; n];
    for (r, c) in rows.into_iter().zip(cols) {
        relabelled[c] = labels[r];
    }
    if relabelled.contains(&usize::MAX) {
        return Err(Error::config("relabelling assignment left an episode without a label"));
    }
    Ok(relabelled)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    fn total(posteriors: &[Vec<f64>], labels: &[usize]) -> f64 {
        labels.iter().enumerate().map(|(e, &k)| posteriors[e][k]).sum()
    }

    fn permutations(items: &[usize]) -> Vec<Vec<usize>> {
        if items.len() <= 1 {
            return vec![items.to_vec()];
        }
        let mut out = Vec::new();
        for i in 0..items.len() {
            let mut rest = items.to_vec();
            let first = rest.remove(i);
            for mut tail in permutations(&rest) {
                tail.insert(0, first);
                out.push(tail);
            }
        }
        out
    }

    #[test]
    fn keeps_the_label_multiset_and_is_optimal_against_brute_force() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(17);
        for _ in 0..200 {
            let n = rng.random_range(1..=6);
            let k = rng.random_range(2..=5);
            let floor = -2.0 * (k as f64).ln();
            let posteriors: Vec<Vec<f64>> =
                (0..n).map(|_| (0..k).map(|_| rng.random_range(floor..0.0)).collect()).collect();
            let labels: Vec<usize> = (0..n).map(|_| rng.random_range(0..k)).collect();
            let new = relabel_by_assignment(&posteriors, &labels).unwrap();
            let (mut a, mut b) = (labels.clone(), new.clone());
            a.sort();
            b.sort();
            assert_eq!(a, b, "the multiset of labels changed");
            let best = permutations(&labels).iter().map(|p| total(&posteriors, p)).fold(f64::NEG_INFINITY, f64::max);
            assert!(
                (total(&posteriors, &new) - best).abs() < 1e-9,
                "not optimal: {} vs {best}",
                total(&posteriors, &new)
            );
        }
    }

    #[test]
    fn swaps_labels_that_fit_the_other_episode() {
        let posteriors = vec![vec![-5.0, -0.01], vec![-0.01, -5.0]];
        assert_eq!(relabel_by_assignment(&posteriors, &[0, 1]).unwrap(), vec![1, 0]);
        assert!(relabel_by_assignment(&posteriors, &[0, 2]).is_err());
    }
}
