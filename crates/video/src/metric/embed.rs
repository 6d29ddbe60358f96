//! Inference with a trained RSFNet: latent vectors of frames and of the pseudo-images of Eq. 14–15,
//! on the plain (non-autodiff) CPU device, in batches.

use burn::module::Module;
use burn::tensor::Device;
use image::RgbImage;
use inbetween_nn::backend;
use rayon::prelude::*;

use super::input::{batch_tensor, frame_planes, resize_planes, Planes};
use super::model::{RsfConfig, RsfNet};
use crate::VideoError;

/// Images per forward pass; the chunks of a call run in parallel (rayon). Small chunks cost no
/// more per image on the CPU backend and keep both cores busy.
pub const EMBED_BATCH: usize = 8;

/// A trained (or, for the "w/o L_d" ablation, untrained) RSFNet ready for inference.
#[derive(Debug, Clone)]
pub struct Embedder {
    /// The network, in inference mode (batch norms use their running statistics).
    pub net: RsfNet,
    /// Its architecture.
    pub config: RsfConfig,
    device: Device,
}

impl Embedder {
    /// Wraps a network, moving it to the plain CPU device in inference mode.
    pub fn new(net: RsfNet, config: RsfConfig) -> Embedder {
        let device = backend::cpu();
        Embedder { net: net.valid().to_device(&device), config, device }
    }

    /// Side of the square images the network reads.
    pub fn side(&self) -> usize {
        self.config.input_side as usize
    }

    /// Latent vectors of resized images (see [`super::input`]).
    pub fn embed_planes(&self, planes: &[Planes]) -> Vec<Vec<f32>> {
        let side = self.side();
        let latent = self.config.latent;
        let indices: Vec<usize> = (0..planes.len()).collect();
        // Fixed chunks, run in parallel: each chunk's result depends only on its images, so the
        // output is the same on any number of threads.
        let chunks: Vec<Vec<Vec<f32>>> = indices
            .par_chunks(EMBED_BATCH)
            .map(|chunk| {
                let x = batch_tensor(planes, chunk, side, &self.device);
                let values = self.net.forward(x).into_data().try_to_vec::<f32>().expect("f32 latents");
                values.chunks_exact(latent).map(<[f32]>::to_vec).collect()
            })
            .collect();
        chunks.into_iter().flatten().collect()
    }

    /// Eq. 7's `R(x_i)` for every frame: one latent vector per frame.
    pub fn embed(&self, images: &[RgbImage]) -> Vec<Vec<f32>> {
        let side = self.side();
        let planes: Vec<Planes> = images.iter().map(|f| frame_planes(f, side)).collect();
        self.embed_planes(&planes)
    }

    /// Latent vectors of the float pseudo-images of Eq. 14–15 (each `w × h × 3`, channels-last,
    /// values in [0, 1]), used for the motion distance δ of Eq. 15. An image of the wrong length is
    /// an error naming it.
    pub fn embed_pseudo(&self, imgs: &[Vec<f32>], w: usize, h: usize) -> Result<Vec<Vec<f32>>, VideoError> {
        if let Some((i, img)) = imgs.iter().enumerate().find(|(_, img)| img.len() != w * h * 3) {
            return Err(VideoError::Invalid(format!(
                "pseudo-image {i} has {} values, expected {w}×{h}×3 = {}",
                img.len(),
                w * h * 3
            )));
        }
        let side = self.side();
        let planes: Vec<Planes> = imgs.par_iter().map(|img| resize_planes(img, w, h, side)).collect();
        Ok(self.embed_planes(&planes))
    }
}
