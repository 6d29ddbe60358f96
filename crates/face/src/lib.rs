//! The face engine (facial animation editing by inpainting blendshape curves with a BiLSTM GAN,
//! `../shared/papers/facial-animation-editing-generative-rnn.md`). Built so far: the data layer
//! ([`data`]): blendshape clips, Live Link Face CSV and a plain curve format (CSV/JSON), resampling.

pub mod data;

pub use data::{BlendshapeClip, FaceError};
