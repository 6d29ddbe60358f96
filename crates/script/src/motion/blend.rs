//! Blending a template action into locomotion (§4.2): the upper body (joints above the hips)
//! comes from the action, the lower body from the locomotion, both on the common skeleton; then
//! arm IK meets contact points given in world metres (§4.3 contact points, e.g. hands at a
//! keyboard).

use super::ik::{solve_limb, Limb};
use super::rig::{heading_of, local_from_global, yaw, Rig};
use crate::error::ScriptError;
use glam::DVec3;
use inbetween_core::clip::Clip;
use inbetween_core::fk::forward;

/// When and how the action plays over the locomotion (frames of the locomotion clip).
#[derive(Clone, Debug, PartialEq)]
pub struct BlendParams {
    /// First locomotion frame where the action starts (fading in from here).
    pub start: usize,
    /// Locomotion frame where the action has faded out (exclusive); None: to the end.
    pub end: Option<usize>,
    /// Fade-in and fade-out lengths, frames.
    pub blend_in: usize,
    pub blend_out: usize,
    /// Loop the action when it is shorter than the window; otherwise hold its last frame.
    pub looping: bool,
    /// First action frame used.
    pub action_offset: usize,
}

impl Default for BlendParams {
    fn default() -> BlendParams {
        BlendParams { start: 0, end: None, blend_in: 8, blend_out: 8, looping: true, action_offset: 0 }
    }
}

impl BlendParams {
    /// Weight of the action at locomotion frame `f` of a clip of `n` frames (0…1, smoothstep
    /// fades).
    pub fn weight(&self, f: usize, n: usize) -> f64 {
        let end = self.end.unwrap_or(n).min(n);
        if f < self.start || f >= end {
            return 0.0;
        }
        let smooth = inbetween_core::interp::smoothstep;
        let fade_in = if self.blend_in == 0 { 1.0 } else { smooth((f - self.start + 1) as f64 / self.blend_in as f64) };
        let fade_out = if self.blend_out == 0 || self.end.is_none() {
            1.0
        } else {
            smooth((end - f) as f64 / self.blend_out as f64)
        };
        fade_in.min(fade_out)
    }

    /// Action frame played at locomotion frame `f` (looped or held).
    pub fn action_frame(&self, f: usize, action_frames: usize) -> usize {
        let k = f.saturating_sub(self.start) + self.action_offset;
        if action_frames == 0 {
            0
        } else if self.looping {
            k % action_frames
        } else {
            k.min(action_frames - 1)
        }
    }
}

/// Upper body of `action` on the lower body of `locomotion` (§4.2). The upper body's root
/// (`LowerBack`) takes the action's orientation relative to the action's heading, re-expressed
/// under the locomotion's heading, so the torso follows where the walker faces; the other upper
/// joints take the action's local rotations. Both clips must be on the same skeleton and rate;
/// the result has the locomotion's length. An error says when the skeletons differ or names the
/// joint of the common rig missing.
pub fn blend_upper(locomotion: &Clip, action: &Clip, params: &BlendParams) -> Result<Clip, ScriptError> {
    if locomotion.skeleton() != action.skeleton() {
        return Err(ScriptError::Invalid(format!(
            "blending an action over locomotion needs both clips on one skeleton (the locomotion has {} joints, the action {})",
            locomotion.skeleton().len(),
            action.skeleton().len()
        )));
    }
    let rig = Rig::for_clip(locomotion, "blending an action over locomotion")?;
    let mask = rig.upper_body_mask();
    let n = locomotion.num_frames();
    let na = action.num_frames();
    let poses: Vec<_> = (0..n)
        .map(|f| {
            let mut p = locomotion.pose(f);
            let w = params.weight(f, n);
            if w <= 0.0 || na == 0 {
                return p;
            }
            let a = action.pose(params.action_frame(f, na));
            let ga = forward(action.skeleton(), &a);
            let gl = forward(locomotion.skeleton(), &p);
            // Upper-body root: heading-relative global orientation of the action.
            let rel = yaw(-heading_of(a.rotations[rig.hips])) * ga.rotations[rig.lower_back];
            let want = yaw(heading_of(p.rotations[rig.hips])) * rel;
            let lb = local_from_global(gl.rotations[rig.hips], want);
            for (j, &upper) in mask.iter().enumerate() {
                if !upper {
                    continue;
                }
                let target = if j == rig.lower_back { lb } else { a.rotations[j] };
                p.rotations[j] = p.rotations[j].slerp(target, w).normalize();
            }
            p
        })
        .collect();
    Ok(Clip::from_poses(locomotion.skeleton().clone(), locomotion.frame_time(), &poses)
        .expect("blended poses fit the skeleton"))
}

/// A hand (or foot) contact: the end of `limb` goes to `target` (world metres) over a window of
/// frames, with fades ([`BlendParams::weight`] semantics; `looping` and `action_offset` unused).
#[derive(Clone, Debug, PartialEq)]
pub struct Contact {
    pub limb: Limb,
    pub target: DVec3,
    pub window: BlendParams,
}

/// Meets contact points with two-bone IK (§4.2 "IK is used …", §4.3 contact cost made zero):
/// at each frame the limb end moves from where the motion puts it towards the contact by the
/// window's weight. Returns the clip and the largest remaining distance at full weight (m); an
/// error names the joint missing when `m` is not on the common rig.
pub fn reach_contacts(m: &Clip, contacts: &[Contact]) -> Result<(Clip, f64), ScriptError> {
    let rig = &Rig::for_clip(m, "reaching contacts")?;
    let n = m.num_frames();
    let mut worst: f64 = 0.0;
    let poses: Vec<_> = (0..n)
        .map(|f| {
            let mut p = m.pose(f);
            for c in contacts {
                let w = c.window.weight(f, n);
                if w <= 0.0 {
                    continue;
                }
                let end = c.limb.chain(rig)[2];
                let now = forward(&rig.skeleton, &p).positions[end];
                let err = solve_limb(rig, &mut p, c.limb, now.lerp(c.target, w), None);
                if w >= 1.0 {
                    worst = worst.max(err);
                }
            }
            p
        })
        .collect();
    Ok((Clip::from_poses(m.skeleton().clone(), m.frame_time(), &poses).expect("IK poses fit the skeleton"), worst))
}
