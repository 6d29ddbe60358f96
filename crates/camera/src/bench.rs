//! The benchmark of the issue: Table 1 (hidden-state initialisation), Table 2 (SD / TD / KD under
//! keyframe displacement), the §6.3 spline comparison, the style-space PCA (Fig. 4) and generation
//! speed. Everything runs on a held-out seeded evaluation set (a seed the training never uses).
//!
//! Protocols (in downsampled steps of 5 frames; errors are ‖Δx^c‖₂ over the 6 Toric values):
//! - **Table 1**: a 45-step window per sequence: 5 ground-truth steps of context, then 40 generated
//!   steps (200 frames) to a keyframe on the last one; z from the extractor on the 60 steps from
//!   the window's start. The hidden state starts at zero, as N(0, 1) noise, warm-started (zero, then
//!   the generator reads the 5 ground-truth steps) or mapped by H (Eq. 6). Error = mean over the
//!   generated steps. The paper trains a separate network for the warm start; we reuse ours. The
//!   `lerp` column is the same error for the straight Toric line from the start to the key.
//! - **Table 2**: 60-step segments with keys at both ends; the end key's θ is displaced by δ
//!   (random sign, kept inside the valid arc). *Ours*: generate with z and the displaced key
//!   (KD = miss at that key), correct onto it (Eq. 9), re-extract z_r, regenerate with z_r and the
//!   true keys: TD = mean error to the ground truth, SD (Eq. 8) = S(Z_r, Z)/S(Z, Z) per behaviour.
//!   *Only style*: generate with the true keys, then bend onto the displaced key by Eq. 9 alone.
//!   *Toric interpolation*: straight lines in Toric space between the keys (no network).
//! - **§6.3**: our track with 3 keys (start, middle, end) vs a Catmull-Rom spline through n evenly
//!   spaced ground-truth keys: the smallest n whose spline error is at most ours.

mod protocol;
mod report;
mod tables;

use protocol::*;
pub use protocol::{pca2, BenchConfig};
pub use report::BenchReport;
pub use tables::{RailsRow, Speed, Table1Row, Table2Row, PAPER_TABLE1, PAPER_TABLE1_AVERAGE, PAPER_TABLE2};

use crate::dataset::Behaviour;
use crate::infer::FastModel;
use crate::model::STYLE_STEPS;
use crate::toric::Lens;
use crate::CameraError;
use inbetween_io::report::{BenchOptions, Report};
use inbetween_io::Progress;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

/// The camera bench's own options (beside [`BenchOptions`]).
#[derive(Clone, Debug, Default)]
pub struct CameraBench {
    /// Weights to bench (None: the committed weights).
    pub weights: Option<std::path::PathBuf>,
}

/// `inbetween camera bench`: the weights, then [`measure`] with [`BenchConfig::quick`] or
/// [`BenchConfig::full`] (`seed` replacing the configuration's), then the report with its charts.
pub fn run(opts: &BenchOptions<CameraBench>) -> Result<Report, CameraError> {
    let loaded = match &opts.engine.weights {
        Some(path) => crate::weights::load(path).map_err(|e| (format!("camera weights {}", path.display()), e)),
        None => crate::weights::committed().map_err(|e| ("the committed camera weights".to_string(), e)),
    };
    let model = loaded.map_err(|(what, e)| CameraError::Request(format!("loading {what}: {e}")))?.model;
    let cfg = if opts.quick { BenchConfig::quick() } else { BenchConfig::full() };
    let cfg = BenchConfig { seed: opts.seed.unwrap_or(cfg.seed), ..cfg };
    let results = measure(&model, &cfg, &opts.progress);
    opts.progress.phase(1, "charts");
    results.report()
}

/// Runs the whole benchmark, advancing `progress` through its phases (style codes, Table 1,
/// Table 2, §6.3, speed); the caller finishes the bar.
pub fn measure(model: &FastModel, cfg: &BenchConfig, progress: &Progress) -> BenchReport {
    let lens = Lens::default();
    let seqs = eval_sequences(cfg.seed, cfg.scenes);
    let mut rng = ChaCha8Rng::seed_from_u64(cfg.seed);
    progress.phase(2 * seqs.len() as u64, "style codes");
    let styles: Vec<(Behaviour, bool, Vec<f32>)> = seqs
        .iter()
        .map(|s| {
            progress.inc(1);
            (s.behaviour, s.main_is_a, style_of(model, &s.chars[..STYLE_STEPS], &s.cams[..STYLE_STEPS]))
        })
        .collect();
    let style_spread = style_spread(model, &seqs, &styles, &mut ChaCha8Rng::seed_from_u64(cfg.seed ^ 0x51), progress);
    progress.phase((seqs.len() * cfg.windows_per_sequence) as u64, "Table 1");
    let table1 = table1(model, &seqs, cfg, &mut rng, progress);
    progress.phase((seqs.len() * cfg.displacements.len()) as u64, "Table 2");
    let table2 = table2(model, &seqs, cfg, &lens, &mut rng, progress);
    progress.phase(seqs.len() as u64, "§6.3 rails");
    let rails = rails(model, &seqs, cfg, &mut rng, progress);
    progress.phase(1, "speed");
    let speed = speed(model, cfg.speed_seconds);
    progress.inc(1);
    BenchReport { config: cfg.clone(), sequences: seqs.len(), table1, table2, rails, speed, style_spread, styles }
}

#[cfg(test)]
mod tests;
