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

use crate::bench::{seconds_per_call, BenchRow};
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
                let (i, f, o, g) = (sigmoid(zr[k]), sigmoid(zr[hd + k]), sigmoid(zr[2 * hd + k]), zr[3 * hd + k].tanh());
                let c = f * state.c[r * hd + k] + i * g;
                state.c[r * hd + k] = c;
                state.h[r * hd + k] = o * c.tanh();
            }
        }
    }
}

/// Frames per second of a plain-Rust `hidden`-unit [`Lstm`] (input `d_input`) stepping `batch`
/// trajectories in lockstep, with a [`Dense`] `hidden → hidden` layer after it (a generator step's
/// shape); the row for a `bench` table. Weights come from a seeded burn cell.
pub fn lstm_runtime_throughput(hidden: usize, d_input: usize, batch: usize, frames: usize, repeats: usize) -> BenchRow {
    let device = crate::backend::cpu();
    let fused = crate::backend::seeded_module(&device, 0, |d| crate::lstm::FusedLstmConfig::new(d_input, hidden).init(d));
    let dense = crate::backend::seeded_module(&device, 1, |d| burn::nn::LinearConfig::new(hidden, hidden).init(d));
    let (lstm, dense) = (Lstm::from_fused(&fused), Dense::from_linear(&dense));
    let x: Vec<f32> = (0..batch * d_input).map(|i| ((i as f32) * 0.37).sin()).collect();
    let mut state = LstmState::zeros(batch, hidden);
    let mut scratch = LstmScratch::for_rows(&lstm, batch);
    let mut y = vec![0.0; batch * hidden];
    let secs = seconds_per_call(1, repeats, || {
        for _ in 0..frames {
            lstm.step(&x, &mut state, batch, &mut scratch);
            dense.forward(&state.h, &mut y, batch);
        }
    });
    BenchRow {
        name: format!("runtime Lstm {hidden} units + Dense, {batch} trajectories"),
        value: (frames * batch) as f64 / secs.max(1e-12),
        unit: "frames/s".into(),
        detail: format!("{frames} frames each, input {d_input}, plain Rust, one thread, no allocation per step"),
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
    fn throughput_row_is_measured() {
        let row = lstm_runtime_throughput(8, 4, 2, 5, 1);
        assert!(row.value.is_finite() && row.value > 0.0, "{row:?}");
        assert_eq!(row.unit, "frames/s");
    }
}
