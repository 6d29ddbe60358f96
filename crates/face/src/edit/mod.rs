//! Masks, constraints (§3.1), key distances (§3.3), blendshape groups, the interpolation baselines, the
//! retrieval prior (issue 25) and the post-processing of an edit.

pub mod constraints;
pub mod distances;
pub mod fill;
pub mod groups;
pub mod mask;
pub mod retrieve;
pub mod seam;

use crate::data::NUM_ARKIT;

pub use constraints::{Constraint, ConstraintKind};
pub use fill::{correct, interpolate, Interp};
pub use mask::{Mask, Segment};
pub use retrieve::{retrieve, MotionLibrary, RetrievalOptions};

/// One frame of the 52 ARKit weights, in [`crate::data::ARKIT_NAMES`] order.
pub type Frame = [f32; NUM_ARKIT];
