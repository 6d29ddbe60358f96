//! Small multi-channel float images for the flow solver: separable correlation with replicated
//! borders, bilinear sampling and resampling. Everything the Farnebäck solver needs, nothing more.

use image::GrayImage;
use rayon::prelude::*;

/// `N` float channels per pixel, row-major (`px[y * w + x]`).
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Grid<const N: usize> {
    pub w: usize,
    pub h: usize,
    pub px: Vec<[f32; N]>,
}

impl<const N: usize> Grid<N> {
    pub fn zeros(w: usize, h: usize) -> Self {
        Grid { w, h, px: vec![[0.0; N]; w * h] }
    }

    /// A `w`×`h` grid whose rows (starting at zero) are filled in parallel by `fill(y, row)`,
    /// [`ROWS_PER_TASK`] rows per rayon task. An empty grid runs nothing.
    pub fn par_rows(w: usize, h: usize, fill: impl Fn(usize, &mut [[f32; N]]) + Sync + Send) -> Self {
        let mut out = Grid::zeros(w, h);
        if w > 0 {
            out.px.par_chunks_mut(w).with_min_len(ROWS_PER_TASK).enumerate().for_each(|(y, row)| fill(y, row));
        }
        out
    }

    /// Bilinear interpolation at a real position, clamped into the image.
    #[inline]
    pub fn bilinear(&self, x: f32, y: f32) -> [f32; N] {
        let x = x.clamp(0.0, (self.w - 1) as f32);
        let y = y.clamp(0.0, (self.h - 1) as f32);
        let (x0, y0) = (x as usize, y as usize);
        let (fx, fy) = (x - x0 as f32, y - y0 as f32);
        // Neighbours to the right / below, repeated on the last column / row.
        let dx = usize::from(x0 + 1 < self.w);
        let dy = if y0 + 1 < self.h { self.w } else { 0 };
        let i = y0 * self.w + x0;
        let (a, b, c, d) = (self.px[i], self.px[i + dx], self.px[i + dy], self.px[i + dy + dx]);
        std::array::from_fn(|k| {
            let top = a[k] + (b[k] - a[k]) * fx;
            let bottom = c[k] + (d[k] - c[k]) * fx;
            top + (bottom - top) * fy
        })
    }
}

/// Rows per rayon task: a 160-px row is too little work to be a task of its own.
pub(crate) const ROWS_PER_TASK: usize = 16;

/// Luma in [0, 1].
pub(crate) fn from_gray(img: &GrayImage) -> Grid<1> {
    let (w, h) = (img.width() as usize, img.height() as usize);
    Grid { w, h, px: img.as_raw().iter().map(|&v| [v as f32 / 255.0]).collect() }
}

/// Separable correlation along rows: `out(x, y) = Σ_t k[t + r] · src(x + t, y)`, t ∈ [−r, r], with
/// the border replicated. `k` has odd length 2r + 1. Each row is padded once so the inner loop
/// has no bounds logic.
pub(crate) fn correlate_rows<const N: usize>(src: &Grid<N>, k: &[f32]) -> Grid<N> {
    let r = k.len() / 2;
    Grid::par_rows(src.w, src.h, |y, row| {
        let line = &src.px[y * src.w..(y + 1) * src.w];
        let padded = pad(line, r);
        for (o, window) in row.iter_mut().zip(padded.windows(k.len())) {
            let mut acc = [0.0f32; N];
            for (kv, p) in k.iter().zip(window) {
                for c in 0..N {
                    acc[c] += kv * p[c];
                }
            }
            *o = acc;
        }
    })
}

/// `line` with its first and last values repeated `r` times on each side.
pub(crate) fn pad<T: Copy>(line: &[T], r: usize) -> Vec<T> {
    let mut v = Vec::with_capacity(line.len() + 2 * r);
    v.extend(std::iter::repeat_n(line[0], r));
    v.extend_from_slice(line);
    v.extend(std::iter::repeat_n(line[line.len() - 1], r));
    v
}

/// Separable correlation along columns, like [`correlate_rows`].
pub(crate) fn correlate_cols<const N: usize>(src: &Grid<N>, k: &[f32]) -> Grid<N> {
    let r = (k.len() / 2) as isize;
    Grid::par_rows(src.w, src.h, |y, row| {
        for (i, &kv) in k.iter().enumerate() {
            let sy = (y as isize + i as isize - r).clamp(0, src.h as isize - 1) as usize;
            let src_row = &src.px[sy * src.w..(sy + 1) * src.w];
            for (o, p) in row.iter_mut().zip(src_row) {
                for c in 0..N {
                    o[c] += kv * p[c];
                }
            }
        }
    })
}

/// Unnormalised Gaussian weights g(t) = exp(−t²/2σ²) for t ∈ [−r, r].
pub(crate) fn gaussian_weights(sigma: f32, radius: usize) -> Vec<f64> {
    let s2 = 2.0 * (sigma.max(1e-3) as f64).powi(2);
    let r = radius as isize;
    (-r..=r).map(|t| (-((t * t) as f64) / s2).exp()).collect()
}

/// Gaussian kernel summing to 1.
pub(crate) fn gaussian_kernel(sigma: f32, radius: usize) -> Vec<f32> {
    let g = gaussian_weights(sigma, radius);
    let sum: f64 = g.iter().sum();
    g.iter().map(|v| (v / sum) as f32).collect()
}

/// Separable Gaussian blur.
pub(crate) fn blur<const N: usize>(src: &Grid<N>, sigma: f32, radius: usize) -> Grid<N> {
    let k = gaussian_kernel(sigma, radius);
    correlate_cols(&correlate_rows(src, &k), &k)
}

/// Bilinear resampling to `w`×`h`, pixel centres aligned (output pixel i samples the source at
/// (i + ½)·src/dst − ½). Values are not scaled.
pub(crate) fn resample<const N: usize>(src: &Grid<N>, w: usize, h: usize) -> Grid<N> {
    if src.w == 0 || src.h == 0 || w == 0 {
        return Grid::zeros(w, h);
    }
    let (sx, sy) = (src.w as f32 / w as f32, src.h as f32 / h as f32);
    Grid::par_rows(w, h, |y, row| {
        let fy = (y as f32 + 0.5) * sy - 0.5;
        for (x, o) in row.iter_mut().enumerate() {
            *o = src.bilinear((x as f32 + 0.5) * sx - 0.5, fy);
        }
    })
}

/// The next pyramid level: anti-alias blur (σ = 1 px, enough for a factor 2) then half size
/// (rounded up).
pub(crate) fn half<const N: usize>(src: &Grid<N>) -> Grid<N> {
    resample(&blur(src, 1.0, 2), src.w.div_ceil(2), src.h.div_ceil(2))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn correlation_uses_the_kernel_orientation_and_replicates_borders() {
        let g = Grid::<1> { w: 4, h: 1, px: vec![[0.0], [1.0], [2.0], [3.0]] };
        // k = [0, 0, 1]: out(x) = src(x + 1), the last pixel repeats.
        let out = correlate_rows(&g, &[0.0, 0.0, 1.0]);
        assert_eq!(out.px, vec![[1.0], [2.0], [3.0], [3.0]]);
        let col = Grid::<1> { w: 1, h: 3, px: vec![[5.0], [6.0], [7.0]] };
        assert_eq!(correlate_cols(&col, &[1.0, 0.0, 0.0]).px, vec![[5.0], [5.0], [6.0]]);
    }

    #[test]
    fn bilinear_interpolates_and_clamps() {
        let g = Grid::<1> { w: 2, h: 2, px: vec![[0.0], [1.0], [2.0], [3.0]] };
        assert!((g.bilinear(0.5, 0.5)[0] - 1.5).abs() < 1e-6);
        assert_eq!(g.bilinear(-3.0, 9.0)[0], 2.0);
    }

    #[test]
    fn halving_keeps_a_constant_image_constant() {
        let g = Grid::<2> { w: 7, h: 5, px: vec![[0.25, -1.0]; 35] };
        let h = half(&g);
        assert_eq!((h.w, h.h), (4, 3));
        assert!(h.px.iter().all(|p| (p[0] - 0.25).abs() < 1e-6 && (p[1] + 1.0).abs() < 1e-6));
    }
}
