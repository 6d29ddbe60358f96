//! Using an object, or acting in place (§4.2): any verb that is not locomotion, sitting, standing
//! up or turning. The library clip for the verb ([`crate::motion::MotionLibrary::retrieve`]) looped
//! to at least [`crate::animate::AnimateConfig::min_action_seconds`], its upper body over the
//! idle or seated lower body ([`crate::motion::blend_upper`]), the hands moved onto the target's
//! contacts by two-bone IK ([`crate::motion::reach_contacts`]; [`hand_contacts`]). A standing
//! character out of reach walks up to the target first; a small prop used in the hand is picked
//! up first ([`super::pick_up`]) and the action plays with it in the hand.

use glam::DVec3;
use inbetween_core::clip::Clip;
use inbetween_core::fk::forward;

use super::Step;
use crate::animate::builder::Builder;
use crate::animate::builder::ON_RIG;
use crate::animate::props::carries;
use crate::animate::spots::{dist2, heading_to, stand_point};
use crate::animate::{contacts_of, ContactJoint, JointContact};
use crate::catalogue::{Catalogue, ContactKind};
use crate::layout::geom;
use crate::motion::blend::{blend_upper, reach_contacts};
use crate::motion::ik::Limb;
use crate::motion::rig::Rig;
use crate::motion::{BlendParams, Contact};
use crate::scene::Scene;

impl Builder<'_> {
    /// An action in place (see the module comment): an "<verb>" segment with the hands' contacts.
    pub fn act(&mut self, step: &Step) {
        let ctx = self.ctx;
        let (scene, cat, rig, cfg) = (ctx.scene, ctx.cat, &ctx.rig, ctx.cfg);
        let (a, verb, obj) = (step.action, step.verb.as_str(), step.object);
        // "Puts the cup on the counter": a held prop is set down; one not held yet (but small
        // enough to carry) is picked up first and then set down.
        if let Some(o) = obj.filter(|_| super::put_down::PUT_VERBS.contains(&a.verb.as_str())) {
            let held = |b: &Self| b.props.iter().any(|p| p.object == o && p.put_down.is_none());
            if !held(self) && carries("take", "reach", None, scene, cat, o) {
                self.pick_up(o, step.speed);
            }
            if held(self) && self.put_down(o, step) {
                return;
            }
        }
        // A small prop used in the hand is picked up first and then carried: the action plays
        // with it in the hand, not with the hand on its resting place.
        let carried = obj.filter(|&o| carries(&a.verb, verb, a.preposition.as_deref(), scene, cat, o));
        if let Some(o) = carried {
            if !self.props.iter().any(|p| p.object == o && p.put_down.is_none()) {
                self.pick_up(o, step.speed);
            }
        }
        let hands_on = if carried.is_some() { None } else { obj };
        let action = ctx.lib.retrieve(verb).filter(|c| c.clip.skeleton() == &rig.skeleton).map(|c| c.clip.clone());
        if action.is_none() && verb != "stand" && verb != "idle" {
            self.notes.push(format!("{}: no clip for \"{}\"; standing instead", self.name, a.verb));
        }
        let clip_len = action.as_ref().map(|m| m.num_frames()).unwrap_or(0).max(1);
        let min = self.min_action_frames();
        let n = clip_len * min.div_ceil(clip_len).max(1);
        // A standing character walks up to a target out of reach first.
        if let (Some(o), None) = (hands_on, self.st.seated) {
            let to = stand_point(scene, cat, self.grid, o, self.st.pos, self.avoid);
            if dist2(to, self.st.pos) > cfg.approach_distance * cfg.approach_distance {
                let start = self.frames.len();
                let h = heading_to(to, geom::center(&scene.objects[o]), self.st.heading);
                self.walk(to, h, "walk", step.speed);
                self.push_segment("walk", start, Some(o), vec![o], Vec::new());
            }
        }
        // Face the target when standing.
        if let (Some(o), None) = (hands_on, self.st.seated) {
            self.st.heading = heading_to(self.st.pos, geom::center(&scene.objects[o]), self.st.heading);
        }
        let base = self.in_place(n);
        let base = crate::motion::rig::clip(rig, &base);
        let mut m = match &action {
            Some(act) => blend_upper(
                &base,
                act,
                &BlendParams { start: 0, end: None, blend_in: 8, blend_out: 0, looping: true, action_offset: 0 },
            )
            .expect(ON_RIG),
            None => base,
        };
        let start = self.frames.len();
        let mut contacts = Vec::new();
        if let (Some(o), true) = (hands_on, cfg.reach) {
            let (ik, jc) = hand_contacts(rig, &m, scene, cat, o, start);
            if !ik.is_empty() {
                m = reach_contacts(&m, &ik).expect(ON_RIG).0;
            }
            contacts = jc;
        }
        self.append(m.poses());
        let mut touching: Vec<usize> = obj.into_iter().collect();
        touching.extend(self.st.seated.map(|s| s.2));
        self.push_segment(verb, start, obj, touching, contacts);
    }
}

/// IK contacts (wrist targets) and cost contacts for a hand action on object `o`: keys take both
/// hands (fingers on the keys, ±10 cm along the object's width), a grip or strike point the right
/// hand, a top surface both wrists ±20 cm apart.
fn hand_contacts(
    rig: &Rig,
    m: &Clip,
    scene: &Scene,
    cat: &Catalogue,
    o: usize,
    start: usize,
) -> (Vec<Contact>, Vec<JointContact>) {
    let n = m.num_frames();
    let Some(c) = cat.get(&scene.objects[o].category) else { return (Vec::new(), Vec::new()) };
    // The character's left (heading 0 faces +Z with the left hand towards +X).
    let h = crate::motion::rig::heading_of(m.pose(0).rotations[rig.hips]);
    let across = DVec3::new(h.cos(), 0.0, -h.sin());
    let window = BlendParams { start: 0, end: None, blend_in: 10, blend_out: 0, looping: false, action_offset: 0 };
    // Hand length (wrist → finger), to put the fingers, not the wrist, on the keys.
    let g0 = forward(&rig.skeleton, &m.pose(0));
    let finger = rig.roles.fingertip(&rig.skeleton, inbetween_core::roles::Side::Left);
    let hand_len = finger.map(|f| (g0.positions[f] - g0.positions[rig.arms[0][3]]).length()).unwrap_or(0.1);
    let root = g0.positions[rig.hips];
    let mut ik = Vec::new();
    let mut jc = Vec::new();
    let kinds = [ContactKind::Keys, ContactKind::Grip, ContactKind::Strike, ContactKind::Top];
    let Some(kind) = kinds.into_iter().find(|k| c.contacts.iter().any(|p| p.kind == *k)) else { return (ik, jc) };
    let p = contacts_of(scene, cat, o, kind)
        .into_iter()
        .min_by(|a, b| {
            let d = |p: &[f32; 3]| (DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64) - root).length();
            d(a).total_cmp(&d(b))
        })
        .expect("a contact of that kind");
    let p = DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64);
    let v = |q: DVec3| [q.x as f32, q.y as f32, q.z as f32];
    let (s0, e0) = (start + window.blend_in, start + n);
    let mut add = |limb: Limb, joint: ContactJoint, point: DVec3, wrist_back: bool| {
        let target = if wrist_back {
            // The wrist stays a hand length short of the point, towards the character.
            let dir = DVec3::new(point.x - root.x, 0.0, point.z - root.z).normalize_or_zero();
            point - dir * hand_len
        } else {
            point
        };
        ik.push(Contact { limb, target, window: window.clone() });
        jc.push(JointContact { joint, kind, point: v(point), start: s0.min(e0), end: e0 });
    };
    match kind {
        ContactKind::Keys => {
            add(Limb::LeftArm, ContactJoint::LeftFinger, p + across * 0.1, true);
            add(Limb::RightArm, ContactJoint::RightFinger, p - across * 0.1, true);
        }
        ContactKind::Top => {
            add(Limb::LeftArm, ContactJoint::LeftWrist, p + across * 0.2, false);
            add(Limb::RightArm, ContactJoint::RightWrist, p - across * 0.2, false);
        }
        _ => add(Limb::RightArm, ContactJoint::RightWrist, p, false),
    }
    (ik, jc)
}
