//! The ensemble's training loss and its gradient written out by hand: every member's layer is one faer GEMM,
//! the activation's derivative is applied in place, and the Gaussian NLL with the soft log-variance bounds is
//! differentiated in closed form. A PETS step is a few dozen small tensors; through burn's autodiff the
//! bookkeeping, copies and reloading the weights into the module each step cost more than the arithmetic.
//! `net.rs` stays the reference: a test holds the loss and every gradient here to burn's.
//!
//! A step runs in two parallel phases. First the members' batches, cut into one equal run of rows per thread
//! (see [`parts`]), go forward, through the loss and back to every layer's output gradient, one task per
//! member within a run: a small preset's layers are a few microseconds of GEMM each, so tasks per layer would
//! spend the step waking threads. Then every (layer, member) weight gradient is one GEMM over all of the
//! member's rows. Rows of a product do not depend on which other rows it computes, and the sums over rows (the
//! loss, the bounds' gradients) are taken after the first phase in row order, so the bytes do not depend on the
//! threads.

use faer::Accum;
use rayon::prelude::*;

use super::config::PetsConfig;
use crate::error::Result;
use crate::nn::activation::{fast_exp, fast_sigmoid as sigmoid, fast_softplus as softplus, Activation};
use crate::nn::adam::AdamStep;
use crate::nn::backprop::{add_column_sums, tensor_index, view, view_mut, zero_gradients};
use crate::nn::gemm::{faer_product, Finish, Kernel, Start};
use crate::nn::{Adam, ParamSet};
use crate::util::wide::widest_fn;

/// mbrl-lib's weight on Σ max_logvar − Σ min_logvar.
const BOUNDS_PENALTY: f32 = 0.01;

/// Layers at least this wide take their weight gradients from mbrl's kernel, narrower ones from faer's.
const WIDE_LAYER: usize = 128;

/// dst = finish(start + a · b) on the calling thread. Where the AVX-512 kernel reads the layouts it takes
/// the bias rows and the activation's slopes into its tiles (as fast as faer on these cache-sized products,
/// and it spares the passes that copied the bias into every row and scaled every input gradient); the
/// kernel is chosen by the layer's shape alone, so the bytes do not depend on the thread count.
fn fused_here(
    dst: faer::MatMut<'_, f32>,
    start: Start<'_>,
    a: faer::MatRef<'_, f32>,
    b: faer::MatRef<'_, f32>,
    finish: Finish<'_>,
) {
    let kernel = Kernel::for_product(&dst, &a, &b);
    kernel.fused(dst, start, a, b, finish);
}

/// One ensemble layer's weights, [members, in, out] and [members, 1, out], as views of a parameter set.
struct Layer<'a> {
    shape: LayerShape,
    weight: &'a [f32],
    bias: &'a [f32],
}

impl<'a> Layer<'a> {
    fn new(params: &'a ParamSet, prefix: &str, members: usize, d_in: usize, d_out: usize) -> Result<Self> {
        let weight_index = tensor_index(params, &format!("{prefix}.weight"), &[members, d_in, d_out])?;
        let bias_index = tensor_index(params, &format!("{prefix}.bias"), &[members, 1, d_out])?;
        Ok(Layer {
            shape: LayerShape { d_in, d_out, weight_index, bias_index },
            weight: &params.tensors[weight_index].values,
            bias: &params.tensors[bias_index].values,
        })
    }

    fn member_weight(&self, member: usize) -> &[f32] {
        let size = self.shape.d_in * self.shape.d_out;
        &self.weight[member * size..(member + 1) * size]
    }

    /// Member `member`'s `rows` inputs `x` → `y` (rows × out).
    fn forward(&self, member: usize, x: &[f32], rows: usize, y: &mut [f32]) {
        let (i, o) = (self.shape.d_in, self.shape.d_out);
        let bias = Start::Row(&self.bias[member * o..(member + 1) * o]);
        let w = view(self.member_weight(member), i, o);
        fused_here(view_mut(y, rows, o), bias, view(x, rows, i), w, Finish::Store);
    }

    /// The input gradients `dx` (rows × in) of member `member` for output gradients `dy`, times the slopes of
    /// the activation below (rows × in): the gradient before that activation.
    fn backward_input(&self, member: usize, dy: &[f32], rows: usize, slopes: &[f32], dx: &mut [f32]) {
        let (i, o) = (self.shape.d_in, self.shape.d_out);
        let w = view(self.member_weight(member), i, o);
        let scale = Finish::Scale(view(slopes, rows, i));
        fused_here(view_mut(dx, rows, i), Start::Zero, view(dy, rows, o), w.transpose(), scale);
    }
}

/// Rows `start..end` of member `member`'s batch.
#[derive(Clone, Copy)]
struct Part {
    member: usize,
    start: usize,
    end: usize,
}

impl Part {
    fn rows(&self) -> usize {
        self.end - self.start
    }
}

/// The ensemble's member-rows (member by member, in memory order) cut into one equal run per thread, each run
/// cut again where it crosses from one member to the next. With the presets' five members on two threads
/// that is two whole members and half of the third per thread: cutting every member in half instead cost each
/// half-member part a quarter more than half a whole one (its weights packed twice, its tiles half as tall),
/// and held the phase to 1.6× one thread's speed. On one thread every part is a whole member.
fn parts(members: usize, rows: usize) -> Vec<Part> {
    let total = members * rows;
    let threads = rayon::current_num_threads().clamp(1, total.max(1));
    let mut parts = Vec::new();
    for run in 0..threads {
        let (begin, end) = (total * run / threads, total * (run + 1) / threads);
        let mut at = begin;
        while at < end {
            let (member, start) = (at / rows, at % rows);
            let stop = end.min((member + 1) * rows);
            parts.push(Part { member, start, end: stop - member * rows });
            at = stop;
        }
    }
    parts
}

/// A [members, rows, width] buffer cut into the parts' pieces, which cover it in order.
fn cut<'a, T>(mut buffer: &'a mut [T], parts: &[Part], width: usize) -> std::vec::IntoIter<&'a mut [T]> {
    let pieces: Vec<&'a mut [T]> = parts
        .iter()
        .map(|p| {
            let (piece, rest) = std::mem::take(&mut buffer).split_at_mut(p.rows() * width);
            buffer = rest;
            piece
        })
        .collect();
    pieces.into_iter()
}

/// Per-layer buffers, each sized for `total_rows` of its layer's width and cut into the parts' pieces.
fn cut_layers<'a>(
    buffers: &'a mut [Vec<f32>],
    widths: &[usize],
    parts: &[Part],
    total_rows: usize,
) -> Vec<std::vec::IntoIter<&'a mut [f32]>> {
    buffers
        .iter_mut()
        .zip(widths)
        .map(|(buffer, &width)| {
            buffer.resize(total_rows * width, 0.0);
            cut(buffer, parts, width)
        })
        .collect()
}

/// A part's pieces of the workspace's buffers.
struct PartBuffers<'a> {
    activations: Vec<&'a mut [f32]>,
    slopes: Vec<&'a mut [f32]>,
    output: &'a mut [f32],
    /// Gradient at each layer's output (before the activation, for hidden layers); empty without gradients.
    d_outputs: Vec<&'a mut [f32]>,
    /// Each row's loss, and its d max_logvar then d min_logvar terms; empty without gradients.
    row_losses: &'a mut [f64],
    row_bounds: &'a mut [f32],
}

/// The ensemble's layers as views of a parameter set in mbrl-lib's names (see `net::torch_name`).
pub struct EnsembleNet<'a> {
    members: usize,
    input_dim: usize,
    target_dim: usize,
    activation: Activation,
    hidden: Vec<Layer<'a>>,
    output: Layer<'a>,
    min_logvar: &'a [f32],
    max_logvar: &'a [f32],
    bounds_index: [usize; 2],
}

/// The buffers of a step, kept from one step to the next: allocated afresh, large blocks go back to the OS
/// when freed and return as zeroed pages, which cost a medium-sized step about a tenth of its time.
#[derive(Debug, Default)]
pub struct Workspace {
    /// Each hidden layer's activations [members, rows, units].
    activations: Vec<Vec<f32>>,
    /// Each hidden activation's derivative at its input.
    slopes: Vec<Vec<f32>>,
    /// The output layer's [members, rows, 2·target_dim]: mean, then the raw log-variance.
    output: Vec<f32>,
    /// The loss's gradient at each layer's output, hidden layers before their activation.
    d_outputs: Vec<Vec<f32>>,
    /// Per row: the loss [members · rows], and the bounds' gradient terms [members · rows, 2 · target_dim].
    row_losses: Vec<f64>,
    row_bounds: Vec<f32>,
    /// After [`EnsembleNet::loss_and_gradients`] with gradients: one per parameter tensor, in their order.
    pub gradients: Vec<Vec<f32>>,
}

/// The soft bounds: upper = max − softplus(max − raw), logvar = min + softplus(upper − min); with the two
/// sigmoids their derivatives need.
struct BoundedLogVar {
    logvar: f32,
    /// σ(max − raw) = d upper / d raw.
    upper_slope: f32,
    /// σ(upper − min) = d logvar / d upper.
    lower_slope: f32,
}

#[inline(always)]
fn bounded(raw: f32, min: f32, max: f32) -> BoundedLogVar {
    let upper = max - softplus(max - raw);
    BoundedLogVar {
        logvar: min + softplus(upper - min),
        upper_slope: sigmoid(max - raw),
        lower_slope: sigmoid(upper - min),
    }
}

impl<'a> EnsembleNet<'a> {
    pub fn new(params: &'a ParamSet, config: &PetsConfig, input_dim: usize, target_dim: usize) -> Result<Self> {
        let (members, units) = (config.ensemble, config.hidden_units);
        let mut hidden = Vec::with_capacity(config.hidden_layers);
        let mut d_in = input_dim;
        for layer in 0..config.hidden_layers {
            hidden.push(Layer::new(params, &format!("hidden_layers.{layer}.0"), members, d_in, units)?);
            d_in = units;
        }
        let output = Layer::new(params, "mean_and_logvar", members, d_in, 2 * target_dim)?;
        let bounds_index = [
            tensor_index(params, "min_logvar", &[1, target_dim])?,
            tensor_index(params, "max_logvar", &[1, target_dim])?,
        ];
        Ok(EnsembleNet {
            members,
            input_dim,
            target_dim,
            activation: config.activation,
            hidden,
            output,
            min_logvar: &params.tensors[bounds_index[0]].values,
            max_logvar: &params.tensors[bounds_index[1]].values,
            bounds_index,
        })
    }

    fn layers(&self) -> impl DoubleEndedIterator<Item = &Layer<'a>> {
        self.hidden.iter().chain(std::iter::once(&self.output))
    }

    /// Sizes the workspace for `rows` per member and cuts it into the parts' pieces.
    fn part_buffers<'w>(
        &self,
        ws: &'w mut Workspace,
        parts: &[Part],
        rows: usize,
        gradients: bool,
    ) -> Vec<PartBuffers<'w>> {
        let e = self.members;
        let hidden = self.hidden.len();
        ws.activations.resize_with(hidden, Vec::new);
        ws.slopes.resize_with(hidden, Vec::new);
        ws.d_outputs.resize_with(if gradients { hidden + 1 } else { 0 }, Vec::new);
        let widths: Vec<usize> = self.layers().map(|l| l.shape.d_out).collect();
        let mut activations = cut_layers(&mut ws.activations, &widths, parts, e * rows);
        let mut slopes = cut_layers(&mut ws.slopes, &widths, parts, e * rows);
        let mut d_outputs = cut_layers(&mut ws.d_outputs, &widths, parts, e * rows);
        let d2 = 2 * self.target_dim;
        ws.output.resize(e * rows * d2, 0.0);
        let mut output = cut(&mut ws.output, parts, d2);
        ws.row_losses.resize(if gradients { e * rows } else { 0 }, 0.0);
        ws.row_bounds.resize(if gradients { e * rows * d2 } else { 0 }, 0.0);
        let (row_width, bound_width) = if gradients { (1, d2) } else { (0, 0) };
        let mut row_losses = cut(&mut ws.row_losses, parts, row_width);
        let mut row_bounds = cut(&mut ws.row_bounds, parts, bound_width);
        let next = |pieces: &mut Vec<std::vec::IntoIter<&'w mut [f32]>>| -> Vec<&'w mut [f32]> {
            pieces.iter_mut().map(|p| p.next().expect("one piece per part")).collect()
        };
        parts
            .iter()
            .map(|_| PartBuffers {
                activations: next(&mut activations),
                slopes: next(&mut slopes),
                output: output.next().expect("one piece per part"),
                d_outputs: next(&mut d_outputs),
                row_losses: row_losses.next().expect("one piece per part"),
                row_bounds: row_bounds.next().expect("one piece per part"),
            })
            .collect()
    }

    /// A part's activations, slopes and output for its rows of `inputs` [members, rows, in].
    fn forward_part(&self, buffers: &mut PartBuffers<'_>, part: Part, x: &[f32]) {
        let rows = part.rows();
        for (k, layer) in self.hidden.iter().enumerate() {
            let (done, next) = buffers.activations.split_at_mut(k);
            let input: &[f32] = if k == 0 { x } else { done[k - 1] };
            layer.forward(part.member, input, rows, next[0]);
            self.activation.apply_with_derivative(next[0], buffers.slopes[k]);
        }
        let last: &[f32] = buffers.activations.last().map_or(x, |a| a);
        self.output.forward(part.member, last, rows, buffers.output);
    }

    /// The part's rows' losses and bounds' gradient terms, and its output gradient written into the last of
    /// `d_outputs`. `scale` is 1 / (rows · target_dim), the member mean's weight.
    fn loss_part(&self, buffers: &mut PartBuffers<'_>, targets: &[f32], scale: f32) {
        let d_output = buffers.d_outputs.last_mut().expect("the output layer's gradient");
        let rows = RowLosses { losses: buffers.row_losses, bounds: buffers.row_bounds, d_output };
        let bounds = (self.min_logvar, self.max_logvar);
        loss_rows(rows, buffers.output, targets, bounds, scale);
    }

    /// Carries the output gradient back to every hidden layer's output, before its activation.
    fn backward_part(&self, buffers: &mut PartBuffers<'_>, part: Part) {
        let layers: Vec<&Layer<'_>> = self.layers().collect();
        for k in (1..layers.len()).rev() {
            let (below, above) = buffers.d_outputs.split_at_mut(k);
            let dx = &mut *below[k - 1];
            layers[k].backward_input(part.member, above[0], part.rows(), buffers.slopes[k - 1], dx);
        }
    }

    /// Mean squared error of the predicted mean against `targets` over every member, row and output, for
    /// inputs [members, rows, in] (normalized) and targets [members, rows, target_dim].
    pub fn mean_squared_error(&self, ws: &mut Workspace, inputs: &[f32], targets: &[f32], rows: usize) -> f64 {
        let (din, d) = (self.input_dim, self.target_dim);
        let parts = parts(self.members, rows);
        let buffers = self.part_buffers(ws, &parts, rows, false);
        let sums: Vec<f64> = buffers
            .into_par_iter()
            .zip(parts.par_iter())
            .map(|(mut buffers, &part)| {
                let first = part.member * rows + part.start;
                self.forward_part(&mut buffers, part, &inputs[first * din..(first + part.rows()) * din]);
                let y = &targets[first * d..(first + part.rows()) * d];
                buffers
                    .output
                    .chunks(2 * d)
                    .zip(y.chunks(d))
                    .map(|(out, y)| out[..d].iter().zip(y).map(|(m, y)| f64::from(m - y).powi(2)).sum::<f64>())
                    .sum()
            })
            .collect();
        sums.iter().sum::<f64>() / targets.len().max(1) as f64
    }

    /// The loss mbrl-lib trains on, for inputs [members, rows, in] (normalized) and targets
    /// [members, rows, target_dim]: per member the mean over rows and outputs of ½((μ − y)² e^{−log σ²} +
    /// log σ²), summed over members, plus 0.01 (Σ max_logvar − Σ min_logvar). Also its gradient for every
    /// tensor of `params` (the set these layers view), left in `ws.gradients`.
    pub fn loss_and_gradients(
        &self,
        params: &ParamSet,
        ws: &mut Workspace,
        inputs: &[f32],
        targets: &[f32],
        rows: usize,
    ) -> f64 {
        let loss = self.output_gradients(params, ws, inputs, targets, rows);
        weight_gradients(&self.shapes(), ws, inputs, rows, None);
        loss
    }

    /// The loss of [`EnsembleNet::loss_and_gradients`] and its gradient at every layer's output; the bounds'
    /// gradients are left in `ws.gradients`, whose other tensors keep their sizes for [`weight_gradients`].
    fn output_gradients(
        &self,
        params: &ParamSet,
        ws: &mut Workspace,
        inputs: &[f32],
        targets: &[f32],
        rows: usize,
    ) -> f64 {
        let (e, d) = (self.members, self.target_dim);
        let din = self.input_dim;
        let scale = 1.0 / (rows * d) as f32;
        let parts = parts(e, rows);
        let buffers = self.part_buffers(ws, &parts, rows, true);
        buffers.into_par_iter().zip(parts.par_iter()).for_each(|(mut buffers, &part)| {
            let first = part.member * rows + part.start;
            self.forward_part(&mut buffers, part, &inputs[first * din..(first + part.rows()) * din]);
            self.loss_part(&mut buffers, &targets[first * d..(first + part.rows()) * d], scale);
            self.backward_part(&mut buffers, part);
        });

        let member_sums: Vec<f64> = ws.row_losses.chunks(rows).map(|member| member.iter().sum()).collect();
        let (mut d_max, mut d_min) = (vec![0.0f32; d], vec![0.0f32; d]);
        for row in ws.row_bounds.chunks(2 * d) {
            d_max.iter_mut().zip(&row[..d]).for_each(|(g, x)| *g += x);
            d_min.iter_mut().zip(&row[d..]).for_each(|(g, x)| *g += x);
        }
        d_max.iter_mut().for_each(|g| *g += BOUNDS_PENALTY);
        d_min.iter_mut().for_each(|g| *g -= BOUNDS_PENALTY);
        let penalty = BOUNDS_PENALTY * (self.max_logvar.iter().sum::<f32>() - self.min_logvar.iter().sum::<f32>());
        let loss = member_sums.iter().map(|s| s / (rows * d) as f64).sum::<f64>() + f64::from(penalty);
        if ws.gradients.len() != params.tensors.len() {
            ws.gradients = zero_gradients(params);
        }
        ws.gradients[self.bounds_index[0]] = d_min;
        ws.gradients[self.bounds_index[1]] = d_max;
        loss
    }

    fn shapes(&self) -> Vec<LayerShape> {
        self.layers().map(|l| l.shape).collect()
    }
}

/// What the loss writes for a part's rows.
struct RowLosses<'a> {
    losses: &'a mut [f64],
    /// Per row, the d max_logvar then d min_logvar terms.
    bounds: &'a mut [f32],
    /// Per row, d mean then d raw log-variance.
    d_output: &'a mut [f32],
}

widest_fn! {
    /// The loss of rows of `output` (mean, then raw log-variance) against `targets`, by blocks of 16 rows so that
    /// the exponentials run across rows in vector lanes (a row has only a few outputs). Each row still sums its
    /// outputs in order, from zero.
    fn loss_rows(into: RowLosses<'_>, output: &[f32], targets: &[f32], bounds: (&[f32], &[f32]), scale: f32) {
        const LANES: usize = 16;
        let d = bounds.0.len();
        let rows = into.losses.len();
        for start in (0..rows).step_by(LANES) {
            let n = LANES.min(rows - start);
            let mut sums = [0.0f64; LANES];
            for j in 0..d {
                let (mut mean, mut raw, mut target) = ([0.0f32; LANES], [0.0f32; LANES], [0.0f32; LANES]);
                for r in 0..n {
                    let row = start + r;
                    mean[r] = output[row * 2 * d + j];
                    raw[r] = output[row * 2 * d + d + j];
                    target[r] = targets[row * d + j];
                }
                let (min, max) = (bounds.0[j], bounds.1[j]);
                let mut terms = [[0.0f32; LANES]; 5];
                for r in 0..LANES {
                    let b = bounded(raw[r], min, max);
                    let error = mean[r] - target[r];
                    let precision = fast_exp(-b.logvar);
                    let d_logvar = 0.5 * (1.0 - error * error * precision) * scale;
                    terms[0][r] = 0.5 * (error * error * precision + b.logvar);
                    terms[1][r] = error * precision * scale;
                    terms[2][r] = d_logvar * b.lower_slope * b.upper_slope;
                    terms[3][r] = d_logvar * b.lower_slope * (1.0 - b.upper_slope);
                    terms[4][r] = d_logvar * (1.0 - b.lower_slope);
                }
                for r in 0..n {
                    let row = start + r;
                    sums[r] += f64::from(terms[0][r]);
                    into.d_output[row * 2 * d + j] = terms[1][r];
                    into.d_output[row * 2 * d + d + j] = terms[2][r];
                    into.bounds[row * 2 * d + j] = terms[3][r];
                    into.bounds[row * 2 * d + d + j] = terms[4][r];
                }
            }
            into.losses[start..start + n].copy_from_slice(&sums[..n]);
        }
    }
}

/// One PETS training step on `params`: the loss and gradients of [`EnsembleNet::loss_and_gradients`], with
/// Adam applied to each (layer, member) block by the task that computed its gradient, while that gradient is
/// still in cache, and to the few remaining tensors after. The same bytes as the gradients followed by
/// [`Adam::update`]; without clipping only (see [`Adam::begin_unclipped_update`]). A non-finite loss is
/// returned without an update, as the unfused step does.
#[allow(clippy::too_many_arguments)]
pub fn train_step(
    params: &mut ParamSet,
    adam: &mut Adam<f32>,
    config: &PetsConfig,
    dims: (usize, usize),
    ws: &mut Workspace,
    inputs: &[f32],
    targets: &[f32],
    rows: usize,
) -> Result<f64> {
    let (loss, shapes) = {
        let net = EnsembleNet::new(params, config, dims.0, dims.1)?;
        (net.output_gradients(params, ws, inputs, targets, rows), net.shapes())
    };
    if !loss.is_finite() {
        return Ok(loss);
    }
    let step = adam.begin_unclipped_update()?;
    let mut optimizer = OptimizerBlocks {
        step,
        params: params.values_mut().into_iter().map(Some).collect(),
        exp_avg: adam.exp_avg.iter_mut().map(Some).collect(),
        exp_avg_sq: adam.exp_avg_sq.iter_mut().map(Some).collect(),
    };
    weight_gradients(&shapes, ws, inputs, rows, Some(&mut optimizer));
    // The tensors no layer task updated: the log-variance bounds.
    let rest = optimizer.params.iter_mut().zip(optimizer.exp_avg.iter_mut().zip(optimizer.exp_avg_sq.iter_mut()));
    for (k, (p, (m, v))) in rest.enumerate() {
        if let (Some(p), Some(m), Some(v)) = (p.take(), m.take(), v.take()) {
            step.apply(p, &ws.gradients[k], m, v);
        }
    }
    Ok(loss)
}

/// A layer's sizes and tensor indices: all the weight-gradient phase needs, free of the parameters' borrow.
#[derive(Clone, Copy)]
struct LayerShape {
    d_in: usize,
    d_out: usize,
    weight_index: usize,
    bias_index: usize,
}

/// The parameters and Adam moments of a fused step, per tensor, each taken by the tasks that update it.
struct OptimizerBlocks<'a> {
    step: AdamStep<f32>,
    params: Vec<Option<&'a mut Vec<f32>>>,
    exp_avg: Vec<Option<&'a mut Vec<f32>>>,
    exp_avg_sq: Vec<Option<&'a mut Vec<f32>>>,
}

impl<'a> OptimizerBlocks<'a> {
    /// Tensor `index`'s parameters and moments, cut into `members` equal blocks.
    fn member_blocks(&mut self, index: usize, members: usize) -> Vec<[&'a mut [f32]; 3]> {
        let take = |list: &mut Vec<Option<&'a mut Vec<f32>>>| list[index].take().expect("each tensor taken once");
        let (p, m, v) = (take(&mut self.params), take(&mut self.exp_avg), take(&mut self.exp_avg_sq));
        debug_assert!(p.len() % members == 0 && m.len() == p.len() && v.len() == p.len(), "tensor {index}: sizes");
        let size = p.len() / members;
        p.chunks_mut(size).zip(m.chunks_mut(size).zip(v.chunks_mut(size))).map(|(p, (m, v))| [p, m, v]).collect()
    }
}

/// A (layer, member) weight-gradient task: the member's layer input and output gradient, and where its
/// weight and bias gradients go, with the blocks Adam then updates in a fused step.
struct WeightTask<'a> {
    shape: LayerShape,
    x: &'a [f32],
    dy: &'a [f32],
    weight_grad: &'a mut [f32],
    bias_grad: &'a mut [f32],
    update: Option<[[&'a mut [f32]; 3]; 2]>,
}

/// Every (layer, member) weight gradient as one independent task (one GEMM over the member's rows), each
/// followed, in a fused step, by Adam on that member's weight and bias.
fn weight_gradients(
    shapes: &[LayerShape],
    ws: &mut Workspace,
    inputs: &[f32],
    rows: usize,
    mut optimizer: Option<&mut OptimizerBlocks<'_>>,
) {
    let mut taken: Vec<(LayerShape, Vec<f32>, Vec<f32>)> = shapes
        .iter()
        .map(|&shape| {
            let weight_grad = std::mem::take(&mut ws.gradients[shape.weight_index]);
            (shape, weight_grad, std::mem::take(&mut ws.gradients[shape.bias_index]))
        })
        .collect();
    let mut tasks = Vec::new();
    for (k, (shape, weight_grad, bias_grad)) in taken.iter_mut().enumerate() {
        let (i, o) = (shape.d_in, shape.d_out);
        let members = weight_grad.len() / (i * o);
        let x: &[f32] = if k == 0 { inputs } else { &ws.activations[k - 1] };
        let mut updates: Vec<Option<[[&mut [f32]; 3]; 2]>> = match optimizer.as_deref_mut() {
            Some(blocks) => {
                let weights = blocks.member_blocks(shape.weight_index, members);
                let biases = blocks.member_blocks(shape.bias_index, members);
                weights.into_iter().zip(biases).map(|(w, b)| Some([w, b])).collect()
            }
            None => (0..members).map(|_| None).collect(),
        };
        let grads = weight_grad.chunks_mut(i * o).zip(bias_grad.chunks_mut(o));
        let data = x.chunks(rows * i).zip(ws.d_outputs[k].chunks(rows * o));
        let members = grads.zip(data).zip(updates.iter_mut()).enumerate();
        for (member, (((weight_grad, bias_grad), (x, dy)), update)) in members {
            let task = WeightTask { shape: *shape, x, dy, weight_grad, bias_grad, update: update.take() };
            tasks.push((member, task));
        }
    }
    // Member by member, so that rayon's halving hands each thread the members whose rows it ran in the first
    // phase (see `parts`), still in its cache: layer by layer, most of the phase read what the other core had
    // written, and the next step wrote over what this one had read, 20 % slower on two threads.
    tasks.sort_by_key(|(member, _)| *member);
    let optimizer_step = optimizer.map(|blocks| blocks.step);
    tasks.into_par_iter().for_each(|(_, task)| {
        let WeightTask { shape, x, dy, weight_grad, bias_grad, update } = task;
        backward_weights(shape, x, dy, rows, weight_grad, bias_grad);
        if let (Some([[p, m, v], [bp, bm, bv]]), Some(step)) = (update, optimizer_step) {
            step.apply(p, weight_grad, m, v);
            step.apply(bp, bias_grad, bm, bv);
        }
    });
    for (shape, weight_grad, bias_grad) in taken {
        ws.gradients[shape.weight_index] = weight_grad;
        ws.gradients[shape.bias_index] = bias_grad;
    }
}

/// One member's weight and bias gradients for its output gradients `dy` (rows × out) at its inputs `x`.
fn backward_weights(
    shape: LayerShape,
    x: &[f32],
    dy: &[f32],
    rows: usize,
    weight_grad: &mut [f32],
    bias_grad: &mut [f32],
) {
    let (i, o) = (shape.d_in, shape.d_out);
    let (dst, xt, dy_view) = (view_mut(weight_grad, i, o), view(x, rows, i).transpose(), view(dy, rows, o));
    // mbrl's kernel is 2 % faster on the step with 200-wide layers and 3 % slower with 64-wide ones, where
    // faer's packing of xᵀ costs less than the kernel's.
    if i >= WIDE_LAYER {
        fused_here(dst, Start::Zero, xt, dy_view, Finish::Store);
    } else {
        // On the calling thread: the first phase's tasks already fill the pool.
        faer_product(dst, Accum::Replace, xt, dy_view);
    }
    bias_grad.fill(0.0);
    add_column_sums(bias_grad, dy);
}

#[cfg(test)]
mod tests {
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    use super::*;
    use crate::models::pets::net::{torch_name, PetsNet};
    use crate::models::pets::Preset;
    use crate::nn::gaussian_nll;
    use crate::nn::tensor::{scalar, tensor, training_device};

    /// Loss and every gradient against burn's autodiff through `PetsNet`, for each activation, with bounds close
    /// enough to the raw log-variances that both soft clamps pass part of their gradient; at a width where
    /// every product is faer's, and at one where the AVX-512 kernel (where there is one) takes the bias rows,
    /// the activation slopes and the hidden weight gradients.
    #[test]
    fn hand_written_gradients_match_burn_autodiff() {
        let (din, dout, rows) = (5, 3, 11);
        let activations = [Activation::Silu, Activation::Relu, Activation::Tanh, Activation::Sigmoid];
        let cases = [7, WIDE_LAYER + 2].into_iter().flat_map(|width| activations.map(|activation| (width, activation)));
        for (case, (width, activation)) in cases.enumerate() {
            let mut config = PetsConfig::preset(Preset::Small);
            (config.ensemble, config.hidden_layers, config.hidden_units, config.activation) = (3, 2, width, activation);
            let device = training_device();
            let mut rng = ChaCha8Rng::seed_from_u64(40 + case as u64);
            let net = PetsNet::init(&config, din, dout, &device, &mut rng);
            let mut params = ParamSet::<f32>::from_module(&net, torch_name);
            for t in &mut params.tensors {
                let (low, high) = match t.name.as_str() {
                    "min_logvar" => (-1.5, -0.5),
                    "max_logvar" => (0.2, 1.0),
                    _ => (-0.8, 0.8),
                };
                t.values.iter_mut().for_each(|v| *v = rng.random_range(low..high));
            }
            let net = params.load_into(net, &device).unwrap();
            let e = config.ensemble;
            let inputs: Vec<f32> = (0..e * rows * din).map(|_| rng.random_range(-2.0..2.0)).collect();
            let targets: Vec<f32> = (0..e * rows * dout).map(|_| rng.random_range(-1.5..1.5)).collect();

            let (mean, logvar) = net.forward(tensor(inputs.clone(), [e, rows, din], &device));
            let reference_loss =
                gaussian_nll(mean, logvar, tensor(targets.clone(), [e, rows, dout], &device)) + net.bounds.penalty();
            let reference = ParamSet::<f32>::gradients(&net, &reference_loss.backward());

            let fused = EnsembleNet::new(&params, &config, din, dout).unwrap();
            let mut ws = Workspace::default();
            // Twice on one workspace: what the first pass leaves behind must not leak into the second.
            let other_inputs: Vec<f32> = inputs.iter().rev().copied().collect();
            fused.loss_and_gradients(&params, &mut ws, &other_inputs, &targets, rows);
            let loss = fused.loss_and_gradients(&params, &mut ws, &inputs, &targets, rows);
            let grads = ws.gradients;
            let theirs = scalar(&reference_loss);
            assert!((loss - theirs).abs() < 1e-4 * (1.0 + theirs.abs()), "case {case}: loss {loss} vs {theirs}");
            for ((tensor, ours), theirs) in params.tensors.iter().zip(&grads).zip(&reference) {
                assert_eq!(ours.len(), theirs.len(), "'{}'", tensor.name);
                let scale = theirs.iter().fold(0.0f32, |m, x| m.max(x.abs())).max(1e-3);
                let worst = ours.iter().zip(theirs).fold(0.0f32, |m, (x, y)| m.max((x - y).abs()));
                assert!(worst <= 2e-4 * scale, "case {case}: '{}' differs by {worst} at scale {scale}", tensor.name);
                assert!(ours.iter().any(|g| *g != 0.0), "case {case}: '{}' got no gradient", tensor.name);
            }
        }
    }

    /// Members never share a sum and GEMMs split by rows only, so the bytes do not depend on the threads.
    #[test]
    fn loss_and_gradients_do_not_depend_on_the_thread_count() {
        let config = PetsConfig::preset(Preset::Medium);
        let (din, dout, rows) = (4, 2, 256);
        let net = PetsNet::init(&config, din, dout, &training_device(), &mut ChaCha8Rng::seed_from_u64(3));
        let params = ParamSet::<f32>::from_module(&net, torch_name);
        let mut rng = ChaCha8Rng::seed_from_u64(4);
        let e = config.ensemble;
        let inputs: Vec<f32> = (0..e * rows * din).map(|_| rng.random_range(-2.0..2.0)).collect();
        let targets: Vec<f32> = (0..e * rows * dout).map(|_| rng.random_range(-0.5..0.5)).collect();
        let run = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| {
                let fused = EnsembleNet::new(&params, &config, din, dout).unwrap();
                let mut ws = Workspace::default();
                let loss = fused.loss_and_gradients(&params, &mut ws, &inputs, &targets, rows);
                (loss.to_bits(), ws.gradients)
            })
        };
        let one = run(1);
        assert_eq!(one, run(2));
        assert_eq!(one, run(3));
        assert_eq!(one, run(7));
    }

    /// Each thread's run of member-rows is within one row of the others', and the parts cover every member's
    /// rows once, in memory order, without crossing a member's end.
    #[test]
    fn parts_share_the_rows_evenly_in_memory_order() {
        for threads in 1..=6 {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            for (members, rows) in [(5, 256), (3, 7), (1, 1), (2, 5)] {
                let parts = pool.install(|| parts(members, rows));
                let mut next = 0;
                for part in &parts {
                    assert!(part.start < part.end && part.end <= rows, "{threads} threads: a part within a member");
                    assert_eq!(part.member * rows + part.start, next, "{threads} threads: parts in order");
                    next = part.member * rows + part.end;
                }
                assert_eq!(next, members * rows);
                let runs = threads.min(members * rows);
                assert!(parts.len() < runs + members, "{threads} threads: at most one cut per run and member");
                if threads == 1 {
                    assert_eq!(parts.len(), members, "one thread: whole members");
                }
            }
        }
    }

    /// The fused step (Adam applied block by block inside the gradient tasks) against the gradients followed by
    /// the whole-set update, over three steps on one workspace, with weight decay on and a uniform learning
    /// rate, at one to three threads: the same bytes for the loss, the weights and both moments.
    #[test]
    fn fused_step_equals_gradients_then_adam_on_any_pool() {
        let mut config = PetsConfig::preset(Preset::Small);
        (config.ensemble, config.hidden_units) = (3, 24);
        config.optimizer.weight_decay = 1e-3;
        let (din, dout, rows) = (4, 2, 96);
        let net = PetsNet::init(&config, din, dout, &training_device(), &mut ChaCha8Rng::seed_from_u64(8));
        let start = ParamSet::<f32>::from_module(&net, torch_name);
        let sizes: Vec<usize> = start.tensors.iter().map(|t| t.values.len()).collect();
        let mut rng = ChaCha8Rng::seed_from_u64(9);
        let e = config.ensemble;
        let batches: Vec<(Vec<f32>, Vec<f32>)> = (0..3)
            .map(|_| {
                let inputs = (0..e * rows * din).map(|_| rng.random_range(-2.0..2.0)).collect();
                let targets = (0..e * rows * dout).map(|_| rng.random_range(-0.5..0.5)).collect();
                (inputs, targets)
            })
            .collect();
        let state = |params: &ParamSet, adam: &Adam<f32>, losses: Vec<u64>| {
            let values: Vec<Vec<f32>> = params.tensors.iter().map(|t| t.values.clone()).collect();
            (losses, values, adam.exp_avg.clone(), adam.exp_avg_sq.clone(), adam.step)
        };
        let unfused = {
            let (mut params, mut adam, mut ws) =
                (start.clone(), Adam::new(config.optimizer, &sizes), Workspace::default());
            let losses = batches
                .iter()
                .map(|(inputs, targets)| {
                    let net = EnsembleNet::new(&params, &config, din, dout).unwrap();
                    let loss = net.loss_and_gradients(&params, &mut ws, inputs, targets, rows);
                    adam.update(&mut params.values_mut(), &mut ws.gradients).unwrap();
                    loss.to_bits()
                })
                .collect();
            state(&params, &adam, losses)
        };
        for threads in [1, 2, 3] {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            let fused = pool.install(|| {
                let (mut params, mut adam, mut ws) =
                    (start.clone(), Adam::new(config.optimizer, &sizes), Workspace::default());
                let losses = batches
                    .iter()
                    .map(|(inputs, targets)| {
                        let step =
                            train_step(&mut params, &mut adam, &config, (din, dout), &mut ws, inputs, targets, rows);
                        step.unwrap().to_bits()
                    })
                    .collect();
                state(&params, &adam, losses)
            });
            assert!(fused == unfused, "{threads} threads: the fused step differs");
        }
        assert_ne!(unfused.1, start.tensors.iter().map(|t| t.values.clone()).collect::<Vec<_>>());
    }

    #[test]
    fn fused_step_refuses_clipping() {
        let mut config = PetsConfig::preset(Preset::Small);
        config.optimizer.clip_grad_norm = Some(1.0);
        let net = PetsNet::init(&config, 2, 1, &training_device(), &mut ChaCha8Rng::seed_from_u64(1));
        let mut params = ParamSet::<f32>::from_module(&net, torch_name);
        let sizes: Vec<usize> = params.tensors.iter().map(|t| t.values.len()).collect();
        let mut adam = Adam::new(config.optimizer, &sizes);
        let e = config.ensemble;
        let (inputs, targets) = (vec![0.1f32; e * 4 * 2], vec![0.2f32; e * 4]);
        let err = train_step(&mut params, &mut adam, &config, (2, 1), &mut Workspace::default(), &inputs, &targets, 4);
        assert!(err.unwrap_err().to_string().contains("clip"));
        assert_eq!(adam.step, 0);
    }
}
