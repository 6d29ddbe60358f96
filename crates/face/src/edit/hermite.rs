//! Piecewise cubic Hermite curves through knots, the one interpolator behind the cubic baseline and
//! the post-processing that makes keys exact and joins C1.

/// A knot at frame `t` with value `v` and, when the curve must match a known derivative there, `slope`
/// (per frame). Knots without a slope get a Catmull–Rom slope from their neighbours.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Knot {
    /// Frame (may be fractional).
    pub t: f64,
    /// Value.
    pub v: f64,
    /// Derivative per frame, if fixed.
    pub slope: Option<f64>,
}

/// Evaluate the C1 Hermite curve through `knots` (sorted by `t`, distinct) at `t`. Before the first and
/// after the last knot the curve is held flat, since a blendshape should
/// not drift away from its last known value.
pub fn hermite(knots: &[Knot], t: f64) -> f64 {
    interval(knots, t, |i, s, h| {
        let (a, b) = (&knots[i], &knots[i + 1]);
        let (ma, mb) = (slope_at(knots, i) * h, slope_at(knots, i + 1) * h);
        let (s2, s3) = (s * s, s * s * s);
        (2.0 * s3 - 3.0 * s2 + 1.0) * a.v + (s3 - 2.0 * s2 + s) * ma + (-2.0 * s3 + 3.0 * s2) * b.v + (s3 - s2) * mb
    })
}

/// Linear interpolation through `knots` (held flat outside them).
pub fn linear(knots: &[Knot], t: f64) -> f64 {
    interval(knots, t, |i, s, _| knots[i].v + (knots[i + 1].v - knots[i].v) * s)
}

/// The value at `t`: the end values outside the knots (0 with none), else `inside(i, s, h)` on the
/// interval `knots[i]..knots[i + 1]` of length `h` at the fraction `s` of it.
fn interval(knots: &[Knot], t: f64, inside: impl Fn(usize, f64, f64) -> f64) -> f64 {
    let (Some(first), Some(last)) = (knots.first(), knots.last()) else { return 0.0 };
    if knots.len() == 1 || t <= first.t {
        return first.v;
    }
    if t >= last.t {
        return last.v;
    }
    let i = knots.partition_point(|k| k.t <= t).saturating_sub(1).min(knots.len() - 2);
    let h = knots[i + 1].t - knots[i].t;
    inside(i, (t - knots[i].t) / h, h)
}

/// The slope at knot `i`: its own, else Catmull–Rom (central difference of the neighbours), one-sided
/// at the ends.
fn slope_at(knots: &[Knot], i: usize) -> f64 {
    if let Some(s) = knots[i].slope {
        return s;
    }
    let last = knots.len() - 1;
    let (a, b) = (if i == 0 { 0 } else { i - 1 }, if i == last { last } else { i + 1 });
    if a == b {
        return 0.0;
    }
    (knots[b].v - knots[a].v) / (knots[b].t - knots[a].t)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn k(t: f64, v: f64, slope: Option<f64>) -> Knot {
        Knot { t, v, slope }
    }

    #[test]
    fn passes_through_knots_and_matches_given_slopes() {
        let knots = [k(0.0, 1.0, Some(0.5)), k(4.0, 2.0, None), k(10.0, 0.0, Some(-1.0))];
        for kn in &knots {
            assert!((hermite(&knots, kn.t) - kn.v).abs() < 1e-12);
        }
        let eps = 1e-6;
        let d0 = (hermite(&knots, eps) - hermite(&knots, 0.0)) / eps;
        assert!((d0 - 0.5).abs() < 1e-4, "{d0}");
        let d1 = (hermite(&knots, 10.0) - hermite(&knots, 10.0 - eps)) / eps;
        assert!((d1 + 1.0).abs() < 1e-4, "{d1}");
        // C1 at the interior knot: left and right derivatives agree.
        let l = (hermite(&knots, 4.0) - hermite(&knots, 4.0 - eps)) / eps;
        let r = (hermite(&knots, 4.0 + eps) - hermite(&knots, 4.0)) / eps;
        assert!((l - r).abs() < 1e-4, "{l} {r}");
    }

    #[test]
    fn reproduces_a_cubic_given_its_end_slopes() {
        let f = |t: f64| 0.01 * t * t * t - 0.1 * t * t + 0.3 * t + 1.0;
        let df = |t: f64| 0.03 * t * t - 0.2 * t + 0.3;
        let knots = [k(0.0, f(0.0), Some(df(0.0))), k(7.0, f(7.0), Some(df(7.0)))];
        for i in 0..=70 {
            let t = i as f64 / 10.0;
            assert!((hermite(&knots, t) - f(t)).abs() < 1e-9);
        }
        assert_eq!(linear(&knots, 3.5), (f(0.0) + f(7.0)) / 2.0);
        assert_eq!(hermite(&knots, -1.0), f(0.0));
        assert_eq!(hermite(&[], 1.0), 0.0);
    }
}
