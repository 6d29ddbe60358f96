//! The learned frame metric of §4: RSFNet, its training on triplets from the clip itself with the
//! distance loss, frame embeddings and the complete graph of latent distances.
//!
//! - [`model`]: RSFNet = CFE (four VGG-like conv blocks) + RFF (NCM Eq. 2, C1R Eq. 3, recursion
//!   Eq. 1) + pooling + dense. **The CFE is trained from scratch**: the paper's ImageNet VGG-19
//!   weights cannot be had offline here, so the whole network (much narrower than VGG) learns from the
//!   clip's own triplets. `use_rff: false` is the "w/o RSFNet" ablation of Table 3.
//! - [`loss`]: the distance loss (Eq. 4–5) and PSNR labels (Eq. 6; read with z = 1 when the
//!   *positive* is the more similar frame, see there why).
//! - [`train`]: seeded triplet sampling from the clip and training on the shared loop
//!   ([`inbetween_nn::train`]); `use_distance_loss: false` is the "w/o L_d" ablation.
//! - [`embed`]: batched inference without autodiff, for frames and for the pseudo-images of Eq. 15.
//! - [`cache`]: one file per clip, config and options, holding the network and the embeddings.
//! - [`graph`]: the complete graph of Eq. 7 and the plain pixel-distance baseline.
//!
//! ```no_run
//! use inbetween_video::metric::{embeddings_cached, graph_from_embeddings, RsfConfig, TrainOptions};
//! # let frames: Vec<image::RgbImage> = Vec::new();
//! let metric = embeddings_cached(std::path::Path::new("cache"), &frames, &RsfConfig::default(),
//!     &TrainOptions { seed: 7, ..TrainOptions::default() }, &inbetween_io::Progress::hidden())?;
//! let graph = graph_from_embeddings(&metric.embeddings);
//! # Ok::<(), inbetween_video::VideoError>(())
//! ```

pub mod cache;
pub mod embed;
pub mod graph;
pub mod input;
pub mod loss;
pub mod model;
pub mod train;

pub use cache::{cache_key, cache_path, embeddings_cached, embeddings_cached_with, ClipMetric};
pub use embed::Embedder;
pub use graph::{graph_from_embeddings, pixel_graph, Graph};
pub use loss::{distance_loss, distance_loss_value, triplet_label, triplet_labels, Triplet};
pub use model::{RsfConfig, RsfNet};
pub use train::{
    agreement, clip_planes, train_on_planes, train_on_planes_with, train_rsfnet, TrainOptions, TrainSummary,
    TripletSampler,
};

#[cfg(test)]
mod tests;
