//! Carried props (beyond the paper, whose scene is static): which objects a verb takes into the
//! hand ([`carries`]), how a held prop follows the hand ([`CarriedProp`]), furniture slid along the
//! floor ([`Slide`]: a chair pulled out from under a desk) and where any object is at a frame
//! ([`object_pose`]). Picking one up is [`super::action::pick_up`].

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

/// A piece of furniture a character slides along the floor (a tucked chair pulled out to sit on,
/// pushed back after): over frames `start..end` its offset from its scene place goes from `from`
/// to `to` (x, z metres, eased), then stays there.
#[derive(Debug, Clone, PartialEq)]
pub struct Slide {
    /// Index into [`Scene::objects`].
    pub object: usize,
    pub start: usize,
    pub end: usize,
    pub from: [f32; 2],
    pub to: [f32; 2],
}

impl Slide {
    /// The offset at `frame` (≥ `start`).
    pub fn offset_at(&self, frame: usize) -> [f32; 2] {
        let span = self.end.saturating_sub(self.start).max(1);
        let w = inbetween_core::interp::smoothstep(frame.saturating_sub(self.start) as f64 / span as f64) as f32;
        [self.from[0] + (self.to[0] - self.from[0]) * w, self.from[1] + (self.to[1] - self.from[1]) * w]
    }
}

/// The offset (x, z metres) slides have moved object `obj` by at `frame`: the latest slide
/// begun at or before it, None when none has.
pub fn slide_offset(anim: &Animation, obj: usize, frame: usize) -> Option<[f32; 2]> {
    anim.characters
        .iter()
        .flat_map(|c| c.slides.iter())
        .filter(|s| s.object == obj && s.start <= frame)
        .max_by_key(|s| s.start)
        .map(|s| s.offset_at(frame))
}

/// Whether object `obj` ever moves: carried by a hand or slid along the floor.
pub fn moves(anim: &Animation, obj: usize) -> bool {
    carried_from(anim, obj).is_some() || anim.characters.iter().any(|c| c.slides.iter().any(|s| s.object == obj))
}

/// Where object `obj` is at `frame`: its base point and rotation, carried by a character's hand
/// (the latest pick-up at or before `frame`), put down, slid along the floor, or at rest in the
/// scene.
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
    let [dx, dz] = slide_offset(anim, obj, frame).unwrap_or([0.0, 0.0]);
    let p = DVec3::new((o.position[0] + dx) as f64, o.position[1] as f64, (o.position[2] + dz) as f64);
    (p, DQuat::from_rotation_y(o.yaw as f64))
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
