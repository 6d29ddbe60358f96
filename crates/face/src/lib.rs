//! The face engine: facial animation editing by inpainting blendshape curves with a BiLSTM GAN
//! (Berson et al., `../shared/papers/facial-animation-editing-generative-rnn.md`).
//!
//! The folders follow the paper's pipeline:
//! - [`data`]: blendshape clips, Live Link Face CSV, plain CSV/JSON curves, resampling to 25 fps (§4.1).
//! - [`visemes`]: the 18 viseme classes of Table 1 and viseme tracks from TextGrid, phoneme timings or text.
//! - [`procedural`]: the procedural face-animation generator the committed weights are trained on.
//! - [`edit`]: masks, constraints (§3.1), the six key distances (§3.3), blendshape groups, baselines and
//!   the post-processing that makes keys exact and borders C1.
//! - [`model`]: the network input layout, the generator and the critic (§3.2).
//! - [`train`]: the losses and the GAN training objective on the shared training loop (§3.3).
//! - [`infer`]: the edit job (`EditJob`), from a clip and a mask to the edited clip.
//! - [`bench`](mod@bench): the evaluation of §5 (Tables 3 and 4, gap lengths, constraint types).
//! - [`preview`]: curve plots and the schematic face GIF.

pub mod bench;
pub mod corpus;
pub mod data;
pub mod demo;
pub mod edit;
mod error;
pub mod infer;
pub mod model;
pub mod preview;
pub mod procedural;
pub mod train;
pub mod visemes;
pub mod weights;

pub use data::{BlendshapeClip, FaceError};

/// Helpers shared by the readers' robustness tests (`data/robustness.rs`, `visemes/robustness.rs`).
#[cfg(test)]
pub(crate) mod test_support {
    use proptest::test_runner::{Config, TestRunner};

    /// The first `cut` bytes of `text`, moved back to a character boundary.
    pub fn truncated(text: &str, cut: usize) -> &str {
        let mut cut = cut.min(text.len());
        while !text.is_char_boundary(cut) {
            cut -= 1;
        }
        &text[..cut]
    }

    /// Property test: `check` never panics on arbitrary text of up to 400 characters (256 cases,
    /// shrunk to the smallest failing text as `proptest!` would, failures kept beside the caller).
    #[track_caller]
    pub fn arbitrary_text_never_panics(check: fn(&str)) {
        let source_file = Some(std::panic::Location::caller().file());
        let mut runner = TestRunner::new(Config {
            source_file,
            rng_seed: proptest::test_runner::RngSeed::Fixed(inbetween_core::seed::PROPTEST_SEED),
            ..Config::with_cases(256)
        });
        if let Err(e) = runner.run(&"(?s).{0,400}", |text| {
            check(&text);
            Ok(())
        }) {
            panic!("{e}\n{runner}");
        }
    }
}
