//! Math-only curves sampled by time (after `bevy_math::curve`): keyed tracks of scalars, vectors
//! or rotations, used for blendshape weights, camera parameters and joint channels alike.

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
    fn rotation_tracks_slerp() {
        let q1 = DQuat::from_rotation_y(1.0);
        let t = Track::from_samples(&[0.0, 1.0], &[DQuat::IDENTITY, q1], Interpolation::Linear).unwrap();
        let mid = t.sample(0.5);
        assert!(crate::rotation::angle_between(mid, DQuat::from_rotation_y(0.5)) < 1e-12);
    }
}
