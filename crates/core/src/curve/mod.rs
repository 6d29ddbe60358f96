//! Math-only curves sampled by time (after `bevy_math::curve`): keyed tracks of scalars, vectors,
//! fixed-size arrays or rotations, runtime pose clips ([`crate::clip::Clip`]) and the adapters
//! that combine them, used for blendshape weights, camera parameters and joint poses alike.
//!
//! A [`Curve`] has a domain, an [`Interval`] of time, and sampling outside it is explicit:
//! [`Curve::sample`] returns `None` there, [`Curve::sample_clamped`] holds the nearest end, and
//! [`Curve::sample_unchecked`] is for callers that already know `t` is inside.
//! [`Curve::sample_unchecked_into`] writes into a value the caller owns, so sampling a
//! [`crate::Pose`] every frame does not allocate.
//!
//! Building blocks, each a [`Curve`]:
//! - [`Track`]: keys with step / linear / Hermite interpolation; [`Track::catmull_rom`] is the
//!   Catmull-Rom spline through samples (tangents by central differences, one-sided at the ends).
//! - [`Samples`]: values at evenly spaced times (a track already sampled per frame).
//! - [`crate::clip::Clip`]: a skeleton's local poses (rotations and translations per joint).
//!
//! Adapters (a small struct each, built by a provided method of [`Curve`]):
//! - [`KeyCorrected`] ([`Curve::corrected_to_keys`]): bent to pass through given keys, by adding
//!   each key's residual blended linearly between keys.
//! - [`Blend`] ([`Curve::blended_with`]): two curves mixed by a constant weight.
//! - [`CrossFade`] ([`Curve::cross_fade_to`]): one curve handing over to another across an interval
//!   with a smoothstep weight.
//! - [`Repeat`] ([`Curve::looped`], [`Curve::repeated`]): played forever or `n` times.
//! - [`TimeWarp`] ([`Curve::time_warped`]) and [`CurveWarp`] ([`Curve::warped_by`]): read through a
//!   function of time or a time curve (speed changes, retiming).
//! - [`Placed`] ([`Curve::placed`]): turned about the vertical and moved (a pose curve by its root).
//!
//! ```
//! use inbetween_core::curve::{Curve, Interval, Track};
//! // Network output every 5th frame, filled to every frame, then pinned to the keys.
//! let spline = Track::catmull_rom(&[0.0, 5.0, 10.0], &[[0.0, 1.0], [0.4, 1.2], [1.1, 1.0]]).unwrap();
//! let pinned = spline.corrected_to_keys(&[(0.0, [0.0, 1.0]), (10.0, [1.0, 1.0])]);
//! assert_eq!(pinned.domain(), Interval::new(0.0, 10.0).unwrap());
//! assert_eq!(pinned.sample(10.0), Some([1.0, 1.0]));
//! assert_eq!(pinned.sample(11.0), None, "outside the domain");
//! assert_eq!(pinned.sample_clamped(11.0), [1.0, 1.0]);
//! assert_eq!(pinned.sample_uniform(1.0).unwrap().len(), 11);
//! // Played twice, at half speed.
//! let slow = pinned.repeated(2).unwrap().time_warped(Interval::new(0.0, 40.0).unwrap(), |t| t / 2.0).unwrap();
//! assert_eq!(slow.sample(40.0), Some([1.0, 1.0]));
//! ```

mod adapters;
mod interval;
mod track;

pub use adapters::{
    Blend, CrossFade, CurveWarp, Interpolate, KeyCorrected, Offset, Placeable, Placed, Repeat, TimeWarp,
};
pub use interval::Interval;
pub use track::{Animatable, Interpolation, Key, Samples, ScalarTrack, Track};

use crate::CoreError;
use glam::{DQuat, DVec3};

/// Anything that yields a value for each time in its domain.
pub trait Curve<T> {
    /// The times where the curve is defined.
    fn domain(&self) -> Interval;

    /// Value at `t`, for a `t` the caller knows lies in the domain. Outside it the result is
    /// whatever the curve's formula gives there (keyed curves hold their nearest end; adapters
    /// pass `t` on): use [`Curve::sample`] or [`Curve::sample_clamped`] to be explicit.
    fn sample_unchecked(&self, t: f64) -> T;

    /// [`Curve::sample_unchecked`] written into `out`, which the caller owns; curves of
    /// heap-backed values (a [`crate::Pose`]) override it so playback does not allocate.
    fn sample_unchecked_into(&self, t: f64, out: &mut T) {
        *out = self.sample_unchecked(t);
    }

    /// Value at `t`, or `None` outside the domain.
    fn sample(&self, t: f64) -> Option<T> {
        self.domain().contains(t).then(|| self.sample_unchecked(t))
    }

    /// Value at the time in the domain nearest to `t` (the first or last value outside it).
    fn sample_clamped(&self, t: f64) -> T {
        self.sample_unchecked(self.domain().clamp(t))
    }

    /// [`Curve::sample_clamped`] written into `out`.
    fn sample_clamped_into(&self, t: f64, out: &mut T) {
        self.sample_unchecked_into(self.domain().clamp(t), out)
    }

    /// Samples at the domain's uniform times `start + i / rate` ([`Interval::uniform_times`]);
    /// fails on an unbounded domain or a rate that is not positive.
    fn sample_uniform(&self, rate: f64) -> Result<Vec<T>, CoreError> {
        Ok(self.domain().uniform_times(rate)?.map(|t| self.sample_unchecked(t)).collect())
    }

    /// This curve plus, at each time, the residuals `key − curve(t_key)` of the keys around it
    /// blended linearly ((1 − l)·r_a + l·r_b, l the position between the two key times; the
    /// nearest key's residual outside them), so the result passes through every key and keeps the
    /// curve's shape in between. Keys at strictly increasing times; a key outside the domain is
    /// measured against the curve's nearest end.
    fn corrected_to_keys(self, keys: &[(f64, T)]) -> KeyCorrected<Self, T>
    where
        Self: Sized,
        T: Offset,
    {
        let residuals = keys.iter().map(|&(t, k)| (t, T::difference(k, self.sample_clamped(t)))).collect();
        KeyCorrected { curve: self, residuals }
    }

    /// This curve mixed towards `other` by `weight` (0 keeps this one, 1 gives `other`), defined
    /// where both are. Fails on a weight outside `[0, 1]` or domains that do not meet.
    fn blended_with<C: Curve<T>>(self, other: C, weight: f64) -> Result<Blend<Self, C>, CoreError>
    where
        Self: Sized,
        T: Interpolate,
    {
        if !(0.0..=1.0).contains(&weight) {
            return Err(CoreError::InvalidCurve(format!("blend weight {weight} is outside [0, 1]")));
        }
        let domain = self.domain().intersect(other.domain()).ok_or_else(|| {
            CoreError::InvalidCurve(format!(
                "cannot blend curves on {} and {}: the domains do not meet",
                self.domain(),
                other.domain()
            ))
        })?;
        Ok(Blend { a: self, b: other, weight, domain })
    }

    /// This curve until `fade.start()`, `next` after `fade.end()`, and between them their mix by
    /// a smoothstep weight ([`CrossFade`]). The domain runs from this curve's start to `next`'s
    /// end; both curves must cover the fade, this one must start before it and `next` end after it.
    fn cross_fade_to<C: Curve<T>>(self, next: C, fade: Interval) -> Result<CrossFade<Self, C>, CoreError>
    where
        Self: Sized,
        T: Interpolate,
    {
        let (a, b) = (self.domain(), next.domain());
        if !a.contains_interval(fade) || !b.contains_interval(fade) {
            return Err(CoreError::InvalidCurve(format!(
                "cross-fade over {fade} needs both curves defined there (first on {a}, second on {b})"
            )));
        }
        let domain = Interval::new(a.start(), b.end())?;
        Ok(CrossFade { a: self, b: next, fade, domain })
    }

    /// This curve played forever, before and after its domain ([`Repeat`]). Fails on a domain
    /// that is unbounded or a single point.
    fn looped(self) -> Result<Repeat<Self>, CoreError>
    where
        Self: Sized,
    {
        let inner = repeatable(self.domain())?;
        Ok(Repeat { curve: self, inner, domain: Interval::EVERYWHERE })
    }

    /// This curve played `times` times from its start, ending on its last value ([`Repeat`]).
    fn repeated(self, times: usize) -> Result<Repeat<Self>, CoreError>
    where
        Self: Sized,
    {
        let inner = repeatable(self.domain())?;
        if times == 0 {
            return Err(CoreError::InvalidCurve("a curve repeated 0 times has no domain".into()));
        }
        let domain = Interval::new(inner.start(), inner.start() + inner.length() * times as f64)?;
        Ok(Repeat { curve: self, inner, domain })
    }

    /// This curve read at `warp(t)` for `t` in `domain` ([`TimeWarp`]); `warp` must map `domain`
    /// into this curve's domain (checked at both ends of `domain` when it is bounded).
    fn time_warped<F: Fn(f64) -> f64>(self, domain: Interval, warp: F) -> Result<TimeWarp<Self, F>, CoreError>
    where
        Self: Sized,
    {
        if domain.is_bounded() {
            for t in [domain.start(), domain.end()] {
                let w = warp(t);
                if !self.domain().contains(w) {
                    return Err(CoreError::InvalidCurve(format!(
                        "time warp maps {t} s to {w} s, outside the curve's domain {}",
                        self.domain()
                    )));
                }
            }
        }
        Ok(TimeWarp { curve: self, domain, warp })
    }

    /// This curve read at `warp(t)`, `warp` a curve of times ([`CurveWarp`]), over `warp`'s domain.
    fn warped_by<W: Curve<f64>>(self, warp: W) -> CurveWarp<Self, W>
    where
        Self: Sized,
    {
        CurveWarp { curve: self, warp }
    }

    /// This curve turned by `yaw` radians about the vertical +Y axis through the origin, then
    /// moved by `offset` ([`Placed`]); a pose curve moves by its root.
    fn placed(self, yaw: f64, offset: DVec3) -> Placed<Self>
    where
        Self: Sized,
        T: Placeable,
    {
        Placed { curve: self, turn: DQuat::from_rotation_y(yaw), offset }
    }
}

/// A domain one can repeat: bounded and longer than a point.
fn repeatable(d: Interval) -> Result<Interval, CoreError> {
    if !d.is_bounded() || d.length() <= 0.0 {
        return Err(CoreError::InvalidCurve(format!("only a bounded curve longer than an instant repeats (got {d})")));
    }
    Ok(d)
}

impl<T, C: Curve<T> + ?Sized> Curve<T> for &C {
    fn domain(&self) -> Interval {
        (**self).domain()
    }
    fn sample_unchecked(&self, t: f64) -> T {
        (**self).sample_unchecked(t)
    }
    fn sample_unchecked_into(&self, t: f64, out: &mut T) {
        (**self).sample_unchecked_into(t, out)
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
        assert_eq!(t.sample(0.5), Some(1.0));
        assert_eq!(t.sample(-1.0), None);
        assert_eq!(t.sample_clamped(-1.0), 0.0);
        assert_eq!(t.sample_clamped(5.0), 0.0);
        let mut s = t.clone();
        s.interpolation = Interpolation::Step;
        assert_eq!(s.sample_unchecked(1.5), 2.0);
        let mut h = t.clone();
        h.interpolation = Interpolation::Hermite;
        // Tangent at the peak is zero by central difference, so the Hermite curve peaks there.
        assert!((h.sample_unchecked(1.0) - 2.0).abs() < 1e-12);
        assert!(h.sample_unchecked(0.9) < 2.0 && h.sample_unchecked(0.9) > 1.8);
        assert_eq!(t.sample_uniform(2.0).unwrap().len(), 5);
    }

    #[test]
    fn catmull_rom_passes_through_samples_and_keeps_lines_straight() {
        let times: Vec<f64> = (0..5).map(|i| (i * 5) as f64).collect();
        let values: Vec<[f64; 2]> = (0..5).map(|i| [i as f64, 2.0 * i as f64]).collect();
        let t = Track::catmull_rom(&times, &values).unwrap();
        for (time, v) in times.iter().zip(&values) {
            assert_eq!(t.sample(*time), Some(*v));
        }
        let filled = t.sample_uniform(1.0).unwrap();
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
            assert_eq!(bent.sample_unchecked(t), k);
        }
        assert_eq!(bent.sample(20.0), None, "the key past the end does not widen the domain");
        assert_eq!(bent.residual_at(5.0), 0.0);
        assert!((bent.sample(2.5).unwrap() - (2.5 + 0.5)).abs() < 1e-12);
        assert_eq!(bent.residual_at(-3.0), 1.0, "before the first key its residual holds");
        assert_eq!(bent.residuals().len(), 3);
        let none = (&line).corrected_to_keys(&[]);
        assert_eq!(none.sample(3.0), line.sample(3.0));
    }

    #[test]
    fn samples_are_exact_at_their_times_and_linear_between() {
        let s = Samples::new(10.0, 1.0, vec![[0.0, 1.0], [2.0, 3.0], [4.0, 5.0]]).unwrap();
        assert_eq!(s.domain(), Interval::new(10.0, 12.0).unwrap());
        assert_eq!(s.sample(11.0), Some([2.0, 3.0]));
        assert_eq!(s.sample(11.5), Some([3.0, 4.0]));
        assert_eq!(s.sample(99.0), None);
        assert_eq!(s.sample_clamped(99.0), [4.0, 5.0]);
        let bent = s.corrected_to_keys(&[(10.0, [1.0, 1.0])]);
        assert_eq!(bent.sample(12.0), Some([5.0, 5.0]), "one key shifts the whole curve");
        assert!(Samples::<f64>::new(0.0, 0.0, vec![1.0]).is_err());
        assert!(Samples::<f64>::new(0.0, 1.0, vec![]).is_err());
    }

    #[test]
    fn rotation_tracks_slerp() {
        let q1 = DQuat::from_rotation_y(1.0);
        let t = Track::from_samples(&[0.0, 1.0], &[DQuat::IDENTITY, q1], Interpolation::Linear).unwrap();
        let mid = t.sample(0.5).unwrap();
        assert!(crate::rotation::angle_between(mid, DQuat::from_rotation_y(0.5)) < 1e-12);
    }

    fn ramp(t0: f64, t1: f64, v0: f64, v1: f64) -> ScalarTrack {
        ScalarTrack::from_samples(&[t0, t1], &[v0, v1], Interpolation::Linear).unwrap()
    }

    #[test]
    fn blend_mixes_by_weight_where_both_curves_exist() {
        let a = ramp(0.0, 10.0, 0.0, 10.0);
        let b = ramp(5.0, 20.0, 100.0, 100.0);
        let m = (&a).blended_with(&b, 0.25).unwrap();
        assert_eq!(m.domain(), Interval::new(5.0, 10.0).unwrap());
        assert_eq!(m.sample(8.0), Some(0.75 * 8.0 + 0.25 * 100.0));
        assert_eq!(m.sample(4.0), None);
        assert_eq!((&a).blended_with(&b, 0.0).unwrap().sample(6.0), a.sample(6.0));
        assert!((&a).blended_with(&b, 1.5).is_err());
        assert!((&a).blended_with(ramp(11.0, 12.0, 0.0, 0.0), 0.5).is_err(), "disjoint domains");
        // Rotations mix by slerp.
        let qa = Samples::new(0.0, 1.0, vec![DQuat::IDENTITY; 2]).unwrap();
        let qb = Samples::new(0.0, 1.0, vec![DQuat::from_rotation_y(1.0); 2]).unwrap();
        let q = qa.blended_with(qb, 0.5).unwrap().sample(0.5).unwrap();
        assert!(crate::rotation::angle_between(q, DQuat::from_rotation_y(0.5)) < 1e-12);
    }

    #[test]
    fn cross_fade_hands_over_smoothly_inside_the_fade_only() {
        let a = ramp(0.0, 10.0, 0.0, 0.0);
        let b = ramp(4.0, 20.0, 1.0, 1.0);
        let fade = Interval::new(4.0, 8.0).unwrap();
        let x = (&a).cross_fade_to(&b, fade).unwrap();
        assert_eq!(x.domain(), Interval::new(0.0, 20.0).unwrap());
        assert_eq!(x.sample(2.0), Some(0.0));
        assert_eq!(x.sample(4.0), Some(0.0));
        assert_eq!(x.sample(6.0), Some(0.5));
        assert_eq!(x.sample(5.0), Some(crate::interp::smoothstep(0.25)));
        assert_eq!(x.sample(8.0), Some(1.0));
        assert_eq!(x.sample(15.0), Some(1.0));
        // Slope is zero at both ends of the fade: no kink when a and b are constant.
        let e = 1e-6;
        assert!((x.sample_unchecked(4.0 + e) - x.sample_unchecked(4.0)) / e < 1e-5);
        assert!((x.sample_unchecked(8.0) - x.sample_unchecked(8.0 - e)) / e < 1e-5);
        assert!((&a).cross_fade_to(&b, Interval::new(9.0, 11.0).unwrap()).is_err(), "a ends inside the fade");
        assert!((&a).cross_fade_to(&b, Interval::new(3.0, 5.0).unwrap()).is_err(), "b starts inside the fade");
    }

    #[test]
    fn repeat_and_loop_wrap_time_into_the_domain() {
        let saw = ramp(1.0, 3.0, 0.0, 2.0);
        let looped = (&saw).looped().unwrap();
        assert_eq!(looped.domain(), Interval::EVERYWHERE);
        assert_eq!(looped.sample(2.0), Some(1.0));
        assert_eq!(looped.sample(4.0), Some(1.0));
        assert_eq!(looped.sample(0.0), Some(1.0), "before the start too");
        assert_eq!(looped.sample(3.0), Some(0.0), "a cycle boundary is the next cycle's start");
        let twice = (&saw).repeated(2).unwrap();
        assert_eq!(twice.domain(), Interval::new(1.0, 5.0).unwrap());
        assert_eq!(twice.sample(4.5), Some(1.5));
        assert_eq!(twice.sample(5.0), Some(2.0), "a finite repetition ends on the last value");
        assert_eq!(twice.sample(5.5), None);
        assert!((&saw).repeated(0).is_err());
        assert!(ramp(1.0, 3.0, 0.0, 2.0).looped().unwrap().looped().is_err(), "an endless curve cannot loop");
        let point = Samples::new(0.0, 1.0, vec![1.0]).unwrap();
        assert!(point.looped().is_err());
    }

    #[test]
    fn time_warps_map_time_through_a_function_or_a_curve() {
        let line = ramp(0.0, 10.0, 0.0, 10.0);
        let reversed = (&line).time_warped(line.domain(), |t| 10.0 - t).unwrap();
        assert_eq!(reversed.sample(2.0), Some(8.0));
        let fast = (&line).time_warped(Interval::new(0.0, 5.0).unwrap(), |t| 2.0 * t).unwrap();
        assert_eq!(fast.sample(2.5), Some(5.0));
        assert_eq!(fast.sample(6.0), None);
        assert!((&line).time_warped(Interval::new(0.0, 6.0).unwrap(), |t| 2.0 * t).is_err(), "12 s is past the end");
        // A retiming curve: hold the first 2 s, then catch up.
        let retime = ScalarTrack::from_samples(&[0.0, 2.0, 4.0], &[0.0, 0.0, 10.0], Interpolation::Linear).unwrap();
        let held = (&line).warped_by(&retime);
        assert_eq!(held.domain(), Interval::new(0.0, 4.0).unwrap());
        assert_eq!(held.sample(1.0), Some(0.0));
        assert_eq!(held.sample(3.0), Some(5.0));
    }

    #[test]
    fn placement_turns_about_the_vertical_then_moves() {
        let path = Samples::new(0.0, 1.0, vec![DVec3::ZERO, DVec3::Z]).unwrap();
        let placed = (&path).placed(std::f64::consts::FRAC_PI_2, DVec3::new(5.0, 0.0, 0.0));
        assert!((placed.sample(1.0).unwrap() - DVec3::new(6.0, 0.0, 0.0)).length() < 1e-12, "+Z turned onto +X");
        assert_eq!(placed.sample(0.0), Some(DVec3::new(5.0, 0.0, 0.0)));
        // A pose moves by its root only: children stay in the root's frame.
        let mut pose = crate::Pose {
            rotations: vec![DQuat::IDENTITY, DQuat::from_rotation_x(0.3)],
            translations: vec![DVec3::new(0.0, 1.0, 2.0), DVec3::new(0.0, 0.0, 1.0)],
        };
        let child = (pose.rotations[1], pose.translations[1]);
        pose.place(DQuat::from_rotation_y(std::f64::consts::PI), DVec3::new(1.0, 0.0, 0.0));
        assert!((pose.translations[0] - DVec3::new(1.0, 1.0, -2.0)).length() < 1e-12);
        assert!(
            crate::rotation::angle_between(pose.rotations[0], DQuat::from_rotation_y(std::f64::consts::PI)) < 1e-12
        );
        assert_eq!((pose.rotations[1], pose.translations[1]), child);
    }
}
