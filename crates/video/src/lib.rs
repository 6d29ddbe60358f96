//! Video resequencing (Le et al., "Regenerating Arbitrary Video Sequences with Distillation
//! Path-Finding"): new frame orders from one clip.
//!
//! The folders follow the paper's pipeline:
//! - [`frames`]: clips in and out (MP4/H.264, GIF, PNG/JPEG folders) and the procedural test clip;
//! - [`motion`]: dense optical flow and the motion features of §5.2 (Eq. 9–11, 13–14);
//! - [`metric`]: RSFNet (§4, Eq. 1–6), its training on triplets from the clip, embeddings and the
//!   complete graph of latent distances (Eq. 7);
//! - [`sdpf`]: Single-source Distillation Path-Finding (Algorithm 1, Eq. 8, 12, 15–20), the
//!   evaluation metrics (Eq. 21–23) and the whole pipeline;
//! - [`job`]: the public jobs ([`job::AnalyseJob`], [`job::ResequenceJob`]) that the command line,
//!   the studio and Python run; [`render`]: the frames of an order, cross-faded where asked.

pub mod bench;
pub mod demo;
pub mod error;
pub mod frames;
pub mod job;
pub mod metric;
pub mod motion;
pub mod pipeline;
pub mod preview;
pub mod render;
pub mod sdpf;

pub use error::VideoError;
