//! Eq. 4.32 and its gradient written out by hand: the training step of the context model (and TRADYN's) without
//! burn's autodiff. One batch-64 step is a few hundred small tensors; on two cores autodiff's bookkeeping,
//! copies and fresh pages cost more than the arithmetic. `net.rs` stays the reference: a test holds the loss and
//! every gradient here to burn's.

use rayon::prelude::*;

use super::config::ContextConfig;
use super::data::Batch;
use super::net::{STD_FLOOR, STD_SCALE, STD_SHIFT, VARIANCE_FLOOR};
use crate::error::{Error, Result};
use crate::nn::activation::{fast_sigmoid as sigmoid, fast_softplus as softplus, fast_tanh as tanh};
use crate::nn::backprop::{
    add_column_sums, add_into, assume_written, block_rows, concat, copy_of, for_each_value, slots, tensor_index,
    unwritten, zero_gradients, zip_values, TwoLayer, TwoLayerTape,
};
use crate::nn::gru_backprop::Gru;
use crate::nn::sparse::SparseColumns;
use crate::nn::ParamSet;

/// The loss and its parts (batch means), as [`super::net::LossParts`] reports them.
#[derive(Clone, Debug, PartialEq)]
pub struct LossValues {
    pub loss: f64,
    pub reconstruction: f64,
    pub single_step: f64,
    pub multi_step: f64,
    pub kl: f64,
    pub posterior_std: f64,
    pub context_std: f64,
}

/// The context network's layers as views of a parameter set.
struct Net<'a> {
    state_encoder: TwoLayer<'a>,
    action_encoder: TwoLayer<'a>,
    context_embedding: TwoLayer<'a>,
    terrain_embedding: Option<TwoLayer<'a>>,
    gru: Gru<'a>,
    mean_decoder: TwoLayer<'a>,
    variance: Variance<'a>,
    transition_encoder: TwoLayer<'a>,
    context_mean: TwoLayer<'a>,
    context_std: TwoLayer<'a>,
}

enum Variance<'a> {
    Decoder(TwoLayer<'a>),
    /// The raw constant (softplus + floor gives the variance) and its index.
    Constant(&'a [f32], usize),
}

impl<'a> Net<'a> {
    fn new(params: &'a ParamSet, config: &ContextConfig, s: usize, local: usize, a: usize) -> Result<Self> {
        let (e, h) = (config.embedding, config.hidden_units);
        let (f, b) = (config.transition_features, config.latent_dim);
        let p = s - local;
        let two = |name: &str, d_in: usize, d_out: usize| TwoLayer::new(params, name, d_in, h, d_out, false);
        let variance = if config.constant_variance {
            let index = tensor_index(params, "constant_variance", &[p])?;
            Variance::Constant(&params.tensors[index].values, index)
        } else {
            Variance::Decoder(two("variance_decoder", e, p)?)
        };
        Ok(Net {
            state_encoder: two("state_encoder", p, e)?,
            action_encoder: two("action_encoder", a, e)?,
            context_embedding: two("context_embedding", b, e)?,
            terrain_embedding: if local > 0 { Some(two("terrain_embedding", local, e)?) } else { None },
            gru: Gru::new(params, "gru", e, if local > 0 { 3 } else { 2 })?,
            mean_decoder: two("mean_decoder", e, p)?,
            variance,
            transition_encoder: two("transition_encoder", 2 * s + a, f)?,
            context_mean: two("context_mean", f, b)?,
            context_std: TwoLayer::new(params, "context_std", f, h, b, true)?,
        })
    }
}

/// A belief's forward values and tapes.
struct BeliefTape {
    mean: Vec<f32>,
    std: Vec<f32>,
    mean_tape: TwoLayerTape,
    std_tape: TwoLayerTape,
    /// −0.3·enc + 0.5, the softplus argument.
    std_arg: Vec<f32>,
}

fn belief(net: &Net, pooled: &[f32], sets: usize) -> BeliefTape {
    let (mean, mean_tape) = net.context_mean.forward(pooled, sets);
    let (enc, std_tape) = net.context_std.forward(pooled, sets);
    let std_arg: Vec<f32> = enc.iter().map(|x| STD_SCALE * x + STD_SHIFT).collect();
    let std = std_arg.iter().map(|x| softplus(*x) + STD_FLOOR).collect();
    BeliefTape { mean, std, mean_tape, std_tape, std_arg }
}

/// Adds the belief heads' gradients and returns d pooled.
fn belief_backward(
    net: &Net,
    pooled: &[f32],
    tape: &BeliefTape,
    d_mean: &[f32],
    d_std: &[f32],
    sets: usize,
    grads: &mut [Vec<f32>],
) -> Vec<f32> {
    let mut d_pooled = net.context_mean.backward(pooled, &tape.mean_tape, d_mean, sets, grads, true);
    let d_enc: Vec<f32> = d_std.iter().zip(&tape.std_arg).map(|(d, x)| d * sigmoid(*x) * STD_SCALE).collect();
    let from_std = net.context_std.backward(pooled, &tape.std_tape, &d_enc, sets, grads, true);
    add_into(&mut d_pooled, &from_std);
    d_pooled
}

/// Max pooling of each set's rows with a zero start (absent rows excluded). Returns the pooled features and,
/// per (set, feature), the row that gave a positive maximum (None where the maximum is the zero start).
fn max_pool(
    features: &[f32],
    sets: usize,
    size: usize,
    f: usize,
    present: Option<&[bool]>,
) -> (Vec<f32>, Vec<Option<usize>>) {
    let mut pooled = vec![0.0f32; sets * f];
    let mut argmax = vec![None; sets * f];
    pooled.par_chunks_mut(f).zip(argmax.par_chunks_mut(f)).enumerate().for_each(|(set, (pooled, argmax))| {
        for row in set * size..(set + 1) * size {
            if present.is_some_and(|p| !p[row]) {
                continue;
            }
            for j in 0..f {
                let x = features[row * f + j];
                if x > pooled[j] {
                    pooled[j] = x;
                    argmax[j] = Some(row);
                }
            }
        }
    });
    (pooled, argmax)
}

/// KL(p ‖ q) per dimension of diagonal Gaussians.
fn kl(pm: f32, ps: f32, qm: f32, qs: f32) -> f32 {
    let ratio = (ps / qs).powi(2);
    let shift = ((pm - qm) / qs).powi(2);
    (ratio + shift - 1.0) * 0.5 + (qs / ps).ln()
}

/// Σ_d log N(x_d | m_d, v_d) per row, and its derivatives with respect to m and v, each row's times
/// `weight(row)` (the row's weight in the loss). Rows go in parallel blocks (serially, this was 4 % of the
/// batch-64 step on two threads); each row is summed in order, so the bytes do not depend on the threads.
fn gaussian_log_likelihood(
    x: &[f32],
    m: &[f32],
    v: &[f32],
    d: usize,
    weight: impl Fn(usize) -> f32 + Sync,
) -> (Vec<f32>, Vec<f32>, Vec<f32>) {
    let log_2pi = (2.0 * std::f32::consts::PI).ln();
    let rows = x.len() / d;
    let mut ll = vec![0.0; rows];
    let mut dm = vec![0.0; x.len()];
    let mut dv = vec![0.0; x.len()];
    let per_task = rows.div_ceil(rayon::current_num_threads()).max(1024);
    let blocks = ll.par_chunks_mut(per_task).zip(dm.par_chunks_mut(per_task * d).zip(dv.par_chunks_mut(per_task * d)));
    blocks.enumerate().for_each(|(block, (ll, (dm, dv)))| {
        for (r, out) in ll.iter_mut().enumerate() {
            let row = block * per_task + r;
            let w = weight(row);
            let mut sum = 0.0;
            for j in 0..d {
                let (k, local) = (row * d + j, r * d + j);
                let diff = x[k] - m[k];
                sum += diff * diff / v[k] + v[k].ln() + log_2pi;
                dm[local] = diff / v[k] * w;
                dv[local] = 0.5 * (diff * diff / (v[k] * v[k]) - 1.0 / v[k]) * w;
            }
            *out = -0.5 * sum;
        }
    });
    (ll, dm, dv)
}

/// Eq. 4.32 on a batch, as [`super::net::ContextNet::loss`] computes it, and with `want_gradients` the gradient
/// of the loss with respect to every tensor of `params` (in its order).
pub fn loss_and_gradients(
    params: &ParamSet,
    batch: &Batch,
    config: &ContextConfig,
    want_gradients: bool,
) -> Result<(LossValues, Option<Vec<Vec<f32>>>)> {
    let (b, n) = (batch.size, batch.chunk);
    if b == 0 || n < 2 {
        return Err(Error::config("context loss: a batch needs at least one chunk of two states"));
    }
    let t = n - 1;
    let s = batch.states.len() / (b * n);
    let l = batch.local_dim;
    let p = s - l;
    let a = batch.actions.len() / (b * t);
    let m = batch.context_max;
    let (e, lat, f) = (config.embedding, config.latent_dim, config.transition_features);
    let net = Net::new(params, config, s, l, a)?;
    let g = 3 * e;
    let steps = t - 1;

    // Transition features of the chunk's and the context's transitions in one pass.
    let transitions = concat(&[&batch.chunk_transitions, &batch.context]);
    let enc_rows = b * t + b * m;
    let (features, enc_tape) = net.transition_encoder.forward_relu(&transitions, enc_rows);
    let (chunk_pool, chunk_arg) = max_pool(&features[..b * t * f], b, t, f, None);
    let (context_pool, context_arg) = max_pool(&features[b * t * f..], b, m, f, Some(&batch.present));
    // Max pooling distributes over a union; ties go to the chunk's side, as burn's max_pair does.
    let union_pool: Vec<f32> = chunk_pool.iter().zip(&context_pool).map(|(c, x)| if c < x { *x } else { *c }).collect();
    let posterior = belief(&net, &union_pool, b);
    let prior = belief(&net, &context_pool, b);
    let zero_pool = vec![0.0; f];
    let empty = belief(&net, &zero_pool, 1);

    let kl_empty: f32 = (0..lat).map(|d| kl(empty.mean[d], empty.std[d], 0.0, 1.0)).sum();
    let kl_floor = config.kl_floor as f32;
    let kl_values: Vec<f32> =
        (0..b * lat).map(|k| kl(posterior.mean[k], posterior.std[k], prior.mean[k], prior.std[k])).collect();
    let kl_context = kl_values.iter().map(|v| v.max(kl_floor)).sum::<f32>() / b as f32;
    let kl_weight = config.kl_weight as f32;

    // Embeddings and the GRU input gates shared by the single-step and multi-step predictions. Only the N − 1
    // states a transition starts from are embedded (chunk i's state k at row i·T + k): the reconstruction term
    // averages over them as the authors' loss does, and the last state is never stepped from.
    let predicted: Vec<f32> = batch.states.chunks(s).flat_map(|row| &row[..p]).copied().collect();
    let starts: Vec<f32> = (0..b).flat_map(|i| &predicted[i * n * p..(i * n + t) * p]).copied().collect();
    let (mut h_all, state_tape) = net.state_encoder.forward(&starts, b * t);
    for_each_value(&mut h_all, |x| *x = tanh(*x));
    let (act_emb, act_tape) = net.action_encoder.forward_relu(&batch.actions, b * t);
    let mut action_gates = net.gru.input_gates(&act_emb, b * t, 1);
    let terrain = net.terrain_embedding.as_ref().map(|embedding| {
        let tau: Vec<f32> = (0..b)
            .flat_map(|i| (0..t).flat_map(move |k| (i * n + k) * s + p..(i * n + k + 1) * s))
            .map(|at| batch.states[at])
            .collect();
        let (emb, tape) = embedding.forward_relu(&tau, b * t);
        (tau, emb, tape)
    });
    if let Some((_, emb, _)) = &terrain {
        net.gru.add_input_gates(emb, b * t, 2, &mut action_gates);
    }

    // The single-step predictions and the multi-step open loop share only their inputs, so they run side by
    // side: the loop's small per-step products leave most of a second thread idle.
    let chunk_rows = block_rows(b, g);
    let single_steps = || {
        // Single-step predictions from every chunk state, each with a fresh β sample.
        let beta_single: Vec<f32> = (0..b * t * lat)
            .map(|k| {
                let (i, d) = (k / (t * lat), k % lat);
                posterior.mean[i * lat + d] + posterior.std[i * lat + d] * batch.noise_single[k]
            })
            .collect();
        let (ctx_single, ctx_single_tape) = net.context_embedding.forward_relu(&beta_single, b * t);
        let gi_single = net.gru.input_gates_from(&action_gates, &ctx_single, b * t, 0);
        let mut h_single = copy_of(&h_all);
        let single_tape = net.gru.step(&gi_single, &mut h_single, b * t);
        (beta_single, ctx_single, ctx_single_tape, h_single, single_tape)
    };
    let open_loop = || {
        // Multi-step: one β per chunk, open loop from s_0; the predictions of s_2.. enter the sum.
        let beta: Vec<f32> =
            (0..b * lat).map(|k| posterior.mean[k] + posterior.std[k] * batch.noise_sequence[k]).collect();
        let (ctx_seq, ctx_seq_tape) = net.context_embedding.forward_relu(&beta, b);
        let mut ctx_gates = vec![0.0; b * g];
        net.gru.add_input_gates(&ctx_seq, b, 0, &mut ctx_gates);
        let mut h: Vec<f32> = (0..b).flat_map(|i| h_all[i * t * e..(i * t + 1) * e].iter().copied()).collect();
        // Step-major: row k·B + i is chunk i at step k.
        let mut seq_h_prev = Vec::with_capacity(t * b * e);
        let mut seq_tapes = Vec::with_capacity(t);
        let mut open_loop = vec![0.0; b * steps * e];
        let mut gi = vec![0.0; b * g];
        for k in 0..t {
            gi.par_chunks_mut(chunk_rows * g).enumerate().for_each(|(block, gi)| {
                for (row, gi) in gi.chunks_mut(g).enumerate() {
                    let i = block * chunk_rows + row;
                    let src = &action_gates[(i * t + k) * g..(i * t + k + 1) * g];
                    let ctx = &ctx_gates[i * g..(i + 1) * g];
                    for ((o, x), c) in gi.iter_mut().zip(src).zip(ctx) {
                        *o = x + c;
                    }
                }
            });
            seq_h_prev.extend_from_slice(&h);
            seq_tapes.push(net.gru.step(&gi, &mut h, b));
            if k >= 1 {
                for i in 0..b {
                    let j = k - 1;
                    open_loop[(i * steps + j) * e..(i * steps + j + 1) * e].copy_from_slice(&h[i * e..(i + 1) * e]);
                }
            }
        }
        (beta, ctx_seq, ctx_seq_tape, seq_h_prev, seq_tapes, open_loop)
    };
    let (
        (beta_single, ctx_single, ctx_single_tape, h_single, single_tape),
        (beta, ctx_seq, ctx_seq_tape, seq_h_prev, seq_tapes, open_loop),
    ) = rayon::join(single_steps, open_loop);

    // One decoder pass over the reconstruction, single-step and multi-step GRU states.
    let rows = 2 * b * t + b * steps;
    let decoded = concat(&[&h_all, &h_single, &open_loop]);
    let mut targets = Vec::with_capacity(rows * p);
    targets.extend_from_slice(&starts);
    for i in 0..b {
        targets.extend_from_slice(&predicted[(i * n + 1) * p..(i * n + n) * p]);
    }
    for i in 0..b {
        targets.extend_from_slice(&predicted[(i * n + 2) * p..(i * n + n) * p]);
    }
    let (mean, mean_tape) = net.mean_decoder.forward(&decoded, rows);
    let (variance, variance_tape) = match &net.variance {
        Variance::Decoder(decoder) => {
            let (raw, tape) = decoder.forward(&decoded, rows);
            let v = raw.iter().map(|x| softplus(*x) + VARIANCE_FLOOR).collect::<Vec<_>>();
            (v, Some((raw, tape)))
        }
        Variance::Constant(raw, _) => {
            let row: Vec<f32> = raw.iter().map(|x| softplus(*x) + VARIANCE_FLOOR).collect();
            (row.iter().cycle().take(rows * p).copied().collect(), None)
        }
    };
    // ∂loss/∂(row log-likelihood): the reconstruction and single-step terms are means over their B·T rows, the
    // multi-step one a mean over chunks of a sum over steps.
    let row_weight = |row: usize| -> f32 {
        if row < 2 * b * t {
            -1.0 / (b * t) as f32
        } else {
            -1.0 / b as f32
        }
    };
    let (ll, d_mean, d_var) = gaussian_log_likelihood(&targets, &mean, &variance, p, row_weight);
    let sum = |range: std::ops::Range<usize>| ll[range].iter().map(|x| *x as f64).sum::<f64>();
    let reconstruction = sum(0..b * t) / (b * t) as f64;
    let single_step = sum(b * t..2 * b * t) / (b * t) as f64;
    let multi_step = sum(2 * b * t..rows) / b as f64;
    let kl_total = kl_empty as f64 + kl_context as f64 * config.kl_weight;
    let mean_of = |v: &[f32]| v.iter().map(|x| *x as f64).sum::<f64>() / v.len() as f64;
    let values = LossValues {
        loss: -(reconstruction + single_step + multi_step) + kl_total,
        reconstruction,
        single_step,
        multi_step,
        kl: kl_total,
        posterior_std: mean_of(&posterior.std),
        context_std: mean_of(&prior.std),
    };
    if !want_gradients {
        return Ok((values, None));
    }

    let mut grads = zero_gradients(params);
    let mut d_decoded = net.mean_decoder.backward(&decoded, &mean_tape, &d_mean, rows, &mut grads, true);
    match (&net.variance, variance_tape) {
        (Variance::Decoder(decoder), Some((raw, tape))) => {
            let d_raw: Vec<f32> = d_var.iter().zip(&raw).map(|(d, x)| d * sigmoid(*x)).collect();
            let from_var = decoder.backward(&decoded, &tape, &d_raw, rows, &mut grads, true);
            add_into(&mut d_decoded, &from_var);
        }
        (Variance::Constant(raw, index), _) => {
            let mut sums = vec![0.0; p];
            add_column_sums(&mut sums, &d_var);
            for ((gr, sm), x) in grads[*index].iter_mut().zip(&sums).zip(raw.iter()) {
                *gr += sm * sigmoid(*x);
            }
        }
        (Variance::Decoder(_), None) => unreachable!("a variance decoder's forward pass leaves its tape"),
    }
    let (d_h_all, d_predicted) = d_decoded.split_at_mut(b * t * e);
    let (d_h_single, d_open) = (&d_predicted[..b * t * e], &d_predicted[b * t * e..]);

    // Back through the open loop and, beside it, through the single steps; their weight gradients are then
    // added in a fixed order.
    let open_loop_back = || {
        // Both are written in full over the steps (every chunk's gates at every step), never zeroed.
        let (mut d_gi_seq, mut seq_d_gh) = (unwritten(b * t * g), unwritten(t * b * g));
        let mut dh = vec![0.0; b * e];
        {
            let (d_gi_slots, d_gh_slots) = (slots(&mut d_gi_seq, b * t * g), slots(&mut seq_d_gh, t * b * g));
            for k in (0..t).rev() {
                if k >= 1 {
                    let j = k - 1;
                    for i in 0..b {
                        let src = &d_open[(i * steps + j) * e..(i * steps + j + 1) * e];
                        add_into(&mut dh[i * e..(i + 1) * e], src);
                    }
                }
                let h_prev = &seq_h_prev[k * b * e..(k + 1) * b * e];
                let d_gh = &mut d_gh_slots[k * b * g..(k + 1) * b * g];
                let d_gi_step;
                (dh, d_gi_step) = net.gru.step_backward(&seq_tapes[k], h_prev, &dh, b, d_gh);
                // Chunk i's gates at step k go to row i·T + k: whole chunks' rows per task.
                d_gi_slots.par_chunks_mut(chunk_rows * t * g).enumerate().for_each(|(block, rows)| {
                    for (row, chunk) in rows.chunks_mut(t * g).enumerate() {
                        let i = block * chunk_rows + row;
                        let src = &d_gi_step[i * g..(i + 1) * g];
                        chunk[k * g..(k + 1) * g].iter_mut().zip(src).for_each(|(slot, x)| _ = slot.write(*x));
                    }
                });
            }
        }
        // SAFETY: steps 0..t wrote every chunk's gates at every step into both.
        unsafe {
            assume_written(&mut d_gi_seq, b * t * g);
            assume_written(&mut seq_d_gh, t * b * g);
        }
        (d_gi_seq, seq_d_gh, dh)
    };
    let single_steps_back = || {
        let mut single_d_gh = unwritten(b * t * g);
        let (d_h_prev_single, d_gi_single) =
            net.gru.step_backward(&single_tape, &h_all, d_h_single, b * t, slots(&mut single_d_gh, b * t * g));
        // SAFETY: the step back wrote every slot of its d_gh.
        unsafe { assume_written(&mut single_d_gh, b * t * g) };
        (d_gi_single, single_d_gh, d_h_prev_single)
    };
    let ((d_gi_seq, seq_d_gh, dh), (d_gi_single, single_d_gh, d_h_prev_single)) =
        rayon::join(open_loop_back, single_steps_back);
    for i in 0..b {
        add_into(&mut d_h_all[i * t * e..(i * t + 1) * e], &dh[i * e..(i + 1) * e]);
    }
    net.gru.hidden_weight_backward(&seq_h_prev, &seq_d_gh, t * b, &mut grads);
    net.gru.hidden_weight_backward(&h_all, &single_d_gh, b * t, &mut grads);
    add_into(d_h_all, &d_h_prev_single);

    // The single steps' context block first: its input-gate gradients then become, in place, the action (and
    // terrain) block's, which both predictions share with b_ih. The blocks are W_ih's disjoint columns.
    let d_ctx_single = net.gru.input_backward_through_relu(&ctx_single, &d_gi_single, b * t, 0, &mut grads);
    let d_beta_single =
        net.context_embedding.backward(&beta_single, &ctx_single_tape, &d_ctx_single, b * t, &mut grads, true);
    let mut d_action_gates = d_gi_single;
    add_into(&mut d_action_gates, &d_gi_seq);
    add_column_sums(&mut grads[net.gru.bias_ih_index()], &d_action_gates);
    let d_act_emb = net.gru.input_backward_through_relu(&act_emb, &d_action_gates, b * t, 1, &mut grads);
    net.action_encoder.backward(&batch.actions, &act_tape, &d_act_emb, b * t, &mut grads, false);
    if let (Some(embedding), Some((tau, emb, tape))) = (&net.terrain_embedding, &terrain) {
        let d_emb = net.gru.input_backward_through_relu(emb, &d_action_gates, b * t, 2, &mut grads);
        embedding.backward(tau, tape, &d_emb, b * t, &mut grads, false);
    }
    let mut d_ctx_gates = vec![0.0; b * g];
    d_ctx_gates.par_chunks_mut(g).zip(d_gi_seq.par_chunks(t * g)).for_each(|(sum, steps)| {
        for step in steps.chunks(g) {
            sum.iter_mut().zip(step).for_each(|(s, x)| *s += x);
        }
    });
    let d_ctx_seq = net.gru.input_backward_through_relu(&ctx_seq, &d_ctx_gates, b, 0, &mut grads);
    let d_beta = net.context_embedding.backward(&beta, &ctx_seq_tape, &d_ctx_seq, b, &mut grads, true);

    // The state encoder.
    let d_state = d_h_all;
    zip_values(d_state, &h_all, |d, y| *d *= 1.0 - y * y);
    net.state_encoder.backward(&starts, &state_tape, d_state, b * t, &mut grads, false);

    // The beliefs: reparameterized samples and the KL terms.
    let mut d_post_mean = vec![0.0; b * lat];
    let mut d_post_std = vec![0.0; b * lat];
    let mut d_prior_mean = vec![0.0; b * lat];
    let mut d_prior_std = vec![0.0; b * lat];
    for (k, d) in d_beta_single.iter().enumerate() {
        let (i, dim) = (k / (t * lat), k % lat);
        d_post_mean[i * lat + dim] += d;
        d_post_std[i * lat + dim] += d * batch.noise_single[k];
    }
    for (k, d) in d_beta.iter().enumerate() {
        d_post_mean[k] += d;
        d_post_std[k] += d * batch.noise_sequence[k];
    }
    let kl_scale = kl_weight / b as f32;
    for k in 0..b * lat {
        // The floor's clamp passes no gradient below it.
        if kl_values[k] < kl_floor {
            continue;
        }
        let (pm, ps, qm, qs) = (posterior.mean[k], posterior.std[k], prior.mean[k], prior.std[k]);
        let q2 = qs * qs;
        let diff = pm - qm;
        d_post_mean[k] += kl_scale * diff / q2;
        d_prior_mean[k] -= kl_scale * diff / q2;
        d_post_std[k] += kl_scale * (ps / q2 - 1.0 / ps);
        d_prior_std[k] += kl_scale * ((q2 - ps * ps - diff * diff) / (q2 * qs));
    }
    let d_empty_mean: Vec<f32> = empty.mean.clone();
    let d_empty_std: Vec<f32> = empty.std.iter().map(|sd| sd - 1.0 / sd).collect();
    belief_backward(&net, &zero_pool, &empty, &d_empty_mean, &d_empty_std, 1, &mut grads);
    let d_union = belief_backward(&net, &union_pool, &posterior, &d_post_mean, &d_post_std, b, &mut grads);
    let mut d_context_pool = belief_backward(&net, &context_pool, &prior, &d_prior_mean, &d_prior_std, b, &mut grads);
    let mut d_chunk_pool = vec![0.0; b * f];
    for k in 0..b * f {
        if chunk_pool[k] < context_pool[k] {
            d_context_pool[k] += d_union[k];
        } else {
            d_chunk_pool[k] += d_union[k];
        }
    }

    // Back through the pools to the transition features' maximizing rows, the only ones with a gradient. A
    // pooled maximum is positive, so the features' ReLU passes it. The chunks' rows come before the contexts'.
    let mut d_features = SparseColumns::new(enc_rows, f);
    for (args, d_pool, offset) in [(&chunk_arg, &d_chunk_pool, 0), (&context_arg, &d_context_pool, b * t)] {
        for (k, (arg, d)) in args.iter().zip(d_pool.iter()).enumerate() {
            if let Some(row) = arg {
                d_features.push(offset + row, k % f, *d);
            }
        }
    }
    net.transition_encoder.sparse_backward(&transitions, &enc_tape, &d_features, &mut grads, false);

    Ok((values, Some(grads)))
}
