//! Table 3's effort measure: how many cubic Bézier keys an animator would need to reproduce an edited
//! curve within a tolerance (the paper uses 0.01).
//!
//! Each curve is split recursively (as in Schneider's curve fitting): a span of samples gets one cubic
//! Bézier with its end points on the data and its two inner control values fitted by least squares
//! (time is the parameter, so the curve is a cubic polynomial of time); where the worst sample is
//! farther than the tolerance, the span splits there. The answer is the number of keys (span end
//! points), which is what an animator places; every key carries two tangent handles.

/// Keys a piecewise cubic Bézier needs to stay within `tolerance` of `values` (at least 2 for two or
/// more samples, 1 for one).
pub fn bezier_keys(values: &[f32], tolerance: f32) -> usize {
    match values.len() {
        0 => 0,
        1 => 1,
        n => 1 + spans_needed(values, 0, n - 1, tolerance),
    }
}

/// Spans needed between samples `a` and `b` (inclusive).
fn spans_needed(y: &[f32], a: usize, b: usize, tol: f32) -> usize {
    let (worst, err) = worst_sample(y, a, b);
    if err <= tol || b - a < 2 {
        return 1;
    }
    spans_needed(y, a, worst, tol) + spans_needed(y, worst, b, tol)
}

/// Cubic Bernstein basis at `s`.
fn basis(s: f64) -> [f64; 4] {
    let r = 1.0 - s;
    [r * r * r, 3.0 * s * r * r, 3.0 * s * s * r, s * s * s]
}

/// Fit the inner control values of one span and return the worst sample and its error.
fn worst_sample(y: &[f32], a: usize, b: usize) -> (usize, f32) {
    let (y0, y3) = (f64::from(y[a]), f64::from(y[b]));
    let len = (b - a) as f64;
    // Normal equations of min Σ (B1 c1 + B2 c2 − (y − B0 y0 − B3 y3))².
    let (mut m11, mut m12, mut m22, mut r1, mut r2) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for (i, v) in y.iter().enumerate().take(b + 1).skip(a) {
        let w = basis((i - a) as f64 / len);
        let rhs = f64::from(*v) - w[0] * y0 - w[3] * y3;
        m11 += w[1] * w[1];
        m12 += w[1] * w[2];
        m22 += w[2] * w[2];
        r1 += w[1] * rhs;
        r2 += w[2] * rhs;
    }
    let det = m11 * m22 - m12 * m12;
    let (c1, c2) = if det.abs() > 1e-12 {
        ((r1 * m22 - r2 * m12) / det, (m11 * r2 - m12 * r1) / det)
    } else {
        (y0 + (y3 - y0) / 3.0, y0 + 2.0 * (y3 - y0) / 3.0)
    };
    let mut worst = (a, 0.0f32);
    for (i, v) in y.iter().enumerate().take(b).skip(a + 1) {
        let w = basis((i - a) as f64 / len);
        let fit = w[0] * y0 + w[1] * c1 + w[2] * c2 + w[3] * y3;
        let e = (fit - f64::from(*v)).abs() as f32;
        if e > worst.1 {
            worst = (i, e);
        }
    }
    if worst.0 == a {
        worst.0 = (a + b) / 2;
    }
    worst
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cubic_needs_two_keys_and_noise_needs_many() {
        let cubic: Vec<f32> = (0..50)
            .map(|i| {
                let t = i as f32 / 49.0;
                0.2 + 0.5 * t * t * t - 0.3 * t * t
            })
            .collect();
        assert_eq!(bezier_keys(&cubic, 0.01), 2);
        let zigzag: Vec<f32> = (0..50).map(|i| if i % 2 == 0 { 0.0 } else { 0.5 }).collect();
        assert!(bezier_keys(&zigzag, 0.01) > 20);
        assert_eq!(bezier_keys(&[0.3], 0.01), 1);
        assert_eq!(bezier_keys(&[], 0.01), 0);
    }

    #[test]
    fn the_fit_stays_within_tolerance_so_tighter_needs_more() {
        let wave: Vec<f32> = (0..200).map(|i| 0.5 + 0.4 * (i as f32 * 0.2).sin()).collect();
        let loose = bezier_keys(&wave, 0.05);
        let tight = bezier_keys(&wave, 0.001);
        assert!(tight > loose, "{tight} vs {loose}");
        // about one key per half-period of the sine at a loose tolerance
        assert!((4..=30).contains(&loose), "{loose}");
    }
}
