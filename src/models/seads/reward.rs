//! The intrinsic reward of SEADS (thesis eq. 7.12 with the refinements of 7.3.5), computed from the forward
//! model's log-likelihoods log q(z_T | z_0, k) of one episode under every skill k.

use super::config::RewardTerms;

/// The least reward an episode can get: −2 log K, the clip of log q(k | z_0, z_T). Episodes that leave the board
/// unchanged get exactly this for every skill.
pub fn reward_floor(skills: usize) -> f64 {
    -2.0 * (skills as f64).ln()
}

/// log q(k | z_0, z_T) for every k from log q(z_T | z_0, k): Bayes with a uniform prior over skills.
pub fn skill_log_posterior(log_likelihoods: &[f64]) -> Vec<f64> {
    let max = log_likelihoods.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let log_sum = max + log_likelihoods.iter().map(|l| (l - max).exp()).sum::<f64>().ln();
    log_likelihoods.iter().map(|l| l - log_sum).collect()
}

/// The skill posterior clipped at the reward floor, which bounds the cost of a skill that looks impossible (the
/// relabelling's assignment costs are these values too).
pub fn clipped_posterior(log_likelihoods: &[f64]) -> Vec<f64> {
    let floor = reward_floor(log_likelihoods.len());
    skill_log_posterior(log_likelihoods).into_iter().map(|p| p.max(floor)).collect()
}

/// The reward of the episode's final transition had it been labelled k, for every k: clipped log q(k|z_0,z_T),
/// minus the second-largest clipped value over k' (so a skill is paid for being distinguishable, not merely
/// likely), plus the novelty bonus −max_k' log q(z_T|z_0,k') capped at log K (paid for outcomes no skill
/// explains yet).
pub fn rewards_for_all_skills(log_likelihoods: &[f64], terms: RewardTerms) -> Vec<f64> {
    let k = log_likelihoods.len();
    let clipped = clipped_posterior(log_likelihoods);
    let mut rewards = clipped.clone();
    if terms.second_best {
        let mut sorted = clipped;
        sorted.sort_by(|a, b| b.total_cmp(a));
        let second = sorted.get(1).copied().unwrap_or(0.0);
        rewards.iter_mut().for_each(|r| *r -= second);
    }
    if terms.novelty {
        let best = log_likelihoods.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let bonus = -best.max(-(k as f64).ln());
        rewards.iter_mut().for_each(|r| *r += bonus);
    }
    rewards
}

/// The reward on an episode's final transition under `label`: the floor for every label when the board did not
/// change (nothing was done, so no skill can be credited), otherwise [`rewards_for_all_skills`] at the label.
pub fn episode_reward(changed: bool, log_likelihoods: &[f64], label: usize, terms: RewardTerms) -> f64 {
    if changed {
        rewards_for_all_skills(log_likelihoods, terms)[label]
    } else {
        reward_floor(log_likelihoods.len())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    const ALL: RewardTerms = RewardTerms { second_best: true, novelty: true };

    #[test]
    fn reward_is_never_below_the_floor() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        for _ in 0..2000 {
            let k = rng.random_range(2..30);
            // Log-likelihoods of Bernoulli products: non-positive, from near 0 to very unlikely.
            let lls: Vec<f64> =
                (0..k).map(|_| -rng.random_range(0.0..400.0f64).powf(rng.random_range(0.1..1.0))).collect();
            for terms in [
                ALL,
                RewardTerms { second_best: false, novelty: false },
                RewardTerms { second_best: true, novelty: false },
            ] {
                for r in rewards_for_all_skills(&lls, terms) {
                    assert!(r >= reward_floor(k) - 1e-12, "{r} < {} for {lls:?}", reward_floor(k));
                }
            }
        }
    }

    #[test]
    fn episodes_that_change_nothing_earn_exactly_the_floor() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        for _ in 0..200 {
            let k = rng.random_range(2..30);
            let lls: Vec<f64> = (0..k).map(|_| -rng.random_range(0.0..50.0)).collect();
            for label in 0..k {
                assert_eq!(episode_reward(false, &lls, label, ALL), reward_floor(k));
                assert!(episode_reward(true, &lls, label, ALL) >= reward_floor(k) - 1e-12);
            }
        }
    }

    #[test]
    fn a_unique_certain_skill_earns_the_most() {
        // Skill 0 predicts the outcome with certainty, the others find it very unlikely.
        let lls = [0.0, -60.0, -60.0, -60.0];
        let r = rewards_for_all_skills(&lls, ALL);
        assert!((r[0] - (0.0 - reward_floor(4))).abs() < 1e-9, "{r:?}");
        assert!(r[1] < r[0]);
        // Two skills explaining it equally well earn nothing over each other: only the novelty bonus (0.1) remains.
        let tie = rewards_for_all_skills(&[-0.1, -0.1, -60.0, -60.0], ALL);
        assert!((tie[0] - 0.1).abs() < 1e-9 && (tie[0] - tie[1]).abs() < 1e-12, "{tie:?}");
    }

    #[test]
    fn novelty_pays_for_outcomes_no_skill_explains() {
        let known = rewards_for_all_skills(&[-0.01, -50.0, -50.0], ALL);
        let novel = rewards_for_all_skills(&[-20.0, -50.0, -50.0], ALL);
        // Same posterior ranking, but the novel outcome adds the full bonus log K.
        assert!((novel[0] - known[0] - (3f64.ln() - 0.01)).abs() < 1e-6, "{known:?} {novel:?}");
    }
}
