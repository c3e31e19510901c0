//! A strided convolution whose kernel is a whole number of strides, run without an im2col matrix. Its input is
//! regrouped once into stride × stride blocks ("space to depth"); the layer is then a stride-1 convolution with
//! a (kernel / stride)² kernel over blocks, and one kernel row of it, over every output position of a group of
//! images, is a single GEMM whose left operand is the regrouped images themselves, read one block apart (its
//! rows overlap).
//!
//! DLGPD's first encoder layer (64 × 64 × 6 frames, kernel 4, stride 2, 32 channels) is why: im2col spends
//! most of that layer gathering 24-float pieces into a matrix 16 times the frames' size, and its 96 × 32 GEMM is
//! too thin to hide the gather.
//!
//! The GEMM has one row per block, so that one image's rows follow the last one's; it therefore also yields
//! the blocks where no kernel window fits (the last `taps` − 1 of each block row and block column). Those rows
//! are dropped when the output is written, and left zero in the output gradient the weight gradient reads.
//! The groups of images are fixed by the batch, and the weight gradient is summed per group and then over the
//! groups in order, so the bytes do not depend on the thread count.

use std::mem::MaybeUninit;
use std::ops::Range;

use faer::{Accum, MatRef};
use rayon::prelude::*;

use super::backprop::{add_into, assume_written, relu_backward, slots, tensor_index, unwritten, view, view_mut};
use super::gemm::faer_product;
use super::params::ParamSet;
use crate::error::{Error, Result};

/// Images per GEMM, and per task: one image's products (992 × 48 by 48 × 32 for DLGPD's layer) are too short to
/// run near the kernel's speed. Small groups keep both threads busy at DLGPD's batches and keep each group's
/// products in cache; each group's weight gradient is summed on its own and the groups' sums are then added in
/// order.
const GROUP: usize = 4;

/// A convolution (torch's Conv2d without padding, weight [out, in, k, k]) over channels-first square images.
pub struct BlockedConv {
    side: usize,
    channels_in: usize,
    channels_out: usize,
    stride: usize,
    /// Blocks per side of the regrouped input.
    blocks: usize,
    /// Kernel side in blocks.
    taps: usize,
    out_side: usize,
    /// For each kernel row of blocks a, the [(b, py, px, c), out] matrix that one GEMM multiplies with; the
    /// rows of a follow those of a − 1.
    weight: Vec<f32>,
    bias: Vec<f32>,
    weight_index: usize,
    bias_index: usize,
}

/// The images a [`BlockedConv`] reads, each checked to be whole. They are regrouped into blocks a group at a
/// time, in each pass, into a buffer that stays in the core's cache: regrouping the whole batch up front wrote a
/// copy of the frames to memory that both passes then read back (3 % of DLGPD's batch-256 step).
pub struct BlockedInput<'a> {
    frames: Vec<&'a [f32]>,
}

impl BlockedConv {
    /// The layer `prefix` (`prefix.weight`, `prefix.bias`) of `params`, over `side`² × `channels_in` images.
    pub fn new(
        params: &ParamSet,
        prefix: &str,
        side: usize,
        (channels_in, channels_out): (usize, usize),
        kernel: usize,
        stride: usize,
    ) -> Result<Self> {
        if channels_in == 0
            || channels_out == 0
            || stride == 0
            || kernel == 0
            || !kernel.is_multiple_of(stride)
            || !side.is_multiple_of(stride)
            || kernel > side
        {
            return Err(Error::config(format!(
                "'{prefix}': a blocked convolution needs channels, a kernel that is a multiple of the stride and \
                 fits the side, and a side that is a multiple of the stride; got side {side}, kernel {kernel}, \
                 stride {stride}, channels {channels_in} → {channels_out}"
            )));
        }
        let weight_index =
            tensor_index(params, &format!("{prefix}.weight"), &[channels_out, channels_in, kernel, kernel])?;
        let bias_index = tensor_index(params, &format!("{prefix}.bias"), &[channels_out])?;
        let (blocks, taps) = (side / stride, kernel / stride);
        let torch = &params.tensors[weight_index].values;
        let mut layer = BlockedConv {
            side,
            channels_in,
            channels_out,
            stride,
            blocks,
            taps,
            out_side: (side - kernel) / stride + 1,
            weight: vec![0.0; kernel * kernel * channels_in * channels_out],
            bias: params.tensors[bias_index].values.clone(),
            weight_index,
            bias_index,
        };
        let rows: Vec<(usize, usize)> = layer.weight_rows().collect();
        for (row, torch_index) in rows {
            layer.weight[row * channels_out..][..channels_out]
                .iter_mut()
                .enumerate()
                .for_each(|(o, w)| *w = torch[o * channels_in * kernel * kernel + torch_index]);
        }
        Ok(layer)
    }

    /// Each row of `weight` with the offset of its (channel, ky, kx) within one output channel of torch's layout.
    fn weight_rows(&self) -> impl Iterator<Item = (usize, usize)> + '_ {
        let (s, c, k) = (self.stride, self.channels_in, self.taps * self.stride);
        (0..self.taps * self.row_width()).map(move |row| {
            let (a, within) = (row / self.row_width(), row % self.row_width());
            let (b, within) = (within / self.depth(), within % self.depth());
            let (py, px, channel) = (within / (s * c), within / c % s, within % c);
            (row, (channel * k + a * s + py) * k + b * s + px)
        })
    }

    /// Values per block: stride² pixels of every channel.
    fn depth(&self) -> usize {
        self.stride * self.stride * self.channels_in
    }

    /// Columns of one kernel row's GEMM: `taps` consecutive blocks.
    fn row_width(&self) -> usize {
        self.taps * self.depth()
    }

    fn blocked_len(&self) -> usize {
        self.blocks * self.blocks * self.depth()
    }

    /// Rows of one image's GEMM: one per block, so that the images' rows follow one another a block apart and
    /// a group of images is one GEMM. Rows whose block starts no kernel window are dropped.
    fn image_rows(&self) -> usize {
        self.blocks * self.blocks
    }

    pub fn input_len(&self) -> usize {
        self.side * self.side * self.channels_in
    }

    /// Values per image of the output, channels-last [out side, out side, channels out].
    pub fn output_len(&self) -> usize {
        self.out_side * self.out_side * self.channels_out
    }

    pub fn out_side(&self) -> usize {
        self.out_side
    }

    /// Channels-first `frames` ([images, channels, side, side], given as consecutive parts), checked to be whole
    /// images, for the passes to regroup as they go.
    pub fn input<'a>(&self, parts: &[&'a [f32]]) -> Result<BlockedInput<'a>> {
        if let Some(part) = parts.iter().find(|p| p.len() % self.input_len() != 0) {
            return Err(Error::data(format!(
                "{} values are not whole {} × {} × {} images",
                part.len(),
                self.channels_in,
                self.side,
                self.side
            )));
        }
        Ok(BlockedInput { frames: parts.iter().flat_map(|p| p.chunks(self.input_len())).collect() })
    }

    /// The group `images` of `input` regrouped into blocks in `blocked`: value (channel, y, x) of an image goes
    /// to block (y / s, x / s) at ((y % s) · s + x % s) · channels + channel. The last image's final GEMM rows
    /// read up to `taps` − 1 block rows and blocks past its end, so zeros follow it.
    fn regroup_group<'b>(
        &self,
        input: &BlockedInput<'_>,
        images: Range<usize>,
        blocked: &'b mut Vec<f32>,
    ) -> &'b [f32] {
        let (image_len, padding) = (self.blocked_len(), (self.taps - 1) * (self.blocks + 1) * self.depth());
        let len = images.len() * image_len + padding;
        blocked.clear();
        blocked.reserve(len);
        let slots = &mut blocked.spare_capacity_mut()[..len];
        let (image_slots, padding_slots) = slots.split_at_mut(images.len() * image_len);
        image_slots
            .chunks_mut(image_len)
            .zip(&input.frames[images])
            .for_each(|(out, frame)| self.regroup_image(frame, out));
        padding_slots.iter_mut().for_each(|slot| _ = slot.write(0.0));
        // SAFETY: regroup_image writes every slot of its image (the map is one-to-one onto them), and the
        // padding was written just above.
        unsafe { blocked.set_len(len) };
        blocked
    }

    fn regroup_image(&self, frame: &[f32], out: &mut [MaybeUninit<f32>]) {
        match self.stride {
            // DLGPD's stride as a constant: the loop below unrolls without a multiplication per pixel, three
            // times faster than with a stride known only at run time.
            2 => self.regroup_image_by(2, frame, out),
            stride => self.regroup_image_by(stride, frame, out),
        }
    }

    /// One image row at a time, every channel of it: its values land in one block row (a few KiB), which stays
    /// in the first cache (channel by channel over the whole image, each store went to the second).
    #[inline(always)]
    fn regroup_image_by(&self, s: usize, frame: &[f32], out: &mut [MaybeUninit<f32>]) {
        let (c, side, depth) = (self.channels_in, self.side, self.depth());
        for y in 0..side {
            let block_row = &mut out[(y / s) * self.blocks * depth..][..self.blocks * depth];
            for channel in 0..c {
                let row = &frame[(channel * side + y) * side..][..side];
                let within = (y % s) * s * c + channel;
                for (block, pixels) in block_row.chunks_exact_mut(depth).zip(row.chunks_exact(s)) {
                    // The slots of this block row's pixels, bounded once so that each store needs no check.
                    let block = &mut block[within..][..(s - 1) * c + 1];
                    for (px, &value) in pixels.iter().enumerate() {
                        block[px * c].write(value);
                    }
                }
            }
        }
    }

    /// The GEMM row of output position `position` (row-major over out side × out side) within its image.
    fn gemm_row(&self, position: usize) -> usize {
        (position / self.out_side) * self.blocks + position % self.out_side
    }

    /// The GEMM rows of a group of `images` regrouped into `blocked` for kernel row `a`: row (image, Y, X) is
    /// `taps` blocks from block (Y + a, X) of its image on.
    fn kernel_row_operand<'a>(&self, blocked: &'a [f32], images: usize, a: usize) -> MatRef<'a, f32> {
        let (depth, rows) = (self.depth(), images * self.image_rows());
        let start = a * self.blocks * depth;
        let end = start + (rows - 1) * depth + self.row_width();
        assert!(end <= blocked.len(), "a blocked operand past its buffer's padding");
        // SAFETY: every element read, at start + r · depth + j for r < rows and j < row_width, lies below `end`,
        // which is inside the buffer; the view is read-only, so its overlapping rows alias nothing written.
        unsafe { MatRef::from_raw_parts(blocked.as_ptr().add(start), rows, self.row_width(), depth as isize, 1) }
    }

    fn kernel_row_weight(&self, a: usize) -> MatRef<'_, f32> {
        let len = self.row_width() * self.channels_out;
        view(&self.weight[a * len..][..len], self.row_width(), self.channels_out)
    }

    /// The image ranges of the groups.
    fn groups(&self, images: usize) -> impl IndexedParallelIterator<Item = Range<usize>> {
        (0..images.div_ceil(GROUP)).into_par_iter().map(move |group| group * GROUP..((group + 1) * GROUP).min(images))
    }

    /// The layer's outputs, channels-last, bias added, through a ReLU when `relu`.
    pub fn forward(&self, input: &BlockedInput<'_>, relu: bool) -> Vec<f32> {
        let (out, images) = (self.channels_out, input.frames.len());
        let len = images * self.output_len();
        if len == 0 {
            return Vec::new();
        }
        let fill_group =
            |images: Range<usize>, y: &mut [MaybeUninit<f32>], (blocked, product): &mut (Vec<f32>, Vec<f32>)| {
                let rows = images.len() * self.image_rows();
                let blocked = self.regroup_group(input, images.clone(), blocked);
                product.resize(rows * out, 0.0);
                for a in 0..self.taps {
                    let accum = if a == 0 { Accum::Replace } else { Accum::Add };
                    let operand = self.kernel_row_operand(blocked, images.len(), a);
                    let product = view_mut(&mut product[..rows * out], rows, out);
                    faer_product(product, accum, operand, self.kernel_row_weight(a));
                }
                let activate = |x: f32| if relu { x.max(0.0) } else { x };
                for (image, y) in y.chunks_mut(self.output_len()).enumerate() {
                    let product = &product[image * self.image_rows() * out..];
                    for (position, slots) in y.chunks_mut(out).enumerate() {
                        let values = &product[self.gemm_row(position) * out..][..out];
                        let pairs = slots.iter_mut().zip(values.iter().zip(&self.bias));
                        pairs.for_each(|(slot, (v, b))| _ = slot.write(activate(v + b)));
                    }
                }
            };
        let mut y = unwritten(len);
        slots(&mut y, len)
            .par_chunks_mut(GROUP * self.output_len())
            .zip(self.groups(images))
            .for_each_init(|| (Vec::new(), Vec::new()), |buffers, (y, images)| fill_group(images, y, buffers));
        // SAFETY: every group's chunk was written in full above: each of its images' positions is one row of `out`.
        unsafe { assume_written(&mut y, len) };
        y
    }

    /// Adds the weight and bias gradients for output gradients `dy` (channels-last, as `forward` returns) to
    /// `grads` (torch's layout). With `relu_output` (this layer's output, through a ReLU), `dy` is the gradient
    /// at the ReLU's output, masked as it is read. The input gradient is not formed: this layer reads the data.
    pub fn backward(&self, input: &BlockedInput<'_>, dy: &[f32], relu_output: Option<&[f32]>, grads: &mut [Vec<f32>]) {
        debug_assert_eq!(dy.len(), input.frames.len() * self.output_len());
        debug_assert!(relu_output.is_none_or(|y| y.len() == dy.len()));
        let out = self.channels_out;
        // Each thread keeps one buffer for its groups' gradients: the rows whose block starts no window are
        // never written, so they stay zero and add nothing.
        let padded_len = GROUP * self.image_rows() * out;
        let group_sums: Vec<(Vec<f32>, Vec<f32>)> = self
            .groups(input.frames.len())
            .map_init(
                || (vec![0.0f32; padded_len], Vec::new()),
                |(padded, blocked), images| {
                    let rows = images.len() * self.image_rows();
                    let padded = &mut padded[..rows * out];
                    let mut bias_sum = vec![0.0f32; out];
                    for (image, padded) in images.clone().zip(padded.chunks_mut(self.image_rows() * out)) {
                        let at = image * self.output_len();
                        let dy = &dy[at..][..self.output_len()];
                        for (position, values) in dy.chunks(out).enumerate() {
                            let row = &mut padded[self.gemm_row(position) * out..][..out];
                            row.copy_from_slice(values);
                            if let Some(y) = relu_output {
                                relu_backward(row, &y[at + position * out..][..out]);
                            }
                            bias_sum.iter_mut().zip(row.iter()).for_each(|(sum, d)| *sum += d);
                        }
                    }
                    let blocked = self.regroup_group(input, images.clone(), blocked);
                    let mut sum = vec![0.0f32; self.weight.len()];
                    for a in 0..self.taps {
                        let operand = self.kernel_row_operand(blocked, images.len(), a);
                        let sum = &mut sum[a * self.row_width() * out..][..self.row_width() * out];
                        faer_product(
                            view_mut(sum, self.row_width(), out),
                            Accum::Replace,
                            operand.transpose(),
                            view(padded, rows, out),
                        );
                    }
                    (sum, bias_sum)
                },
            )
            .collect();
        let mut group_sums = group_sums.into_iter();
        let Some((mut sum, mut bias_sum)) = group_sums.next() else { return };
        group_sums.for_each(|(group, bias)| {
            add_into(&mut sum, &group);
            add_into(&mut bias_sum, &bias);
        });
        let torch = &mut grads[self.weight_index];
        let per_output = self.channels_in * self.taps * self.stride * self.taps * self.stride;
        for (row, torch_index) in self.weight_rows() {
            for (o, g) in sum[row * out..][..out].iter().enumerate() {
                torch[o * per_output + torch_index] += g;
            }
        }
        add_into(&mut grads[self.bias_index], &bias_sum);
    }
}

#[cfg(test)]
mod tests {
    use burn::tensor::Tensor;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    use super::*;
    use crate::nn::backprop::zero_gradients;
    use crate::nn::conv::Conv2dConfig;
    use crate::nn::conv_backprop::tests::close;
    use crate::nn::conv_backprop::to_channels_first;
    use crate::nn::tensor::{tensor, training_device, values};

    /// Output and parameter gradients against burn's Conv2d for the loss Σ y ⊙ R, over images given in two
    /// parts, with kernels of one, two and three strides.
    #[test]
    fn matches_burn_forward_and_backward() {
        let device = training_device();
        for (side, cin, cout, k, s, images) in
            [(8, 2, 3, 4, 2, 5), (9, 3, 4, 6, 3, 3), (6, 4, 5, 2, 2, 2), (10, 1, 2, 6, 2, 7)]
        {
            let mut rng = ChaCha8Rng::seed_from_u64(side as u64 * 31 + k as u64);
            let conv = Conv2dConfig::new(cin, cout, k, s).init(&device, &mut rng);
            let x: Vec<f32> = (0..images * cin * side * side).map(|_| rng.random_range(-1.0..1.0)).collect();
            let out_side = (side - k) / s + 1;
            let r: Vec<f32> = (0..images * cout * out_side * out_side).map(|_| rng.random_range(-1.0..1.0)).collect();
            let xt: Tensor<4> = tensor(x.clone(), [images, cin, side, side], &device);
            let y = conv.forward(xt);
            let burn_grads = (y.clone() * tensor(r.clone(), y.dims(), &device)).sum().backward();
            let params = ParamSet::<f32>::from_module(&conv, |n: &str| format!("layer.{n}"));
            let ours = BlockedConv::new(&params, "layer", side, (cin, cout), k, s).unwrap();
            let split = (images / 2) * cin * side * side;
            let input = ours.input(&[&x[..split], &x[split..]]).unwrap();
            let y_ours = ours.forward(&input, false);
            close(&to_channels_first(&y_ours, cout, out_side), &values(&y), "output");
            let mut grads = zero_gradients(&params);
            let r_last = crate::nn::conv_backprop::to_channels_last(&r, cout, out_side);
            ours.backward(&input, &r_last, None, &mut grads);
            for ((t, g), theirs) in
                params.tensors.iter().zip(&grads).zip(ParamSet::<f32>::gradients(&conv, &burn_grads))
            {
                close(g, &theirs, &t.name);
            }
        }
    }

    #[test]
    fn refuses_kernels_that_are_not_whole_strides() {
        let device = training_device();
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let params = ParamSet::<f32>::from_module(&Conv2dConfig::new(2, 3, 5, 2).init(&device, &mut rng), |n: &str| {
            format!("layer.{n}")
        });
        let error = BlockedConv::new(&params, "layer", 8, (2, 3), 5, 2).err().expect("kernel 5 over stride 2");
        assert!(error.to_string().contains("multiple of the stride"), "{error}");
    }

    /// A kernel-4, stride-2 layer of random weights over `side`² images.
    fn random_layer(rng: &mut ChaCha8Rng, side: usize, (cin, cout): (usize, usize)) -> (ParamSet, BlockedConv) {
        let conv = Conv2dConfig::new(cin, cout, 4, 2).init(&training_device(), rng);
        let params = ParamSet::<f32>::from_module(&conv, |n: &str| format!("layer.{n}"));
        let layer = BlockedConv::new(&params, "layer", side, (cin, cout), 4, 2).unwrap();
        (params, layer)
    }

    #[test]
    fn bytes_do_not_depend_on_the_thread_count() {
        let mut rng = ChaCha8Rng::seed_from_u64(4);
        let (params, layer) = random_layer(&mut rng, 16, (3, 8));
        let images = 11;
        let x: Vec<f32> = (0..images * layer.input_len()).map(|_| rng.random_range(-1.0..1.0)).collect();
        let dy: Vec<f32> = (0..images * layer.output_len()).map(|_| rng.random_range(-1.0..1.0)).collect();
        let run = |threads| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| {
                let input = layer.input(&[&x]).unwrap();
                let mut grads = zero_gradients(&params);
                layer.backward(&input, &dy, None, &mut grads);
                (layer.forward(&input, false), grads)
            })
        };
        let one = run(1);
        for threads in [2, 3] {
            assert!(one == run(threads), "{threads} threads");
        }
    }

    /// The im2col layer's output and gradients on DLGPD's layer shape and on kernels of one and three blocks,
    /// with batches of several weight-gradient groups whose last group is partial.
    #[test]
    fn matches_the_im2col_layer_on_larger_batches() {
        let device = training_device();
        for (side, cin, cout, k, s, images) in [(64, 6, 32, 4, 2, 3), (32, 5, 7, 6, 2, 9), (24, 2, 3, 24, 2, 14)] {
            let mut rng = ChaCha8Rng::seed_from_u64(side as u64);
            let conv = Conv2dConfig::new(cin, cout, k, s).init(&device, &mut rng);
            let params = ParamSet::<f32>::from_module(&conv, |n: &str| format!("layer.{n}"));
            let blocked = BlockedConv::new(&params, "layer", side, (cin, cout), k, s).unwrap();
            let grids = crate::nn::conv_backprop::Grids::conv(side, cin, cout, k, s);
            let down = crate::nn::conv_backprop::Direction::Down;
            let im2col = crate::nn::conv_backprop::StridedConv::new(&params, "layer", grids, down).unwrap();
            let x: Vec<f32> = (0..images * blocked.input_len()).map(|_| rng.random_range(-1.0..1.0)).collect();
            let input = blocked.input(&[&x]).unwrap();
            let x_last = crate::nn::conv_backprop::to_channels_last(&x, cin, side);
            let y = blocked.forward(&input, false);
            close(&y, &im2col.forward(&x_last, images, false), "output");
            let dy: Vec<f32> = (0..y.len()).map(|_| rng.random_range(-1.0..1.0)).collect();
            let (mut ours, mut theirs) = (zero_gradients(&params), zero_gradients(&params));
            blocked.backward(&input, &dy, None, &mut ours);
            im2col.backward(
                &x_last,
                &mut dy.clone(),
                None,
                images,
                &mut theirs,
                crate::nn::conv_backprop::InputGradient::Skip,
            );
            for (ours, theirs) in ours.iter().zip(&theirs) {
                close(ours, theirs, "parameter gradient");
            }
        }
    }

    /// The ReLU in the forward pass and the mask in the backward pass give what separate passes give.
    #[test]
    fn fused_relu_matches_separate_passes() {
        let mut rng = ChaCha8Rng::seed_from_u64(9);
        let (params, layer) = random_layer(&mut rng, 12, (3, 5));
        let images = 9;
        let x: Vec<f32> = (0..images * layer.input_len()).map(|_| rng.random_range(-1.0..1.0)).collect();
        let input = layer.input(&[&x]).unwrap();
        let mut y = layer.forward(&input, false);
        crate::nn::backprop::relu_in_place(&mut y);
        assert!(layer.forward(&input, true) == y, "the fused ReLU changed the output's bits");
        let dy: Vec<f32> = (0..y.len()).map(|_| rng.random_range(-1.0..1.0)).collect();
        let mut masked = dy.clone();
        crate::nn::backprop::relu_backward(&mut masked, &y);
        let (mut separate, mut fused) = (zero_gradients(&params), zero_gradients(&params));
        layer.backward(&input, &masked, None, &mut separate);
        layer.backward(&input, &dy, Some(&y), &mut fused);
        for (ours, theirs) in fused.iter().zip(&separate) {
            close(ours, theirs, "parameter gradient");
        }
    }

    #[test]
    fn parts_that_are_not_whole_images_are_errors() {
        let device = training_device();
        let conv = Conv2dConfig::new(2, 3, 4, 2).init(&device, &mut ChaCha8Rng::seed_from_u64(5));
        let params = ParamSet::<f32>::from_module(&conv, |n: &str| format!("layer.{n}"));
        let layer = BlockedConv::new(&params, "layer", 8, (2, 3), 4, 2).unwrap();
        let error = layer.input(&[&[0.0; 128], &[0.0; 127]]).err().expect("127 values are not an image");
        assert!(error.to_string().contains("not whole 2 × 8 × 8 images"), "{error}");
    }
}
