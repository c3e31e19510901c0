//! The swing-up task's success test (thesis 3.5.2), defined by the env that scores it so every controller
//! (CEM on the simulator, PETS, DLGPD from images) is judged by the same rule.

/// Rewards at the end of an episode that must all be high: the pendulum stays up, not just passes the top.
pub const SUCCESS_WINDOW: usize = 25;
/// gym's reward is −(θ² + 0.1 θ̇² + 0.001 u²); above −1 means within about one radian of upright and slow.
pub const SUCCESS_MIN_REWARD: f64 = -1.0;

/// The thesis' success criterion: every one of the last 25 rewards above −1.
pub fn is_success(rewards: &[f64]) -> bool {
    rewards.len() >= SUCCESS_WINDOW && rewards[rewards.len() - SUCCESS_WINDOW..].iter().all(|&r| r > SUCCESS_MIN_REWARD)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn success_needs_the_whole_window_high() {
        let mut r = vec![-5.0; 150];
        for x in r.iter_mut().skip(150 - SUCCESS_WINDOW) {
            *x = -0.5;
        }
        assert!(is_success(&r));
        r[149] = -1.0;
        assert!(!is_success(&r));
        assert!(!is_success(&[-0.1; 10]));
    }
}
