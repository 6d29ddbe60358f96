//! Script part 2: characters that walk, sit and act in the furnished scene (Zhang et al. 2021,
//! §3.2 template actions, §4.2 motion synthesis, §4.3 routes and contacts).
//!
//! - [`library`]: template actions indexed by tags (built-in procedural clips, CMU BVH when the
//!   shared corpus is present: cgspeed BVH via [`cmu`], iClone/Character Creator BVH via [`cc`],
//!   Kenney blocky characters via [`kenney`]), retrieved by verb lemma ([`verbs`]);
//! - [`cycle`]: gait cycles cut from captured walks (loopable, along +Z) for locomotion;
//! - [`locomotion`]: walking a route (A* on the layout's occupancy grid) with eased start/stop,
//!   limited turn rate and foot locking; [`locomotion::foot_skate`] measures skate;
//! - [`blend`]: upper body of an action on the lower body of locomotion, then contact IK;
//! - [`ik`]: analytic two-bone IK and hips placement for sitting;
//! - [`rig`]: the common skeleton (core's CMU-style skeleton in metres, floor y = 0, facing +Z).

pub mod blend;
pub mod cc;
pub mod cmu;
pub mod cycle;
mod grounding;
pub mod ik;
pub mod kenney;
pub mod library;
pub mod locomotion;
pub mod procedural;
pub mod rig;
pub mod verbs;

pub use blend::{blend_upper, reach_contacts, BlendParams, Contact};
pub use ik::{place_hips, solve_limb, two_bone, Limb, TwoBone};
pub use library::{ClipSource, LibraryClip, MotionLibrary};
pub use locomotion::{foot_skate, lock_feet, walk_route, walk_route_stats, LockParams, WalkParams, WalkStats};
pub use rig::Rig;
