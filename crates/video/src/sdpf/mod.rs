//! Single-source Distillation Path-Finding (§5, Algorithm 1): from a start frame the user picks,
//! walk the complete graph of frame distances (Eq. 7). At each step keep the unvisited frames close
//! in content (S1, Eq. 8), then those whose motion continues the current one (C_d, Eq. 12; C_t,
//! Eq. 15–17; S2, Eq. 18–19), and draw the next frame from a seeded softmax of their motion
//! distances (Eq. 20); stop early when S2 is empty.
//!
//! - [`distill`]: one step (Eq. 8, 12, 16–20);
//! - [`search`]: the walk, target length, loop closure, several distinct sequences;
//! - [`cuts`]: scene-cut detection, so that walks stay inside a shot;
//! - [`reverse`]: whether a shot's motion is directed, and the count of backward steps;
//! - [`metrics`]: M_D (Eq. 21) and Δo (Eq. 22–23);
//! - [`ssim`](mod@ssim): SSIM of transitions (Wang et al. 2004; not in the paper), the bench's perceptual proxy;
//! - [`explain`](mod@explain): `--explain` text;
//! - [`sspf`](mod@sspf): the shortest-path baseline (Fig. 3(a));
//! - [`texture`]: matched transitions (Schödl et al. 2000), the way on where S2 is empty (issue 41).
//!
//! Readings of the paper where its text is ambiguous (each is documented where it is coded):
//! - **η (Eq. 8)** is the mean of the N(N−1) off-diagonal edge weights (the paper: "Σ e_ij / N …
//!   the mean of the weights"); S1 uses `e_ck < η` strictly, so a graph whose distances are all
//!   equal has an empty S1 and stops at once.
//! - **C_d (Eq. 12)** acts when the current frame is an LMS frame and S1 holds an LMS frame; it
//!   then keeps only the LMS candidates whose tendency is within ξ = π/3 (angles wrapped), as in
//!   Fig. 13 where the non-LMS candidates are dropped.
//! - **C_t (Eq. 16–17).** The paper writes "δ ≤ ω" with δ = −distance (Eq. 15). Read literally,
//!   that keeps the candidates whose motion differs *more* than average. The text ("to control
//!   the motion in adjacent frames not to change frequently or drastically") and Eq. 20 (which
//!   favours large δ, i.e. small distances) say the opposite. So C_t keeps the candidates whose
//!   motion distance is at most:
//!   - the mean over S1, when n1 ≥ 2;
//!   - FC's distance to its ±90° rotations ([`MotionDistance::rotated_floor`]), when n1 < 2.
//! - **S2 (Eq. 18–19)** holds the candidates that pass both C_d and C_t ("+" read as "and").
//!   Each constraint judges all of S1, and ω is the mean over all of S1.
//!
//! Differences on purpose (see [`SdpfParams`]):
//! - **Eq. 20's scale.** δ is a latent distance, whose scale depends on the network; we divide
//!   it by ω so that the temperature τ means the same on any clip, and use τ = 0.1.
//! - **Content in the choice.** Eq. 20 adds λ · e_ck / ē (λ = 2) to the relative motion distance,
//!   so that among the S1 frames the closer in content are likelier. `SdpfParams::paper_choice`
//!   gives Eq. 20 as printed.
//!
//! Beyond the paper:
//! - **reverse distillation C_r**: no step that plays the motion backwards (a step to one of the
//!   three previous source frames, or to a frame of the shot closer in content to the current
//!   frame's past than to its future). C_d cannot do this: it compares the tendencies of the two
//!   frames' own motions, and the previous frame moves just like the current one. In shots judged
//!   undirected (water, fire, flicker; [`judge_directed`]) `allow_reverse` lets such steps through;
//! - shots: no jump across a scene cut unless `allow_cuts`;
//! - a target length, by default the source's frame count; where S2 is empty, instead of the
//!   paper's early stop (`stop_early` keeps it), the next source frame or a matched transition
//!   ([`texture`]) towards frames not yet shown, a cut to the shot that best matches when none is
//!   left in the shot, and once all is shown the longest loop; a step cap keeps Eq. 20's draws
//!   about as smooth as the source's own steps;
//! - loop closure back to the start frame;
//! - several distinct sequences from one graph;
//! - a record of every transition for `--explain`.

pub mod cuts;
pub mod distill;
pub mod explain;
pub mod metrics;
pub mod reverse;
pub mod search;
pub mod ssim;
pub mod sspf;
pub mod texture;
pub mod types;

pub use cuts::{cut_scores, detect_cuts, detect_cuts_with, detect_shots, shots_from_cuts, CutParams};
pub use distill::{eta, softmax};
pub use explain::{explain, explain_step};
pub use metrics::{
    distinct_fraction, frame_rms, longest_repeated_cycle, overlap, overlap_delta_o, per_100_frames,
    short_cycle_repeats, shot_changes, source_md, stability_md, try_stability_md, Cycle, Overlap,
};
pub use reverse::{
    backward_positions, backward_steps, direction_flips, direction_words, is_backward_step, judge_directed,
    DIRECTED_LMS_SHARE,
};
pub use search::{sdpf, several, several_with};
pub use ssim::{ssim, ssim_planes, transition_ssims, Plane, SSIM_SIDE};
pub use sspf::sspf;
pub use texture::Transitions;
pub use types::{
    Candidate, CdState, CrState, MatrixMotion, MotionDistance, MotionInfo, NoMotion, Omega, Path, SdpfParams, SdpfPath,
    StepKind, StopReason, Transition,
};

#[cfg(test)]
mod tests;
