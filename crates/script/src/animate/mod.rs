//! Script part 2 (§4.2–4.3): the characters of a composed script acting in its furnished scene.
//!
//! For each character (character nodes of the query SSG grouped by name, actions in script
//! order) one timeline is built on the common rig ([`crate::motion::rig`]):
//! - "walk to X": an A* route on the layout's occupancy grid ([`Grid::astar`]) from where the
//!   character stands (the first start at the room's door, [`layout::door`]) to the free cell
//!   nearest X's stand point (its `Stand` contact, else a point just past a side of its support,
//!   `stand_point`), walked with
//!   [`walk_route`] (foot locking), ending turned towards X;
//! - "sit on X": walk to the point in front of X's seat contact, the sit-down clip placed so the
//!   pelvis lands on the seat (height corrected with the legs re-solved), then a seated loop;
//! - any other verb: when standing further than [`AnimateConfig::approach_distance`] from the
//!   target's stand point, a walk there first; then the library clip ([`MotionLibrary::retrieve`]) looped to at least
//!   [`AnimateConfig::min_action_seconds`], its upper body blended over the idle (or seated)
//!   lower body with [`crate::motion::blend_upper`], hands moved to the target's `Keys`/`Grip`/`Top`/`Strike`
//!   contacts with [`crate::motion::reach_contacts`] (two-bone IK, clamped when out of reach: the gap left is
//!   what the contact cost of [`crate::optimize`] measures);
//! - a small prop used in the hand ("sings with the microphone", "picks up the phone"): walked to
//!   (a seated character stands up and sits down again), picked up with the reach clip, then
//!   carried: it follows the right hand ([`CarriedProp`], [`object_pose`]) through the action.
//!
//! Stand points and seats keep clear of every spot an earlier character stands or sits at, so
//! two characters never share one.
//!
//! Several characters all start at frame 0 near the door (at least [`PASSING_DISTANCE`] apart);
//! a later character's grid blocks where earlier ones end up. [`crowd`] then keeps every pair of
//! roots [`PASSING_DISTANCE`] apart at every frame, standing and sitting included (prioritised
//! planning over space-time reservations: waits and detours, the later character yielding
//! first), and notes what it cannot solve. [`incremental::StorySession`] re-solves only the
//! characters (and the objects they touch) an edit changes.
//!
//! Segments are joined with a short cross-fade. Camera commands become [`CameraShot`]s and
//! [`camera_pose`] places the camera for a frame.

mod camera;
pub mod crowd;
pub mod incremental;

pub use camera::{camera_pose, camera_shots};
pub use crowd::{min_clearance, Clearance};
pub(crate) use crowd::{WalkChoice, WalkInfo};

use std::collections::HashMap;

use glam::{DQuat, DVec3};
use inbetween_core::fk::forward;
use inbetween_core::motion::interpolate_pose;
use inbetween_core::{Motion, Pose};

use crate::catalogue::{Catalogue, ContactKind};
use crate::compose::Composition;
use crate::layout::{self, geom, grid, grid::Grid};
use crate::motion::blend::{blend_upper_on, reach_contacts_on};
use crate::motion::ik::{solve_limb, Limb, PELVIS_ABOVE_SEAT};
use crate::motion::locomotion::place_clip_on;
use crate::motion::procedural::{seat_point, SEAT_HEIGHT};
use crate::motion::rig::{Rig, FPS};
use crate::motion::{walk_route, BlendParams, Contact, MotionLibrary, WalkParams};
use crate::scene::{Origin, Scene};
use crate::ssg::{NodeId, Ssg};

/// One action of a character's timeline: frames `[start, end)` of its motion.
#[derive(Debug, Clone, PartialEq)]
pub struct Segment {
    /// Verb lemma ("walk", "sit", "type"); an approach walk before "sit on X" is its own "walk".
    pub verb: String,
    pub start: usize,
    pub end: usize,
    /// Label of the scene object acted on, if any.
    pub target: Option<String>,
    /// Index of that object in [`Scene::objects`].
    pub object: Option<usize>,
    /// Objects the body may touch during the segment (the target, the seat sat on): the collision
    /// cost leaves them out.
    pub touching: Vec<usize>,
    /// Joint–contact pairs this segment aims at (the contact cost's P, Eq. 2).
    pub contacts: Vec<JointContact>,
}

/// The five contact joints of the contact cost (§4.3): hips, wrists, middle fingers.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ContactJoint {
    /// The pelvis (midpoint of the hip joints); its contact point is the seat point raised by
    /// [`PELVIS_ABOVE_SEAT`].
    Hips,
    LeftWrist,
    RightWrist,
    /// `LeftHandIndex1` (the rig's middle-finger stand-in).
    LeftFinger,
    RightFinger,
}

/// A contact point (world metres) a joint should be at over frames `[start, end)`.
#[derive(Debug, Clone, PartialEq)]
pub struct JointContact {
    pub joint: ContactJoint,
    pub kind: ContactKind,
    pub point: [f32; 3],
    pub start: usize,
    pub end: usize,
}

/// One character's animation.
#[derive(Debug, Clone, PartialEq)]
pub struct CharacterTrack {
    pub name: String,
    /// Common rig skeleton, metres, world placement, [`FPS`].
    pub motion: Motion,
    pub segments: Vec<Segment>,
    /// Small props the character picks up and carries (see [`CarriedProp`]).
    pub props: Vec<CarriedProp>,
}

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
        let n = track.motion.num_frames();
        if frame < self.from || n == 0 || self.joint >= track.motion.skeleton.len() {
            return None;
        }
        let g = forward(&track.motion.skeleton, &track.motion.pose(frame.min(n - 1)));
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

/// Horizontal distance (metres) from the root within which a hand picks a prop up without walking.
const PICK_REACH: f32 = 0.55;

/// Whether acting on `obj` with `verb` (lemma; `canonical` its library tag) carries it: a small
/// object that rests on a surface, has a grip and carries nothing, and a verb that takes it
/// ("picks up the phone") or uses it in the hand ("sings with the microphone", "drinks soda").
fn carries(verb: &str, canonical: &str, preposition: Option<&str>, scene: &Scene, cat: &Catalogue, obj: usize) -> bool {
    let o = &scene.objects[obj];
    let Some(c) = cat.get(&o.category) else { return false };
    let small = c.support == crate::catalogue::Support::Surface && o.size.iter().all(|&v| v <= PROP_SIZE);
    let grip = c.contacts.iter().any(|p| p.kind == ContactKind::Grip);
    let free = !scene.objects.iter().any(|x| x.support == Some(obj));
    let held = TAKE_VERBS.contains(&verb) || preposition == Some("with") || matches!(canonical, "drink" | "call");
    small && grip && free && held
}

/// A camera view held over frames `[start, end)`.
#[derive(Debug, Clone, PartialEq)]
pub struct CameraShot {
    /// "front", "back", "left", "right", "top", "close", "wide".
    pub view: String,
    pub start: usize,
    pub end: usize,
}

/// The animated scene.
#[derive(Debug, Clone, PartialEq)]
pub struct Animation {
    pub fps: f64,
    pub scene: Scene,
    pub characters: Vec<CharacterTrack>,
    pub camera: Vec<CameraShot>,
    /// What could not be done as asked (no route, no clip for a verb, unknown target).
    pub notes: Vec<String>,
}

impl Animation {
    /// Frames of the longest character track (at least 1).
    pub fn frames(&self) -> usize {
        self.characters.iter().map(|c| c.motion.num_frames()).max().unwrap_or(0).max(1)
    }
}

/// Settings of [`animate`].
#[derive(Debug, Clone, PartialEq)]
pub struct AnimateConfig {
    /// Short action clips are looped to at least this long, seconds.
    pub min_action_seconds: f64,
    /// Move hands to the target's contact points with IK.
    pub reach: bool,
    /// Foot locking while walking.
    pub lock_feet: bool,
    /// Cruise speed for "slowly", m/s.
    pub slow_speed: f64,
    /// Characters start this far apart along the door wall, metres.
    pub start_spacing: f32,
    /// Cross-fade between segments, frames.
    pub crossfade: usize,
    /// A standing character further than this (metres) from where it would use its target
    /// walks there before acting.
    pub approach_distance: f32,
}

impl Default for AnimateConfig {
    fn default() -> AnimateConfig {
        AnimateConfig {
            min_action_seconds: 2.0,
            reach: true,
            lock_feet: true,
            slow_speed: 0.7,
            start_spacing: 0.7,
            crossfade: 6,
            approach_distance: 0.6,
        }
    }
}

/// Animates every character of the composition in its scene (see the module comment).
pub fn animate(comp: &Composition, cat: &Catalogue, lib: &MotionLibrary, cfg: &AnimateConfig) -> Animation {
    animate_scene(&comp.scene, &comp.query, cat, lib, cfg)
}

/// [`animate`] for a scene and query graph given separately (the optimiser animates disturbed
/// copies of the scene).
pub fn animate_scene(
    scene: &Scene,
    query: &Ssg,
    cat: &Catalogue,
    lib: &MotionLibrary,
    cfg: &AnimateConfig,
) -> Animation {
    animate_cached(scene, query, cat, lib, cfg, &mut WalkCache::default())
}

/// Walks already generated, by route and parameters (a disturbed scene often leaves a route as
/// it was).
#[derive(Default)]
pub(crate) struct WalkCache {
    walks: HashMap<Vec<u64>, Motion>,
}

impl WalkCache {
    fn walk(&mut self, route: &[[f32; 2]], lib: &MotionLibrary, p: &WalkParams) -> Motion {
        let mut key: Vec<u64> = route.iter().map(|q| ((q[0].to_bits() as u64) << 32) | q[1].to_bits() as u64).collect();
        key.push(p.speed.unwrap_or(-1.0).to_bits());
        key.push(p.initial_heading.unwrap_or(9.0).to_bits());
        key.push(p.final_heading.unwrap_or(9.0).to_bits());
        key.push(p.verb.bytes().fold(0u64, |h, b| h.wrapping_mul(131).wrapping_add(b as u64)));
        key.push(p.lock_feet as u64);
        if let Some(m) = self.walks.get(&key) {
            return m.clone();
        }
        let m = walk_route(route, lib, p);
        self.walks.insert(key, m.clone());
        m
    }
}

/// The scene object a query node became: the object placed for that node, else the first of the
/// same category.
pub fn object_of_node(scene: &Scene, query: &Ssg, node: NodeId) -> Option<usize> {
    scene.objects.iter().position(|o| matches!(o.origin, Origin::Script { node: n, .. } if n == node)).or_else(|| {
        let cat = &query.objects.get(node)?.category;
        scene.objects.iter().position(|o| &o.category == cat)
    })
}

/// World position of an object's contact point: the catalogue's local point scaled by the
/// object's size over the category's, turned and moved with the object.
pub fn contact_world(scene: &Scene, cat: &Catalogue, obj: usize, local: [f32; 3]) -> [f32; 3] {
    let o = &scene.objects[obj];
    let base = cat.get(&o.category).map(|c| c.size).unwrap_or(o.size);
    let s = |k: usize| if base[k] > 1e-6 { o.size[k] / base[k] } else { 1.0 };
    let xz = geom::to_world(geom::center(o), o.yaw, [local[0] * s(0), local[2] * s(2)]);
    [xz[0], o.position[1] + local[1] * s(1), xz[1]]
}

/// Contact points of an object of one kind, world metres.
pub fn contacts_of(scene: &Scene, cat: &Catalogue, obj: usize, kind: ContactKind) -> Vec<[f32; 3]> {
    let Some(c) = cat.get(&scene.objects[obj].category) else { return Vec::new() };
    c.contacts.iter().filter(|p| p.kind == kind).map(|p| contact_world(scene, cat, obj, p.local)).collect()
}

/// A character's actions with their sentence, grouped by name in order of appearance.
pub(crate) fn characters(query: &Ssg) -> Vec<(String, Actions)> {
    let mut out: Vec<(String, Vec<(usize, crate::ssg::Action)>)> = Vec::new();
    let mut nodes: Vec<&crate::ssg::CharacterNode> = query.characters.iter().collect();
    nodes.sort_by_key(|c| c.sentence);
    for c in nodes {
        let key = c.name.to_lowercase();
        let acts = c.actions.iter().map(|a| (c.sentence, a.clone()));
        match out.iter_mut().find(|(n, _)| n.to_lowercase() == key) {
            Some((_, list)) => list.extend(acts),
            None => out.push((c.name.clone(), acts.collect())),
        }
    }
    out
}

/// Where a character is between actions.
struct State {
    pos: [f32; 2],
    heading: f64,
    /// Seated: (stand point in front of the seat, seat point, object).
    seated: Option<([f32; 2], [f32; 3], usize)>,
}

/// Builds one character's frames.
struct Builder<'a> {
    rig: Rig,
    lib: &'a MotionLibrary,
    fallback: Option<MotionLibrary>,
    cfg: &'a AnimateConfig,
    frames: Vec<Pose>,
    segments: Vec<Segment>,
    /// Per walk (in order): how long to wait first and which route to take (set by
    /// [`crowd::separate`]; the default walks at once along the A* route).
    choices: &'a [WalkChoice],
    /// The walks made so far.
    walks: Vec<WalkInfo>,
    /// Seat points (x, z) sat on.
    seats: Vec<[f32; 2]>,
    /// Props picked up so far.
    props: Vec<CarriedProp>,
}

/// Closest approach (metres) between two characters' roots that [`crowd::separate`] accepts.
pub const PASSING_DISTANCE: f32 = 0.5;

fn smooth(t: f64) -> f64 {
    let t = t.clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

impl<'a> Builder<'a> {
    /// A clip of the library on the common rig, by exact name, else from the procedural library.
    fn named(&mut self, name: &str) -> Motion {
        if let Some(c) = self.lib.get(name).filter(|c| c.motion.skeleton == self.rig.skeleton) {
            return c.motion.clone();
        }
        let proc = self.fallback.get_or_insert_with(|| MotionLibrary::procedural(0));
        proc.get(name).expect("procedural clip").motion.clone()
    }

    fn idle_clip(&mut self) -> Motion {
        match self.lib.retrieve("idle").filter(|c| c.motion.skeleton == self.rig.skeleton) {
            Some(c) => c.motion.clone(),
            None => self.named("procedural idle"),
        }
    }

    /// Appends poses, cross-fading the first few from the last frame.
    fn append(&mut self, mut poses: Vec<Pose>) {
        if let Some(last) = self.frames.last().cloned() {
            let n = self.cfg.crossfade.min(poses.len());
            for (k, p) in poses.iter_mut().take(n).enumerate() {
                let w = smooth((k + 1) as f64 / (n + 1) as f64);
                *p = interpolate_pose(&last, p, w);
            }
        }
        self.frames.extend(poses);
    }

    /// `n` frames of a looped clip with its origin placed at `at`, facing `heading`.
    fn looped(&self, clip: &Motion, at: [f32; 2], heading: f64, n: usize) -> Vec<Pose> {
        let placed = place_clip_on(&self.rig, clip, at, heading).poses();
        (0..n).map(|k| placed[k % placed.len()].clone()).collect()
    }

    /// Raises the root by `dy(k)` at frame k, re-solving the legs so the ankles stay put.
    fn lift(&self, poses: &mut [Pose], dy: impl Fn(usize) -> f64) {
        for (k, p) in poses.iter_mut().enumerate() {
            let d = dy(k);
            if d.abs() < 1e-5 {
                continue;
            }
            let g = forward(&self.rig.skeleton, p);
            let ankles = [g.positions[self.rig.legs[0][2]], g.positions[self.rig.legs[1][2]]];
            p.translations[self.rig.hips].y += d;
            for (leg, a) in [Limb::LeftLeg, Limb::RightLeg].into_iter().zip(ankles) {
                solve_limb(&self.rig, p, leg, a, None);
            }
        }
    }

    /// Seated loop frames on a seat (stand point `at`, seat point `seat`, facing `heading`).
    fn seated(&mut self, at: [f32; 2], seat: [f32; 3], heading: f64, n: usize) -> Vec<Pose> {
        let clip = self.named("procedural sit");
        let mut poses = self.looped(&clip, at, heading, n);
        let dy = seat[1] as f64 - SEAT_HEIGHT;
        self.lift(&mut poses, |_| dy);
        poses
    }

    fn push_segment(
        &mut self,
        verb: &str,
        start: usize,
        object: Option<usize>,
        scene: &Scene,
        touching: Vec<usize>,
        contacts: Vec<JointContact>,
    ) {
        self.segments.push(Segment {
            verb: verb.to_string(),
            start,
            end: self.frames.len(),
            target: object.map(|o| scene.objects[o].label.clone()),
            object,
            touching,
            contacts,
        });
    }

    /// Stands up from a seat (if seated).
    fn stand_up(&mut self, st: &mut State, scene: &Scene) {
        let Some((at, seat, obj)) = st.seated.take() else { return };
        let clip = self.named("procedural stand up");
        let mut poses = place_clip_on(&self.rig, &clip, at, st.heading).poses();
        let n = poses.len().max(2);
        let dy = seat[1] as f64 - SEAT_HEIGHT;
        self.lift(&mut poses, |k| dy * (1.0 - smooth(k as f64 / (n - 1) as f64)));
        let start = self.frames.len();
        self.append(poses);
        self.push_segment("stand_up", start, Some(obj), scene, vec![obj], Vec::new());
        st.pos = at;
    }

    /// Walks to the point in front of seat `s` of object `o`, sits down (pelvis onto the seat) and
    /// stays seated `hold` frames: a "walk" and a "sit" segment, the latter with the hips contact.
    #[allow(clippy::too_many_arguments)]
    fn sit_on(
        &mut self,
        st: &mut State,
        scene: &Scene,
        g: &Grid,
        o: usize,
        s: [f32; 3],
        hold: usize,
        speed: Option<f64>,
        cache: &mut WalkCache,
        notes: &mut Vec<String>,
        name: &str,
    ) {
        let yaw = scene.objects[o].yaw as f64;
        let sp = seat_point();
        let f = [yaw.sin(), yaw.cos()];
        // The sit-down clip's seat lies `-sp.z` behind where it starts.
        let at = [s[0] + (-sp.z * f[0]) as f32, s[2] + (-sp.z * f[1]) as f32];
        let start = self.frames.len();
        self.walk(st, g, at, yaw, "walk", speed, cache, notes, name);
        self.push_segment("walk", start, Some(o), scene, vec![o], Vec::new());
        let start = self.frames.len();
        let clip = self.named("procedural sit down");
        let mut poses = place_clip_on(&self.rig, &clip, st.pos, yaw).poses();
        let n = poses.len().max(2);
        let dy = s[1] as f64 - SEAT_HEIGHT;
        self.lift(&mut poses, |k| dy * smooth(k as f64 / (n - 1) as f64));
        self.append(poses);
        let seated_from = self.frames.len();
        let poses = self.seated(st.pos, s, yaw, hold.max(1));
        self.append(poses);
        st.seated = Some((st.pos, s, o));
        self.seats.push([s[0], s[2]]);
        let hips = JointContact {
            joint: ContactJoint::Hips,
            kind: ContactKind::Seat,
            point: [s[0], s[1] + PELVIS_ABOVE_SEAT as f32, s[2]],
            start: seated_from,
            end: self.frames.len(),
        };
        self.push_segment("sit", start, Some(o), scene, vec![o], vec![hips]);
    }

    /// Picks up prop `o` with the right hand: from where the character is when the grip is within
    /// [`PICK_REACH`], else (standing up first if seated) after walking to the prop, and back to
    /// the seat afterwards. The reach clip plays with the wrist brought onto the grip by IK (the
    /// root lowered, legs bent, for a prop low down); at the frame the hand is there the prop is
    /// taken ([`CarriedProp`]), and a "pick_up" segment measures the wrist on the grip.
    #[allow(clippy::too_many_arguments)]
    fn pick_up(
        &mut self,
        st: &mut State,
        scene: &Scene,
        cat: &Catalogue,
        g: &Grid,
        o: usize,
        avoid: &[[f32; 2]],
        speed: Option<f64>,
        cache: &mut WalkCache,
        notes: &mut Vec<String>,
        name: &str,
    ) {
        let Some(grip) = contacts_of(scene, cat, o, ContactKind::Grip).into_iter().next() else { return };
        let gxz = [grip[0], grip[2]];
        let seat_before = st.seated;
        if dist2(gxz, st.pos) > PICK_REACH * PICK_REACH {
            self.stand_up(st, scene);
            let to = stand_point(scene, cat, g, o, st.pos, avoid);
            let start = self.frames.len();
            let h = heading_to(to, gxz, st.heading);
            self.walk(st, g, to, h, "walk", speed, cache, notes, name);
            self.push_segment("walk", start, Some(o), scene, vec![o], Vec::new());
        }
        if st.seated.is_none() {
            st.heading = heading_to(st.pos, gxz, st.heading);
        }
        let rig = self.rig.clone();
        let clip = match self.lib.retrieve("reach").filter(|c| c.motion.skeleton == rig.skeleton) {
            Some(c) => c.motion.clone(),
            None => self.named("procedural reach"),
        };
        let n = clip.num_frames().max(30);
        let base = match st.seated {
            Some((at, s, _)) => self.seated(at, s, st.heading, n),
            None => {
                let idle = self.idle_clip();
                self.looped(&idle, st.pos, st.heading, n)
            }
        };
        let base = crate::motion::rig::clip(&rig, &base);
        let m = blend_upper_on(
            &rig,
            &base,
            &clip,
            &BlendParams { start: 0, end: None, blend_in: 8, blend_out: 0, looping: false, action_offset: 0 },
        );
        // The hand closes at frame `grab`: IK weight rises to 1 there and falls after.
        let grab = n / 2;
        let bump = |k: usize| {
            if k <= grab {
                smooth(k as f64 / grab as f64)
            } else {
                smooth((n - 1 - k) as f64 / (n - 1 - grab) as f64)
            }
        };
        let mut poses = m.poses();
        if st.seated.is_none() {
            // For a prop below the hands' reach (a microphone on the floor) bend the knees and
            // lean the back forward, about the character's left axis.
            let low = ((0.75 - grip[1] as f64) / 0.6).clamp(0.0, 1.0);
            self.lift(&mut poses, |k| -0.5 * low * bump(k));
            let left = DVec3::new(st.heading.cos(), 0.0, -st.heading.sin());
            for (k, p) in poses.iter_mut().enumerate() {
                let lean = 0.9 * low * bump(k);
                if lean > 1e-4 {
                    let gl = forward(&rig.skeleton, p);
                    let parent = rig.skeleton.parent(rig.lower_back).map_or(DQuat::IDENTITY, |j| gl.rotations[j]);
                    let want = DQuat::from_axis_angle(left, lean) * gl.rotations[rig.lower_back];
                    p.rotations[rig.lower_back] = crate::motion::rig::local_from_global(parent, want);
                }
            }
        }
        let m = crate::motion::rig::clip(&rig, &poses);
        let window = BlendParams {
            start: 0,
            end: Some(n),
            blend_in: grab,
            blend_out: n - grab,
            looping: false,
            action_offset: 0,
        };
        let target = DVec3::new(grip[0] as f64, grip[1] as f64, grip[2] as f64);
        let m = reach_contacts_on(&rig, &m, &[Contact { limb: Limb::RightArm, target, window }]).0;
        // The prop's grip goes to the hand joint; its rotation relative to the hand stays as it
        // was at the grab.
        let hand = rig.arms[1][3];
        let gp = forward(&rig.skeleton, &m.pose(grab));
        let wq = gp.rotations[hand];
        let obj = &scene.objects[o];
        let q_obj = DQuat::from_rotation_y(obj.yaw as f64);
        let base_point = DVec3::new(obj.position[0] as f64, obj.position[1] as f64, obj.position[2] as f64);
        let rotation = (wq.inverse() * q_obj).normalize();
        let grip_from_base = q_obj.inverse() * (target - base_point);
        let offset = -(rotation * grip_from_base);
        let start = self.frames.len();
        self.append(m.poses());
        self.props.push(CarriedProp { object: o, joint: hand, from: start + grab, offset, rotation });
        let contact = JointContact {
            joint: ContactJoint::RightWrist,
            kind: ContactKind::Grip,
            point: grip,
            start: start + grab.saturating_sub(2),
            end: start + grab + 3,
        };
        let mut touching = vec![o];
        touching.extend(st.seated.map(|s| s.2));
        self.push_segment("pick_up", start, Some(o), scene, touching, vec![contact]);
        // Back to the seat it left.
        if let (Some((_, s, so)), None) = (seat_before, st.seated) {
            self.sit_on(st, scene, g, so, s, 10, speed, cache, notes, name);
        }
    }

    /// Walks along a route to `to`, turning to `final_heading`, after waiting in place as this
    /// walk's [`WalkChoice`] says.
    #[allow(clippy::too_many_arguments)]
    fn walk(
        &mut self,
        st: &mut State,
        grid: &Grid,
        to: [f32; 2],
        final_heading: f64,
        verb: &str,
        speed: Option<f64>,
        cache: &mut WalkCache,
        notes: &mut Vec<String>,
        name: &str,
    ) {
        let choice = self.choices.get(self.walks.len()).cloned().unwrap_or_default();
        let route = match choice.route {
            Some(r) => r,
            None => route(grid, st.pos, to).unwrap_or_else(|| {
                notes.push(format!(
                    "{name}: no route from ({:.2}, {:.2}) to ({:.2}, {:.2}); walking straight",
                    st.pos[0], st.pos[1], to[0], to[1]
                ));
                vec![st.pos, to]
            }),
        };
        let params = WalkParams {
            verb: if self.lib.cycle(verb).is_some() { verb.to_string() } else { "walk".into() },
            speed,
            initial_heading: Some(st.heading),
            final_heading: Some(final_heading),
            lock_feet: self.cfg.lock_feet,
            ..WalkParams::default()
        };
        let m = cache.walk(&route, self.lib, &params);
        let wait_start = self.frames.len();
        if choice.wait > 0 {
            let idle = self.idle_clip();
            let wait = self.looped(&idle, st.pos, st.heading, choice.wait);
            self.append(wait);
        }
        let poses = m.poses();
        if let Some(last) = poses.last() {
            let r = last.translations[self.rig.hips];
            st.pos = [r.x as f32, r.z as f32];
        }
        let walk_start = self.frames.len();
        self.append(poses);
        self.walks.push(WalkInfo { wait_start, walk_start, end: self.frames.len(), route, params });
        st.heading = final_heading;
    }
}

/// A walking route on `grid` from `from` to `to`: when an end lies on a blocked cell (next to a
/// seat, just stood up) the route goes through the nearest free cell.
fn route(grid: &Grid, from: [f32; 2], to: [f32; 2]) -> Option<Vec<[f32; 2]>> {
    let free = |p: [f32; 2]| if grid.is_free_at(p) { Some(p) } else { grid.nearest_free(p).map(|c| grid.center(c)) };
    let (s, g) = (free(from)?, free(to)?);
    let mut path = grid.astar(s, g)?;
    if s != from {
        path.insert(0, from);
    }
    if g != to {
        path.push(to);
    }
    Some(path)
}

/// Extra margin (metres) beyond [`PASSING_DISTANCE`] kept between a stand point and the spots
/// where earlier characters stand or sit.
const SPOT_MARGIN: f32 = 0.1;

/// Where to stand to use an object: its stand contact, else a point just past one of the four
/// sides of its support (the side nearest the object first, the front preferred); each candidate
/// also shifted sideways along its side, and moved to the nearest free cell reachable from `from`.
/// The candidate chosen keeps clear of `avoid` (where earlier characters stand or sit: two
/// characters never share a spot), then stays close to the object, then to `from`.
fn stand_point(
    scene: &Scene,
    cat: &Catalogue,
    grid: &Grid,
    obj: usize,
    from: [f32; 2],
    avoid: &[[f32; 2]],
) -> [f32; 2] {
    let o = &scene.objects[obj];
    // (point, where the character would ideally be for it, extra cost of the side).
    let mut candidates: Vec<([f32; 2], [f32; 2], f32)> = Vec::new();
    let stands: Vec<[f32; 2]> = contacts_of(scene, cat, obj, ContactKind::Stand).iter().map(|p| [p[0], p[2]]).collect();
    for p in &stands {
        let side = [o.yaw.cos(), -o.yaw.sin()];
        for shift in [0.0f32, -0.4, 0.4, -0.8, 0.8] {
            candidates.push(([p[0] + side[0] * shift, p[1] + side[1] * shift], *p, 0.0));
        }
    }
    if stands.is_empty() {
        // An object on a surface is used from its support's sides.
        let base = o.support.map(|s| &scene.objects[s]).unwrap_or(o);
        let local = geom::to_local(geom::center(base), base.yaw, geom::center(o));
        let (hw, hd) = (base.size[0] / 2.0, base.size[2] / 2.0);
        let out = grid::WALKER_RADIUS + 0.1;
        // (point on the side nearest the object, outward normal, along-side axis, half length, penalty)
        let sides = [
            ([local[0].clamp(-hw, hw), hd], [0.0, 1.0], [1.0, 0.0], hw, 0.0),
            ([local[0].clamp(-hw, hw), -hd], [0.0, -1.0], [1.0, 0.0], hw, 0.15),
            ([hw, local[1].clamp(-hd, hd)], [1.0, 0.0], [0.0, 1.0], hd, 0.15),
            ([-hw, local[1].clamp(-hd, hd)], [-1.0, 0.0], [0.0, 1.0], hd, 0.15),
        ];
        // Keys (keyboard, laptop, piano) are used from the side they face.
        let keys = cat.get(&o.category).is_some_and(|c| c.contacts.iter().any(|p| p.kind == ContactKind::Keys));
        let (fs, fc) = (o.yaw - base.yaw).sin_cos();
        for (at, n, along, half, penalty) in sides {
            if keys && n[0] * fs + n[1] * fc < 0.7 {
                continue;
            }
            let ideal = [at[0] + n[0] * out, at[1] + n[1] * out];
            for shift in [0.0f32, -0.4, 0.4] {
                let q = [ideal[0] + along[0] * shift, ideal[1] + along[1] * shift];
                // Stay beside the side (a shift past its end would stand at a corner).
                if shift != 0.0 && (q[0] * along[0] + q[1] * along[1]).abs() > half + 0.05 {
                    continue;
                }
                let world_ideal = geom::to_world(geom::center(base), base.yaw, ideal);
                // The side nearest the object keeps the hands' reach short.
                let reach = dist2(world_ideal, geom::center(o)).sqrt();
                candidates.push((geom::to_world(geom::center(base), base.yaw, q), world_ideal, penalty + reach));
            }
        }
    }
    let reach = grid
        .cell_of(from)
        .filter(|c| !grid.is_blocked(*c))
        .or_else(|| grid.nearest_free(from))
        .map(|c| grid.reachable_from(c));
    let snap = |p: [f32; 2]| -> Option<[f32; 2]> {
        let p = if grid.is_free_at(p) { p } else { grid.center(grid.nearest_free(p)?) };
        let ok = match (&reach, grid.cell_of(p)) {
            (Some(r), Some((i, j))) => r[j * grid.nx + i],
            _ => true,
        };
        ok.then_some(p)
    };
    let crowd = |p: [f32; 2]| {
        avoid.iter().map(|a| (PASSING_DISTANCE + SPOT_MARGIN - dist2(p, *a).sqrt()).max(0.0)).sum::<f32>()
    };
    let best = candidates
        .into_iter()
        .filter_map(|(p, ideal, penalty)| {
            let q = snap(p)?;
            let cost = 10.0 * crowd(q) + dist2(q, ideal).sqrt() + penalty + 0.01 * dist2(q, from).sqrt();
            Some((cost, q))
        })
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .map(|b| b.1);
    best.unwrap_or_else(|| grid.nearest_free(geom::center(o)).map(|c| grid.center(c)).unwrap_or(geom::center(o)))
}

fn dist2(a: [f32; 2], b: [f32; 2]) -> f32 {
    (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)
}

/// Heading (0 = +Z) from `a` towards `b`.
fn heading_to(a: [f32; 2], b: [f32; 2], default: f64) -> f64 {
    let (dx, dz) = ((b[0] - a[0]) as f64, (b[1] - a[1]) as f64);
    if dx.hypot(dz) < 1e-4 {
        default
    } else {
        dx.atan2(dz)
    }
}

/// The animation with a walk cache (the optimiser re-animates many nearly equal scenes).
pub(crate) fn animate_cached(
    scene: &Scene,
    query: &Ssg,
    cat: &Catalogue,
    lib: &MotionLibrary,
    cfg: &AnimateConfig,
    cache: &mut WalkCache,
) -> Animation {
    animate_planned(scene, query, cat, lib, cfg, cache, &HashMap::new()).animation
}

/// The scene, query and settings one character is built in.
pub(crate) struct Ctx<'a> {
    pub scene: &'a Scene,
    pub query: &'a Ssg,
    pub cat: &'a Catalogue,
    pub lib: &'a MotionLibrary,
    pub cfg: &'a AnimateConfig,
    pub rig: Rig,
}

/// A character's actions with the sentence each comes from.
pub(crate) type Actions = Vec<(usize, crate::ssg::Action)>;

/// Everything needed to rebuild one character with other walk choices, and what it built.
#[derive(Debug, Clone)]
pub(crate) struct CharacterPlan {
    pub actions: Actions,
    pub start: [f32; 2],
    /// Where the characters planned before end up (blocked in `grid`).
    pub blocked_by: Vec<[f32; 2]>,
    /// The character's occupancy grid (objects plus `blocked_by`).
    pub grid: Grid,
    pub choices: Vec<WalkChoice>,
    pub track: CharacterTrack,
    /// Root (x, z) per frame.
    pub traj: Vec<[f32; 2]>,
    pub walks: Vec<WalkInfo>,
    /// (sentence, first frame) of every action, for the camera cuts.
    pub marks: Vec<(usize, usize)>,
    pub notes: Vec<String>,
    /// Where it ends: the stand point, and the seat when seated (later characters keep clear).
    pub end_spots: Vec<[f32; 2]>,
    /// Every spot it stands or sits at (start, walk ends, seats): later characters' stand points
    /// keep clear of them.
    pub spots: Vec<[f32; 2]>,
    /// The earlier characters' spots this one's stand points keep clear of.
    pub avoid: Vec<[f32; 2]>,
}

/// What [`animate_planned`] returns.
pub(crate) struct Planned {
    pub animation: Animation,
    pub plans: Vec<CharacterPlan>,
    /// Per character: built (or rebuilt) in this call rather than taken from `frozen`.
    pub resolved: Vec<bool>,
    /// Character builds per character (the crowd repair rebuilds a character per change).
    pub builds: Vec<usize>,
}

/// Animates every character: each built on its own timeline (later characters' grids block
/// where earlier ones end up), then [`crowd::separate`] adds waits and detours until every pair
/// of roots keeps [`PASSING_DISTANCE`] at every frame. A character found in `frozen` (by lower-case
/// name) whose start and blocked spots are unchanged is taken as it is, and only rebuilt when a
/// conflict cannot be solved otherwise.
pub(crate) fn animate_planned(
    scene: &Scene,
    query: &Ssg,
    cat: &Catalogue,
    lib: &MotionLibrary,
    cfg: &AnimateConfig,
    cache: &mut WalkCache,
    frozen: &HashMap<String, CharacterPlan>,
) -> Planned {
    let ctx = Ctx { scene, query, cat, lib, cfg, rig: Rig::standard() };
    let base_grid = Grid::from_objects(&scene.room, &scene.objects, grid::CELL, grid::WALKER_RADIUS);
    let mut plans: Vec<CharacterPlan> = Vec::new();
    let mut names = Vec::new();
    let (mut resolved, mut builds) = (Vec::new(), Vec::new());
    // Where earlier characters end up: later characters' routes keep clear of them.
    let mut occupied: Vec<[f32; 2]> = Vec::new();
    // Every spot earlier characters stand or sit at: later stand points keep clear of them.
    let mut spots: Vec<[f32; 2]> = Vec::new();
    for (ci, (name, actions)) in characters(query).into_iter().enumerate() {
        let mut g = base_grid.clone();
        for p in &occupied {
            g.block_rect(*p, [0.0, 0.0], 0.0, PASSING_DISTANCE + grid::CELL);
        }
        let starts: Vec<[f32; 2]> = plans.iter().map(|p| p.start).collect();
        let start = start_spot(scene, cfg, &base_grid, &g, &starts, ci);
        let plan = match frozen.get(&name.to_lowercase()) {
            Some(p) if p.start == start && p.blocked_by == occupied && p.avoid == spots && p.actions == actions => {
                resolved.push(false);
                builds.push(0);
                CharacterPlan { grid: g, ..p.clone() }
            }
            _ => {
                resolved.push(true);
                builds.push(1);
                build_character(&ctx, &name, actions, start, g, occupied.clone(), spots.clone(), Vec::new(), cache)
            }
        };
        occupied.extend(plan.end_spots.iter().copied());
        spots.extend(plan.spots.iter().copied());
        names.push(name);
        plans.push(plan);
    }
    let crowd_notes = crowd::separate(&ctx, &names, &mut plans, &mut resolved, &mut builds, cache);
    let mut notes: Vec<String> = plans.iter().flat_map(|p| p.notes.iter().cloned()).collect();
    notes.extend(crowd_notes);
    let marks: Vec<(usize, usize)> = plans.iter().flat_map(|p| p.marks.iter().copied()).collect();
    let tracks = plans.iter().map(|p| p.track.clone()).collect();
    let mut anim = Animation { fps: FPS, scene: scene.clone(), characters: tracks, camera: Vec::new(), notes };
    anim.camera = camera_shots(&anim, query, &marks);
    Planned { animation: anim, plans, resolved, builds }
}

/// Where character `ci` starts: along the door wall, `start_spacing` apart on alternating sides,
/// on the free cell nearest that spot that is reachable from the door and at least
/// [`PASSING_DISTANCE`] from the characters placed before (`starts`).
fn start_spot(
    scene: &Scene,
    cfg: &AnimateConfig,
    base_grid: &Grid,
    g: &Grid,
    starts: &[[f32; 2]],
    ci: usize,
) -> [f32; 2] {
    let door = layout::door(&scene.room);
    let side = if ci.is_multiple_of(2) { 1.0 } else { -1.0 };
    let want = [door[0] + side * cfg.start_spacing * ci.div_ceil(2) as f32, door[1]];
    let mut gs = g.clone();
    for p in starts {
        gs.block_rect(*p, [0.0, 0.0], 0.0, PASSING_DISTANCE);
    }
    let door_reach = g.nearest_free(door).map(|c| g.reachable_from(c));
    let mut best: Option<(f32, [f32; 2])> = None;
    for j in 0..gs.nz {
        for i in 0..gs.nx {
            let ok = !gs.is_blocked((i, j)) && door_reach.as_ref().is_none_or(|r| r[j * g.nx + i]);
            let c = gs.center((i, j));
            if ok && best.is_none_or(|(d, _)| dist2(c, want) < d) {
                best = Some((dist2(c, want), c));
            }
        }
    }
    best.map(|b| b.1)
        .or_else(|| base_grid.nearest_free(want).map(|c| g.center(c)))
        .unwrap_or([scene.room.width / 2.0, scene.room.depth / 2.0])
}

/// Builds one character's timeline from `start` on its grid `g`, walking as `choices` say.
#[allow(clippy::too_many_arguments)]
pub(crate) fn build_character(
    ctx: &Ctx,
    name: &str,
    actions: Actions,
    start: [f32; 2],
    g: Grid,
    blocked_by: Vec<[f32; 2]>,
    avoid: Vec<[f32; 2]>,
    choices: Vec<WalkChoice>,
    cache: &mut WalkCache,
) -> CharacterPlan {
    let (scene, query, cat, lib, cfg, rig) = (ctx.scene, ctx.query, ctx.cat, ctx.lib, ctx.cfg, &ctx.rig);
    let mut notes = Vec::new();
    let mut marks = Vec::new();
    let mut st = State { pos: start, heading: std::f64::consts::PI, seated: None };
    let mut b = Builder {
        rig: rig.clone(),
        lib,
        fallback: None,
        cfg,
        frames: Vec::new(),
        segments: Vec::new(),
        choices: &choices,
        walks: Vec::new(),
        seats: Vec::new(),
        props: Vec::new(),
    };
    for (sentence, a) in &actions {
        marks.push((*sentence, b.frames.len()));
        let obj = a.target.and_then(|t| object_of_node(scene, query, t));
        if a.target.is_some() && obj.is_none() {
            notes.push(format!("{name}: the target of \"{}\" is not in the scene", a.verb));
        }
        let verb = crate::motion::verbs::canonical(&a.verb).unwrap_or(a.verb.as_str()).to_string();
        let slow = a.manner.iter().any(|m| matches!(m.as_str(), "slowly" | "carefully" | "gently" | "lazily"));
        let speed = slow.then_some(cfg.slow_speed);
        let locomotion = lib.cycle(&verb).is_some() || verb == "walk" || verb == "run";
        if locomotion {
            b.stand_up(&mut st, scene);
            let start = b.frames.len();
            let (to, h) = match obj {
                Some(o) => {
                    let to = stand_point(scene, cat, &g, o, st.pos, &avoid);
                    (to, heading_to(to, geom::center(&scene.objects[o]), st.heading))
                }
                None => {
                    let f = [st.heading.sin() as f32, st.heading.cos() as f32];
                    let p = [st.pos[0] + 2.0 * f[0], st.pos[1] + 2.0 * f[1]];
                    let to = g.nearest_free(p).map(|c| g.center(c)).unwrap_or(st.pos);
                    (to, st.heading)
                }
            };
            b.walk(&mut st, &g, to, h, &verb, speed, cache, &mut notes, name);
            b.push_segment(&verb, start, obj, scene, obj.into_iter().collect(), Vec::new());
            continue;
        }
        if verb == "sit" || verb == "sit_down" {
            let seat = obj.and_then(|o| {
                let seats = contacts_of(scene, cat, o, ContactKind::Seat);
                // The nearest seat, away from where earlier characters stand or sit.
                let crowd = |p: &[f32; 3]| {
                    avoid
                        .iter()
                        .map(|a| (PASSING_DISTANCE + SPOT_MARGIN - dist2([p[0], p[2]], *a).sqrt()).max(0.0))
                        .sum::<f32>()
                };
                let cost = |p: &[f32; 3]| 10.0 * crowd(p) + dist2([p[0], p[2]], st.pos).sqrt();
                seats.into_iter().min_by(|p, q| cost(p).total_cmp(&cost(q))).map(|s| (o, s))
            });
            match (seat, st.seated) {
                (Some((o, s)), seated) if seated.is_none_or(|(_, _, so)| so != o) => {
                    b.stand_up(&mut st, scene);
                    let hold = (cfg.min_action_seconds * FPS).round() as usize;
                    b.sit_on(&mut st, scene, &g, o, s, hold, speed, cache, &mut notes, name);
                }
                _ => {
                    if seat.is_none() && obj.is_some() {
                        notes.push(format!("{name}: nothing to sit on in {}", scene.objects[obj.unwrap_or(0)].label));
                    }
                    // Already seated (or no seat): hold.
                    let start = b.frames.len();
                    let n = (cfg.min_action_seconds * FPS).round() as usize;
                    let poses = match st.seated {
                        Some((at, s, _)) => b.seated(at, s, st.heading, n),
                        None => {
                            let idle = b.idle_clip();
                            b.looped(&idle, st.pos, st.heading, n)
                        }
                    };
                    b.append(poses);
                    let touching = st.seated.map(|s| vec![s.2]).unwrap_or_default();
                    b.push_segment("sit", start, obj, scene, touching, Vec::new());
                }
            }
            continue;
        }
        if verb == "stand_up" || (verb == "stand" && st.seated.is_some()) {
            b.stand_up(&mut st, scene);
            continue;
        }
        // Turning on the spot.
        let turn = if verb == "turn" {
            if a.manner.iter().any(|m| m == "right") {
                Some(-std::f64::consts::FRAC_PI_2)
            } else if a.manner.iter().any(|m| m == "left") {
                Some(std::f64::consts::FRAC_PI_2)
            } else {
                Some(std::f64::consts::PI)
            }
        } else {
            None
        };
        if let (Some(dh), None) = (turn, st.seated) {
            let start = b.frames.len();
            let to = st.heading + dh;
            let m = cache.walk(
                &[st.pos],
                lib,
                &WalkParams {
                    initial_heading: Some(st.heading),
                    final_heading: Some(to),
                    lock_feet: cfg.lock_feet,
                    ..WalkParams::default()
                },
            );
            b.append(m.poses());
            st.heading = to;
            b.push_segment("turn", start, obj, scene, Vec::new(), Vec::new());
            continue;
        }
        // A small prop used in the hand is picked up first and then carried: the action plays
        // with it in the hand, not with the hand on its resting place.
        let carried = obj.filter(|&o| carries(&a.verb, &verb, a.preposition.as_deref(), scene, cat, o));
        if let Some(o) = carried {
            if !b.props.iter().any(|p| p.object == o) {
                b.pick_up(&mut st, scene, cat, &g, o, &avoid, speed, cache, &mut notes, name);
            }
        }
        let hands_on = if carried.is_some() { None } else { obj };
        // An action in place, over the idle or seated lower body.
        let action = lib.retrieve(&verb).filter(|c| c.motion.skeleton == rig.skeleton).map(|c| c.motion.clone());
        if action.is_none() && verb != "stand" && verb != "idle" {
            notes.push(format!("{name}: no clip for \"{}\"; standing instead", a.verb));
        }
        let clip_len = action.as_ref().map(|m| m.num_frames()).unwrap_or(0).max(1);
        let min = (cfg.min_action_seconds * FPS).round() as usize;
        let n = clip_len * min.div_ceil(clip_len).max(1);
        // A standing character walks up to a target out of reach first.
        if let (Some(o), None) = (hands_on, st.seated) {
            let to = stand_point(scene, cat, &g, o, st.pos, &avoid);
            if dist2(to, st.pos) > cfg.approach_distance * cfg.approach_distance {
                let start = b.frames.len();
                let h = heading_to(to, geom::center(&scene.objects[o]), st.heading);
                b.walk(&mut st, &g, to, h, "walk", speed, cache, &mut notes, name);
                b.push_segment("walk", start, Some(o), scene, vec![o], Vec::new());
            }
        }
        // Face the target when standing.
        if let (Some(o), None) = (hands_on, st.seated) {
            st.heading = heading_to(st.pos, geom::center(&scene.objects[o]), st.heading);
        }
        let base = match st.seated {
            Some((at, s, _)) => b.seated(at, s, st.heading, n),
            None => {
                let idle = b.idle_clip();
                b.looped(&idle, st.pos, st.heading, n)
            }
        };
        let base = crate::motion::rig::clip(rig, &base);
        let mut m = match &action {
            Some(act) => blend_upper_on(
                rig,
                &base,
                act,
                &BlendParams { start: 0, end: None, blend_in: 8, blend_out: 0, looping: true, action_offset: 0 },
            ),
            None => base,
        };
        let start = b.frames.len();
        let mut contacts = Vec::new();
        if let (Some(o), true) = (hands_on, cfg.reach) {
            let (ik, jc) = hand_contacts(rig, &m, scene, cat, o, start);
            if !ik.is_empty() {
                m = reach_contacts_on(rig, &m, &ik).0;
            }
            contacts = jc;
        }
        b.append(m.poses());
        let mut touching: Vec<usize> = obj.into_iter().collect();
        touching.extend(st.seated.map(|s| s.2));
        b.push_segment(&verb, start, obj, scene, touching, contacts);
    }
    if b.frames.is_empty() {
        let idle = b.idle_clip();
        let poses = b.looped(&idle, st.pos, st.heading, (cfg.min_action_seconds * FPS).round() as usize);
        b.append(poses);
    }
    if b.frames.is_empty() {
        let idle = b.idle_clip();
        let poses = b.looped(&idle, st.pos, st.heading, (cfg.min_action_seconds * FPS).round() as usize);
        b.append(poses);
    }
    let mut end_spots = vec![st.pos];
    if let Some((_, s, _)) = st.seated {
        end_spots.push([s[0], s[2]]);
    }
    let motion = crate::motion::rig::clip(rig, &b.frames);
    let traj: Vec<[f32; 2]> =
        b.frames.iter().map(|p| [p.translations[rig.hips].x as f32, p.translations[rig.hips].z as f32]).collect();
    let walks = b.walks;
    let track = CharacterTrack { name: name.to_string(), motion, segments: b.segments, props: b.props };
    let mut spots = vec![start];
    spots.extend(walks.iter().filter_map(|w| traj.get(w.end.saturating_sub(1)).copied()));
    spots.extend(b.seats.iter().copied());
    CharacterPlan {
        actions,
        start,
        blocked_by,
        grid: g,
        choices,
        track,
        traj,
        walks,
        marks,
        notes,
        end_spots,
        spots,
        avoid,
    }
}

/// IK contacts (wrist targets) and cost contacts for a hand action on object `o`: keys take both
/// hands (fingers on the keys, ±10 cm along the object's width), a grip or strike point the right
/// hand, a top surface both wrists ±20 cm apart.
fn hand_contacts(
    rig: &Rig,
    m: &Motion,
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
    let finger = |side: &str| {
        rig.skeleton.find(&format!("{side}HandIndex1")).or_else(|| rig.skeleton.find(&format!("{side}FingerBase")))
    };
    let hand_len = finger("Left").map(|f| (g0.positions[f] - g0.positions[rig.arms[0][3]]).length()).unwrap_or(0.1);
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
