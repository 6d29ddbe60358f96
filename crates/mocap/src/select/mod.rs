//! Keyframe selectors. All keep the first and last frame (constraint 19b–c of the paper) and return
//! `k` keyframes in total.
//!
//! - [`random`](mod@random): RC, `k − 2` interior frames drawn uniformly (seeded).
//! - [`uniform`](mod@uniform): UC, evenly spaced frames.
//! - [`greedy`](mod@greedy): the paper's Greedy (§5.4), adding the frame that lowers the error most, one at a time.
//! - [`optimal`](mod@optimal): the exact minimum of the total error for `k` keys, a dynamic programme over the
//!   per-segment costs (beyond the paper); never worse than Greedy. [`optimal_spherical`] gives the same
//!   keys on one clip in about a millisecond (only the objective is tabulated, hopeless segments dropped).
//! - [`cost_to_go`](mod@cost_to_go): the least error reachable from any key set with any number of keys
//!   left (SIDQL's pretraining targets).
//! - [`refine`](mod@refine): moves each key of a set to the best frame between its neighbours until none
//!   moves (beyond the paper); SIDQL finishes its keys with it.
//! - [`error_bounded`](mod@error_bounded): the fewest keys keeping every frame's error under a bound, also exact.
//! - [`sidql`](mod@sidql): the paper's deep Q-network policy (§4).
//!
//! [`job::SelectJob`] runs any of them (but the random baseline) on a clip, as the front ends do.

pub mod cost_to_go;
pub mod error_bounded;
pub mod greedy;
pub mod job;
pub mod optimal;
pub mod random;
pub mod refine;
pub mod sidql;
pub mod uniform;

pub use cost_to_go::{angle_segment_costs, completion_values, cost_to_go};
pub use error_bounded::error_bounded;
pub use greedy::{greedy, greedy_cancellable, GreedyOrder};
pub use optimal::{optimal, optimal_spherical, optimal_spherical_cancellable, optimal_spherical_memo, OptimalMemo};
pub use random::random;
pub use refine::refine_keys;
pub use uniform::uniform;

use crate::{MocapError, Result};

/// Checks that `k` keys fit a clip of `n` frames.
pub fn check_k(n: usize, k: usize) -> Result<()> {
    if n < 2 || k < 2 || k > n {
        return Err(MocapError::Invalid(format!("{k} keyframes do not fit a clip of {n} frames (need 2 ≤ k ≤ n)")));
    }
    Ok(())
}
