//! The ensemble's training loss and its gradient written out by hand: every member's layer is one faer GEMM,
//! the activation's derivative is applied in place, and the Gaussian NLL with the soft log-variance bounds is
//! differentiated in closed form. A PETS step is a few dozen small tensors; through burn's autodiff the
//! bookkeeping, copies and reloading the weights into the module each step cost more than the arithmetic.
//! `net.rs` stays the reference: a test holds the loss and every gradient here to burn's.
//!
//! Members never share a sum, so each member's work runs as its own rayon task, and the GEMMs inside split by
//! rows only: every number is summed by one thread in one order, so the bytes do not depend on the threads.

use faer::Accum;
use rayon::prelude::*;

use super::config::PetsConfig;
use crate::error::Result;
use crate::nn::activation::{fast_exp, fast_sigmoid as sigmoid, fast_softplus as softplus, Activation};
use crate::nn::backprop::{add_column_sums, matmul, tensor_index, view, view_mut, zero_gradients};
use crate::nn::ParamSet;

/// Elements per parallel task of an element-wise pass.
const ELEMENTWISE_BLOCK: usize = 1 << 14;

/// mbrl-lib's weight on Σ max_logvar − Σ min_logvar.
const BOUNDS_PENALTY: f32 = 0.01;

/// One ensemble layer's weights, [members, in, out] and [members, 1, out], as views of a parameter set.
struct Layer<'a> {
    d_in: usize,
    d_out: usize,
    weight: &'a [f32],
    bias: &'a [f32],
    weight_index: usize,
    bias_index: usize,
}

impl<'a> Layer<'a> {
    fn new(params: &'a ParamSet, prefix: &str, members: usize, d_in: usize, d_out: usize) -> Result<Self> {
        let weight_index = tensor_index(params, &format!("{prefix}.weight"), &[members, d_in, d_out])?;
        let bias_index = tensor_index(params, &format!("{prefix}.bias"), &[members, 1, d_out])?;
        Ok(Layer {
            d_in,
            d_out,
            weight: &params.tensors[weight_index].values,
            bias: &params.tensors[bias_index].values,
            weight_index,
            bias_index,
        })
    }

    /// [members, rows, in] → `y` [members, rows, out], one GEMM per member.
    fn forward(&self, x: &[f32], rows: usize, y: &mut Vec<f32>) {
        let (i, o) = (self.d_in, self.d_out);
        y.resize(x.len() / i * o, 0.0);
        y.par_chunks_mut(rows * o)
            .zip(x.par_chunks(rows * i))
            .zip(self.weight.par_chunks(i * o).zip(self.bias.par_chunks(o)))
            .for_each(|((y, x), (w, b))| {
                y.chunks_mut(o).for_each(|row| row.copy_from_slice(b));
                matmul(view_mut(y, rows, o), Accum::Add, view(x, rows, i), view(w, i, o));
            });
    }

    /// Writes this layer's weight and bias gradients for output gradients `dy` at inputs `x` into
    /// `weight_grad` and `bias_grad` (shaped like the layer's tensors).
    fn backward_weights(&self, x: &[f32], dy: &[f32], rows: usize, weight_grad: &mut [f32], bias_grad: &mut [f32]) {
        let (i, o) = (self.d_in, self.d_out);
        weight_grad
            .par_chunks_mut(i * o)
            .zip(bias_grad.par_chunks_mut(o))
            .zip(x.par_chunks(rows * i).zip(dy.par_chunks(rows * o)))
            .for_each(|((gw, gb), (x, dy))| {
                matmul(view_mut(gw, i, o), Accum::Replace, view(x, rows, i).transpose(), view(dy, rows, o));
                gb.fill(0.0);
                add_column_sums(gb, dy);
            });
    }

    /// The input gradients `dx` [members, rows, in] for output gradients `dy`.
    fn backward_input(&self, dy: &[f32], rows: usize, dx: &mut Vec<f32>) {
        let (i, o) = (self.d_in, self.d_out);
        dx.resize(dy.len() / o * i, 0.0);
        dx.par_chunks_mut(rows * i).zip(dy.par_chunks(rows * o)).zip(self.weight.par_chunks(i * o)).for_each(
            |((dx, dy), w)| {
                matmul(view_mut(dx, rows, i), Accum::Replace, view(dy, rows, o), view(w, i, o).transpose());
            },
        );
    }
}

/// The ensemble's layers as views of a parameter set in mbrl-lib's names (see `net::torch_name`).
pub struct EnsembleNet<'a> {
    members: usize,
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
    /// Every layer's input: the network's, then each hidden layer's activations.
    inputs: Vec<Vec<f32>>,
    /// Each hidden activation's derivative at its input.
    slopes: Vec<Vec<f32>>,
    /// The output layer's [members, rows, 2·target_dim]: mean, then the raw log-variance.
    output: Vec<f32>,
    d_output: Vec<f32>,
    d_input: Vec<f32>,
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
            target_dim,
            activation: config.activation,
            hidden,
            output,
            min_logvar: &params.tensors[bounds_index[0]].values,
            max_logvar: &params.tensors[bounds_index[1]].values,
            bounds_index,
        })
    }

    /// Fills the workspace's activations, slopes and output for `inputs` [members, rows, in].
    fn forward(&self, ws: &mut Workspace, inputs: &[f32], rows: usize) {
        ws.inputs.resize_with(self.hidden.len() + 1, Vec::new);
        ws.slopes.resize_with(self.hidden.len(), Vec::new);
        ws.inputs[0].clear();
        ws.inputs[0].extend_from_slice(inputs);
        for (k, layer) in self.hidden.iter().enumerate() {
            let (done, next) = ws.inputs.split_at_mut(k + 1);
            let h = &mut next[0];
            layer.forward(&done[k], rows, h);
            let slope = &mut ws.slopes[k];
            slope.resize(h.len(), 0.0);
            h.par_chunks_mut(ELEMENTWISE_BLOCK)
                .zip(slope.par_chunks_mut(ELEMENTWISE_BLOCK))
                .for_each(|(h, slope)| self.activation.apply_with_derivative(h, slope));
        }
        self.output.forward(ws.inputs.last().expect("the input is the first entry"), rows, &mut ws.output);
    }

    /// Mean squared error of the predicted mean against `targets` over every member, row and output, for
    /// inputs [members, rows, in] (normalized) and targets [members, rows, target_dim].
    pub fn mean_squared_error(&self, ws: &mut Workspace, inputs: &[f32], targets: &[f32], rows: usize) -> f64 {
        self.forward(ws, inputs, rows);
        let d = self.target_dim;
        let sum: f64 = ws
            .output
            .chunks(2 * d)
            .zip(targets.chunks(d))
            .map(|(out, y)| out[..d].iter().zip(y).map(|(m, y)| f64::from(m - y).powi(2)).sum::<f64>())
            .sum();
        sum / targets.len().max(1) as f64
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
        let (e, d) = (self.members, self.target_dim);
        self.forward(ws, inputs, rows);
        let scale = 1.0 / (rows * d) as f32;
        let mut d_output = std::mem::take(&mut ws.d_output);
        d_output.resize(ws.output.len(), 0.0);
        let mut d_min = vec![0.0f32; d];
        let mut d_max = vec![0.0f32; d];
        let mut member_sums = vec![0.0f64; e];
        for (row, ((out, y), d_out)) in
            ws.output.chunks(2 * d).zip(targets.chunks(d)).zip(d_output.chunks_mut(2 * d)).enumerate()
        {
            let mut row_sum = 0.0f64;
            for j in 0..d {
                let b = bounded(out[d + j], self.min_logvar[j], self.max_logvar[j]);
                let error = out[j] - y[j];
                let precision = fast_exp(-b.logvar);
                row_sum += f64::from(0.5 * (error * error * precision + b.logvar));
                d_out[j] = error * precision * scale;
                let d_logvar = 0.5 * (1.0 - error * error * precision) * scale;
                d_out[d + j] = d_logvar * b.lower_slope * b.upper_slope;
                d_max[j] += d_logvar * b.lower_slope * (1.0 - b.upper_slope);
                d_min[j] += d_logvar * (1.0 - b.lower_slope);
            }
            member_sums[row / rows] += row_sum;
        }
        let penalty = BOUNDS_PENALTY * (self.max_logvar.iter().sum::<f32>() - self.min_logvar.iter().sum::<f32>());
        let loss = member_sums.iter().map(|s| s / (rows * d) as f64).sum::<f64>() + f64::from(penalty);
        if ws.gradients.len() != params.tensors.len() {
            ws.gradients = zero_gradients(params);
        }
        d_max.iter_mut().for_each(|g| *g += BOUNDS_PENALTY);
        d_min.iter_mut().for_each(|g| *g -= BOUNDS_PENALTY);
        ws.gradients[self.bounds_index[0]] = d_min;
        ws.gradients[self.bounds_index[1]] = d_max;

        // dy and dx trade buffers layer by layer; both stay in the workspace.
        let mut dy = d_output;
        let mut dx = std::mem::take(&mut ws.d_input);
        let layers = self.hidden.iter().chain(std::iter::once(&self.output)).collect::<Vec<_>>();
        for (k, layer) in layers.iter().enumerate().rev() {
            let (mut weight_grad, mut bias_grad) = (
                std::mem::take(&mut ws.gradients[layer.weight_index]),
                std::mem::take(&mut ws.gradients[layer.bias_index]),
            );
            layer.backward_weights(&ws.inputs[k], &dy, rows, &mut weight_grad, &mut bias_grad);
            ws.gradients[layer.weight_index] = weight_grad;
            ws.gradients[layer.bias_index] = bias_grad;
            if k == 0 {
                break;
            }
            layer.backward_input(&dy, rows, &mut dx);
            dx.par_chunks_mut(ELEMENTWISE_BLOCK).zip(ws.slopes[k - 1].par_chunks(ELEMENTWISE_BLOCK)).for_each(
                |(d, slope)| {
                    d.iter_mut().zip(slope).for_each(|(d, s)| *d *= s);
                },
            );
            std::mem::swap(&mut dy, &mut dx);
        }
        ws.d_output = dy;
        ws.d_input = dx;
        loss
    }
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
    /// enough to the raw log-variances that both soft clamps pass part of their gradient.
    #[test]
    fn hand_written_gradients_match_burn_autodiff() {
        let (din, dout, rows) = (5, 3, 11);
        for (case, activation) in
            [Activation::Silu, Activation::Relu, Activation::Tanh, Activation::Sigmoid].into_iter().enumerate()
        {
            let mut config = PetsConfig::preset(Preset::Small);
            (config.ensemble, config.hidden_layers, config.hidden_units, config.activation) = (3, 2, 7, activation);
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
    }
}
