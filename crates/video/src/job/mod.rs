//! The video engine's public jobs (issue 43, ozz's job shape: inputs with [`Default`] carrying the
//! engine's constants, `validate()`, then `run(&Cancel, &Progress)`, and a report that prints itself
//! and serialises with serde):
//! - [`AnalyseJob`]: a clip (a file, or frames in memory) → flows, tendencies and LMS frames
//!   (Eq. 9–11), RSFNet trained on the clip or read from its cache (Eq. 1–6), the graph (Eq. 7),
//!   shots and their direction; its [`AnalyseReport`] keeps the clip and the analysis, so that later
//!   orders reuse them;
//! - [`ResequenceJob`]: new frame orders from a start frame (SDPF, Algorithm 1, with the walk of
//!   issue 41), each measured (M_D of Eq. 21, Δo of Eq. 23, backward steps over the engine's
//!   window) and explained step by step, and, when asked, written as MP4 or GIF with a contact sheet
//!   (optionally cross-faded at costly transitions, [`crate::render`]).
//!
//! The command line (`inbetween video resequence`), the studio's video panel and the Python package
//! only translate their inputs into these jobs and show the reports.

mod analyse;
mod resequence;

pub use analyse::{AnalyseJob, AnalyseReport, StageTime, VideoInput};
pub use resequence::{
    numbered, sheet_path, Jump, JumpKind, ResequenceJob, ResequenceReport, ResequenceSource, Sequence,
};

/// Backward steps: a step to one of this many previous source frames (`i → i−1, i−2, i−3`) plays
/// the source backwards (issue 26). The same as [`SdpfParams::reverse_window`](crate::sdpf::SdpfParams)'s
/// default, which C_r enforces; reports and the bench count by it.
pub const BACKWARD_WINDOW: usize = 3;

#[cfg(test)]
mod tests;
