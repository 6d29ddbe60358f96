//! SIDQL selection (§4): a trained deep Q-network adds, one at a time, the frame with the highest
//! Q-value until `k` keys are chosen; beyond the paper, the keys are then checked against uniform
//! keys and refined ([`crate::dqn::Finish`]). Training lives in [`crate::dqn`].

pub use crate::dqn::SidqlPolicy;

use crate::representation::SphericalMotion;
use crate::Result;
use inbetween_core::KeyframeSet;

/// `k` keys for a window chosen by `policy`.
pub fn sidql(policy: &SidqlPolicy, rep: &SphericalMotion, k: usize) -> Result<KeyframeSet> {
    policy.select(rep, k)
}
