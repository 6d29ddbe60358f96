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
pub mod infer;
pub mod model;
pub mod preview;
pub mod procedural;
pub mod train;
pub mod visemes;
pub mod weights;

pub use data::{BlendshapeClip, FaceError};
