//! Script part 2 (§4.2–4.3): the characters of a composed script acting in its furnished scene.
//!
//! For each character (character nodes of the query SSG grouped by name, actions in script
//! order) one timeline is built on the common rig ([`crate::motion::rig`]). Each action's verb is
//! read once into an [`action::Verb`] and played by its own module of [`action`]:
//! - "walk to X" ([`action::walk`]): an A* route on the layout's occupancy grid
//!   ([`crate::layout::grid::Grid::astar`]) from where the character stands (the first start at the
//!   room's door, [`crate::layout::door`]) to the free cell nearest X's stand point (its `Stand`
//!   contact, else a point just past a side of its support, [`spots`]), walked with
//!   [`crate::motion::walk_route`] (foot locking), ending turned towards X;
//! - "sit on X" ([`action::sit`]): walk to the point in front of X's seat contact, the sit-down
//!   clip placed so the pelvis lands on the seat (height corrected with the legs re-solved), then a
//!   seated loop; "stand up" ([`action::stand_up`]) leaves the seat;
//! - "turn" ([`action::turn`]): turning on the spot;
//! - any other verb ([`action::act`]): when standing further than
//!   [`AnimateConfig::approach_distance`] from the target's stand point, a walk there first; then
//!   the library clip ([`MotionLibrary::retrieve`]) looped to at least
//!   [`AnimateConfig::min_action_seconds`], its upper body blended over the idle (or seated) lower
//!   body with [`crate::motion::blend_upper`], hands moved to the target's
//!   `Keys`/`Grip`/`Top`/`Strike` contacts with [`crate::motion::reach_contacts`] (two-bone IK,
//!   clamped when out of reach: the gap left is what the contact cost of §4.3 measures);
//! - a small prop used in the hand ("sings with the microphone", "picks up the phone",
//!   [`action::pick_up`]): walked to (a seated character stands up and sits down again), picked
//!   up with the reach clip, then carried: it follows the right hand ([`CarriedProp`],
//!   [`object_pose`]) through the action.
//!
//! One [`builder::Builder`] per character holds what every action needs (the scene, its grid,
//! the walk cache, the notes, the name) and what the timeline has so far.
//!
//! Stand points and seats keep clear of every spot an earlier character stands or sits at, so
//! two characters never share one.
//!
//! Several characters all start at frame 0 near the door (at least [`PASSING_DISTANCE`] apart);
//! a later character's grid blocks where earlier ones end up. [`crowd`] then keeps every pair of
//! roots [`PASSING_DISTANCE`] apart at every frame, standing and sitting included (prioritised
//! planning over space-time reservations: waits and detours, the later character yielding
//! first), and notes what it cannot solve. [`crate::story_session::StorySession`] (above this module and
//! the optimiser) re-solves only the characters (and the objects they touch) an edit changes.
//!
//! Segments are joined with a short cross-fade. Camera commands become [`CameraShot`]s and
//! [`camera_pose`] places the camera for a frame.

pub(crate) mod action;
pub(crate) mod builder;
pub(crate) mod camera;
pub(crate) mod character;
pub(crate) mod context;
pub mod crowd;
pub(crate) mod plan;
mod props;
pub(crate) mod routes;
pub(crate) mod spots;

pub use action::sit::GRIP_ABOVE;
pub use camera::{camera_pose, camera_shots, camera_track, view_at, ShotCameras};
pub(crate) use character::{Actions, CharacterPlan};
pub(crate) use context::Setup;
pub use crowd::{min_clearance, Clearance};
pub(crate) use plan::{animate_planned, characters};
pub use props::{carried_from, moves, object_pose, slide_offset, CarriedProp, PutDown, Slide};
pub(crate) use routes::WalkCache;

use std::collections::HashMap;

use inbetween_core::clip::Clip;

use crate::catalogue::{Catalogue, ContactKind};
use crate::compose::Composition;
use crate::layout::geom;
use crate::motion::MotionLibrary;
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
    /// [`crate::motion::ik::PELVIS_ABOVE_SEAT`].
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
    /// Common rig skeleton, metres, world placement, [`crate::motion::rig::FPS`]; at least one
    /// frame. Written out as BVH channels only at the file boundary ([`crate::output`]).
    pub clip: Clip,
    pub segments: Vec<Segment>,
    /// Small props the character picks up and carries (see [`CarriedProp`]).
    pub props: Vec<CarriedProp>,
    /// Furniture it slides along the floor (see [`Slide`]), in time order.
    pub slides: Vec<Slide>,
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
        self.characters.iter().map(|c| c.clip.num_frames()).max().unwrap_or(0).max(1)
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

/// Closest approach (metres) between two characters' roots that [`crowd::separate`] accepts.
pub const PASSING_DISTANCE: f32 = 0.5;

/// Whether a verb lemma as the parser gives it (with its particles in `manner`: "get" + "up") has
/// motion in `lib`: locomotion, sitting, standing up, turning and lying are built, any other verb
/// needs a clip ([`crate::story_session::StorySession::check_verbs`] refuses a script with one that has
/// none).
pub fn verb_has_motion(verb: &str, manner: &[String], lib: &MotionLibrary) -> bool {
    let a = crate::ssg::Action {
        verb: verb.to_string(),
        preposition: None,
        target: None,
        manner: manner.to_vec(),
        destination: None,
        person: None,
    };
    action::plays(&action::Step::read(&a, None, lib, 0.0), lib)
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
    let cancel = inbetween_core::cancel::Cancel::new();
    animate_planned(&Setup { cat, lib, cfg, cancel: &cancel }, scene, query, cache, &HashMap::new()).animation
}
