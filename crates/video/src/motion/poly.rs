//! Polynomial expansion (Farnebäck, "Two-frame motion estimation based on polynomial expansion",
//! 2003): every neighbourhood of the image is approximated by a quadratic
//! f(x) ≈ xᵀA x + bᵀx + c in local coordinates, fitted by least squares weighted with a Gaussian
//! "applicability" a(x) = g(x₁)·g(x₂).
//!
//! Because the weights are the same at every pixel, the fit is a fixed linear map of six weighted
//! moments Σ a(x)·x₁ᵖx₂ᵠ·f(x + ·) (p + q ≤ 2), and each moment is separable: a row pass with g·tᵖ
//! followed by a column pass with g·tᵠ. The 6×6 Gram matrix of the basis {1, x₁, x₂, x₁², x₂²,
//! x₁x₂} under the applicability is inverted once.

use super::grid::{gaussian_weights, pad, Grid};

/// Per pixel: `[b₁, b₂, A₁₁, A₂₂, A₁₂]` of the local quadratic (c is not needed for motion).
pub(crate) type Expansion = Grid<5>;

/// Fits the local quadratics of `img` over a (2r+1)² neighbourhood, r = `poly_n / 2` (at least 1),
/// with a Gaussian applicability of standard deviation `sigma`.
pub(crate) fn expand(img: &Grid<1>, poly_n: usize, sigma: f32) -> Expansion {
    let radius = (poly_n / 2).max(1);
    let g = gaussian_weights(sigma, radius);
    let kernel = |p: i32| -> Vec<f32> {
        let r = radius as f64;
        g.iter().enumerate().map(|(i, gv)| (gv * (i as f64 - r).powi(p)) as f32).collect()
    };
    let k = [kernel(0), kernel(1), kernel(2)];
    let moments = column_moments(&row_moments(img, &k), &k);
    let inv = invert6(gram(&g, radius));
    // Only b and A are needed: rows 1..6 of the inverse, in f32 for speed (the entries are O(1)).
    let rows: [[f32; 6]; 5] = std::array::from_fn(|r| std::array::from_fn(|c| inv[r + 1][c] as f32));
    let mut out = Grid::zeros(img.w, img.h);
    for (o, m) in out.px.iter_mut().zip(&moments.px) {
        let r: [f32; 5] = std::array::from_fn(|i| dot6(&rows[i], m));
        *o = [r[0], r[1], r[2], r[3], 0.5 * r[4]];
    }
    out
}

#[inline]
fn dot6(a: &[f32; 6], b: &[f32; 6]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3] + a[4] * b[4] + a[5] * b[5]
}

/// Row pass: h_p = Σ_t g(t)·tᵖ·f(x + t, y) for p = 0, 1, 2 (`k[p]`), in one sweep.
fn row_moments(img: &Grid<1>, k: &[Vec<f32>; 3]) -> Grid<3> {
    let (w, len) = (img.w, k[0].len());
    debug_assert!(k[1].len() == len && k[2].len() == len);
    Grid::par_rows(img.w, img.h, |y, row| {
        let padded = pad(&img.px[y * w..(y + 1) * w], len / 2);
        for (o, window) in row.iter_mut().zip(padded.windows(len)) {
            for (((p, a), b), c) in window.iter().zip(&k[0]).zip(&k[1]).zip(&k[2]) {
                o[0] += a * p[0];
                o[1] += b * p[0];
                o[2] += c * p[0];
            }
        }
    })
}

/// Column pass: the six moments in basis order 1, x₁, x₂, x₁², x₂², x₁x₂ (x₁ along rows, x₂
/// along columns) from the row moments h₀, h₁, h₂.
fn column_moments(h: &Grid<3>, k: &[Vec<f32>; 3]) -> Grid<6> {
    let (w, hh, r) = (h.w, h.h as isize, (k[0].len() / 2) as isize);
    Grid::par_rows(h.w, h.h, |y, row| {
        for (i, ((&g0, &g1), &g2)) in k[0].iter().zip(&k[1]).zip(&k[2]).enumerate() {
            let sy = (y as isize + i as isize - r).clamp(0, hh - 1) as usize;
            for (o, p) in row.iter_mut().zip(&h.px[sy * w..(sy + 1) * w]) {
                o[0] += g0 * p[0];
                o[1] += g0 * p[1];
                o[2] += g1 * p[0];
                o[3] += g0 * p[2];
                o[4] += g2 * p[0];
                o[5] += g1 * p[1];
            }
        }
    })
}

/// Gram matrix Σ a(x)·bₖ(x)·bₗ(x) of the six basis functions over the window.
fn gram(g: &[f64], radius: usize) -> [[f64; 6]; 6] {
    let r = radius as isize;
    let mut m = [[0.0; 6]; 6];
    for y in -r..=r {
        for x in -r..=r {
            let a = g[(x + r) as usize] * g[(y + r) as usize];
            let (xf, yf) = (x as f64, y as f64);
            let b = [1.0, xf, yf, xf * xf, yf * yf, xf * yf];
            for k in 0..6 {
                for l in 0..6 {
                    m[k][l] += a * b[k] * b[l];
                }
            }
        }
    }
    m
}

/// Gauss–Jordan inverse with partial pivoting. The Gram matrix is positive definite for any
/// window of at least 3×3 pixels, so the pivots never vanish.
fn invert6(mut m: [[f64; 6]; 6]) -> [[f64; 6]; 6] {
    let mut inv = [[0.0; 6]; 6];
    for (i, row) in inv.iter_mut().enumerate() {
        row[i] = 1.0;
    }
    for col in 0..6 {
        let pivot = (col..6).max_by(|&a, &b| m[a][col].abs().total_cmp(&m[b][col].abs())).unwrap_or(col);
        m.swap(col, pivot);
        inv.swap(col, pivot);
        let p = m[col][col];
        for k in 0..6 {
            m[col][k] /= p;
            inv[col][k] /= p;
        }
        for row in 0..6 {
            if row != col {
                let f = m[row][col];
                for k in 0..6 {
                    m[row][k] -= f * m[col][k];
                    inv[row][k] -= f * inv[col][k];
                }
            }
        }
    }
    inv
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An exact quadratic image must be recovered exactly (away from the replicated border).
    #[test]
    fn recovers_the_coefficients_of_a_quadratic_image() {
        let (w, h) = (15usize, 13usize);
        let f = |x: f64, y: f64| 0.3 + 0.02 * x - 0.01 * y + 0.003 * x * x + 0.001 * y * y - 0.002 * x * y;
        let px = (0..w * h).map(|i| [f((i % w) as f64, (i / w) as f64) as f32]).collect();
        let e = expand(&Grid { w, h, px }, 5, 1.2);
        let (x, y) = (7.0, 6.0);
        let c = e.px[6 * w + 7];
        // Gradient of f at (x, y) is b; the Hessian / 2 is A.
        let b1 = 0.02 + 2.0 * 0.003 * x - 0.002 * y;
        let b2 = -0.01 + 2.0 * 0.001 * y - 0.002 * x;
        let want = [b1, b2, 0.003, 0.001, -0.001];
        for k in 0..5 {
            assert!((c[k] as f64 - want[k]).abs() < 1e-5, "coefficient {k}: {} vs {}", c[k], want[k]);
        }
    }
}
