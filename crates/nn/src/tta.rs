//! Time-to-arrival (TTA) embedding of Harvey et al. 2020, "Robust Motion In-betweening"
//! (section "Time-to-arrival embeddings").
//!
//! A transformer-style sinusoidal positional encoding evaluated at the number of frames left
//! before the target keyframe, added to (or concatenated with) the recurrent generator's
//! latent codes so one model handles any transition length:
//! ```text
//! z_tta,2i   = sin(tta / basis^(2i/d))
//! z_tta,2i+1 = cos(tta / basis^(2i/d))
//! ```
//! with `d` the embedding size and `basis = 10000`. `tta` is clamped at `max_tta`, so beyond it
//! the embedding stays constant (the paper caps it so far-away targets look alike).

use burn::tensor::{Device, Tensor, TensorData};

/// Sinusoidal time-to-arrival embedding.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TtaEmbedding {
    /// Embedding size `d` (must be even).
    pub dim: usize,
    /// Frequency basis (10000 in the paper).
    pub basis: f32,
    /// Frames-to-arrival above this value embed like `max_tta`.
    pub max_tta: f32,
}

impl TtaEmbedding {
    /// Embedding of size `dim` with the paper's basis 10000 and the given cap.
    ///
    /// # Panics
    /// If `dim` is odd or zero: sin/cos pairs need an even size.
    pub fn new(dim: usize, max_tta: f32) -> Self {
        assert!(
            dim > 0 && dim % 2 == 0,
            "TtaEmbedding: dim must be even and > 0, got {dim}"
        );
        Self {
            dim,
            basis: 10_000.0,
            max_tta,
        }
    }

    /// The same embedding with another frequency basis.
    pub fn with_basis(mut self, basis: f32) -> Self {
        self.basis = basis;
        self
    }

    /// Embedding values for one `tta`, computed on the CPU in f64 then rounded to f32.
    pub fn values(&self, tta: f32) -> Vec<f32> {
        let t = f64::from(tta.min(self.max_tta));
        let d = self.dim as f64;
        (0..self.dim / 2)
            .flat_map(|i| {
                let angle = t / f64::from(self.basis).powf(2.0 * i as f64 / d);
                [angle.sin() as f32, angle.cos() as f32]
            })
            .collect()
    }

    /// `[dim]` embedding of one time-to-arrival.
    pub fn embed(&self, tta: f32, device: &Device) -> Tensor<1> {
        Tensor::from_data(TensorData::new(self.values(tta), [self.dim]), device)
    }

    /// `[ttas.len(), dim]` embeddings, one row per batch element (e.g. trajectories of
    /// different lengths).
    pub fn embed_batch(&self, ttas: &[f32], device: &Device) -> Tensor<2> {
        let values: Vec<f32> = ttas.iter().flat_map(|&t| self.values(t)).collect();
        Tensor::from_data(TensorData::new(values, [ttas.len(), self.dim]), device)
    }

    /// `[frames, dim]` table for tta = frames−1, …, 1, 0: row `t` is the embedding at step `t`
    /// of a transition of `frames` steps that arrives on its last row.
    pub fn schedule(&self, frames: usize, device: &Device) -> Tensor<2> {
        let ttas: Vec<f32> = (0..frames).rev().map(|t| t as f32).collect();
        self.embed_batch(&ttas, device)
    }
}
