//! A clip prepared for keyframe jobs: the spherical representation the selectors work on (§3.1),
//! the local key poses the rotation reconstruction interpolates, the source's joint positions the
//! measured error compares against, all made once; and what the selectors learn on the clip
//! (greedy's insertion order, the optimal search's segment costs, SIDQL's window keyings), kept for
//! the next key count. [`crate::SelectJob`] and [`crate::ReconstructJob`] run on one.

use crate::metrics::ErrorMeasure;
use crate::rotations::RotationMotion;
use crate::select::sidql::{SidqlLong, SidqlPolicy};
use crate::select::{GreedyOrder, OptimalMemo};
use crate::{Result, SphericalMotion};
use glam::DVec3;
use inbetween_core::units::UnitChoice;
use inbetween_core::{positions_clip, Motion};
use std::sync::{Mutex, MutexGuard, OnceLock};

/// The longest clip whose optimal-search memo is kept (20·n² bytes: 80 MB at 2000 frames). With
/// it, the first optimal K costs seconds on 1000 frames and the next ones tens of milliseconds.
pub const OPTIMAL_MEMO_FRAMES: usize = 2000;

/// One clip and everything the keyframe jobs compute once per clip.
pub struct PreparedClip {
    pub motion: Motion,
    /// The clip's length unit and why (errors are reported in cm).
    pub unit: UnitChoice,
    /// The spherical representation the selectors work on (§3.1), lengths in cm.
    pub rep: SphericalMotion,
    /// Local rotations and velocities per frame: the key poses (and their tangents) of a
    /// reconstruction.
    pub rotations: RotationMotion,
    /// World joint positions per frame (file units), the reference of the measured error.
    pub positions: Vec<Vec<DVec3>>,
    greedy: Mutex<Option<GreedyOrder<'static>>>,
    optimal: Mutex<Option<OptimalMemo>>,
    sidql: Mutex<Option<SidqlLong<'static>>>,
}

impl PreparedClip {
    /// Prepares `motion`, its lengths in `unit`.
    pub fn new(motion: Motion, unit: UnitChoice) -> Result<PreparedClip> {
        let cm = unit.cm_per_unit();
        let mut rep = SphericalMotion::from_motion(&motion)?;
        rep.cm_per_unit = cm;
        let rotations = RotationMotion::from_motion_in(&motion, cm)?;
        let positions = positions_clip(&motion);
        Ok(PreparedClip {
            motion,
            unit,
            rep,
            rotations,
            positions,
            greedy: Mutex::new(None),
            optimal: Mutex::new(None),
            sidql: Mutex::new(None),
        })
    }

    /// [`PreparedClip::new`] with the unit inferred from the skeleton's rest pose.
    pub fn inferred(motion: Motion) -> Result<PreparedClip> {
        let unit = UnitChoice::resolve(None, &motion.skeleton);
        PreparedClip::new(motion, unit)
    }

    pub fn num_frames(&self) -> usize {
        self.motion.num_frames()
    }

    /// Greedy's insertion order on this clip (angle objective), grown as larger K are asked.
    pub(crate) fn greedy(&self) -> MutexGuard<'_, Option<GreedyOrder<'static>>> {
        self.greedy.lock().unwrap_or_else(|p| p.into_inner())
    }

    /// The optimal search's memo, for clips up to [`OPTIMAL_MEMO_FRAMES`] frames.
    pub(crate) fn optimal_memo(&self) -> Option<MutexGuard<'_, Option<OptimalMemo>>> {
        let n = self.num_frames();
        (n <= OPTIMAL_MEMO_FRAMES).then(|| {
            let mut memo = self.optimal.lock().unwrap_or_else(|p| p.into_inner());
            memo.get_or_insert_with(|| OptimalMemo::new(n, ErrorMeasure::Angle));
            memo
        })
    }

    /// SIDQL's windows of this clip and their keyings so far (the committed policy).
    pub(crate) fn sidql(&self) -> Result<MutexGuard<'_, Option<SidqlLong<'static>>>> {
        let mut sidql = self.sidql.lock().unwrap_or_else(|p| p.into_inner());
        if sidql.is_none() {
            *sidql = Some(SidqlLong::new(committed_policy()?, &self.motion, self.unit.cm_per_unit())?);
        }
        Ok(sidql)
    }
}

/// The committed SIDQL policy (weights compiled into the binary), loaded once per process.
pub fn committed_policy() -> Result<&'static SidqlPolicy> {
    static POLICY: OnceLock<SidqlPolicy> = OnceLock::new();
    if let Some(p) = POLICY.get() {
        return Ok(p);
    }
    let p = SidqlPolicy::committed()?;
    Ok(POLICY.get_or_init(|| p))
}
