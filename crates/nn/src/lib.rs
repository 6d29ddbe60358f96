//! Shared machine-learning building blocks for the inbetween engines, on burn 0.22.
//!
//! Tensors in burn 0.22 carry no backend type parameter: a [`Tensor<D>`](burn::tensor::Tensor)
//! lives on a [`Device`](burn::tensor::Device), and every constructor here takes `&Device`, so the
//! same model code runs on the pure-Rust flex CPU backend (default, see [`backend::cpu`]), with
//! autodiff ([`backend::cpu_autodiff`]) or, behind the opt-in `cuda` crate feature, on a GPU.
//!
//! Modules:
//! - [`backend`]: device helpers (flex CPU, autodiff, optional CUDA) and seeding. flex has one
//!   random generator per process and burn initialises parameters lazily, so build models with
//!   [`backend::seeded_module`] to get the same weights for the same seed even when other threads
//!   (parallel tests) draw random numbers.
//! - [`lstm`]: fused LSTM cell ([`lstm::FusedLstm`]) and stacked bidirectional LSTM
//!   ([`lstm::BiLstm`]) over sequences kept as `Vec` of per-step `[batch, features]` tensors.
//! - [`tta`]: time-to-arrival sinusoidal embedding (Harvey et al. 2020).
//! - [`spectral`]: spectral-normalised linear and 1-D convolution layers.
//! - [`train`]: the one training loop of every engine (Adam, lr decay with warm restarts, clipping,
//!   time limit, per-step and per-epoch hooks, checkpoints, bit-identical resume including the
//!   objective's own state).
//! - [`checkpoint`]: atomic save/load of module and optimiser records plus a JSON sidecar.
//! - [`weights`]: trained weights as burnpack + a JSON card (kind, config, provenance, metrics);
//!   committed weights compiled in with `include_bytes!`.
//! - [`runtime`]: plain-Rust Dense/LSTM inference layers built from trained modules, no allocation
//!   per step.
//! - [`bench`](mod@bench): throughput rows for the `bench` commands.

pub mod backend;
pub mod bench;
pub mod checkpoint;
pub mod lstm;
pub mod runtime;
pub mod spectral;
pub mod train;
pub mod tta;
pub mod weights;

mod error;

pub use error::NnError;

/// Re-export of the pinned burn, so engine crates can name the exact same types.
pub use burn;
