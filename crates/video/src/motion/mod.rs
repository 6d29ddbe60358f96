//! Motion (§5.2 of the paper): dense optical flow and the features built on it.
//!
//! - [`farneback`]: dense flow by polynomial expansion, coarse to fine (pure Rust);
//! - [`normalized_magnitude`] (Eq. 9), [`motion_tendency`] (Eq. 10), [`lms_frames`] (Eq. 11):
//!   the dominant direction of each frame and the linear-motion segments that directional
//!   distillation C_d (Eq. 12) acts on;
//! - [`pseudo_images`] (Eq. 13–14) and [`rotate_flow`] (A₁, A₂ of Eq. 17): the inputs of the
//!   motion distance δ(FC, FK) (Eq. 15) behind coherent distillation C_t (Eq. 16–17);
//! - [`analyse_clip`]: all of it for a clip, with the backward flows FC.

mod clip;
mod farneback;
mod grid;
mod poly;
mod pseudo;
mod tendency;
#[cfg(test)]
mod tests;

pub use clip::{analyse_clip, ClipMotion};
pub use farneback::{farneback, FlowParams};
pub use pseudo::{pseudo_images, rotate_flow, threshold, MU0};
pub use tendency::{
    angle_between, lms_frames, motion_tendency, motion_tendency_with_floor, normalized_magnitude, DELTA, LMS_MIN_LEN,
    SIGMA, STATIC_MAX_PX,
};

/// A dense flow field: `uv[y * width + x]` = (u, v), the displacement in pixels of pixel (x, y)
/// (x to the right, y downwards).
#[derive(Clone, Debug, PartialEq)]
pub struct Flow {
    pub width: usize,
    pub height: usize,
    pub uv: Vec<[f32; 2]>,
}

impl Flow {
    /// No motion.
    pub fn zeros(width: usize, height: usize) -> Flow {
        Flow::uniform(width, height, [0.0, 0.0])
    }

    /// The same vector everywhere.
    pub fn uniform(width: usize, height: usize, uv: [f32; 2]) -> Flow {
        Flow { width, height, uv: vec![uv; width * height] }
    }

    /// The vector at (x, y).
    pub fn at(&self, x: usize, y: usize) -> [f32; 2] {
        self.uv[y * self.width + x]
    }

    /// Every vector reversed (the flow of the opposite frame order, to first order).
    pub fn negated(&self) -> Flow {
        Flow { width: self.width, height: self.height, uv: self.uv.iter().map(|v| [-v[0], -v[1]]).collect() }
    }

    /// ‖F_ij‖₂ per pixel; a non-finite vector counts as 0.
    pub fn magnitudes(&self) -> Vec<f32> {
        self.uv
            .iter()
            .map(|v| {
                let m = (v[0] * v[0] + v[1] * v[1]).sqrt();
                if m.is_finite() {
                    m
                } else {
                    0.0
                }
            })
            .collect()
    }

    /// Mean endpoint error against `other` over the pixels at least `margin` px from every
    /// border (`None` if no pixel is left or the sizes differ).
    pub fn mean_endpoint_error(&self, other: &Flow, margin: usize) -> Option<f64> {
        if (self.width, self.height) != (other.width, other.height) {
            return None;
        }
        let (mut sum, mut n) = (0.0f64, 0usize);
        for y in margin..self.height.saturating_sub(margin) {
            for x in margin..self.width.saturating_sub(margin) {
                let (a, b) = (self.at(x, y), other.at(x, y));
                sum += ((a[0] - b[0]) as f64).hypot((a[1] - b[1]) as f64);
                n += 1;
            }
        }
        (n > 0).then(|| sum / n as f64)
    }

    /// The field on a `width`×`height` grid by nearest sampling (vectors unchanged); a clone when
    /// the size already matches, zeros when this flow is empty.
    pub(crate) fn resampled_nearest(&self, width: usize, height: usize) -> Flow {
        if (self.width, self.height) == (width, height) {
            return self.clone();
        }
        if self.width == 0 || self.height == 0 {
            return Flow::zeros(width, height);
        }
        let pick = |i: usize, n: usize, src: usize| ((i * 2 + 1) * src / (2 * n)).min(src - 1);
        let uv = (0..width * height)
            .map(|i| self.at(pick(i % width, width, self.width), pick(i / width, height, self.height)))
            .collect();
        Flow { width, height, uv }
    }
}
