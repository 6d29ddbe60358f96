//! Reconstruction error (Eq. 15–18, 24) and per-segment costs.
//!
//! The paper's unit is the mean angle error: |Δθ| + |Δφ| summed over all angle-carrying joints and
//! frames (Eq. 15–17) and divided by the number of terms (frames × joints × 2), in radians; Eq. 24
//! averages it over clips. Beside it we report the mean per-joint position error (MPJPE) in cm and
//! its maximum, so results compare with position-based tools.
//!
//! Every frame strictly inside a segment depends only on that segment's two keyframes (Eq. 14), so
//! the total error is a sum of per-segment costs: [`SegmentTable`] tabulates them, which is what the
//! greedy, optimal and error-bounded selectors search over.

use crate::reconstruct::{segment_frame, SphericalReconstruction};
use crate::representation::SphericalMotion;
use glam::{DQuat, DVec3};
use inbetween_core::metrics::wrapped_angle_difference;
use inbetween_core::KeyframeSet;
use rayon::prelude::*;

/// The error of the frames strictly inside one segment.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SegmentCost {
    /// Sum of angle errors (radians) over the segment's frames and joints.
    pub angle_sum: f64,
    /// Sum of per-joint position errors in cm.
    pub cm_sum: f64,
    /// Largest per-joint position error in cm.
    pub cm_max: f64,
}

impl SegmentCost {
    pub fn combine(self, o: SegmentCost) -> SegmentCost {
        SegmentCost {
            angle_sum: self.angle_sum + o.angle_sum,
            cm_sum: self.cm_sum + o.cm_sum,
            cm_max: self.cm_max.max(o.cm_max),
        }
    }
}

/// What a selector minimises.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ErrorMeasure {
    /// The paper's mean angle error (Eq. 18).
    Angle,
    /// Mean per-joint position error.
    Position,
}

impl ErrorMeasure {
    #[inline]
    pub fn of(self, c: &SegmentCost) -> f64 {
        match self {
            ErrorMeasure::Angle => c.angle_sum,
            ErrorMeasure::Position => c.cm_sum,
        }
    }
}

/// Buffers a segment evaluation reuses, so the inner loops never allocate.
#[derive(Clone, Debug, Default)]
pub struct Scratch {
    pub angles: Vec<f64>,
    pub positions: Vec<DVec3>,
    pub rotations: Vec<DQuat>,
    pub locals: Vec<DQuat>,
    pub translations: Vec<DVec3>,
}

/// A reconstruction model whose in-betweens depend only on the two keys around them.
pub trait SegmentModel: Sync {
    fn num_frames(&self) -> usize;
    /// Joints counted by the position error.
    fn num_joints(&self) -> usize;
    /// Terms per frame of the angle mean (joints × 2 for θ, φ; joints for rotation errors).
    fn angle_terms_per_frame(&self) -> usize;
    fn scratch(&self) -> Scratch;
    /// The error of frame `f` reconstructed from keys `a < f < b`.
    fn frame_cost(&self, a: usize, b: usize, f: usize, scratch: &mut Scratch) -> SegmentCost;

    /// The error of the frames strictly between keys `a < b`.
    fn segment_cost(&self, a: usize, b: usize, scratch: &mut Scratch) -> SegmentCost {
        (a + 1..b).fold(SegmentCost::default(), |acc, f| acc.combine(self.frame_cost(a, b, f, scratch)))
    }

    /// Like [`SegmentModel::segment_cost`], but gives up with `None` as soon as one frame exceeds
    /// `max_cm`. Frames are visited from the middle outwards, where in-betweens drift most, so
    /// infeasible segments are rejected after a frame or two.
    fn segment_cost_within(&self, a: usize, b: usize, max_cm: f64, scratch: &mut Scratch) -> Option<SegmentCost> {
        let mid = (a + b) / 2;
        let mut acc = SegmentCost::default();
        for d in 0..b - a {
            let right = mid + d;
            let left = mid.checked_sub(d).filter(|_| d > 0);
            for f in [Some(right), left].into_iter().flatten().filter(|&f| f > a && f < b) {
                acc = acc.combine(self.frame_cost_within(a, b, f, max_cm, scratch)?);
            }
        }
        Some(acc)
    }

    /// Frame `f`'s cost, or `None` when it breaks the bound (`max_cm`, or a model's own bound).
    fn frame_cost_within(
        &self,
        a: usize,
        b: usize,
        f: usize,
        max_cm: f64,
        scratch: &mut Scratch,
    ) -> Option<SegmentCost> {
        Some(self.frame_cost(a, b, f, scratch)).filter(|c| c.cm_max <= max_cm)
    }

    /// Error of a whole keyframe set, as the sum of its segments.
    fn error(&self, keys: &KeyframeSet) -> ReconstructionError {
        let mut s = self.scratch();
        let total = keys
            .segments()
            .map(|(a, b)| self.segment_cost(a, b, &mut s))
            .fold(SegmentCost::default(), SegmentCost::combine);
        ReconstructionError::from_total(total, self.num_frames(), self.num_joints(), self.angle_terms_per_frame())
    }
}

/// Joint position error of a rebuilt clip against its source, in cm: per frame the mean distance
/// over joints, the mean of those over frames and the largest single joint distance.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct PositionError {
    pub per_frame_cm: Vec<f64>,
    pub mean_cm: f64,
    pub max_cm: f64,
}

impl PositionError {
    /// Compares world joint positions `[frame][joint]` (file units, `cm_per_unit` cm each).
    pub fn between(original: &[Vec<DVec3>], rebuilt: &[Vec<DVec3>], cm_per_unit: f64) -> PositionError {
        let mut max_cm = 0.0f64;
        let per_frame_cm: Vec<f64> = original
            .iter()
            .zip(rebuilt)
            .map(|(fa, fb)| {
                let mut sum = 0.0;
                for (x, y) in fa.iter().zip(fb) {
                    let d = x.distance(*y) * cm_per_unit;
                    max_cm = max_cm.max(d);
                    sum += d;
                }
                sum / fa.len().max(1) as f64
            })
            .collect();
        let mean_cm = per_frame_cm.iter().sum::<f64>() / per_frame_cm.len().max(1) as f64;
        PositionError { per_frame_cm, mean_cm, max_cm }
    }
}

impl std::fmt::Display for PositionError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "mean {:.2} cm, max {:.2} cm", self.mean_cm, self.max_cm)
    }
}

/// Mean angle error (radians), mean and max position error (cm) of one reconstruction.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct ReconstructionError {
    pub mean_angle: f64,
    pub mean_cm: f64,
    pub max_cm: f64,
}

impl ReconstructionError {
    /// Means over all frames of the clip (keyframes count, with zero error), Eq. 17–18.
    pub fn from_total(total: SegmentCost, frames: usize, joints: usize, angle_terms: usize) -> ReconstructionError {
        ReconstructionError {
            mean_angle: total.angle_sum / (frames * angle_terms.max(1)) as f64,
            mean_cm: total.cm_sum / (frames * joints.max(1)) as f64,
            max_cm: total.cm_max,
        }
    }
}

impl SegmentModel for SphericalMotion {
    fn num_frames(&self) -> usize {
        self.num_frames
    }

    fn num_joints(&self) -> usize {
        self.num_joints
    }

    fn angle_terms_per_frame(&self) -> usize {
        2 * self.angle_joint_count()
    }

    fn scratch(&self) -> Scratch {
        Scratch {
            angles: vec![0.0; 2 * self.num_joints],
            positions: vec![DVec3::ZERO; self.num_joints],
            ..Scratch::default()
        }
    }

    fn frame_cost(&self, a: usize, b: usize, f: usize, s: &mut Scratch) -> SegmentCost {
        let (n, nj) = (self.num_frames, self.num_joints);
        let mut cost = SegmentCost::default();
        segment_frame(self, a, b, f, &mut s.angles, &mut s.positions);
        for j in 0..nj {
            if self.has_angles[j] {
                let i = j * n + f;
                cost.angle_sum += (s.angles[2 * j] - self.theta[i]).abs()
                    + wrapped_angle_difference(s.angles[2 * j + 1], self.phi[i]);
            }
            let d = s.positions[j].distance(self.positions[f * nj + j]) * self.cm_per_unit;
            cost.cm_sum += d;
            cost.cm_max = cost.cm_max.max(d);
        }
        cost
    }
}

/// Error of a full reconstruction against its source, computed frame by frame (independent of the
/// segment decomposition; tests use it to check the tables).
pub fn spherical_error(rep: &SphericalMotion, rec: &SphericalReconstruction) -> ReconstructionError {
    let (n, nj) = (rep.num_frames, rep.num_joints);
    let mut total = SegmentCost::default();
    for j in 0..nj {
        if rep.has_angles[j] {
            for f in 0..n {
                let i = j * n + f;
                total.angle_sum +=
                    (rec.theta[i] - rep.theta[i]).abs() + wrapped_angle_difference(rec.phi[i], rep.phi[i]);
            }
        }
    }
    for (a, b) in rec.positions.iter().zip(&rep.positions) {
        let d = a.distance(*b) * rep.cm_per_unit;
        total.cm_sum += d;
        total.cm_max = total.cm_max.max(d);
    }
    ReconstructionError::from_total(total, n, nj, 2 * rep.angle_joint_count())
}

/// All segment costs with a gap of at most `max_gap` frames, stored as a band: row `a` holds
/// `b = a+1 ..= a+max_gap`.
#[derive(Clone, Debug)]
pub struct SegmentTable {
    pub num_frames: usize,
    pub max_gap: usize,
    costs: Vec<SegmentCost>,
}

impl SegmentTable {
    /// Every segment of the clip (max gap = the whole clip): the O(n²) table of a window.
    pub fn full(model: &dyn SegmentModel) -> SegmentTable {
        Self::banded(model, model.num_frames().saturating_sub(1).max(1))
    }

    /// Segments up to `max_gap` frames long, computed in parallel over rows.
    pub fn banded(model: &dyn SegmentModel, max_gap: usize) -> SegmentTable {
        Self::fill(model, max_gap, |a, b, scratch| model.segment_cost(a, b, scratch))
    }

    /// Segments up to `max_gap` frames long whose every frame stays within `max_cm`; the others are
    /// stored with an infinite `cm_max` (not computed in full), which is all the error-bounded
    /// selector needs to know about them.
    pub fn bounded(model: &dyn SegmentModel, max_gap: usize, max_cm: f64) -> SegmentTable {
        let infeasible = SegmentCost { angle_sum: f64::INFINITY, cm_sum: f64::INFINITY, cm_max: f64::INFINITY };
        Self::fill(model, max_gap, |a, b, scratch| {
            model.segment_cost_within(a, b, max_cm, scratch).unwrap_or(infeasible)
        })
    }

    /// Rows of segment costs `(a, a + 1 ..= a + max_gap)`, computed in parallel over rows with one
    /// scratch buffer per worker.
    fn fill(
        model: &dyn SegmentModel,
        max_gap: usize,
        cost: impl Fn(usize, usize, &mut Scratch) -> SegmentCost + Sync,
    ) -> SegmentTable {
        let n = model.num_frames();
        let g = max_gap.clamp(1, n.saturating_sub(1).max(1));
        let mut costs = vec![SegmentCost::default(); n * g];
        costs.par_chunks_mut(g).enumerate().for_each_init(
            || model.scratch(),
            |scratch, (a, row)| {
                for (k, slot) in row.iter_mut().enumerate() {
                    let b = a + k + 1;
                    if b < n {
                        *slot = cost(a, b, scratch);
                    }
                }
            },
        );
        SegmentTable { num_frames: n, max_gap: g, costs }
    }

    /// Same as [`SegmentTable::full`] on the calling thread only (for callers that already run
    /// many windows in parallel).
    pub fn full_serial(model: &dyn SegmentModel) -> SegmentTable {
        let n = model.num_frames();
        let g = n.saturating_sub(1).max(1);
        let mut costs = vec![SegmentCost::default(); n * g];
        let mut scratch = model.scratch();
        for a in 0..n {
            for b in a + 1..n {
                costs[a * g + (b - a - 1)] = model.segment_cost(a, b, &mut scratch);
            }
        }
        SegmentTable { num_frames: n, max_gap: g, costs }
    }

    /// Cost of segment `a < b`, if it is within the band.
    #[inline]
    pub fn get(&self, a: usize, b: usize) -> Option<&SegmentCost> {
        if a < b && b < self.num_frames && b - a <= self.max_gap {
            Some(&self.costs[a * self.max_gap + (b - a - 1)])
        } else {
            None
        }
    }

    /// Total cost of a keyframe set (None if a segment is outside the band).
    pub fn total(&self, keys: &KeyframeSet) -> Option<SegmentCost> {
        keys.segments().try_fold(SegmentCost::default(), |acc, (a, b)| self.get(a, b).map(|c| acc.combine(*c)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reconstruct::reconstruct_spherical;
    use crate::representation::JointFilter;
    use inbetween_core::procedural::{gait, GaitParams};

    #[test]
    fn segment_sums_equal_the_frame_by_frame_error() {
        let mut p = GaitParams::walk();
        p.frames = 40;
        let rep = SphericalMotion::from_motion(&JointFilter::paper().apply(&gait(&p))).unwrap();
        let keys = KeyframeSet::new(vec![9, 22, 30], 40).unwrap();
        let direct = spherical_error(&rep, &reconstruct_spherical(&rep, &keys));
        let summed = rep.error(&keys);
        let table = SegmentTable::full(&rep).total(&keys).unwrap();
        let tabled = ReconstructionError::from_total(table, 40, rep.num_joints, 2 * rep.angle_joint_count());
        for e in [summed, tabled] {
            assert!((e.mean_angle - direct.mean_angle).abs() < 1e-12);
            assert!((e.mean_cm - direct.mean_cm).abs() < 1e-9);
            assert!((e.max_cm - direct.max_cm).abs() < 1e-9);
        }
        assert!(direct.mean_angle > 0.0 && direct.max_cm > direct.mean_cm);
        let all = KeyframeSet::new((0..40).collect(), 40).unwrap();
        assert_eq!(rep.error(&all), ReconstructionError::default());
    }

    #[test]
    fn banded_table_matches_full_and_serial() {
        let mut p = GaitParams::run();
        p.frames = 30;
        let rep = SphericalMotion::from_motion(&JointFilter::paper().apply(&gait(&p))).unwrap();
        let full = SegmentTable::full(&rep);
        let serial = SegmentTable::full_serial(&rep);
        let band = SegmentTable::banded(&rep, 5);
        for a in 0..30 {
            for b in a + 1..30 {
                assert_eq!(full.get(a, b), serial.get(a, b));
                let bounded = SegmentTable::bounded(&rep, 29, 2.0);
                let c = full.get(a, b).unwrap();
                match bounded.get(a, b) {
                    Some(x) if x.cm_max.is_finite() => assert!((x.cm_sum - c.cm_sum).abs() < 1e-9 && c.cm_max <= 2.0),
                    _ => assert!(c.cm_max > 2.0),
                }
                if b - a <= 5 {
                    assert_eq!(full.get(a, b), band.get(a, b));
                } else {
                    assert!(band.get(a, b).is_none());
                }
            }
        }
    }
}
