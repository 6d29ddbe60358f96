//! Throughput helpers for a `bench` subcommand (speed goals live here, never in unit tests).
//!
//! [`lstm_throughput`] measures the blocks the engines use: a 256-unit [`FusedLstm`](crate::lstm::FusedLstm) stepping
//! one trajectory and a batch of trajectories (inference, no autodiff), and a stacked
//! [`BiLstm`](crate::lstm::BiLstm) forward + backward + Adam step (training);
//! [`lstm_runtime_throughput`] the same LSTM as plain-Rust [`runtime`] layers. [`table`] lays the rows out.

use burn::module::Module;
use burn::optim::{AdamConfig, GradientsParams};
use burn::tensor::{Device, Distribution, Tensor};

use crate::backend;
use crate::lstm::{BiLstmConfig, FusedLstmConfig, LstmState};
use crate::runtime::{self, Dense, Lstm, LstmScratch};
use inbetween_io::report::{num, Table};

/// One measured quantity.
#[derive(Debug, Clone, PartialEq)]
pub struct BenchRow {
    /// What was measured.
    pub name: String,
    /// The measured value (see `unit`).
    pub value: f64,
    /// Unit of `value`, e.g. "frames/s" or "s/step".
    pub unit: String,
    /// Sizes and repetitions behind the number.
    pub detail: String,
}

pub use inbetween_io::report::seconds_per_call;

/// Sizes for [`lstm_throughput`].
#[derive(Debug, Clone, PartialEq)]
pub struct LstmBenchOptions {
    /// Hidden units of the unidirectional LSTM (256 in the camera generator).
    pub hidden: usize,
    /// Input features per frame.
    pub d_input: usize,
    /// Frames per trajectory in the inference runs.
    pub frames: usize,
    /// Trajectories in the batched inference run.
    pub batch: usize,
    /// BiLSTM hidden units per direction.
    pub bi_hidden: usize,
    /// BiLSTM stacked layers.
    pub bi_layers: usize,
    /// BiLSTM training batch.
    pub bi_batch: usize,
    /// BiLSTM sequence length.
    pub bi_frames: usize,
    /// Measured repetitions of each case (after one warm-up).
    pub repeats: usize,
}

impl Default for LstmBenchOptions {
    fn default() -> Self {
        Self {
            hidden: 256,
            d_input: 64,
            frames: 900,
            batch: 16,
            bi_hidden: 128,
            bi_layers: 2,
            bi_batch: 32,
            bi_frames: 200,
            repeats: 3,
        }
    }
}

impl LstmBenchOptions {
    /// Small sizes for a quick check that the bench runs (not meaningful numbers).
    pub fn smoke() -> Self {
        Self {
            hidden: 16,
            d_input: 4,
            frames: 10,
            batch: 2,
            bi_hidden: 8,
            bi_layers: 1,
            bi_batch: 2,
            bi_frames: 6,
            repeats: 1,
        }
    }
}

fn random_frames(frames: usize, batch: usize, features: usize, device: &Device) -> Vec<Tensor<2>> {
    (0..frames).map(|_| Tensor::random([batch, features], Distribution::Normal(0.0, 1.0), device)).collect()
}

/// Frames per second of a `hidden`-unit FusedLstm stepping `batch` trajectories of `frames`
/// frames (inference device, inputs generated up front).
fn lstm_inference_fps(opts: &LstmBenchOptions, batch: usize, device: &Device) -> f64 {
    let lstm = backend::seeded_module(device, 0, |d| FusedLstmConfig::new(opts.d_input, opts.hidden).init(d));
    let xs = backend::seeded(device, 1, || random_frames(opts.frames, batch, opts.d_input, device));
    let secs = seconds_per_call(1, opts.repeats, || {
        let mut state: Option<LstmState> = None;
        for x in &xs {
            state = Some(lstm.step(x.clone(), state));
        }
        // Reading the result back makes sure all the work ran.
        let _ = state.map(|s| s.h.sum().into_scalar::<f32>());
    });
    (opts.frames * batch) as f64 / secs
}

/// Seconds per BiLSTM training step: forward over the sequence, mean-square loss, backward,
/// Adam update.
fn bilstm_train_step_seconds(opts: &LstmBenchOptions, device: &Device) -> f64 {
    let config = BiLstmConfig::new(opts.d_input, opts.bi_hidden).with_num_layers(opts.bi_layers);
    let model = backend::seeded_module(device, 0, |d| config.init(d));
    let xs = backend::seeded(device, 1, || random_frames(opts.bi_frames, opts.bi_batch, opts.d_input, device));
    let mut model = Some(model);
    let mut optim = AdamConfig::new().init();
    seconds_per_call(1, opts.repeats, || {
        let current = model.take().expect("model is put back after every step");
        let outputs = current.forward_seq(&xs);
        let loss = Tensor::cat(outputs, 1).square().mean();
        let grads = GradientsParams::from_grads(loss.backward(), &current);
        let updated = optim.step(1e-3, current, grads);
        // Read one parameter back so the update has run.
        let _ = updated.layers[0].forward.gates.weight.val().sum().into_scalar::<f32>();
        model = Some(updated);
    })
}

/// Measure the LSTM blocks on the flex CPU backend; see the module docs for the cases.
pub fn lstm_throughput(opts: &LstmBenchOptions) -> Vec<BenchRow> {
    let infer = backend::cpu();
    let single = lstm_inference_fps(opts, 1, &infer);
    let batched = lstm_inference_fps(opts, opts.batch, &infer);
    let train = backend::cpu_autodiff();
    let bi = bilstm_train_step_seconds(opts, &train);
    let model = FusedLstmConfig::new(opts.d_input, opts.hidden).init(&infer);
    vec![
        BenchRow {
            name: format!("FusedLstm {} units, 1 trajectory", opts.hidden),
            value: single,
            unit: "frames/s".into(),
            detail: format!("{} frames, input {}, {} params", opts.frames, opts.d_input, model.num_params()),
        },
        BenchRow {
            name: format!("FusedLstm {} units, {} trajectories", opts.hidden, opts.batch),
            value: batched,
            unit: "frames/s".into(),
            detail: format!("{} frames each, counted over all trajectories", opts.frames),
        },
        BenchRow {
            name: format!("BiLstm {}×{} fwd+bwd+Adam", opts.bi_layers, opts.bi_hidden),
            value: bi,
            unit: "s/step".into(),
            detail: format!("batch {} × {} frames, input {}", opts.bi_batch, opts.bi_frames, opts.d_input),
        },
    ]
}

/// Frames per second of a plain-Rust `hidden`-unit [`Lstm`] (input `d_input`) stepping `batch`
/// trajectories in lockstep, with a [`Dense`] `hidden → hidden` layer after it (a generator step's
/// shape); the row for a `bench` table. Weights come from a seeded burn cell.
pub fn lstm_runtime_throughput(hidden: usize, d_input: usize, batch: usize, frames: usize, repeats: usize) -> BenchRow {
    let device = crate::backend::cpu();
    let fused =
        crate::backend::seeded_module(&device, 0, |d| crate::lstm::FusedLstmConfig::new(d_input, hidden).init(d));
    let dense = crate::backend::seeded_module(&device, 1, |d| burn::nn::LinearConfig::new(hidden, hidden).init(d));
    let (lstm, dense) = (Lstm::from_fused(&fused), Dense::from_linear(&dense));
    let x: Vec<f32> = (0..batch * d_input).map(|i| ((i as f32) * 0.37).sin()).collect();
    let mut state = runtime::LstmState::zeros(batch, hidden);
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

/// The rows as a report table (`.to_text()` for the terminal).
pub fn table(rows: &[BenchRow]) -> Table {
    let mut t = Table::new("nn_bench", "nn blocks: throughput", &["case", "value", "unit", "detail"]);
    for row in rows {
        t.row([row.name.clone(), num(row.value, 3), row.unit.clone(), row.detail.clone()]);
    }
    t
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn throughput_row_is_measured() {
        let row = lstm_runtime_throughput(8, 4, 2, 5, 1);
        assert!(row.value.is_finite() && row.value > 0.0, "{row:?}");
        assert_eq!(row.unit, "frames/s");
    }

    #[test]
    fn bench_runs_on_tiny_sizes_and_formats_a_table() {
        let rows = lstm_throughput(&LstmBenchOptions::smoke());
        assert_eq!(rows.len(), 3);
        assert!(rows.iter().all(|r| r.value.is_finite() && r.value > 0.0));
        let table = table(&rows).to_text();
        assert_eq!(table.lines().count(), 5, "{table}");
        assert!(table.contains("frames/s") && table.contains("s/step"));
    }
}
