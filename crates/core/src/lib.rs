//! Core types and math every inbetween engine speaks: skeletons, BVH-form motion clips ([`Motion`]),
//! runtime pose clips ([`clip::Clip`]), rotations, forward kinematics, resampling and windowing,
//! curves with an [`Interval`] domain and their adapters ([`curve`]), keyframe sets, interpolation,
//! error metrics, joint roles on any humanoid rig ([`roles`]), length units, seeding ([`seed`]),
//! cooperative cancellation and time limits ([`cancel`]), angle wrapping ([`angle`]), order statistics ([`stats`]), Toric space
//! for two-subject camera framing ([`toric`]) and the camera over a clip's frames that the script and
//! camera engines place ([`camera`]).

pub mod angle;
pub mod camera;
pub mod cancel;
pub mod clip;
pub mod curve;
pub mod fk;
pub mod interp;
pub mod keyframes;
pub mod metrics;
pub mod motion;
pub mod procedural;
pub mod roles;
pub mod rotation;
pub mod seed;
pub mod skeleton;
pub mod stats;
pub mod toric;
pub mod units;

pub use clip::{Clip, SamplingContext};
pub use curve::{Animatable, Curve, Interpolation, Interval, Key, KeyCorrected, Samples, ScalarTrack, Track};
pub use fk::{forward, forward_clip, forward_into, positions_clip, GlobalPose};
pub use keyframes::KeyframeSet;
pub use metrics::{position_error, rotation_error, ErrorStats};
pub use motion::{Motion, Pose};
pub use rotation::{Axis, EulerOrder};
pub use skeleton::{Channel, Joint, Skeleton};

mod error;
pub use error::CoreError;

/// The README's examples, compiled and run as doctests.
#[doc = include_str!("../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;
