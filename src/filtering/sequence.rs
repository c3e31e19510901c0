//! Filtering a whole measurement sequence and forecasting past its end.

use super::ekf::{predict, update, Belief, EkfModel, Mat, Vector};
use super::FilterError;

/// Filtered beliefs after each measurement slot and the marginal log-likelihood of the sequence.
#[derive(Clone, Debug, PartialEq)]
pub struct FilterOutput<const N: usize, D = ()> {
    /// Mean after slot k (filtered, or only predicted where slot k had no measurement).
    pub states: Vec<Vector<N>>,
    pub covariances: Vec<Mat<N, N>>,
    pub modes: Vec<D>,
    /// Σ log N(m_k | h(x̂_k|k−1), S_k) over the slots that had a measurement (eq. 6.24).
    pub log_likelihood: f64,
}

impl<const N: usize, D: Copy> FilterOutput<N, D> {
    /// The belief after the last slot, where a forecast would start; None for an empty sequence.
    pub fn last_belief(&self) -> Option<Belief<N, D>> {
        let k = self.states.len().checked_sub(1)?;
        Some(Belief { mean: self.states[k], cov: self.covariances[k], mode: self.modes[k] })
    }
}

/// Filters `measurements` starting from N(x0, p0) in the model's default mode. As in the Kalman filter recursion
/// (6.3.2), the initial belief is at the time before the first slot: every slot is one prediction step, followed by a
/// correction when the slot holds a measurement; a `None` slot (a dropout) is the prediction alone.
pub fn filter<Mo, const N: usize, const M: usize>(
    model: &Mo,
    x0: &Vector<N>,
    p0: &Mat<N, N>,
    measurements: &[Option<[f64; M]>],
) -> Result<FilterOutput<N, Mo::Mode>, FilterError>
where
    Mo: EkfModel<N, M>,
{
    filter_belief(model, &Belief::new(*x0, *p0), measurements)
}

/// [`filter`] from a belief that carries its own mode (e.g. a ball initialized after its table impact).
pub fn filter_belief<Mo, const N: usize, const M: usize>(
    model: &Mo,
    initial: &Belief<N, Mo::Mode>,
    measurements: &[Option<[f64; M]>],
) -> Result<FilterOutput<N, Mo::Mode>, FilterError>
where
    Mo: EkfModel<N, M>,
{
    let mut out = FilterOutput {
        states: Vec::with_capacity(measurements.len()),
        covariances: Vec::with_capacity(measurements.len()),
        modes: Vec::with_capacity(measurements.len()),
        log_likelihood: 0.0,
    };
    let mut belief = *initial;
    for (index, slot) in measurements.iter().enumerate() {
        belief = predict(model, &belief);
        if let Some(m) = slot {
            let (corrected, log_likelihood) =
                update(model, &belief, &Vector::<M>::from(*m)).map_err(|e| e.at(index))?;
            belief = corrected;
            out.log_likelihood += log_likelihood;
        }
        out.states.push(belief.mean);
        out.covariances.push(belief.cov);
        out.modes.push(belief.mode);
    }
    Ok(out)
}

/// Open-loop prediction of `steps` beliefs (mean and covariance) after `start`.
pub fn forecast<Mo, const N: usize, const M: usize>(
    model: &Mo,
    start: &Belief<N, Mo::Mode>,
    steps: usize,
) -> Vec<Belief<N, Mo::Mode>>
where
    Mo: EkfModel<N, M>,
{
    let mut out = Vec::with_capacity(steps);
    let mut belief = *start;
    for _ in 0..steps {
        belief = predict(model, &belief);
        out.push(belief);
    }
    out
}

/// Open-loop prediction of `steps` means after `start`, skipping the covariance (and Jacobian) work.
pub fn forecast_means<Mo, const N: usize, const M: usize>(
    model: &Mo,
    start: &Vector<N>,
    mode: Mo::Mode,
    steps: usize,
) -> Vec<Vector<N>>
where
    Mo: EkfModel<N, M>,
{
    let mut mode = mode;
    let mut x = *start;
    (0..steps)
        .map(|_| {
            x = model.predict_mean(&x, &mut mode);
            x
        })
        .collect()
}
