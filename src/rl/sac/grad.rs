//! SAC's two losses and their gradients written out by hand over the torch-layout buffers (`nn::backprop`):
//! the twin critics' squared error and the actor's reparameterized objective through the frozen critics. An
//! update at batch 128 is a few dozen small tensors; burn's autodiff spent more on its graph and on reloading
//! both networks into their modules every update than on the arithmetic. `networks.rs` stays the reference: a
//! test holds both losses and every gradient here to burn's.

use super::networks::{policy_trunk_prefixes, q_prefixes, LOG_STD_MAX, LOG_STD_MIN, POLICY, TANH_EPSILON};
use crate::error::Result;
use crate::nn::backprop::{add_into, relu_backward, relu_in_place, zero_gradients, Dense};
use crate::nn::ParamSet;

/// ½ ln 2π, the Gaussian's normalizing term per dimension.
const HALF_LN_2PI: f32 = 0.918_938_5;

/// Dense layers with ReLU between them (none after the last), as the SEADS agent's networks are built.
struct ReluStack<'a> {
    layers: Vec<Dense<'a>>,
}

/// Every layer's input, from the network's own input on.
struct StackTape {
    inputs: Vec<Vec<f32>>,
}

impl<'a> ReluStack<'a> {
    fn new(params: &'a ParamSet, prefixes: &[String], widths: &[usize]) -> Result<Self> {
        let layers = prefixes
            .iter()
            .zip(widths.windows(2))
            .map(|(prefix, w)| Dense::new(params, prefix, w[0], w[1], false))
            .collect::<Result<Vec<_>>>()?;
        Ok(ReluStack { layers })
    }

    /// The last layer's output; with `relu_last`, ReLU'd too (a trunk rather than a whole network).
    fn forward(&self, x: &[f32], rows: usize, relu_last: bool) -> (Vec<f32>, StackTape) {
        let mut inputs = vec![x.to_vec()];
        let last = self.layers.len() - 1;
        for (k, layer) in self.layers.iter().enumerate() {
            let mut y = layer.forward(inputs.last().expect("the input is the first entry"), rows);
            if k < last || relu_last {
                relu_in_place(&mut y);
            }
            if k == last {
                return (y, StackTape { inputs });
            }
            inputs.push(y);
        }
        unreachable!("a stack has at least one layer")
    }

    /// Backward from the output gradients `dy` (of the ReLU'd output `y` when the forward had `relu_last`):
    /// adds the weights' gradients to `grads` (none for a network held fixed), and returns the input gradients
    /// when asked for.
    fn backward(
        &self,
        tape: &StackTape,
        relu_output: Option<&[f32]>,
        dy: &[f32],
        rows: usize,
        mut grads: Option<&mut [Vec<f32>]>,
        want_dx: bool,
    ) -> Vec<f32> {
        let mut d = dy.to_vec();
        if let Some(y) = relu_output {
            relu_backward(&mut d, y);
        }
        for (k, layer) in self.layers.iter().enumerate().rev() {
            let need_dx = k > 0 || want_dx;
            d = match grads.as_deref_mut() {
                Some(grads) => layer.backward(&tape.inputs[k], &d, rows, grads, need_dx),
                None if need_dx => layer.backward_input(&d, rows),
                None => Vec::new(),
            };
            if k > 0 {
                // The input of layer k is the ReLU'd output of layer k − 1.
                relu_backward(&mut d, &tape.inputs[k]);
            }
        }
        d
    }
}

fn twin<'a>(params: &'a ParamSet, prefix: &str, d_in: usize, hidden: &[usize]) -> Result<[ReluStack<'a>; 2]> {
    let mut widths = vec![d_in];
    widths.extend_from_slice(hidden);
    widths.push(1);
    let stack = |head: &str| ReluStack::new(params, &q_prefixes(prefix, head, hidden.len()), &widths);
    Ok([stack("q1")?, stack("q2")?])
}

/// The critics' loss mean (q1 − y)² + mean (q2 − y)² on `input` (rows × (obs + action)), the mean of (q1 + q2)/2,
/// and the gradient for every tensor of `params` (the critics named `prefix.q1.*`, `prefix.q2.*`).
pub fn critic_loss_and_gradients(
    params: &ParamSet,
    prefix: &str,
    hidden: &[usize],
    input: &[f32],
    targets: &[f32],
    rows: usize,
) -> Result<(f64, f64, Vec<Vec<f32>>)> {
    let d_in = input.len() / rows.max(1);
    let [q1_net, q2_net] = twin(params, prefix, d_in, hidden)?;
    // The critics share no tensor: each runs on its own thread into its own gradients, merged by name.
    let one_critic = |critic: &ReluStack| {
        let mut grads = zero_gradients(params);
        let (q, tape) = critic.forward(input, rows, false);
        let mut sum = 0.0f64;
        let dq: Vec<f32> = q
            .iter()
            .zip(targets)
            .map(|(q, y)| {
                sum += f64::from((q - y) * (q - y));
                2.0 * (q - y) / rows as f32
            })
            .collect();
        critic.backward(&tape, None, &dq, rows, Some(&mut grads), false);
        (sum / rows as f64, q.iter().map(|&q| f64::from(q)).sum::<f64>(), grads)
    };
    let ((loss1, q_sum1, mut grads), (loss2, q_sum2, mut grads2)) =
        rayon::join(|| one_critic(&q1_net), || one_critic(&q2_net));
    let q2_prefix = format!("{prefix}.q2.");
    for (tensor, (grad, grad2)) in params.tensors.iter().zip(grads.iter_mut().zip(&mut grads2)) {
        if tensor.name.starts_with(&q2_prefix) {
            *grad = std::mem::take(grad2);
        }
    }
    Ok((loss1 + loss2, (q_sum1 + q_sum2) / (2 * rows) as f64, grads))
}

/// What the actor's loss reports beside its gradients.
pub struct ActorLoss {
    /// mean (α log π − min(q1, q2)).
    pub loss: f64,
    /// −mean log π.
    pub entropy: f64,
    pub gradients: Vec<Vec<f32>>,
}

/// The actor's loss mean(α log π(a|s) − min(q1, q2)(s, a)) for the reparameterized actions
/// a = tanh(mean + σ·ε)·scale + bias with noise `eps` (rows × action), through the critics in `critic_params`
/// held fixed, and its gradient for every tensor of `policy_params`.
#[allow(clippy::too_many_arguments)]
pub fn actor_loss_and_gradients(
    policy_params: &ParamSet,
    critic_params: &ParamSet,
    critic_prefix: &str,
    hidden: &[usize],
    obs: &[f32],
    eps: &[f32],
    scale: &[f32],
    bias: &[f32],
    alpha: f32,
    rows: usize,
) -> Result<ActorLoss> {
    let a = scale.len();
    let od = obs.len() / rows.max(1);
    let last = *hidden.last().expect("validated: at least one hidden layer");
    let mut trunk_widths = vec![od];
    trunk_widths.extend_from_slice(hidden);
    let trunk = ReluStack::new(policy_params, &policy_trunk_prefixes(hidden.len()), &trunk_widths)?;
    let mean_head = Dense::new(policy_params, &format!("{POLICY}.mean_linear"), last, a, false)?;
    let log_std_head = Dense::new(policy_params, &format!("{POLICY}.log_std_linear"), last, a, false)?;
    let critics = twin(critic_params, critic_prefix, od + a, hidden)?;

    let (h, trunk_tape) = trunk.forward(obs, rows, true);
    let mean = mean_head.forward(&h, rows);
    let raw_log_std = log_std_head.forward(&h, rows);
    let n = rows * a;
    let (mut squashed, mut std, mut log_prob) = (vec![0.0f32; n], vec![0.0f32; n], vec![0.0f32; rows]);
    let mut critic_input = Vec::with_capacity(rows * (od + a));
    for r in 0..rows {
        critic_input.extend_from_slice(&obs[r * od..(r + 1) * od]);
        for j in 0..a {
            let k = r * a + j;
            let log_std = raw_log_std[k].clamp(LOG_STD_MIN, LOG_STD_MAX);
            std[k] = log_std.exp();
            let y = (mean[k] + std[k] * eps[k]).tanh();
            squashed[k] = y;
            log_prob[r] +=
                -0.5 * eps[k] * eps[k] - log_std - HALF_LN_2PI - ((1.0 - y * y) * scale[j] + TANH_EPSILON).ln();
            critic_input.push(y * scale[j] + bias[j]);
        }
    }
    let [q1_net, q2_net] = &critics;
    let ((q1, tape1), (q2, tape2)) =
        rayon::join(|| q1_net.forward(&critic_input, rows, false), || q2_net.forward(&critic_input, rows, false));

    let per_row = 1.0 / rows as f32;
    let (mut loss, mut log_prob_sum) = (0.0f64, 0.0f64);
    // min(q1, q2) takes q2 where q2 < q1 and q1 otherwise (ties included), and so does its gradient.
    let (mut dq1, mut dq2) = (vec![0.0f32; rows], vec![0.0f32; rows]);
    for r in 0..rows {
        let q_min = if q2[r] < q1[r] {
            dq2[r] = -per_row;
            q2[r]
        } else {
            dq1[r] = -per_row;
            q1[r]
        };
        loss += f64::from(alpha * log_prob[r] - q_min);
        log_prob_sum += f64::from(log_prob[r]);
    }
    let (mut d_input, d_input2) = rayon::join(
        || q1_net.backward(&tape1, None, &dq1, rows, None, true),
        || q2_net.backward(&tape2, None, &dq2, rows, None, true),
    );
    add_into(&mut d_input, &d_input2);

    let d_log_prob = alpha * per_row;
    let (mut d_mean, mut d_raw_log_std) = (vec![0.0f32; n], vec![0.0f32; n]);
    for r in 0..rows {
        for j in 0..a {
            let k = r * a + j;
            let y = squashed[k];
            let one_minus = 1.0 - y * y;
            let d_action = d_input[r * (od + a) + od + j];
            let d_y = d_action * scale[j] + d_log_prob * 2.0 * y * scale[j] / (one_minus * scale[j] + TANH_EPSILON);
            let d_u = d_y * one_minus;
            d_mean[k] = d_u;
            let d_log_std = d_u * std[k] * eps[k] - d_log_prob;
            let inside = (LOG_STD_MIN..=LOG_STD_MAX).contains(&raw_log_std[k]);
            d_raw_log_std[k] = if inside { d_log_std } else { 0.0 };
        }
    }
    let mut gradients = zero_gradients(policy_params);
    let mut d_h = mean_head.backward(&h, &d_mean, rows, &mut gradients, true);
    add_into(&mut d_h, &log_std_head.backward(&h, &d_raw_log_std, rows, &mut gradients, true));
    trunk.backward(&trunk_tape, Some(&h), &d_h, rows, Some(&mut gradients), false);
    Ok(ActorLoss { loss: loss / rows as f64, entropy: -log_prob_sum / rows as f64, gradients })
}
