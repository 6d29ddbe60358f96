//! Plain-Rust inference layers copied out of trained burn modules: no autodiff, no tensors, no
//! allocation per step.
//!
//! A trained network is built once with [`Dense::from_linear`] and [`Lstm::from_fused`]; every
//! call after that writes into buffers the caller owns ([`LstmScratch`] for the LSTM's gate
//! buffers, plain slices for the dense layers), so stepping a recurrent network frame by frame
//! allocates nothing once the buffers have their size. Rows are independent trajectories stepped
//! in lockstep (`[rows][features]`, row-major), which reuses each weight row while it is in cache.
//!
//! The arithmetic is that of burn's `Linear` and [`FusedLstm`](crate::lstm::FusedLstm) (gate
//! blocks `i, f, o, g`; see [`crate::lstm`]); the tests check equality with burn's forward to
//! 1e-5.
//!
//! ```
//! use inbetween_nn::runtime::{Lstm, LstmScratch, LstmState};
//! # let device = inbetween_nn::backend::cpu();
//! # let burn_lstm = inbetween_nn::lstm::FusedLstmConfig::new(3, 8).init(&device);
//! let lstm = Lstm::from_fused(&burn_lstm);
//! let mut state = LstmState::zeros(1, lstm.hidden);
//! let mut scratch = LstmScratch::default();
//! for x in [[0.1f32, 0.2, 0.3], [0.0, -0.1, 0.5]] {
//!     lstm.step(&x, &mut state, 1, &mut scratch);
//! }
//! assert_eq!(state.h.len(), 8);
//! ```

use crate::lstm::FusedLstm;
use burn::nn::Linear;
use burn::tensor::Tensor;

/// A parameter's values as f32 (converted from the backend's float type when it differs; the
/// conversion to f32 cannot then fail).
fn tensor_values<const D: usize>(t: Tensor<D>) -> Vec<f32> {
    t.into_data().convert::<f32>().try_into_vec::<f32>().unwrap_or_default()
}

/// A fully connected layer `y = x W + b`, W stored `[in][out]` row-major (burn's `Linear` layout).
#[derive(Debug, Clone, PartialEq)]
pub struct Dense {
    /// `n_in × n_out` weights, row `i` multiplies input `i`.
    pub w: Vec<f32>,
    /// `n_out` biases (zeros when the burn layer has none).
    pub b: Vec<f32>,
    /// Input features.
    pub n_in: usize,
    /// Output features.
    pub n_out: usize,
}

impl Dense {
    /// Copies a burn `Linear`'s parameters.
    pub fn from_linear(l: &Linear) -> Dense {
        let w = l.weight.val();
        let [n_in, n_out] = w.dims();
        let b = l.bias.as_ref().map_or(vec![0.0; n_out], |b| tensor_values(b.val()));
        Dense { w: tensor_values(w), b, n_in, n_out }
    }

    /// `y[r] = x[r] W + b` for `rows` rows: `x` holds at least `rows × n_in` values, `y` at least
    /// `rows × n_out`. Inputs that are exactly 0 are skipped (they add nothing).
    pub fn forward(&self, x: &[f32], y: &mut [f32], rows: usize) {
        let (ni, no) = (self.n_in, self.n_out);
        for r in 0..rows {
            y[r * no..(r + 1) * no].copy_from_slice(&self.b);
        }
        for i in 0..ni {
            let wrow = &self.w[i * no..(i + 1) * no];
            for r in 0..rows {
                let xi = x[r * ni + i];
                if xi == 0.0 {
                    continue;
                }
                let yr = &mut y[r * no..(r + 1) * no];
                for (yj, wj) in yr.iter_mut().zip(wrow) {
                    *yj += xi * wj;
                }
            }
        }
    }
}

/// (Leaky) ReLU in place: `slope` is the negative slope, 0 for the plain ReLU (burn's
/// `leaky_relu(x, slope)`).
pub fn leaky_relu(v: &mut [f32], slope: f32) {
    for x in v {
        if *x < 0.0 {
            *x *= slope;
        }
    }
}

/// The logistic function σ(x) = 1 / (1 + e^(−x)).
pub fn sigmoid(x: f32) -> f32 {
    1.0 / (1.0 + (-x).exp())
}

/// Recurrent state of an [`Lstm`] for `rows` trajectories, each `[rows][hidden]` row-major.
#[derive(Debug, Clone, PartialEq)]
pub struct LstmState {
    /// Hidden state h (the cell's output).
    pub h: Vec<f32>,
    /// Cell state c.
    pub c: Vec<f32>,
}

impl LstmState {
    /// All-zero state.
    pub fn zeros(rows: usize, hidden: usize) -> LstmState {
        LstmState { h: vec![0.0; rows * hidden], c: vec![0.0; rows * hidden] }
    }
}

/// The gate buffers of one [`Lstm::step`]: they grow to the largest row count seen and are then
/// reused, so steps after the first allocate nothing.
#[derive(Debug, Clone, Default)]
pub struct LstmScratch {
    xh: Vec<f32>,
    z: Vec<f32>,
}

impl LstmScratch {
    /// Buffers already sized for `rows` trajectories of `lstm`.
    pub fn for_rows(lstm: &Lstm, rows: usize) -> LstmScratch {
        let mut s = LstmScratch::default();
        s.reserve(lstm, rows);
        s
    }

    fn reserve(&mut self, lstm: &Lstm, rows: usize) {
        let (xh, z) = (rows * lstm.gates.n_in, rows * lstm.gates.n_out);
        if self.xh.len() < xh {
            self.xh.resize(xh, 0.0);
        }
        if self.z.len() < z {
            self.z.resize(z, 0.0);
        }
    }
}

/// The fused LSTM cell of [`crate::lstm::FusedLstm`]: `[i, f, o, g] = W·[x, h] + b`,
/// `c' = σ(f) ⊙ c + σ(i) ⊙ tanh(g)`, `h' = σ(o) ⊙ tanh(c')`.
#[derive(Debug, Clone, PartialEq)]
pub struct Lstm {
    /// `[d_input + hidden] → [4·hidden]`, gate blocks `i, f, o, g`.
    pub gates: Dense,
    /// Hidden units.
    pub hidden: usize,
}

impl Lstm {
    /// Copies a burn [`FusedLstm`]'s parameters.
    pub fn from_fused(l: &FusedLstm) -> Lstm {
        Lstm { gates: Dense::from_linear(&l.gates), hidden: l.d_hidden }
    }

    /// Input features per step.
    pub fn d_input(&self) -> usize {
        self.gates.n_in - self.hidden
    }

    /// One step for `rows` trajectories: `x` is `[rows][d_input]`; `state` holds `rows` rows.
    pub fn step(&self, x: &[f32], state: &mut LstmState, rows: usize, scratch: &mut LstmScratch) {
        let hd = self.hidden;
        let d_in = self.d_input();
        let w = d_in + hd;
        scratch.reserve(self, rows);
        let (xh, z) = (&mut scratch.xh[..rows * w], &mut scratch.z[..rows * 4 * hd]);
        for r in 0..rows {
            xh[r * w..r * w + d_in].copy_from_slice(&x[r * d_in..(r + 1) * d_in]);
            xh[r * w + d_in..(r + 1) * w].copy_from_slice(&state.h[r * hd..(r + 1) * hd]);
        }
        self.gates.forward(xh, z, rows);
        for r in 0..rows {
            let zr = &z[r * 4 * hd..(r + 1) * 4 * hd];
            for k in 0..hd {
                let (i, f, o, g) =
                    (sigmoid(zr[k]), sigmoid(zr[hd + k]), sigmoid(zr[2 * hd + k]), zr[3 * hd + k].tanh());
                let c = f * state.c[r * hd + k] + i * g;
                state.c[r * hd + k] = c;
                state.h[r * hd + k] = o * c.tanh();
            }
        }
    }
}

/// `y += a·x`, with a fused multiply-add when `FMA` (only instantiated where the CPU has one).
#[inline(always)]
fn axpy<const FMA: bool>(a: f32, x: &[f32], y: &mut [f32]) {
    if FMA {
        for (yi, xi) in y.iter_mut().zip(x) {
            *yi = xi.mul_add(a, *yi);
        }
    } else {
        for (yi, xi) in y.iter_mut().zip(x) {
            *yi += a * xi;
        }
    }
}

/// `y += Σ_k a[k]·x_k` over the `n_out`-wide rows `xs[k·n_out..]` of a block of 4 weight rows: one
/// pass over `y` for four rows of weights (a fused multiply-add chain when `FMA`).
#[inline(always)]
fn axpy4<const FMA: bool>(a: &[f32], xs: &[f32], n_out: usize, y: &mut [f32]) {
    let (a0, a1, a2, a3) = (a[0], a[1], a[2], a[3]);
    let (x0, rest) = xs.split_at(n_out);
    let (x1, rest) = rest.split_at(n_out);
    let (x2, x3) = rest.split_at(n_out);
    let y = &mut y[..n_out];
    let (x3, x2, x1, x0) = (&x3[..n_out], &x2[..n_out], &x1[..n_out], &x0[..n_out]);
    for k in 0..n_out {
        y[k] = if FMA {
            x3[k].mul_add(a3, x2[k].mul_add(a2, x1[k].mul_add(a1, x0[k].mul_add(a0, y[k]))))
        } else {
            y[k] + a0 * x0[k] + a1 * x1[k] + a2 * x2[k] + a3 * x3[k]
        };
    }
}

/// `y += x · W` for one row `x` (`n_in` values), `W` `n_in × n_out` row-major: weight rows taken
/// four at a time ([`axpy4`]); groups of four zero inputs are skipped.
#[inline(always)]
fn row_times_matrix<const FMA: bool>(x: &[f32], w: &[f32], n_out: usize, y: &mut [f32]) {
    let n_in = x.len();
    let full = n_in / 4 * 4;
    for i in (0..full).step_by(4) {
        let a = &x[i..i + 4];
        if a.iter().any(|v| *v != 0.0) {
            axpy4::<FMA>(a, &w[i * n_out..(i + 4) * n_out], n_out, y);
        }
    }
    for i in full..n_in {
        if x[i] != 0.0 {
            axpy::<FMA>(x[i], &w[i * n_out..(i + 1) * n_out], y);
        }
    }
}

/// `y[r] = b + x[r] · W` for `rows` rows, `W` `n_in × n_out` row-major (a block of a [`Dense`]'s
/// rows: the fused LSTM gates split into their `x` and `h` parts).
#[inline(always)]
fn affine_rows<const FMA: bool>(
    w: &[f32],
    b: &[f32],
    n_out: usize,
    x: &[f32],
    n_in: usize,
    y: &mut [f32],
    rows: usize,
) {
    for r in 0..rows {
        let yr = &mut y[r * n_out..(r + 1) * n_out];
        yr.copy_from_slice(b);
        row_times_matrix::<FMA>(&x[r * n_in..(r + 1) * n_in], w, n_out, yr);
    }
}

/// e^x in plain arithmetic that the compiler vectorises (libm's `expf` is a call per value):
/// `x = n·ln 2 + r` with `|r| ≤ ln 2 / 2`, a degree-6 Taylor polynomial for e^r (truncation below
/// 2e-7 relative), and 2^n written into the exponent bits. Inputs are clamped to [−87, 88], where
/// 2^n stays a normal float.
#[inline(always)]
fn exp_approx(x: f32) -> f32 {
    const ROUND: f32 = 12_582_912.0; // 1.5·2^23: adding and subtracting it rounds to an integer.
    let x = x.clamp(-87.0, 88.0);
    let n = (x * std::f32::consts::LOG2_E + ROUND) - ROUND;
    let r = x - n * 0.693_145_75 - n * 1.428_606_8e-6;
    let p = 1.0 + r * (1.0 + r * (0.5 + r * (1.0 / 6.0 + r * (1.0 / 24.0 + r * (1.0 / 120.0 + r * (1.0 / 720.0))))));
    p * f32::from_bits(((n as i32 + 127) as u32) << 23)
}

/// σ(x) in place over a slice, vectorisable.
#[inline(always)]
fn sigmoid_slice(v: &mut [f32]) {
    for x in v {
        *x = 1.0 / (1.0 + exp_approx(-*x));
    }
}

/// tanh(x) = 2σ(2x) − 1 in place over a slice, vectorisable (absolute error about 1e-7).
#[inline(always)]
fn tanh_slice(v: &mut [f32]) {
    for x in v {
        *x = 2.0 / (1.0 + exp_approx(-2.0 * *x)) - 1.0;
    }
}

/// One bidirectional layer of a [`BiLstm`]: a cell reading the sequence forwards and one reading it
/// backwards.
#[derive(Debug, Clone, PartialEq)]
pub struct BiLstmLayer {
    /// Reads frames first to last.
    pub forward: Lstm,
    /// Reads frames last to first.
    pub backward: Lstm,
}

/// The stacked bidirectional LSTM of [`crate::lstm::BiLstm`] over one whole sequence: output frame
/// `t` is `[h_forward_t, h_backward_t]` of the last layer.
///
/// Each direction first projects every frame's input at once (`b + x_t · W_x` for all `t`, one pass
/// over the input weights for the whole sequence), then steps only the recurrent part
/// `h_{t−1} · W_h`; weight rows go four at a time over the accumulator, the gate nonlinearities use a
/// vectorisable e^x (relative error below 5e-7), and where the CPU has AVX2 and FMA (checked at run
/// time) the loops are compiled for them. All buffers live in a [`BiLstmScratch`] that grows to the longest sequence seen
/// and is then reused, so a call allocates nothing once warm. The two directions of a layer are
/// independent; [`BiLstm::forward_parallel`] runs them on two threads.
///
/// ```
/// use inbetween_nn::runtime::{BiLstm, BiLstmScratch};
/// # let device = inbetween_nn::backend::cpu();
/// # let burn_lstm = inbetween_nn::lstm::BiLstmConfig::new(3, 8).with_num_layers(2).init(&device);
/// let lstm = BiLstm::from_bilstm(&burn_lstm);
/// let mut scratch = BiLstmScratch::default();
/// let frames = 5;
/// let input = vec![0.1f32; frames * 3];
/// let out = lstm.forward(&input, frames, &mut scratch);
/// assert_eq!(out.len(), frames * 16);
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct BiLstm {
    /// Layers from input to output.
    pub layers: Vec<BiLstmLayer>,
}

/// Buffers of one direction of one layer.
#[derive(Debug, Clone, Default)]
struct DirectionScratch {
    /// `frames × 4·hidden` input projections.
    xz: Vec<f32>,
    /// `frames × hidden` outputs of this direction.
    out: Vec<f32>,
    h: Vec<f32>,
    c: Vec<f32>,
}

/// The reusable buffers of [`BiLstm::forward`].
#[derive(Debug, Clone, Default)]
pub struct BiLstmScratch {
    dirs: [DirectionScratch; 2],
    /// Layer outputs, alternating (`frames × 2·hidden`).
    seq: [Vec<f32>; 2],
}

fn grow(v: &mut Vec<f32>, len: usize) {
    if v.len() < len {
        v.resize(len, 0.0);
    }
}

impl Lstm {
    /// Runs the cell over `frames` frames of `input` (`frames × d_input`), last to first when
    /// `reverse`, from a zero state; writes every frame's `h` to `s.out` (`frames × hidden`, in
    /// frame order either way). Uses AVX2 + FMA where the CPU has them (checked at run time).
    fn run_sequence(&self, input: &[f32], frames: usize, reverse: bool, s: &mut DirectionScratch) {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma") {
            // SAFETY: the CPU supports AVX2 and FMA (checked just above).
            unsafe { self.run_sequence_avx2(input, frames, reverse, s) };
            return;
        }
        self.run_sequence_with::<false>(input, frames, reverse, s);
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    fn run_sequence_avx2(&self, input: &[f32], frames: usize, reverse: bool, s: &mut DirectionScratch) {
        self.run_sequence_with::<true>(input, frames, reverse, s);
    }

    #[inline(always)]
    fn run_sequence_with<const FMA: bool>(
        &self,
        input: &[f32],
        frames: usize,
        reverse: bool,
        s: &mut DirectionScratch,
    ) {
        let (hd, d_in) = (self.hidden, self.d_input());
        let n4 = 4 * hd;
        grow(&mut s.xz, frames * n4);
        grow(&mut s.out, frames * hd);
        grow(&mut s.h, hd);
        grow(&mut s.c, hd);
        let (w_x, w_h) = self.gates.w.split_at(d_in * n4);
        affine_rows::<FMA>(w_x, &self.gates.b, n4, input, d_in, &mut s.xz, frames);
        s.h[..hd].fill(0.0);
        s.c[..hd].fill(0.0);
        for k in 0..frames {
            let t = if reverse { frames - 1 - k } else { k };
            let z = &mut s.xz[t * n4..(t + 1) * n4];
            row_times_matrix::<FMA>(&s.h[..hd], w_h, n4, z);
            // Gate blocks i, f, o (sigmoid) and g (tanh).
            let (sig, g) = z.split_at_mut(3 * hd);
            sigmoid_slice(sig);
            tanh_slice(g);
            let (i, rest) = sig.split_at(hd);
            let (f, o) = rest.split_at(hd);
            let out = &mut s.out[t * hd..(t + 1) * hd];
            let c = &mut s.c[..hd];
            for j in 0..hd {
                c[j] = f[j] * c[j] + i[j] * g[j];
                out[j] = c[j];
            }
            tanh_slice(out);
            for ((oj, hj), ob) in out.iter_mut().zip(&mut s.h[..hd]).zip(o) {
                *oj *= ob;
                *hj = *oj;
            }
        }
    }
}

impl BiLstm {
    /// Copies a burn [`crate::lstm::BiLstm`]'s parameters.
    pub fn from_bilstm(b: &crate::lstm::BiLstm) -> BiLstm {
        let layers = b
            .layers
            .iter()
            .map(|l| BiLstmLayer { forward: Lstm::from_fused(&l.forward), backward: Lstm::from_fused(&l.backward) })
            .collect();
        BiLstm { layers }
    }

    /// Input features per frame.
    pub fn d_input(&self) -> usize {
        self.layers.first().map_or(0, |l| l.forward.d_input())
    }

    /// Output features per frame (`2·hidden`).
    pub fn d_output(&self) -> usize {
        self.layers.last().map_or(0, |l| 2 * l.forward.hidden)
    }

    /// The last layer's outputs (`frames × 2·hidden`, frame-major) for `input`
    /// (`frames × d_input`), in `scratch`'s buffers.
    pub fn forward<'s>(&self, input: &[f32], frames: usize, scratch: &'s mut BiLstmScratch) -> &'s [f32] {
        self.run(input, frames, scratch, false)
    }

    /// [`Self::forward`] with the backward direction of each layer on a second (scoped) thread: one
    /// spawn per layer, the same arithmetic, bit-identical results.
    pub fn forward_parallel<'s>(&self, input: &[f32], frames: usize, scratch: &'s mut BiLstmScratch) -> &'s [f32] {
        self.run(input, frames, scratch, true)
    }

    fn run<'s>(&self, input: &[f32], frames: usize, scratch: &'s mut BiLstmScratch, parallel: bool) -> &'s [f32] {
        assert!(
            input.len() >= frames * self.d_input(),
            "BiLstm::forward: input holds {} values, fewer than {frames} frames × {} features",
            input.len(),
            self.d_input()
        );
        let BiLstmScratch { dirs, seq } = scratch;
        let mut current = 0;
        for (k, layer) in self.layers.iter().enumerate() {
            let hd = layer.forward.hidden;
            {
                let [fwd_s, bwd_s] = &mut *dirs;
                let layer_in: &[f32] = if k == 0 { input } else { &seq[current] };
                if parallel {
                    std::thread::scope(|scope| {
                        scope.spawn(|| layer.backward.run_sequence(layer_in, frames, true, bwd_s));
                        layer.forward.run_sequence(layer_in, frames, false, fwd_s);
                    });
                } else {
                    layer.forward.run_sequence(layer_in, frames, false, fwd_s);
                    layer.backward.run_sequence(layer_in, frames, true, bwd_s);
                }
            }
            let next = if k == 0 { 0 } else { 1 - current };
            let out = &mut seq[next];
            grow(out, frames * 2 * hd);
            for t in 0..frames {
                out[t * 2 * hd..t * 2 * hd + hd].copy_from_slice(&dirs[0].out[t * hd..(t + 1) * hd]);
                out[t * 2 * hd + hd..(t + 1) * 2 * hd].copy_from_slice(&dirs[1].out[t * hd..(t + 1) * hd]);
            }
            current = next;
        }
        &seq[current][..frames * self.d_output()]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::backend;
    use crate::lstm::{FusedLstmConfig, LstmState as BurnState};
    use burn::nn::LinearConfig;
    use burn::tensor::{Device, TensorData};

    fn rows_tensor(values: &[f32], cols: usize, device: &Device) -> Tensor<2> {
        Tensor::from_data(TensorData::new(values.to_vec(), [values.len() / cols, cols]), device)
    }

    fn values(t: Tensor<2>) -> Vec<f32> {
        t.into_data().try_into_vec::<f32>().unwrap()
    }

    fn assert_close(a: &[f32], b: &[f32], what: &str) {
        assert_eq!(a.len(), b.len(), "{what}: lengths");
        let worst = a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0f32, f32::max);
        assert!(worst < 1e-5, "{what}: max difference {worst}");
    }

    fn input(rows: usize, cols: usize, phase: f32) -> Vec<f32> {
        (0..rows * cols).map(|i| (i as f32 * 0.71 + phase).sin() * 1.5).collect()
    }

    #[test]
    fn dense_equals_burn_linear() {
        let device = backend::cpu();
        let linear = backend::seeded_module(&device, 11, |d| LinearConfig::new(7, 5).init(d));
        let dense = Dense::from_linear(&linear);
        let mut x = input(3, 7, 0.2);
        x[4] = 0.0; // the skipped-zero path
        let mut y = vec![0.0; 15];
        dense.forward(&x, &mut y, 3);
        assert_close(&y, &values(linear.forward(rows_tensor(&x, 7, &device))), "dense");
        // A nonzero result: the layer is not trivially zero.
        assert!(y.iter().any(|v| v.abs() > 1e-3));
    }

    #[test]
    fn lstm_equals_burn_fused_lstm_over_several_steps_and_rows() {
        let device = backend::cpu();
        let fused = backend::seeded_module(&device, 12, |d| FusedLstmConfig::new(6, 9).init(d));
        let lstm = Lstm::from_fused(&fused);
        let rows = 3;
        let mut state = LstmState::zeros(rows, 9);
        let mut burn_state = BurnState::zeros(rows, 9, &device);
        let mut scratch = LstmScratch::default();
        for t in 0..5 {
            let x = input(rows, 6, t as f32);
            lstm.step(&x, &mut state, rows, &mut scratch);
            burn_state = fused.step(rows_tensor(&x, 6, &device), Some(burn_state));
            assert_close(&state.h, &values(burn_state.h.clone()), &format!("h at step {t}"));
            assert_close(&state.c, &values(burn_state.c.clone()), &format!("c at step {t}"));
        }
        assert!(state.h.iter().any(|v| v.abs() > 1e-2), "the state moved");
    }

    #[test]
    fn steps_reuse_the_scratch_buffers() {
        let device = backend::cpu();
        let fused = backend::seeded_module(&device, 13, |d| FusedLstmConfig::new(4, 8).init(d));
        let lstm = Lstm::from_fused(&fused);
        let mut scratch = LstmScratch::for_rows(&lstm, 2);
        let (xh, z) = (scratch.xh.as_ptr(), scratch.z.as_ptr());
        let mut state = LstmState::zeros(2, 8);
        for t in 0..4 {
            lstm.step(&input(2, 4, t as f32), &mut state, 2, &mut scratch);
        }
        // One row fits in the two-row buffers too.
        let mut one = LstmState::zeros(1, 8);
        lstm.step(&input(1, 4, 0.0), &mut one, 1, &mut scratch);
        assert_eq!((scratch.xh.as_ptr(), scratch.z.as_ptr()), (xh, z), "no buffer was reallocated");
    }

    #[test]
    fn leaky_relu_scales_only_negatives() {
        let mut v = [-2.0f32, 0.0, 3.0];
        leaky_relu(&mut v, 0.01);
        assert_eq!(v, [-0.02, 0.0, 3.0]);
    }

    #[test]
    fn runtime_bilstm_equals_burn_bilstm_and_reuses_its_buffers() {
        use crate::lstm::{stack_time, BiLstmConfig};
        let device = backend::cpu();
        let burn_lstm = backend::seeded_module(&device, 14, |d| BiLstmConfig::new(5, 7).with_num_layers(3).init(d));
        let lstm = BiLstm::from_bilstm(&burn_lstm);
        assert_eq!((lstm.d_input(), lstm.d_output()), (5, 14));
        let frames = 9;
        let mut x = input(frames, 5, 0.4);
        x[7] = 0.0; // the skipped-zero path
                    // burn: one [1, 5] tensor per frame.
        let steps: Vec<Tensor<2>> = (0..frames).map(|t| rows_tensor(&x[t * 5..(t + 1) * 5], 5, &device)).collect();
        let expected: Vec<f32> = stack_time(&burn_lstm.forward_seq(&steps)).into_data().try_into_vec::<f32>().unwrap();
        let mut scratch = BiLstmScratch::default();
        let got = lstm.forward(&x, frames, &mut scratch).to_vec();
        assert_close(&got, &expected, "bilstm");
        assert!(got.iter().any(|v| v.abs() > 1e-2), "the outputs moved");
        let parallel = lstm.forward_parallel(&x, frames, &mut scratch).to_vec();
        assert_eq!(parallel, got, "two threads give the same bits");
        // A shorter sequence afterwards reuses the buffers and equals a fresh run.
        let ptrs =
            |s: &BiLstmScratch| (s.seq[0].as_ptr(), s.seq[1].as_ptr(), s.dirs[0].xz.as_ptr(), s.dirs[1].out.as_ptr());
        let before = ptrs(&scratch);
        let short = lstm.forward(&x[..4 * 5], 4, &mut scratch).to_vec();
        assert_eq!(ptrs(&scratch), before, "no buffer was reallocated");
        assert_eq!(short, lstm.forward(&x[..4 * 5], 4, &mut BiLstmScratch::default()).to_vec());
    }

    #[test]
    fn fast_exp_sigmoid_and_tanh_are_accurate() {
        let (mut worst_exp, mut worst_act) = (0.0f64, 0.0f64);
        for k in -20_000..=20_000 {
            let x = k as f32 * 0.004; // −80 … 80
            let e = f64::from(x).exp();
            worst_exp = worst_exp.max(((f64::from(exp_approx(x)) - e) / e).abs());
            let mut v = [x / 8.0];
            sigmoid_slice(&mut v);
            worst_act = worst_act.max((f64::from(v[0]) - 1.0 / (1.0 + (-f64::from(x) / 8.0).exp())).abs());
            let mut v = [x / 8.0];
            tanh_slice(&mut v);
            worst_act = worst_act.max((f64::from(v[0]) - (f64::from(x) / 8.0).tanh()).abs());
        }
        assert!(worst_exp < 5e-7, "exp relative error {worst_exp}");
        assert!(worst_act < 5e-7, "sigmoid/tanh absolute error {worst_act}");
        // Far outside the clamp: tiny and huge but finite, so σ and tanh saturate cleanly.
        assert_eq!(exp_approx(-1000.0), exp_approx(-87.0));
        assert!(exp_approx(-1000.0) > 0.0 && exp_approx(1000.0).is_finite());
        let mut v = [-1000.0f32, 1000.0];
        tanh_slice(&mut v);
        assert_eq!(v, [-1.0, 1.0]);
    }

    #[test]
    fn portable_and_vectorised_cells_agree() {
        let device = backend::cpu();
        let fused = backend::seeded_module(&device, 15, |d| FusedLstmConfig::new(6, 16).init(d));
        let lstm = Lstm::from_fused(&fused);
        let x = input(11, 6, 0.3);
        let (mut a, mut b) = (DirectionScratch::default(), DirectionScratch::default());
        lstm.run_sequence(&x, 11, true, &mut a);
        lstm.run_sequence_with::<false>(&x, 11, true, &mut b);
        assert_close(&a.out, &b.out, "dispatched vs portable");
        assert!(a.out.iter().any(|v| v.abs() > 1e-2));
    }
}
