//! Carried props (beyond the paper, whose scene is static): which objects a verb takes into the
//! hand ([`carries`]), how a held prop follows the hand ([`CarriedProp`]) and where any object is
//! at a frame ([`object_pose`]). Picking one up is [`super::action::pick_up`].

use glam::{DQuat, DVec3};
use inbetween_core::fk::forward;

use super::{Animation, CharacterTrack};
use crate::catalogue::{Catalogue, ContactKind};
use crate::scene::Scene;

/// A small prop a character holds (beyond the paper, whose scene is static): it rests at its
/// scene pose until frame `from`, when the hand closes on it, then follows that hand joint to the
/// end (held after the track ends).
#[derive(Debug, Clone, PartialEq)]
pub struct CarriedProp {
    /// Index into [`Scene::objects`].
    pub object: usize,
    /// Joint of the character's skeleton it follows (the right hand).
    pub joint: usize,
    /// First frame it is in the hand.
    pub from: usize,
    /// The prop's base point and rotation in the joint's frame: its grip point sits at the joint.
    pub offset: DVec3,
    pub rotation: DQuat,
}

impl CarriedProp {
    /// The prop's base point (world metres) and rotation at `frame` of the carrying `track`, None
    /// before it is picked up.
    pub fn pose_at(&self, track: &CharacterTrack, frame: usize) -> Option<(DVec3, DQuat)> {
        let n = track.clip.num_frames();
        if frame < self.from || n == 0 || self.joint >= track.clip.skeleton().len() {
            return None;
        }
        let g = forward(track.clip.skeleton(), &track.clip.pose(frame.min(n - 1)));
        let (p, q) = (g.positions[self.joint], g.rotations[self.joint]);
        Some((p + q * self.offset, (q * self.rotation).normalize()))
    }
}

/// Where object `obj` is at `frame`: its base point and rotation, carried by a character's hand
/// or at rest in the scene.
pub fn object_pose(anim: &Animation, obj: usize, frame: usize) -> (DVec3, DQuat) {
    for c in &anim.characters {
        for p in c.props.iter().filter(|p| p.object == obj) {
            if let Some(pose) = p.pose_at(c, frame) {
                return pose;
            }
        }
    }
    let o = &anim.scene.objects[obj];
    (DVec3::new(o.position[0] as f64, o.position[1] as f64, o.position[2] as f64), DQuat::from_rotation_y(o.yaw as f64))
}

/// The first frame from which object `obj` is in someone's hand, if it ever is.
pub fn carried_from(anim: &Animation, obj: usize) -> Option<usize> {
    anim.characters.iter().flat_map(|c| c.props.iter()).filter(|p| p.object == obj).map(|p| p.from).min()
}

/// Verb lemmas that take an object into the hand.
const TAKE_VERBS: &[&str] =
    &["pick", "take", "grab", "hold", "carry", "fetch", "lift", "get", "collect", "bring", "raise"];

/// Largest side (metres) of an object one hand carries.
const PROP_SIZE: f32 = 0.45;

/// Whether acting on `obj` with `verb` (lemma; `canonical` its library tag) carries it: a small
/// object that rests on a surface, has a grip and carries nothing, and a verb that takes it
/// ("picks up the phone") or uses it in the hand ("sings with the microphone", "drinks soda").
pub(crate) fn carries(
    verb: &str,
    canonical: &str,
    preposition: Option<&str>,
    scene: &Scene,
    cat: &Catalogue,
    obj: usize,
) -> bool {
    let o = &scene.objects[obj];
    let Some(c) = cat.get(&o.category) else { return false };
    let small = c.support == crate::catalogue::Support::Surface && o.size.iter().all(|&v| v <= PROP_SIZE);
    let grip = c.contacts.iter().any(|p| p.kind == ContactKind::Grip);
    let free = !scene.objects.iter().any(|x| x.support == Some(obj));
    let held = TAKE_VERBS.contains(&verb) || preposition == Some("with") || matches!(canonical, "drink" | "call");
    small && grip && free && held
}
