//! RSFNet (§4.1, Fig. 2): one R-Encoder, i.e. the Coarse Feature Extractor (CFE) followed by
//! Recursive Feature Fining (RFF, Eq. 1–3), pooling and a dense layer to the latent vector. The
//! paper's "triplet of R-Encoders sharing their weights" is this one network applied to the anchor,
//! the positive and the negative (in one batch, see [`super::train`]).
//!
//! # Differences from the paper
//! - **CFE from scratch.** The paper takes the first four blocks of an ImageNet VGG-19. Those weights
//!   cannot be had offline here (no package registry ships them), so the CFE is four VGG-like blocks
//!   (`convs_per_block` × (Conv3×3 + ReLU), then 2×2 max pooling into the next block), much narrower
//!   than VGG's 64–512 channels, trained from scratch on the clip itself together with the rest of
//!   the network. `X_i` is block `i`'s output before its pooling, so `X_1 … X_4` have sides
//!   `S, S/2, S/4, S/8` for an input of side `S`.
//! - **C1R (Eq. 3)** reads `φ(F_c) = C¹(F_c) + BN(C³(BN(C¹(F_c))))` with one shared point-wise
//!   convolution `C¹` (both terms use the same `C¹(F_c)`): a residual block on the 1×1 projection,
//!   without a ReLU, as the paper describes. `C¹` maps `F_{i−1} ⊗ X_i` to the channels of `X_i`.
//! - **NCM (Eq. 2)** `Ψ = P(C³(Norm(·)))` uses batch normalisation as its `Norm` (the paper leaves
//!   the normaliser open) and 2×2 max pooling as `P`, so `F_i` has half the side of `X_i` and
//!   matches `X_{i+1}` for the concatenation of Eq. 1.
//! - **Pooling.** The paper does not say how `F_4` becomes a vector. Global average pooling would
//!   discard *where* things are, which is most of what tells frames of one clip apart (a pendulum on
//!   the left or on the right), so `F_4` is average-pooled to a `pool_grid × pool_grid` map
//!   (`pool_grid = 1` is global pooling), flattened and fed to the dense layer.
//! - **"w/o RSFNet"** (Table 3): `use_rff = false` skips RFF; `X_4` is pooled the same way and fed
//!   to the dense layer.

use burn::module::Module;
use burn::nn::conv::{Conv2d, Conv2dConfig};
use burn::nn::{BatchNorm, BatchNormConfig, Linear, LinearConfig, PaddingConfig2d};
use burn::tensor::activation::relu;
use burn::tensor::module::{adaptive_avg_pool2d, max_pool2d};
use burn::tensor::ops::MaxPoolOptions;
use burn::tensor::{Device, Tensor};
use serde::{Deserialize, Serialize};

use crate::VideoError;

/// Architecture of an [`RsfNet`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RsfConfig {
    /// Frames are resized (area average) to `input_side × input_side` RGB in [0, 1]. A multiple of 16.
    pub input_side: u32,
    /// Channels of the four CFE blocks (`X_1 … X_4`); RFF keeps the channels of `X_i` in `F_i`.
    pub channels: [usize; 4],
    /// Conv3×3 + ReLU layers per CFE block (VGG-19 has 2, 2, 4, 4). The default 1 halves the
    /// training time of 2 on 64×64 inputs (0.36 against 0.67 s per step of 8 triplets, measured on
    /// the shared 2-core machine) for the same triplet agreement.
    pub convs_per_block: usize,
    /// Side of the pooled map fed to the dense layer (1 = global average pooling).
    pub pool_grid: usize,
    /// Dimensions of the latent vector (the node feature `v_i` of the graph).
    pub latent: usize,
    /// With RFF (Eq. 1–3); `false` is the "w/o RSFNet" ablation: pooled CFE features only.
    pub use_rff: bool,
}

impl Default for RsfConfig {
    fn default() -> Self {
        RsfConfig {
            input_side: 32,
            channels: [8, 16, 32, 32],
            convs_per_block: 1,
            pool_grid: 2,
            latent: 32,
            use_rff: true,
        }
    }
}

impl RsfConfig {
    /// A small network for tests and tiny inputs (32×32).
    pub fn tiny() -> RsfConfig {
        RsfConfig {
            input_side: 32,
            channels: [4, 8, 8, 16],
            convs_per_block: 1,
            pool_grid: 2,
            latent: 16,
            use_rff: true,
        }
    }

    /// Checks the sizes; the error names the field.
    pub fn validate(&self) -> Result<(), VideoError> {
        let bad = |m: String| Err(VideoError::Invalid(format!("RSFNet config: {m}")));
        if self.input_side < 16 || !self.input_side.is_multiple_of(16) {
            return bad(format!("input_side must be a positive multiple of 16, got {}", self.input_side));
        }
        if self.channels.contains(&0) || self.convs_per_block == 0 || self.latent == 0 || self.pool_grid == 0 {
            return bad(format!(
                "channels {:?}, convs_per_block {}, latent {} and pool_grid {} must all be at least 1",
                self.channels, self.convs_per_block, self.latent, self.pool_grid
            ));
        }
        let last_side = self.last_side();
        if self.pool_grid > last_side {
            return bad(format!(
                "pool_grid {} is larger than the last feature map ({last_side}×{last_side})",
                self.pool_grid
            ));
        }
        Ok(())
    }

    /// Side of the map that is pooled: `F_4` (side S/16) with RFF, `X_4` (S/8) without.
    pub fn last_side(&self) -> usize {
        let s = self.input_side as usize;
        if self.use_rff {
            s / 16
        } else {
            s / 8
        }
    }

    /// Builds the network on `device` (call inside [`inbetween_nn::backend::seeded_module`] for
    /// reproducible weights). Call [`validate`](Self::validate) first.
    pub fn init(&self, device: &Device) -> RsfNet {
        let mut c_in = 3;
        let cfe = self
            .channels
            .iter()
            .map(|&c| {
                let block = CfeBlock::new(c_in, c, self.convs_per_block, device);
                c_in = c;
                block
            })
            .collect();
        let (ncm, c1r) = if self.use_rff {
            let ncm = self.channels.iter().map(|&c| Ncm::new(c, device)).collect();
            let c1r =
                (1..4).map(|i| C1r::new(self.channels[i - 1] + self.channels[i], self.channels[i], device)).collect();
            (ncm, c1r)
        } else {
            (Vec::new(), Vec::new())
        };
        let flat = self.channels[3] * self.pool_grid * self.pool_grid;
        RsfNet { cfe, ncm, c1r, dense: LinearConfig::new(flat, self.latent).init(device), pool_grid: self.pool_grid }
    }
}

fn conv3(c_in: usize, c_out: usize, device: &Device) -> Conv2d {
    Conv2dConfig::new([c_in, c_out], [3, 3]).with_padding(PaddingConfig2d::Explicit(1, 1, 1, 1)).init(device)
}

fn conv1(c_in: usize, c_out: usize, device: &Device) -> Conv2d {
    Conv2dConfig::new([c_in, c_out], [1, 1]).init(device)
}

/// 2×2 max pooling, stride 2 (the `P` of Eq. 2 and VGG's pooling).
fn pool2(x: Tensor<4>) -> Tensor<4> {
    max_pool2d(x, MaxPoolOptions::new([2, 2]).with_stride([2, 2]))
}

/// One VGG-like CFE block: `n` × (Conv3×3 + ReLU). Its output is `X_i`.
#[derive(Module, Debug)]
pub struct CfeBlock {
    pub convs: Vec<Conv2d>,
}

impl CfeBlock {
    fn new(c_in: usize, c_out: usize, n: usize, device: &Device) -> CfeBlock {
        CfeBlock { convs: (0..n).map(|k| conv3(if k == 0 { c_in } else { c_out }, c_out, device)).collect() }
    }

    pub fn forward(&self, mut x: Tensor<4>) -> Tensor<4> {
        for conv in &self.convs {
            x = relu(conv.forward(x));
        }
        x
    }
}

/// NCM block, Eq. 2: `Ψ(F) = P(C³(Norm(F)))`.
#[derive(Module, Debug)]
pub struct Ncm {
    pub norm: BatchNorm,
    pub conv: Conv2d,
}

impl Ncm {
    fn new(c: usize, device: &Device) -> Ncm {
        Ncm { norm: BatchNormConfig::new(c).init(device), conv: conv3(c, c, device) }
    }

    pub fn forward(&self, x: Tensor<4>) -> Tensor<4> {
        pool2(self.conv.forward(self.norm.forward(x)))
    }
}

/// C1R block, Eq. 3: `φ(F_c) = C¹(F_c) + BN(C³(BN(C¹(F_c))))`.
#[derive(Module, Debug)]
pub struct C1r {
    pub point: Conv2d,
    pub bn_in: BatchNorm,
    pub conv: Conv2d,
    pub bn_out: BatchNorm,
}

impl C1r {
    fn new(c_in: usize, c_out: usize, device: &Device) -> C1r {
        C1r {
            point: conv1(c_in, c_out, device),
            bn_in: BatchNormConfig::new(c_out).init(device),
            conv: conv3(c_out, c_out, device),
            bn_out: BatchNormConfig::new(c_out).init(device),
        }
    }

    pub fn forward(&self, fc: Tensor<4>) -> Tensor<4> {
        let y = self.point.forward(fc);
        let residual = self.bn_out.forward(self.conv.forward(self.bn_in.forward(y.clone())));
        y + residual
    }
}

/// One R-Encoder: CFE, RFF (when built with `use_rff`), pooling, dense. Works on any device.
#[derive(Module, Debug)]
pub struct RsfNet {
    /// The four CFE blocks.
    pub cfe: Vec<CfeBlock>,
    /// NCM blocks Ψ for `F_1 … F_4` (empty without RFF).
    pub ncm: Vec<Ncm>,
    /// C1R blocks φ for `F_2 … F_4` (empty without RFF).
    pub c1r: Vec<C1r>,
    /// `channels[3] · pool_grid² → latent`.
    pub dense: Linear,
    /// Side of the pooled map.
    pub pool_grid: usize,
}

impl RsfNet {
    /// The CFE feature maps `X_1 … X_4` of a `[batch, 3, S, S]` input.
    pub fn coarse_features(&self, x: Tensor<4>) -> Vec<Tensor<4>> {
        let mut maps: Vec<Tensor<4>> = Vec::with_capacity(4);
        for (i, block) in self.cfe.iter().enumerate() {
            let input = if i == 0 { x.clone() } else { pool2(maps[i - 1].clone()) };
            maps.push(block.forward(input));
        }
        maps
    }

    /// RFF, Eq. 1: `F_1 = Ψ(X_1)`, `F_i = Ψ(φ(F_{i−1} ⊗ X_i))`; returns `F_4`.
    pub fn fine_features(&self, xs: Vec<Tensor<4>>) -> Tensor<4> {
        let mut xs = xs.into_iter();
        let mut f = self.ncm[0].forward(xs.next().expect("four CFE maps"));
        for (i, x) in xs.enumerate() {
            let fc = Tensor::cat(vec![f, x], 1);
            f = self.ncm[i + 1].forward(self.c1r[i].forward(fc));
        }
        f
    }

    /// Latent vectors `[batch, latent]` of a `[batch, 3, S, S]` input (RGB in [0, 1]).
    pub fn forward(&self, x: Tensor<4>) -> Tensor<2> {
        let xs = self.coarse_features(x);
        let last =
            if self.ncm.is_empty() { xs.into_iter().last().expect("four CFE maps") } else { self.fine_features(xs) };
        let pooled = adaptive_avg_pool2d(last, [self.pool_grid, self.pool_grid]);
        self.dense.forward(pooled.flatten(1, 3))
    }
}
