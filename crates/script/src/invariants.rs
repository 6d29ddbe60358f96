//! What a person would reject at a glance in a 3D client (issue 27), measured on an animated
//! story: feet through the floor, planted feet not flat, hips sunk while walking, the camera's
//! view of the character blocked by furniture or the camera inside an object, objects that do
//! not rest on anything, and facing relations that are not kept.
//!
//! [`check`] measures an [`Animation`] (its scene is the one every output shows) with the
//! composition's relations; [`Report::counts`] gives one number per invariant (goal: all 0),
//! which the script bench tabulates over the built-in and random stories and the property test
//! asserts.

use glam::DVec3;
use inbetween_core::fk::{forward_into, GlobalPose};

use crate::animate::camera::{obstacles, sees, sight_targets};
use crate::animate::{camera_track, carried_from, Animation};
use crate::catalogue::{Catalogue, Support};
use crate::layout::geom;
use crate::motion::rig::{hip_height, Rig};
use crate::scene::{Mount, Origin, PlacedObject, Room, Scene};
use crate::ssg::Relation;

/// Deepest a joint may go under the floor, metres.
pub const FLOOR_TOLERANCE: f64 = 0.01;
/// A planted foot's toe base and ankle stay within this of their rest heights, metres.
pub const FLAT_TOLERANCE: f64 = 0.02;
/// While walking the hips stay at least this fraction of their rest height.
pub const WALK_HIP_FRACTION: f64 = 0.9;
/// Shots must see the framed character in at least this fraction of frames.
pub const SIGHT_FRACTION: f64 = 0.98;
/// An object rests within this of its support's top (or the floor), metres.
pub const REST_TOLERANCE: f32 = 0.01;
/// A wall object's back is within this of a wall, metres.
pub const WALL_TOLERANCE: f32 = 0.02;
/// Ankle speed under which a foot counts as planted, m/s.
const PLANTED_SPEED: f64 = 0.15;

/// How `obj` should be held up: by its support object, else by its category's support (a surface
/// object without a support stands on the floor).
pub fn mount_of(scene: &Scene, cat: &Catalogue, obj: usize) -> Mount {
    let o = &scene.objects[obj];
    if o.support.is_some() {
        return Mount::On;
    }
    match cat.get(&o.category).map(|c| c.support) {
        Some(Support::Wall) => Mount::Wall,
        Some(Support::Ceiling) => Mount::Ceiling,
        _ => Mount::Floor,
    }
}

/// [`mount_of`] every object of the scene.
pub fn mounts(scene: &Scene, cat: &Catalogue) -> Vec<Mount> {
    (0..scene.objects.len()).map(|i| mount_of(scene, cat, i)).collect()
}

/// Why an object does not rest where its mount says, or None when it does.
pub fn rest_problem(scene: &Scene, cat: &Catalogue, obj: usize) -> Option<String> {
    let o = &scene.objects[obj];
    let room = &scene.room;
    let y = o.position[1];
    match mount_of(scene, cat, obj) {
        Mount::Floor => {
            (y.abs() > REST_TOLERANCE).then(|| format!("{} stands {:.3} m above the floor on nothing", o.label, y))
        }
        Mount::On => {
            let s = o.support.expect("mount On has a support");
            let Some(sup) = scene.objects.get(s) else {
                return Some(format!("{} rests on object {s}, which is not in the scene", o.label));
            };
            let gap = y - sup.top();
            let on_a_shelf =
                cat.get(&sup.category).is_some_and(|c| c.has_shelves()) && y > sup.position[1] && gap < 0.0;
            if gap.abs() > REST_TOLERANCE && !on_a_shelf {
                Some(format!(
                    "{} is {:.3} m {} the top of {}",
                    o.label,
                    gap.abs(),
                    if gap > 0.0 { "above" } else { "under" },
                    sup.label
                ))
            } else if !geom::center_inside(o, sup) {
                Some(format!("{}'s centre is off the top of {}", o.label, sup.label))
            } else {
                None
            }
        }
        Mount::Wall => {
            let d = wall_distance(room, o);
            (d > WALL_TOLERANCE || y <= 0.0).then(|| format!("{} hangs {:.3} m from the nearest wall", o.label, d))
        }
        Mount::Ceiling => {
            let gap = room.height - o.top();
            (gap.abs() > REST_TOLERANCE).then(|| format!("{} hangs {:.3} m under the ceiling", o.label, gap))
        }
    }
}

/// Distance from an object's footprint to the nearest wall, metres (0 when touching).
fn wall_distance(room: &Room, o: &PlacedObject) -> f32 {
    let [hx, hz] = o.half_extents_xz();
    let [x, _, z] = o.position;
    [x - hx, room.width - (x + hx), z - hz, room.depth - (z + hz)].into_iter().fold(f32::INFINITY, f32::min).max(0.0)
}

/// What [`check`] found. Frame counts are summed over characters.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Report {
    pub frames: usize,
    /// Character frames with a joint (toe tips included) more than [`FLOOR_TOLERANCE`] under the
    /// floor, and the deepest (metres, positive down).
    pub below_floor: usize,
    pub deepest: f64,
    /// The first (character, frame) under the floor, and the first not flat, for messages.
    pub first_below: Option<(String, usize)>,
    pub first_not_flat: Option<(String, usize)>,
    /// Foot frames planted (slow ankle near the floor) but not flat.
    pub planted: usize,
    pub not_flat: usize,
    /// Walking frames with the hips under [`WALK_HIP_FRACTION`] of their rest height, and the
    /// lowest hips while walking (metres).
    pub walking: usize,
    pub low_hips: usize,
    pub lowest_walking_hips: f64,
    /// Frames where an object box cuts the line from the camera to a framed joint.
    pub blocked: usize,
    /// Frames with the camera inside an object.
    pub camera_inside: usize,
    /// Objects that rest on nothing (see [`rest_problem`]).
    pub floating: Vec<String>,
    /// Facing relations not kept ("chair in front of desk faces away").
    pub facing: Vec<String>,
}

impl Report {
    /// One count per invariant, in [`Report::NAMES`]' order; each should be 0.
    pub fn counts(&self) -> [usize; 6] {
        let sight = if self.frames > 0 && (self.blocked as f64) > (1.0 - SIGHT_FRACTION) * self.frames as f64 {
            self.blocked
        } else {
            0
        };
        [
            self.below_floor,
            self.not_flat,
            self.low_hips,
            sight + self.camera_inside,
            self.floating.len(),
            self.facing.len(),
        ]
    }

    /// Names of [`Report::counts`].
    pub const NAMES: [&'static str; 6] = [
        "joint under floor (frames)",
        "planted foot not flat (frames)",
        "hips low while walking (frames)",
        "camera blocked or inside (frames)",
        "objects resting on nothing",
        "facing relations broken",
    ];

    /// One line per kind of violation, empty when every invariant holds.
    pub fn problems(&self) -> Vec<String> {
        let mut out = Vec::new();
        let c = self.counts();
        let at = |first: &Option<(String, usize)>| {
            first.as_ref().map(|(name, f)| format!(", first {name} at frame {f}")).unwrap_or_default()
        };
        if c[0] > 0 {
            out.push(format!(
                "{} frames with a joint under the floor (deepest {:.3} m{})",
                c[0],
                self.deepest,
                at(&self.first_below)
            ));
        }
        if c[1] > 0 {
            out.push(format!("{} of {} planted foot frames not flat{}", c[1], self.planted, at(&self.first_not_flat)));
        }
        if c[2] > 0 {
            out.push(format!(
                "{} of {} walking frames with low hips (lowest {:.3} m)",
                c[2], self.walking, self.lowest_walking_hips
            ));
        }
        if c[3] > 0 {
            out.push(format!(
                "camera view blocked in {} of {} frames, inside an object in {}",
                self.blocked, self.frames, self.camera_inside
            ));
        }
        out.extend(self.floating.iter().cloned());
        out.extend(self.facing.iter().cloned());
        out
    }
}

/// Measures every invariant on an animation whose scene was composed with `relations`
/// (`(relation, active, anchor)` indices into `anim.scene.objects`).
pub fn check(anim: &Animation, cat: &Catalogue, relations: &[(Relation, usize, usize)]) -> Report {
    let mut r = Report { frames: anim.frames(), lowest_walking_hips: f64::INFINITY, ..Report::default() };
    let track = camera_track(anim);
    // Head and hips per frame of each character, for the line of sight.
    let mut bodies: Vec<Option<Vec<[DVec3; 2]>>> = Vec::new();
    for c in &anim.characters {
        let Ok(rig) = Rig::try_of(c.clip.skeleton().clone()) else {
            bodies.push(None);
            continue;
        };
        let n = c.clip.num_frames();
        let mut g = GlobalPose { positions: Vec::new(), rotations: Vec::new() };
        let mut all = Vec::with_capacity(n);
        for f in 0..n {
            forward_into(&rig.skeleton, &c.clip.pose(f), &mut g);
            all.push(g.clone());
        }
        body(&mut r, &rig, c, &all, anim.fps);
        bodies.push((n > 0).then(|| all.iter().map(|g| [g.positions[rig.head], g.positions[rig.hips]]).collect()));
    }
    if r.lowest_walking_hips == f64::INFINITY {
        r.lowest_walking_hips = 0.0;
    }
    // Line of sight from the shot camera to whom it frames.
    let obstacles = obstacles(anim);
    for f in 0..r.frames {
        let eye = track.pose(f).eye.as_dvec3();
        if obstacles.iter().any(|o| geom::point_in_box(o, eye)) {
            r.camera_inside += 1;
        } else if !sees(&obstacles, eye, &sight_targets(&bodies, f, track.framed.get(f).copied().unwrap_or(1))) {
            r.blocked += 1;
        }
    }
    for i in 0..anim.scene.objects.len() {
        if carried_from(anim, i).is_some() {
            continue;
        }
        if let Some(p) = rest_problem(&anim.scene, cat, i) {
            r.floating.push(p);
        }
    }
    // A carried prop once put down rests like any object.
    for c in &anim.characters {
        for prop in &c.props {
            let Some(d) = &prop.put_down else { continue };
            let mut at = anim.scene.clone();
            let o = &mut at.objects[prop.object];
            o.position = [d.position.x as f32, d.position.y as f32, d.position.z as f32];
            o.yaw = crate::motion::rig::heading_of(d.rotation) as f32;
            o.support = d.support;
            if let Some(p) = rest_problem(&at, cat, prop.object) {
                r.floating.push(format!("{} (put down by {} at frame {})", p, c.name, d.frame));
            }
        }
    }
    // Facing: the script's own "in front of" relations of seats.
    let objects = &anim.scene.objects;
    for &(rel, a, b) in relations {
        if rel != Relation::InFrontOf || a >= objects.len() || b >= objects.len() {
            continue;
        }
        if !matches!(objects[a].origin, Origin::Script { .. })
            || !cat.get(&objects[a].category).is_some_and(|c| c.is_seat())
        {
            continue;
        }
        if let Some(p) = facing_problem(&objects[a], &objects[b]) {
            r.facing.push(p);
        }
    }
    r
}

/// Verbs whose segments may put the body on the floor.
fn on_the_floor(verb: &str) -> bool {
    matches!(verb, "lie" | "crawl" | "kneel" | "fall")
}

/// The body invariants of one character.
fn body(r: &mut Report, rig: &Rig, c: &crate::animate::CharacterTrack, g: &[GlobalPose], fps: f64) {
    let rest = rig.fk(&rig.standing());
    let rest_ankle = rest.positions[rig.legs[0][2]].y;
    let rest_toe = rest.positions[rig.legs[0][3]].y;
    let rest_hips = hip_height();
    let floor_ok = |f: usize| c.segments.iter().any(|s| f >= s.start && f < s.end && on_the_floor(&s.verb));
    let walking = |f: usize| c.segments.iter().any(|s| f >= s.start && f < s.end && s.verb == "walk");
    for (f, p) in g.iter().enumerate() {
        let mut low = p.positions.iter().map(|v| v.y).fold(f64::INFINITY, f64::min);
        for leg in &rig.legs {
            if let Some(tip) = p.end_site(&rig.skeleton, leg[3]) {
                low = low.min(tip.y);
            }
        }
        if -low > FLOOR_TOLERANCE && !floor_ok(f) {
            r.below_floor += 1;
            r.deepest = r.deepest.max(-low);
            r.first_below.get_or_insert_with(|| (c.name.clone(), f));
        }
        if walking(f) {
            r.walking += 1;
            let h = p.positions[rig.hips].y;
            r.lowest_walking_hips = r.lowest_walking_hips.min(h);
            if h < WALK_HIP_FRACTION * rest_hips {
                r.low_hips += 1;
            }
        }
        for leg in &rig.legs {
            let ankle = p.positions[leg[2]];
            let next = g.get(f + 1).or(f.checked_sub(1).map(|k| &g[k])).map(|q| q.positions[leg[2]]);
            let speed = next.map(|q| (q - ankle).length() * fps).unwrap_or(0.0);
            if speed < PLANTED_SPEED && ankle.y < rest_ankle + FLAT_TOLERANCE && !floor_ok(f) {
                r.planted += 1;
                let toe = p.positions[leg[3]].y;
                if (toe - rest_toe).abs() > FLAT_TOLERANCE || ankle.y < rest_ankle - FLAT_TOLERANCE {
                    r.not_flat += 1;
                    r.first_not_flat.get_or_insert_with(|| (c.name.clone(), f));
                }
            }
        }
    }
}

/// Why `active` ("in front of" `anchor`) does not face it, or None.
fn facing_problem(active: &PlacedObject, anchor: &PlacedObject) -> Option<String> {
    let angle = geom::facing_angle(active, anchor);
    (angle > geom::FACING_TOLERANCE_DEG)
        .then(|| format!("{} is in front of {} but faces {:.0}° away from it", active.label, anchor.label, angle))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn object(label: &str, position: [f32; 3], yaw: f32, size: [f32; 3]) -> PlacedObject {
        PlacedObject {
            label: label.into(),
            category: label.into(),
            attributes: Vec::new(),
            position,
            yaw,
            size,
            support: None,
            origin: Origin::Script { sentence: 0, node: 0 },
        }
    }

    #[test]
    fn a_segment_hits_a_box_only_when_it_passes_through() {
        let b = object("box", [1.0, 0.0, 1.0], 0.3, [0.5, 1.0, 0.5]);
        let y = DVec3::Y * 0.5;
        assert!(geom::segment_hits_box(&b, DVec3::new(0.0, 0.5, 1.0), DVec3::new(2.0, 0.5, 1.0)));
        assert!(!geom::segment_hits_box(&b, DVec3::new(0.0, 1.5, 1.0), DVec3::new(2.0, 1.5, 1.0)));
        assert!(!geom::segment_hits_box(&b, DVec3::new(0.0, 0.5, 1.0), DVec3::new(0.6, 0.5, 1.0)));
        assert!(geom::segment_hits_box(&b, DVec3::new(1.0, 0.0, 1.0) + y, DVec3::new(1.0, 0.0, 1.0) + y));
        assert!(geom::point_in_box(&b, DVec3::new(1.0, 0.9, 1.0)));
        assert!(!geom::point_in_box(&b, DVec3::new(1.0, 1.1, 1.0)));
    }

    #[test]
    fn facing_is_measured_towards_the_anchor() {
        let desk = object("desk", [2.0, 0.0, 2.0], 0.0, [1.2, 0.75, 0.6]);
        // A chair at +z of the desk faces it when turned to face −z (yaw π).
        let facing = object("chair", [2.0, 0.0, 2.8], std::f32::consts::PI, [0.5, 0.9, 0.5]);
        let away = object("chair", [2.0, 0.0, 2.8], 0.0, [0.5, 0.9, 0.5]);
        assert_eq!(facing_problem(&facing, &desk), None);
        assert!(facing_problem(&away, &desk).unwrap().contains("180°"));
    }
}
