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
        assert!(dim > 0 && dim.is_multiple_of(2), "TtaEmbedding: dim must be even and > 0, got {dim}");
        Self { dim, basis: 10_000.0, max_tta }
    }

    /// Like [`new`](Self::new) but returns an error instead of panicking on a bad `dim` or cap
    /// (for sizes read from files or the command line).
    pub fn try_new(dim: usize, max_tta: f32) -> Result<Self, crate::NnError> {
        if dim == 0 || !dim.is_multiple_of(2) {
            return Err(crate::NnError::Config(format!(
                "TTA embedding size must be even and > 0 (sin/cos pairs), got {dim}"
            )));
        }
        if !(max_tta >= 0.0 && max_tta.is_finite()) {
            return Err(crate::NnError::Config(format!("TTA cap must be finite and >= 0, got {max_tta}")));
        }
        Ok(Self::new(dim, max_tta))
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::backend;

    #[test]
    fn values_follow_the_sin_cos_formula() {
        let tta = TtaEmbedding::new(8, 30.0);
        let z = tta.values(5.0);
        assert_eq!(z.len(), 8);
        for i in 0..4 {
            let angle = 5.0_f64 / 10_000f64.powf(2.0 * i as f64 / 8.0);
            assert!((z[2 * i] as f64 - angle.sin()).abs() < 1e-7, "z[{}]", 2 * i);
            assert!((z[2 * i + 1] as f64 - angle.cos()).abs() < 1e-7, "z[{}]", 2 * i + 1);
        }
        // Hand-checked first pair: sin(5), cos(5).
        assert!((z[0] - (-0.958_924_3)).abs() < 1e-6 && (z[1] - 0.283_662_2).abs() < 1e-6);
        // At arrival every sine is 0 and every cosine 1.
        let at_target = tta.values(0.0);
        assert!(at_target.chunks(2).all(|p| p[0] == 0.0 && p[1] == 1.0));
    }

    #[test]
    fn tta_is_capped() {
        let tta = TtaEmbedding::new(16, 30.0);
        assert_eq!(tta.values(30.0), tta.values(75.0));
        assert_ne!(tta.values(29.0), tta.values(30.0));
    }

    #[test]
    fn tensor_shapes_and_schedule_order() {
        let device = backend::cpu();
        let tta = TtaEmbedding::new(6, 30.0).with_basis(100.0);
        assert_eq!(tta.embed(3.0, &device).dims(), [6]);
        let batch = tta.embed_batch(&[0.0, 1.0, 2.0], &device);
        assert_eq!(batch.dims(), [3, 6]);
        let schedule = tta.schedule(4, &device);
        assert_eq!(schedule.dims(), [4, 6]);
        let rows = schedule.into_data().try_to_vec::<f32>().unwrap();
        assert_eq!(&rows[..6], tta.values(3.0).as_slice());
        assert_eq!(&rows[18..], tta.values(0.0).as_slice());
    }

    #[test]
    #[should_panic(expected = "dim must be even")]
    fn odd_dimension_is_rejected() {
        let _ = TtaEmbedding::new(5, 30.0);
    }

    #[test]
    fn try_new_reports_bad_sizes() {
        let err = TtaEmbedding::try_new(7, 30.0).unwrap_err().to_string();
        assert!(err.contains("even") && err.contains('7'), "{err}");
        assert!(TtaEmbedding::try_new(8, f32::NAN).is_err());
        assert_eq!(TtaEmbedding::try_new(8, 30.0).unwrap(), TtaEmbedding::new(8, 30.0));
    }
}
