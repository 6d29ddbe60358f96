//! Dense optical flow by Farnebäck's polynomial expansion, coarse to fine.
//!
//! The paper (§5.2.1) computes the flows Y = {F_{a→a+1}} with an off-the-shelf estimator [24]; any
//! dense flow will do. Farnebäck's method is small, has no learned weights, and is accurate to a
//! fraction of a pixel on textured frames, which is all that Eq. 9–14 need.
//!
//! The model: if the next frame is the previous one moved by d, f₂(x) = f₁(x − d), the local
//! quadratics agree in A and differ in b: b₂ = b₁ − 2A·d, so d = −½A⁻¹(b₂ − b₁). With a prior
//! displacement d̃ (from the coarser level or the last iteration) the next frame's expansion is
//! read at x + d̃ and
//!   A = (A₁(x) + A₂(x + d̃)) / 2,  Δb = −½(b₂(x + d̃) − b₁(x)) + A·d̃,  A·d = Δb.
//! One pixel's equation is under-determined (aperture problem), so d minimises
//! Σ w·‖A·d − Δb‖² over a Gaussian window w: d = (Σ w AᵀA)⁻¹ Σ w AᵀΔb. A small Tikhonov term
//! λ‖d − d̃‖² keeps the prior where the window has no texture (uniform regions), instead of
//! pulling the flow to zero there; at a fixed point (d = d̃) it has no effect, so it adds no bias.

use super::grid::{blur, from_gray, half, resample, Grid};
use super::poly::{expand, Expansion};
use super::Flow;
use image::GrayImage;

/// Settings of [`farneback`]. The defaults suit frames of ≤ 160 px width (the clip flows).
#[derive(Clone, Debug, PartialEq)]
pub struct FlowParams {
    /// Pyramid levels including the full-resolution one (each halves the size). Displacements up
    /// to about 2^(levels−1) · 1.5 px are reachable. Capped so the coarsest side stays ≥
    /// `min_level_side`.
    pub levels: usize,
    /// Side of the Gaussian averaging window (px) over which the displacement is assumed constant.
    pub window: usize,
    /// Refinements per pyramid level.
    pub iterations: usize,
    /// Neighbourhood side of the polynomial expansion (5 or 7).
    pub poly_n: usize,
    /// Standard deviation of the expansion's Gaussian applicability (1.1 for 5, 1.5 for 7).
    pub poly_sigma: f32,
    /// Tikhonov weight λ pulling d towards the prior where the window is textureless
    /// (intensities are in [0, 1]).
    pub regularization: f32,
    /// Smallest side (px) a pyramid level may have.
    pub min_level_side: usize,
}

impl Default for FlowParams {
    fn default() -> Self {
        FlowParams {
            levels: 4,
            window: 13,
            iterations: 3,
            poly_n: 5,
            poly_sigma: 1.1,
            regularization: 1e-6,
            min_level_side: 12,
        }
    }
}

/// Dense flow from `prev` to `next`: `uv[y·w + x]` is where pixel (x, y) of `prev` went
/// (next(x + u, y + v) ≈ prev(x, y)), in pixels of `prev`.
///
/// Never panics: an empty image gives an empty flow; a `next` of another size is first resampled
/// to `prev`'s size (bilinear), so the flow is on `prev`'s grid.
pub fn farneback(prev: &GrayImage, next: &GrayImage, p: &FlowParams) -> Flow {
    let (w, h) = (prev.width() as usize, prev.height() as usize);
    if w == 0 || h == 0 {
        return Flow::zeros(w, h);
    }
    let mut b = from_gray(next);
    if b.w != w || b.h != h {
        b = if b.w == 0 || b.h == 0 { Grid::zeros(w, h) } else { resample(&b, w, h) };
    }
    flow_between(&Prepared::new(from_gray(prev), p), &Prepared::new(b, p), p)
}

/// One frame's polynomial expansions on every pyramid level (full resolution first). A frame takes
/// part in up to four flows of a clip (as prev and next, forwards and backwards), so
/// [`super::analyse_clip`] expands each frame once and reuses it.
pub(crate) struct Prepared {
    levels: Vec<Expansion>,
}

impl Prepared {
    /// Expansions of `img` for the settings `p`.
    pub(crate) fn new(img: Grid<1>, p: &FlowParams) -> Prepared {
        let levels = level_count(img.w, img.h, p);
        let levels = pyramid(img, levels).iter().map(|g| expand(g, p.poly_n, p.poly_sigma)).collect();
        Prepared { levels }
    }

    /// A frame from a grayscale image.
    pub(crate) fn from_image(img: &GrayImage, p: &FlowParams) -> Prepared {
        Prepared::new(from_gray(img), p)
    }

    fn size(&self) -> (usize, usize) {
        self.levels.first().map_or((0, 0), |e| (e.w, e.h))
    }
}

/// Flow from `a` to `b`, coarse to fine. Frames of different sizes or an empty frame give a zero
/// flow on `a`'s grid (the public [`farneback`] resamples before it gets here).
pub(crate) fn flow_between(a: &Prepared, b: &Prepared, p: &FlowParams) -> Flow {
    let (w, h) = a.size();
    if w == 0 || h == 0 || a.size() != b.size() || a.levels.len() != b.levels.len() {
        return Flow::zeros(w, h);
    }
    let coarsest = &a.levels[a.levels.len() - 1];
    let mut flow = Grid::<2>::zeros(coarsest.w, coarsest.h);
    for (ea, eb) in a.levels.iter().zip(&b.levels).rev() {
        flow = upscale_flow(&flow, ea.w, ea.h);
        flow = refine(ea, eb, flow, p);
    }
    Flow { width: w, height: h, uv: flow.px }
}

/// Levels actually used: at most `p.levels` (≥ 1), with the coarsest side ≥ `min_level_side`.
fn level_count(w: usize, h: usize, p: &FlowParams) -> usize {
    let mut side = w.min(h);
    let mut n = 1;
    while n < p.levels && side.div_ceil(2) >= p.min_level_side.max(1) {
        side = side.div_ceil(2);
        n += 1;
    }
    n
}

/// Full resolution first, then successive halvings.
fn pyramid(img: Grid<1>, levels: usize) -> Vec<Grid<1>> {
    let mut out = vec![img];
    while out.len() < levels {
        let next = half(out.last().expect("pyramid starts non-empty"));
        out.push(next);
    }
    out
}

/// Carries a coarse flow to a finer grid: resampled, vectors scaled by the size ratio.
fn upscale_flow(flow: &Grid<2>, w: usize, h: usize) -> Grid<2> {
    if flow.w == w && flow.h == h {
        return flow.clone();
    }
    let (sx, sy) = (w as f32 / flow.w as f32, h as f32 / flow.h as f32);
    let mut out = resample(flow, w, h);
    for v in &mut out.px {
        v[0] *= sx;
        v[1] *= sy;
    }
    out
}

/// `p.iterations` displacement updates on one pyramid level.
fn refine(ea: &Expansion, eb: &Expansion, mut flow: Grid<2>, p: &FlowParams) -> Grid<2> {
    let radius = (p.window / 2).max(1);
    let sigma = (p.window.max(3) as f32) / 4.0;
    for _ in 0..p.iterations.max(1) {
        let normal = blur(&normal_equations(ea, eb, &flow), sigma, radius);
        flow = solve(&normal, &flow, p.regularization);
    }
    flow
}

/// Per pixel: the entries of AᵀA (g₁₁, g₁₂, g₂₂) and AᵀΔb (h₁, h₂) for the current flow. A pixel
/// whose displaced position leaves the image has no counterpart and contributes nothing.
fn normal_equations(ea: &Expansion, eb: &Expansion, flow: &Grid<2>) -> Grid<5> {
    let (w, h) = (ea.w, ea.h);
    Grid::par_rows(w, h, |y, row| {
        for (x, o) in row.iter_mut().enumerate() {
            let i = y * w + x;
            let d = flow.px[i];
            let (sx, sy) = (x as f32 + d[0], y as f32 + d[1]);
            if !(sx >= 0.0 && sy >= 0.0 && sx <= (w - 1) as f32 && sy <= (h - 1) as f32) {
                continue;
            }
            *o = pixel_equations(&ea.px[i], &eb.bilinear(sx, sy), d);
        }
    })
}

/// One pixel's contribution, from the two expansions `c1` (at x) and `c2` (at x + d̃).
#[inline]
fn pixel_equations(c1: &[f32; 5], c2: &[f32; 5], d: [f32; 2]) -> [f32; 5] {
    let a11 = 0.5 * (c1[2] + c2[2]);
    let a22 = 0.5 * (c1[3] + c2[3]);
    let a12 = 0.5 * (c1[4] + c2[4]);
    let db1 = -0.5 * (c2[0] - c1[0]) + a11 * d[0] + a12 * d[1];
    let db2 = -0.5 * (c2[1] - c1[1]) + a12 * d[0] + a22 * d[1];
    [a11 * a11 + a12 * a12, a12 * (a11 + a22), a12 * a12 + a22 * a22, a11 * db1 + a12 * db2, a12 * db1 + a22 * db2]
}

/// d = (G + λI)⁻¹ (h + λ·d̃) per pixel; G + λI is positive definite for λ > 0, so this never
/// divides by zero (a non-positive λ falls back to the smallest positive one that keeps it so).
fn solve(normal: &Grid<5>, prior: &Grid<2>, lambda: f32) -> Grid<2> {
    let l = if lambda > 0.0 { lambda } else { 1e-12 };
    let px = normal
        .px
        .iter()
        .zip(&prior.px)
        .map(|(n, d)| {
            let (g11, g12, g22) = (n[0] + l, n[1], n[2] + l);
            let (h1, h2) = (n[3] + l * d[0], n[4] + l * d[1]);
            let det = g11 * g22 - g12 * g12;
            if !det.is_finite() || det <= 0.0 {
                return *d;
            }
            [(g22 * h1 - g12 * h2) / det, (g11 * h2 - g12 * h1) / det]
        })
        .collect();
    Grid { w: normal.w, h: normal.h, px }
}
