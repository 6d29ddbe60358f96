//! Order statistics, written once for every engine and bench: the nearest-rank [`percentile`] (the
//! codec's p99 error, ACL's convention), the interpolated [`quantile`] (box plots, bench tables) and
//! the [`median`] of timings.

/// The `p` quantile (`p` in [0, 1]) by nearest rank: the smallest value with at least `p · n` values at
/// or below it. Reorders `v`; 0 for no value.
pub fn percentile(v: &mut [f64], p: f64) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    let i = ((p * v.len() as f64).ceil() as usize).clamp(1, v.len()) - 1;
    *v.select_nth_unstable_by(i, f64::total_cmp).1
}

/// The `p` quantile (`p` in [0, 1], clamped) of the finite values by linear interpolation between order
/// statistics; NaN for no finite value.
pub fn quantile(values: &[f64], p: f64) -> f64 {
    let v = sorted_finite(values);
    if v.is_empty() {
        return f64::NAN;
    }
    quantile_sorted(&v, p)
}

/// [`quantile`] of values already sorted ascending, all finite and at least one.
pub fn quantile_sorted(v: &[f64], p: f64) -> f64 {
    let pos = p.clamp(0.0, 1.0) * (v.len() - 1) as f64;
    let (i, f) = (pos.floor() as usize, pos.fract());
    v[i] + (v[(i + 1).min(v.len() - 1)] - v[i]) * f
}

/// The finite values of `values`, sorted ascending.
pub fn sorted_finite(values: &[f64]) -> Vec<f64> {
    let mut v: Vec<f64> = values.iter().copied().filter(|x| x.is_finite()).collect();
    v.sort_by(f64::total_cmp);
    v
}

/// The median of `v` (reordered): the middle value, or the mean of the two middle ones; NaN for none.
pub fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n == 0 {
        return f64::NAN;
    }
    if n % 2 == 1 {
        v[n / 2]
    } else {
        (v[n / 2 - 1] + v[n / 2]) / 2.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nearest_rank_percentile() {
        let mut v: Vec<f64> = (1..=100).rev().map(f64::from).collect();
        assert_eq!(percentile(&mut v, 0.99), 99.0);
        assert_eq!(percentile(&mut v, 1.0), 100.0);
        assert_eq!(percentile(&mut v, 0.0), 1.0);
        assert_eq!(percentile(&mut [], 0.5), 0.0);
    }

    #[test]
    fn quantiles_interpolate_between_order_statistics() {
        let v = [4.0, f64::NAN, 1.0, 3.0, 2.0];
        assert_eq!(quantile(&v, 0.5), 2.5);
        assert_eq!(quantile(&v, 0.25), 1.75);
        assert_eq!(quantile(&v, 2.0), 4.0);
        assert!(quantile(&[f64::NAN], 0.5).is_nan());
    }

    #[test]
    fn median_of_odd_and_even_counts() {
        assert_eq!(median(&mut [3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&mut [4.0, 1.0, 3.0, 2.0]), 2.5);
        assert!(median(&mut []).is_nan());
    }
}
