//! Math-only curves sampled by time (after `bevy_math::curve`): keyed tracks of scalars, vectors,
//! fixed-size arrays or rotations, used for blendshape weights, camera parameters and joint
//! channels alike.
//!
//! Building blocks, each a [`Curve`]:
//! - [`Track`]: keys with step / linear / Hermite interpolation; [`Track::catmull_rom`] is the
//!   Catmull-Rom spline through samples (tangents by central differences, one-sided at the ends).
//! - [`Samples`]: values at evenly spaced times (a track already sampled per frame).
//! - [`KeyCorrected`] (adapter, [`Curve::corrected_to_keys`]): a curve bent so it passes through
//!   given keys, by adding each key's residual blended linearly between keys.
//!
//! ```
//! use inbetween_core::curve::{Curve, Track};
//! // Network output every 5th frame, filled to every frame, then pinned to the keys.
//! let spline = Track::catmull_rom(&[0.0, 5.0, 10.0], &[[0.0, 1.0], [0.4, 1.2], [1.1, 1.0]]).unwrap();
//! let pinned = spline.corrected_to_keys(&[(0.0, [0.0, 1.0]), (10.0, [1.0, 1.0])]);
//! assert_eq!(pinned.sample(10.0), [1.0, 1.0]);
//! assert_eq!(pinned.sample_uniform(1.0).len(), 11);
//! ```

use crate::interp::{hermite, hermite_quat, hermite_vec3};
use crate::CoreError;
use glam::{DQuat, DVec3};
use serde::{Deserialize, Serialize};

/// Anything that yields a value for each time in its domain.
pub trait Curve<T> {
    /// Closed time interval `(start, end)` where the curve is defined.
    fn domain(&self) -> (f64, f64);
    /// Value at time `t`; times outside the domain are clamped to it.
    fn sample(&self, t: f64) -> T;

    /// Samples at `start + i / fps` for every frame inside the domain.
    fn sample_uniform(&self, fps: f64) -> Vec<T> {
        let (a, b) = self.domain();
        let n = ((b - a) * fps + 1e-9).floor() as usize + 1;
        (0..n).map(|i| self.sample(a + i as f64 / fps)).collect()
    }

    /// This curve plus, at each time, the residuals `key − curve(t_key)` of the keys around it
    /// blended linearly ((1 − l)·r_a + l·r_b, l the position between the two key times; the
    /// nearest key's residual outside them), so the result passes through every key and keeps the
    /// curve's shape in between. Keys at strictly increasing times.
    fn corrected_to_keys(self, keys: &[(f64, T)]) -> KeyCorrected<Self, T>
    where
        Self: Sized,
        T: Offset,
    {
        let residuals = keys.iter().map(|&(t, k)| (t, T::difference(k, self.sample(t)))).collect();
        KeyCorrected { curve: self, residuals }
    }
}

impl<T, C: Curve<T> + ?Sized> Curve<T> for &C {
    fn domain(&self) -> (f64, f64) {
        (**self).domain()
    }
    fn sample(&self, t: f64) -> T {
        (**self).sample(t)
    }
}

/// Values with differences: what [`Curve::corrected_to_keys`] needs.
pub trait Offset: Copy {
    /// `a − b`.
    fn difference(a: Self, b: Self) -> Self;
    /// `a + d`.
    fn offset(a: Self, d: Self) -> Self;
    /// `(1 − l)·a + l·b`.
    fn blend(a: Self, b: Self, l: f64) -> Self;
    /// The zero difference.
    fn zero() -> Self;
}

/// [`Offset`] for types with vector arithmetic (`-`, `+`, scaling by an `f64`).
macro_rules! vector_offset {
    ($($t:ty => $zero:expr),*) => {$(
        impl Offset for $t {
            fn difference(a: $t, b: $t) -> $t {
                a - b
            }
            fn offset(a: $t, d: $t) -> $t {
                a + d
            }
            fn blend(a: $t, b: $t, l: f64) -> $t {
                (1.0 - l) * a + l * b
            }
            fn zero() -> $t {
                $zero
            }
        }
    )*};
}

vector_offset!(f64 => 0.0, DVec3 => DVec3::ZERO);

impl<const N: usize> Offset for [f64; N] {
    fn difference(a: Self, b: Self) -> Self {
        std::array::from_fn(|i| a[i] - b[i])
    }
    fn offset(a: Self, d: Self) -> Self {
        std::array::from_fn(|i| a[i] + d[i])
    }
    fn blend(a: Self, b: Self, l: f64) -> Self {
        std::array::from_fn(|i| f64::blend(a[i], b[i], l))
    }
    fn zero() -> Self {
        [0.0; N]
    }
}

/// A curve bent through keys (see [`Curve::corrected_to_keys`]); the camera engine's exact-key
/// correction (Jiang et al. 2021, Eq. 9 used as a post-correction).
#[derive(Clone, Debug, PartialEq)]
pub struct KeyCorrected<C, T> {
    curve: C,
    residuals: Vec<(f64, T)>,
}

impl<C, T: Offset> KeyCorrected<C, T> {
    /// The blended residual added at time `t`.
    pub fn residual_at(&self, t: f64) -> T {
        let res = &self.residuals;
        let j = res.partition_point(|&(kt, _)| kt <= t);
        match (j.checked_sub(1).map(|i| res[i]), res.get(j)) {
            (Some((ta, ra)), Some(&(tb, rb))) => T::blend(ra, rb, (t - ta) / (tb - ta)),
            (Some((_, r)), None) | (None, Some(&(_, r))) => r,
            (None, None) => T::zero(),
        }
    }

    /// Each key's residual before correction, `key − curve(t_key)`.
    pub fn residuals(&self) -> &[(f64, T)] {
        &self.residuals
    }
}

impl<T: Offset, C: Curve<T>> Curve<T> for KeyCorrected<C, T> {
    fn domain(&self) -> (f64, f64) {
        self.curve.domain()
    }
    fn sample(&self, t: f64) -> T {
        T::offset(self.curve.sample(t), self.residual_at(t))
    }
}

/// Values at `start, start + 1/rate, …` (e.g. one per frame), linear in between; a sampled
/// track that the adapters here can bend.
#[derive(Clone, Debug, PartialEq)]
pub struct Samples<T> {
    start: f64,
    rate: f64,
    values: Vec<T>,
}

impl<T: Animatable> Samples<T> {
    /// Fails on no values or a rate that is not finite and positive.
    pub fn new(start: f64, rate: f64, values: Vec<T>) -> Result<Self, CoreError> {
        if values.is_empty() || !(rate.is_finite() && rate > 0.0) || !start.is_finite() {
            return Err(CoreError::InvalidCurve(format!(
                "samples need values and a positive rate (got {} values at rate {rate})",
                values.len()
            )));
        }
        Ok(Samples { start, rate, values })
    }

    pub fn values(&self) -> &[T] {
        &self.values
    }
}

impl<T: Animatable> Curve<T> for Samples<T> {
    fn domain(&self) -> (f64, f64) {
        (self.start, self.start + (self.values.len() - 1) as f64 / self.rate)
    }
    fn sample(&self, t: f64) -> T {
        let x = ((t - self.start) * self.rate).clamp(0.0, (self.values.len() - 1) as f64);
        let i = x.floor() as usize;
        let u = x - i as f64;
        if u == 0.0 || i + 1 >= self.values.len() {
            return self.values[i];
        }
        T::linear(self.values[i], self.values[i + 1], u)
    }
}

/// How a track fills the time between two keys.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Interpolation {
    /// Hold the earlier key's value.
    Step,
    /// Straight line (slerp for rotations).
    Linear,
    /// Cubic Hermite through values with the keys' tangents (per second).
    Hermite,
}

/// Values a track can interpolate. The tangent of a rotation is its body-frame angular velocity.
pub trait Animatable: Copy + std::fmt::Debug + PartialEq {
    type Tangent: Copy + std::fmt::Debug + PartialEq;
    fn linear(a: Self, b: Self, u: f64) -> Self;
    fn hermite(a: Self, ta: Self::Tangent, b: Self, tb: Self::Tangent, h: f64, u: f64) -> Self;
    /// Tangent by finite difference of three neighbours at times `t0 < t1 < t2` (one-sided at ends).
    fn finite_tangent(prev: (f64, Self), next: (f64, Self)) -> Self::Tangent;
}

impl Animatable for f64 {
    type Tangent = f64;
    fn linear(a: f64, b: f64, u: f64) -> f64 {
        a + (b - a) * u
    }
    fn hermite(a: f64, ta: f64, b: f64, tb: f64, h: f64, u: f64) -> f64 {
        hermite(a, ta, b, tb, h, u)
    }
    fn finite_tangent(prev: (f64, f64), next: (f64, f64)) -> f64 {
        (next.1 - prev.1) / (next.0 - prev.0)
    }
}

impl Animatable for DVec3 {
    type Tangent = DVec3;
    fn linear(a: DVec3, b: DVec3, u: f64) -> DVec3 {
        a.lerp(b, u)
    }
    fn hermite(a: DVec3, ta: DVec3, b: DVec3, tb: DVec3, h: f64, u: f64) -> DVec3 {
        hermite_vec3(a, ta, b, tb, h, u)
    }
    fn finite_tangent(prev: (f64, DVec3), next: (f64, DVec3)) -> DVec3 {
        (next.1 - prev.1) / (next.0 - prev.0)
    }
}

impl Animatable for DQuat {
    type Tangent = DVec3;
    fn linear(a: DQuat, b: DQuat, u: f64) -> DQuat {
        a.slerp(b, u)
    }
    fn hermite(a: DQuat, ta: DVec3, b: DQuat, tb: DVec3, h: f64, u: f64) -> DQuat {
        hermite_quat(a, ta, b, tb, h, u)
    }
    fn finite_tangent(prev: (f64, DQuat), next: (f64, DQuat)) -> DVec3 {
        crate::interp::angular_velocity(prev.1, next.1, next.0 - prev.0)
    }
}

impl<const N: usize> Animatable for [f64; N] {
    type Tangent = [f64; N];
    fn linear(a: Self, b: Self, u: f64) -> Self {
        std::array::from_fn(|i| f64::linear(a[i], b[i], u))
    }
    fn hermite(a: Self, ta: Self, b: Self, tb: Self, h: f64, u: f64) -> Self {
        std::array::from_fn(|i| hermite(a[i], ta[i], b[i], tb[i], h, u))
    }
    fn finite_tangent(prev: (f64, Self), next: (f64, Self)) -> Self {
        std::array::from_fn(|i| (next.1[i] - prev.1[i]) / (next.0 - prev.0))
    }
}

/// One key: a time, a value and the tangent used by Hermite interpolation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Key<T: Animatable> {
    pub time: f64,
    pub value: T,
    pub tangent: T::Tangent,
}

/// Keys at strictly increasing times, interpolated one way.
#[derive(Clone, Debug, PartialEq)]
pub struct Track<T: Animatable> {
    keys: Vec<Key<T>>,
    pub interpolation: Interpolation,
}

/// A scalar curve (blendshape weight, focal length, …).
pub type ScalarTrack = Track<f64>;

impl<T: Animatable> Track<T> {
    /// Fails on no keys or on times that are not finite and strictly increasing.
    pub fn new(keys: Vec<Key<T>>, interpolation: Interpolation) -> Result<Self, CoreError> {
        if keys.is_empty() {
            return Err(CoreError::InvalidCurve("a track needs at least one key".into()));
        }
        for (i, w) in keys.windows(2).enumerate() {
            if !(w[0].time.is_finite() && w[1].time.is_finite() && w[0].time < w[1].time) {
                return Err(CoreError::InvalidCurve(format!(
                    "key {} at t={} does not come after key {} at t={}",
                    i + 1,
                    w[1].time,
                    i,
                    w[0].time
                )));
            }
        }
        Ok(Track { keys, interpolation })
    }

    /// Keys at `times` with tangents from finite differences of the neighbours (Catmull-Rom style).
    pub fn from_samples(times: &[f64], values: &[T], interpolation: Interpolation) -> Result<Self, CoreError> {
        if times.len() != values.len() {
            return Err(CoreError::InvalidCurve(format!("{} times but {} values", times.len(), values.len())));
        }
        let n = times.len();
        let keys = (0..n)
            .map(|i| {
                let tangent = if n < 2 {
                    T::finite_tangent((0.0, values[i]), (1.0, values[i]))
                } else {
                    let (p, q) = (i.saturating_sub(1), (i + 1).min(n - 1));
                    T::finite_tangent((times[p], values[p]), (times[q], values[q]))
                };
                Key { time: times[i], value: values[i], tangent }
            })
            .collect();
        Track::new(keys, interpolation)
    }

    /// The Catmull-Rom spline through `values` at `times`: Hermite with tangents from the
    /// neighbouring samples ((x_{i+1} − x_{i−1}) / (t_{i+1} − t_{i−1}), one-sided at the ends).
    pub fn catmull_rom(times: &[f64], values: &[T]) -> Result<Self, CoreError> {
        Track::from_samples(times, values, Interpolation::Hermite)
    }

    pub fn keys(&self) -> &[Key<T>] {
        &self.keys
    }

    /// Index of the key segment containing `t` (clamped).
    fn segment(&self, t: f64) -> usize {
        let i = self.keys.partition_point(|k| k.time <= t);
        i.saturating_sub(1).min(self.keys.len().saturating_sub(2))
    }
}

impl<T: Animatable> Curve<T> for Track<T> {
    fn domain(&self) -> (f64, f64) {
        (self.keys[0].time, self.keys[self.keys.len() - 1].time)
    }

    fn sample(&self, t: f64) -> T {
        let (start, end) = self.domain();
        if self.keys.len() == 1 || t <= start {
            return self.keys[0].value;
        }
        if t >= end {
            return self.keys[self.keys.len() - 1].value;
        }
        let i = self.segment(t);
        let (a, b) = (&self.keys[i], &self.keys[i + 1]);
        let h = b.time - a.time;
        let u = (t - a.time) / h;
        match self.interpolation {
            Interpolation::Step => a.value,
            Interpolation::Linear => T::linear(a.value, b.value, u),
            Interpolation::Hermite => T::hermite(a.value, a.tangent, b.value, b.tangent, h, u),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rejects_unsorted_keys() {
        let k = |t| Key { time: t, value: 0.0, tangent: 0.0 };
        assert!(ScalarTrack::new(vec![k(0.0), k(0.0)], Interpolation::Linear).is_err());
        assert!(ScalarTrack::new(vec![], Interpolation::Linear).is_err());
        assert!(ScalarTrack::new(vec![k(0.0), k(f64::NAN)], Interpolation::Linear).is_err());
    }

    #[test]
    fn modes_interpolate_as_named() {
        let t = ScalarTrack::from_samples(&[0.0, 1.0, 2.0], &[0.0, 2.0, 0.0], Interpolation::Linear).unwrap();
        assert_eq!(t.sample(0.5), 1.0);
        assert_eq!(t.sample(-1.0), 0.0);
        assert_eq!(t.sample(5.0), 0.0);
        let mut s = t.clone();
        s.interpolation = Interpolation::Step;
        assert_eq!(s.sample(1.5), 2.0);
        let mut h = t.clone();
        h.interpolation = Interpolation::Hermite;
        // Tangent at the peak is zero by central difference, so the Hermite curve peaks there.
        assert!((h.sample(1.0) - 2.0).abs() < 1e-12);
        assert!(h.sample(0.9) < 2.0 && h.sample(0.9) > 1.8);
        assert_eq!(t.sample_uniform(2.0).len(), 5);
    }

    #[test]
    fn catmull_rom_passes_through_samples_and_keeps_lines_straight() {
        let times: Vec<f64> = (0..5).map(|i| (i * 5) as f64).collect();
        let values: Vec<[f64; 2]> = (0..5).map(|i| [i as f64, 2.0 * i as f64]).collect();
        let t = Track::catmull_rom(&times, &values).unwrap();
        for (time, v) in times.iter().zip(&values) {
            assert_eq!(t.sample(*time), *v);
        }
        let filled = t.sample_uniform(1.0);
        assert_eq!(filled.len(), 21);
        assert!((filled[7][0] - 1.4).abs() < 1e-12 && (filled[7][1] - 2.8).abs() < 1e-12, "linear data stays linear");
        assert!(Track::catmull_rom(&[0.0, 0.0], &[[0.0; 2]; 2]).is_err());
    }

    #[test]
    fn key_correction_hits_every_key_and_blends_residuals_linearly_between() {
        let line = ScalarTrack::from_samples(&[0.0, 10.0], &[0.0, 10.0], Interpolation::Linear).unwrap();
        // Residuals +1 at t=0 and −1 at t=10, +2 at t=20 (past the curve's end it holds 10).
        let keys = [(0.0, 1.0), (10.0, 9.0), (20.0, 12.0)];
        let bent = (&line).corrected_to_keys(&keys);
        for (t, k) in keys {
            assert_eq!(bent.sample(t), k);
        }
        assert_eq!(bent.residual_at(5.0), 0.0);
        assert!((bent.sample(2.5) - (2.5 + 0.5)).abs() < 1e-12);
        assert_eq!(bent.residual_at(-3.0), 1.0, "before the first key its residual holds");
        assert_eq!(bent.residuals().len(), 3);
        let none = (&line).corrected_to_keys(&[]);
        assert_eq!(none.sample(3.0), line.sample(3.0));
    }

    #[test]
    fn samples_are_exact_at_their_times_and_linear_between() {
        let s = Samples::new(10.0, 1.0, vec![[0.0, 1.0], [2.0, 3.0], [4.0, 5.0]]).unwrap();
        assert_eq!(s.domain(), (10.0, 12.0));
        assert_eq!(s.sample(11.0), [2.0, 3.0]);
        assert_eq!(s.sample(11.5), [3.0, 4.0]);
        assert_eq!(s.sample(99.0), [4.0, 5.0]);
        let bent = s.corrected_to_keys(&[(10.0, [1.0, 1.0])]);
        assert_eq!(bent.sample(12.0), [5.0, 5.0], "one key shifts the whole curve");
        assert!(Samples::<f64>::new(0.0, 0.0, vec![1.0]).is_err());
        assert!(Samples::<f64>::new(0.0, 1.0, vec![]).is_err());
    }

    #[test]
    fn rotation_tracks_slerp() {
        let q1 = DQuat::from_rotation_y(1.0);
        let t = Track::from_samples(&[0.0, 1.0], &[DQuat::IDENTITY, q1], Interpolation::Linear).unwrap();
        let mid = t.sample(0.5);
        assert!(crate::rotation::angle_between(mid, DQuat::from_rotation_y(0.5)) < 1e-12);
    }
}
