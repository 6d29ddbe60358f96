//! The per-frame objectives the pruned search sums: any segment model's frame cost, or the angle
//! term alone (Eq. 24), vectorised over joints.

use crate::metrics::{ErrorMeasure, SegmentModel};
use crate::representation::SphericalMotion;
use inbetween_core::interp::hermite_basis;
use std::f64::consts::TAU;

/// One objective's error of the frames reconstructed from keys `a < b`, frame by frame: a segment's
/// cost is `0.0 + frame(a+1) + … + frame(b−1)` in this order.
pub(super) trait FrameObjective {
    /// Writes the error of frame `f` to `out[f − lo]` for every `f` in `lo..hi` (`a < lo ≤ hi ≤ b`).
    fn frames(&mut self, a: usize, b: usize, lo: usize, hi: usize, out: &mut [f64]);
}

/// Any model's frame cost through [`SegmentModel::frame_cost`] (the position objective).
pub(super) struct ModelFrames<'m> {
    pub(super) model: &'m dyn SegmentModel,
    pub(super) objective: ErrorMeasure,
    pub(super) scratch: crate::metrics::Scratch,
}

impl FrameObjective for ModelFrames<'_> {
    fn frames(&mut self, a: usize, b: usize, lo: usize, hi: usize, out: &mut [f64]) {
        for (f, o) in (lo..hi).zip(out) {
            *o = self.objective.of(&self.model.frame_cost(a, b, f, &mut self.scratch));
        }
    }
}

/// The angle term of [`SphericalMotion`]'s frame cost alone: θ and φ of every angle-carrying joint
/// by the Hermite cubic of `reconstruct::segment_frame`, against the source, with the same
/// floating-point operations in the same order (each frame sums its joints in joint order). Joints
/// are the vector lanes: the source is copied frame-major.
#[derive(Clone, Debug)]
pub(crate) struct AngleFrames {
    /// Angle-carrying joints.
    m: usize,
    /// θ, θ̇, φ, φ̇ of the angle-carrying joints, frame-major (`[frame * m + joint]`).
    theta: Vec<f64>,
    dtheta: Vec<f64>,
    phi: Vec<f64>,
    dphi: Vec<f64>,
    frame_time: f64,
    term: Vec<f64>,
}

impl AngleFrames {
    pub(crate) fn new(rep: &SphericalMotion) -> AngleFrames {
        let n = rep.num_frames;
        let angled: Vec<usize> = (0..rep.num_joints).filter(|&j| rep.has_angles[j]).collect();
        let pick = |v: &[f64]| (0..n).flat_map(|f| angled.iter().map(move |&j| v[j * n + f])).collect();
        AngleFrames {
            m: angled.len(),
            theta: pick(&rep.theta),
            dtheta: pick(&rep.dtheta),
            phi: pick(&rep.phi),
            dphi: pick(&rep.dphi),
            frame_time: rep.frame_time,
            term: vec![0.0; angled.len()],
        }
    }
}

impl FrameObjective for AngleFrames {
    fn frames(&mut self, a: usize, b: usize, lo: usize, hi: usize, out: &mut [f64]) {
        let mut term = std::mem::take(&mut self.term);
        self.eval(a, b, lo, hi, out, &mut term);
        self.term = term;
    }
}

impl AngleFrames {
    /// Angle-carrying joints: the length of the `term` buffer [`AngleFrames::eval`] needs.
    pub(crate) fn joints(&self) -> usize {
        self.m
    }

    /// The angle error of frames `lo..hi` reconstructed from keys `a < lo ≤ hi ≤ b`, into
    /// `out[f − lo]`, with `term` (at least [`AngleFrames::joints`] long) as scratch. Uses AVX2
    /// where the CPU has it (checked at run time): the same operations on wider vectors, so the
    /// same numbers.
    pub(crate) fn eval(&self, a: usize, b: usize, lo: usize, hi: usize, out: &mut [f64], term: &mut [f64]) {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU supports AVX2 (checked just above).
            unsafe { self.frames_avx2(a, b, lo, hi, out, term) };
            return;
        }
        self.frames_with(a, b, lo, hi, out, term);
    }

    /// The cost of segment `(a, b)`: its frames' errors summed in frame order (the same number as
    /// [`SegmentModel::segment_cost`]'s `angle_sum`). `buf` holds at least `b − a` values.
    pub(crate) fn segment(&self, a: usize, b: usize, buf: &mut [f64], term: &mut [f64]) -> f64 {
        self.eval(a, b, a + 1, b, &mut buf[..b - a - 1], term);
        buf[..b - a - 1].iter().fold(0.0, |s, t| s + t)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn frames_avx2(&self, a: usize, b: usize, lo: usize, hi: usize, out: &mut [f64], term: &mut [f64]) {
        self.frames_with(a, b, lo, hi, out, term);
    }

    #[inline(always)]
    pub(super) fn frames_with(&self, a: usize, b: usize, lo: usize, hi: usize, out: &mut [f64], term: &mut [f64]) {
        let m = self.m;
        fn row(v: &[f64], m: usize, f: usize) -> &[f64] {
            &v[f * m..][..m]
        }
        let at = |v, f| row(v, m, f);
        let (ta, tva, tb, tvb) = (at(&self.theta, a), at(&self.dtheta, a), at(&self.theta, b), at(&self.dtheta, b));
        let (pa, pva, pb, pvb) = (at(&self.phi, a), at(&self.dphi, a), at(&self.phi, b), at(&self.dphi, b));
        let term = &mut term[..m];
        // As `segment_frame` computes them.
        let h = (b - a) as f64 * self.frame_time;
        for (f, o) in (lo..hi).zip(out.iter_mut()) {
            let (h00, h10, h01, h11) = hermite_basis((f - a) as f64 / (b - a) as f64);
            let (h10, h11) = (h10 * h, h11 * h);
            let (tf, pf) = (at(&self.theta, f), at(&self.phi, f));
            // Core `hermite`: h00·p0 + h10·h·v0 + h01·p1 + h11·h·v1, left to right.
            let mut wide = false;
            for j in 0..m {
                let theta = h00 * ta[j] + h10 * tva[j] + h01 * tb[j] + h11 * tvb[j];
                let phi = h00 * pa[j] + h10 * pva[j] + h01 * pb[j] + h11 * pvb[j];
                let d = phi - pf[j];
                let within = d.abs() < TAU; // false for NaN too
                wide |= !within;
                let r = if d < 0.0 { d + TAU } else { d };
                term[j] = (theta - tf[j]).abs() + r.min(TAU - r);
            }
            if wide {
                // Some φ difference is a turn or more (or not a number): core's formula in full.
                for j in 0..m {
                    let theta = h00 * ta[j] + h10 * tva[j] + h01 * tb[j] + h11 * tvb[j];
                    let phi = h00 * pa[j] + h10 * pva[j] + h01 * pb[j] + h11 * pvb[j];
                    term[j] = (theta - tf[j]).abs() + wrapped_angle_difference(phi, pf[j]);
                }
            }
            *o = term.iter().fold(0.0, |s, t| s + t);
        }
    }
}

/// `inbetween_core::metrics::wrapped_angle_difference`, bit for bit, without the `fmod` call for
/// differences within a turn (where `d % τ` is `d` exactly).
#[inline]
pub(super) fn wrapped_angle_difference(a: f64, b: f64) -> f64 {
    let d = a - b;
    let r = if d.abs() < TAU {
        if d < 0.0 {
            d + TAU
        } else {
            d
        }
    } else {
        d.rem_euclid(TAU)
    };
    r.min(TAU - r)
}
