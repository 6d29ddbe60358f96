//! Carried props (beyond the paper, whose scene is static): which objects a verb takes into the
//! hand ([`carries`]), how a held prop follows the hand ([`CarriedProp`]) and where any object is
//! at a frame ([`object_pose`]). Picking one up is [`super::action::pick_up`].

use glam::{DQuat, DVec3};
use inbetween_core::fk::forward;

use super::{Animation, CharacterTrack};
use crate::catalogue::{Catalogue, ContactKind};
use crate::scene::Scene;

/// A small prop a character holds (beyond the paper, whose scene is static): it rests at its
/// scene pose until frame `from`, when the hand closes on it, then follows that hand joint, to the
/// end (held after the track ends) or until it is put down ([`PutDown`]).
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
    /// Where and when the hand lets it go, if it does.
    pub put_down: Option<PutDown>,
}

/// A carried prop set down: from `frame` on it rests at `position` (its base point, world
/// metres) with `rotation`, on `support` (an object's top) or on the floor (None); over the
/// `blend` frames before, it moves from the hand's pose onto that rest.
#[derive(Debug, Clone, PartialEq)]
pub struct PutDown {
    pub frame: usize,
    pub position: DVec3,
    pub rotation: DQuat,
    pub support: Option<usize>,
    pub blend: usize,
}

impl CarriedProp {
    /// The prop's base point (world metres) and rotation at `frame` of the carrying `track`, None
    /// before it is picked up.
    pub fn pose_at(&self, track: &CharacterTrack, frame: usize) -> Option<(DVec3, DQuat)> {
        let n = track.clip.num_frames();
        if frame < self.from || n == 0 || self.joint >= track.clip.skeleton().len() {
            return None;
        }
        // The hand joint's position and rotation.
        let hand = |f: usize| {
            let g = forward(track.clip.skeleton(), &track.clip.pose(f.min(n - 1)));
            (g.positions[self.joint], g.rotations[self.joint])
        };
        // The grip in the prop's own frame (the hand joint holds it).
        let grip = -(self.rotation.inverse() * self.offset);
        match &self.put_down {
            Some(d) if frame >= d.frame => Some((d.position, d.rotation)),
            Some(d) if d.blend > 0 && frame + d.blend >= d.frame => {
                // The grip stays in the hand while the prop turns upright about it; the hand's
                // small miss of the rest grip at the release is taken up over the same frames.
                let (p, q) = hand(frame);
                let miss = (d.position + d.rotation * grip) - hand(d.frame).0;
                let w = inbetween_core::interp::smoothstep(1.0 - (d.frame - frame) as f64 / (d.blend + 1) as f64);
                let q = (q * self.rotation).normalize().slerp(d.rotation, w).normalize();
                Some((p + miss * w - q * grip, q))
            }
            _ => {
                let (p, q) = hand(frame);
                Some((p + q * self.offset, (q * self.rotation).normalize()))
            }
        }
    }
}

/// Where object `obj` is at `frame`: its base point and rotation, carried by a character's hand
/// (the latest pick-up at or before `frame`), put down, or at rest in the scene.
pub fn object_pose(anim: &Animation, obj: usize, frame: usize) -> (DVec3, DQuat) {
    let latest = anim
        .characters
        .iter()
        .flat_map(|c| c.props.iter().map(move |p| (c, p)))
        .filter(|(_, p)| p.object == obj && p.from <= frame)
        .max_by_key(|(_, p)| p.from);
    if let Some(pose) = latest.and_then(|(c, p)| p.pose_at(c, frame)) {
        return pose;
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
