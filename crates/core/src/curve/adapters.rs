//! Curve adapters: each wraps one or two curves and is itself a [`Curve`], built by a provided
//! method of [`Curve`] (`corrected_to_keys`, `blended_with`, `cross_fade_to`, `looped`, `repeated`,
//! `time_warped`, `warped_by`, `placed`), so they chain: `walk.looped().placed(yaw, start)`.
//!
//! The value traits they need: [`Offset`] (differences, for key correction), [`Interpolate`]
//! (weighted mixes, for blends and cross-fades) and [`Placeable`] (a rigid move about the vertical,
//! for root placement).

use super::{Animatable, Curve, Interval};
use crate::interp::smoothstep;
use crate::motion::Pose;
use glam::{DQuat, DVec3};

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

/// Values that mix by a weight `u ∈ [0, 1]` (0 gives `self`, 1 gives `other`): what blends and
/// cross-fades need. Keyed values mix as their linear interpolation (slerp for rotations); a
/// [`Pose`] slerps every joint's rotation and interpolates every translation linearly.
pub trait Interpolate: Clone {
    fn interpolate(&self, other: &Self, u: f64) -> Self;
    /// [`Interpolate::interpolate`] written into `out` (no allocation for a [`Pose`] of the right size).
    fn interpolate_into(&self, other: &Self, u: f64, out: &mut Self) {
        *out = self.interpolate(other, u);
    }
}

impl<T: Animatable> Interpolate for T {
    fn interpolate(&self, other: &T, u: f64) -> T {
        T::linear(*self, *other, u)
    }
}

impl Interpolate for Pose {
    fn interpolate(&self, other: &Pose, u: f64) -> Pose {
        crate::motion::interpolate_pose(self, other, u)
    }
    fn interpolate_into(&self, other: &Pose, u: f64, out: &mut Pose) {
        out.rotations.clear();
        out.rotations.extend(self.rotations.iter().zip(&other.rotations).map(|(a, b)| a.slerp(*b, u)));
        out.translations.clear();
        out.translations.extend(self.translations.iter().zip(&other.translations).map(|(a, b)| a.lerp(*b, u)));
    }
}

/// Values that can be moved rigidly on the ground: turned by `turn` (a rotation about the vertical
/// +Y axis) about the origin, then shifted by `offset`. What [`Curve::placed`] needs.
pub trait Placeable {
    fn place(&mut self, turn: DQuat, offset: DVec3);
}

impl Placeable for DVec3 {
    fn place(&mut self, turn: DQuat, offset: DVec3) {
        *self = turn * *self + offset;
    }
}

/// A pose moves by its root (joint 0, parentless in every [`crate::Skeleton`]): the root's local
/// rotation is turned and its translation turned and shifted; the rest follows by forward kinematics.
impl Placeable for Pose {
    fn place(&mut self, turn: DQuat, offset: DVec3) {
        if let (Some(r), Some(t)) = (self.rotations.first_mut(), self.translations.first_mut()) {
            *r = (turn * *r).normalize();
            *t = turn * *t + offset;
        }
    }
}

/// A curve bent through keys (see [`Curve::corrected_to_keys`]); the camera engine's exact-key
/// correction (Jiang et al. 2021, Eq. 9 used as a post-correction).
#[derive(Clone, Debug, PartialEq)]
pub struct KeyCorrected<C, T> {
    pub(super) curve: C,
    pub(super) residuals: Vec<(f64, T)>,
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
    fn domain(&self) -> Interval {
        self.curve.domain()
    }
    fn sample_unchecked(&self, t: f64) -> T {
        T::offset(self.curve.sample_unchecked(t), self.residual_at(t))
    }
}

/// Two curves mixed by a constant weight (see [`Curve::blended_with`]): `a(t)` mixed towards
/// `b(t)` by `weight` (0 is `a`, 1 is `b`), over the times both are defined.
#[derive(Clone, Debug, PartialEq)]
pub struct Blend<A, B> {
    pub(super) a: A,
    pub(super) b: B,
    pub(super) weight: f64,
    pub(super) domain: Interval,
}

impl<T: Interpolate, A: Curve<T>, B: Curve<T>> Curve<T> for Blend<A, B> {
    fn domain(&self) -> Interval {
        self.domain
    }
    fn sample_unchecked(&self, t: f64) -> T {
        self.a.sample_unchecked(t).interpolate(&self.b.sample_unchecked(t), self.weight)
    }
    fn sample_unchecked_into(&self, t: f64, out: &mut T) {
        let a = self.a.sample_unchecked(t);
        let b = self.b.sample_unchecked(t);
        a.interpolate_into(&b, self.weight, out);
    }
}

/// A hand-over from one curve to another (see [`Curve::cross_fade_to`]): `a` before the fade,
/// `b` after it, and inside the fade interval `[t0, t1]` their mix by the smoothstep weight
/// `w = s((t − t0) / (t1 − t0))`, `s(x) = 3x² − 2x³` ([`smoothstep`]), so both value and slope
/// join without a jump.
#[derive(Clone, Debug, PartialEq)]
pub struct CrossFade<A, B> {
    pub(super) a: A,
    pub(super) b: B,
    pub(super) fade: Interval,
    pub(super) domain: Interval,
}

impl<A, B> CrossFade<A, B> {
    /// The weight of the second curve at `t` (0 before the fade, 1 after it).
    pub fn weight(&self, t: f64) -> f64 {
        if t <= self.fade.start() {
            0.0
        } else if t >= self.fade.end() {
            1.0
        } else {
            smoothstep((t - self.fade.start()) / self.fade.length())
        }
    }
}

impl<T: Interpolate, A: Curve<T>, B: Curve<T>> Curve<T> for CrossFade<A, B> {
    fn domain(&self) -> Interval {
        self.domain
    }
    fn sample_unchecked(&self, t: f64) -> T {
        match self.weight(t) {
            w if w <= 0.0 => self.a.sample_unchecked(t),
            w if w >= 1.0 => self.b.sample_unchecked(t),
            w => self.a.sample_unchecked(t).interpolate(&self.b.sample_unchecked(t), w),
        }
    }
    fn sample_unchecked_into(&self, t: f64, out: &mut T) {
        match self.weight(t) {
            w if w <= 0.0 => self.a.sample_unchecked_into(t, out),
            w if w >= 1.0 => self.b.sample_unchecked_into(t, out),
            w => {
                let a = self.a.sample_unchecked(t);
                let b = self.b.sample_unchecked(t);
                a.interpolate_into(&b, w, out);
            }
        }
    }
}

/// A curve played again and again (see [`Curve::looped`], [`Curve::repeated`]): time `t` maps to
/// `start + (t − start) mod length` of the inner domain. The inner curve's end is reached only at
/// the very end of a finite repetition; elsewhere a cycle boundary samples its start, so a seamless
/// loop needs a curve whose end equals its start.
#[derive(Clone, Debug, PartialEq)]
pub struct Repeat<C> {
    pub(super) curve: C,
    pub(super) inner: Interval,
    pub(super) domain: Interval,
}

impl<C> Repeat<C> {
    /// The inner curve's time for time `t` of the repetition.
    pub fn inner_time(&self, t: f64) -> f64 {
        if t >= self.domain.end() {
            return self.inner.end();
        }
        self.inner.start() + (t - self.inner.start()).rem_euclid(self.inner.length())
    }
}

impl<T, C: Curve<T>> Curve<T> for Repeat<C> {
    fn domain(&self) -> Interval {
        self.domain
    }
    fn sample_unchecked(&self, t: f64) -> T {
        self.curve.sample_unchecked(self.inner_time(t))
    }
    fn sample_unchecked_into(&self, t: f64, out: &mut T) {
        self.curve.sample_unchecked_into(self.inner_time(t), out)
    }
}

/// A curve read through a time map (see [`Curve::time_warped`]): `c(f(t))` over a given domain.
/// `f` must map that domain into the inner curve's domain; speed changes, reversal and easing are
/// time maps.
#[derive(Clone, Debug, PartialEq)]
pub struct TimeWarp<C, F> {
    pub(super) curve: C,
    pub(super) domain: Interval,
    pub(super) warp: F,
}

impl<T, C: Curve<T>, F: Fn(f64) -> f64> Curve<T> for TimeWarp<C, F> {
    fn domain(&self) -> Interval {
        self.domain
    }
    fn sample_unchecked(&self, t: f64) -> T {
        self.curve.sample_unchecked((self.warp)(t))
    }
    fn sample_unchecked_into(&self, t: f64, out: &mut T) {
        self.curve.sample_unchecked_into((self.warp)(t), out)
    }
}

/// A curve read through a time curve (see [`Curve::warped_by`]): `c(w(t))` over `w`'s domain, `w`
/// a keyed `Curve<f64>` whose values lie in `c`'s domain (e.g. a retiming track drawn by hand).
#[derive(Clone, Debug, PartialEq)]
pub struct CurveWarp<C, W> {
    pub(super) curve: C,
    pub(super) warp: W,
}

impl<T, C: Curve<T>, W: Curve<f64>> Curve<T> for CurveWarp<C, W> {
    fn domain(&self) -> Interval {
        self.warp.domain()
    }
    fn sample_unchecked(&self, t: f64) -> T {
        self.curve.sample_unchecked(self.warp.sample_unchecked(t))
    }
    fn sample_unchecked_into(&self, t: f64, out: &mut T) {
        self.curve.sample_unchecked_into(self.warp.sample_unchecked(t), out)
    }
}

/// A curve moved rigidly on the ground (see [`Curve::placed`]): every sample turned by `yaw`
/// radians about the vertical +Y axis through the origin, then shifted by `offset` (for a pose,
/// its root moves and the body follows).
#[derive(Clone, Debug, PartialEq)]
pub struct Placed<C> {
    pub(super) curve: C,
    pub(super) turn: DQuat,
    pub(super) offset: DVec3,
}

impl<C> Placed<C> {
    /// The rotation about +Y applied to every sample.
    pub fn turn(&self) -> DQuat {
        self.turn
    }
}

impl<T: Placeable, C: Curve<T>> Curve<T> for Placed<C> {
    fn domain(&self) -> Interval {
        self.curve.domain()
    }
    fn sample_unchecked(&self, t: f64) -> T {
        let mut v = self.curve.sample_unchecked(t);
        v.place(self.turn, self.offset);
        v
    }
    fn sample_unchecked_into(&self, t: f64, out: &mut T) {
        self.curve.sample_unchecked_into(t, out);
        out.place(self.turn, self.offset);
    }
}
