//! The SIDQL deep Q-network (§4): the keyframe MDP ([`env`]), the Q-network ([`model`]), the replay
//! memory ([`replay`]) and training with main and target networks ([`train`]).

pub mod env;
pub mod model;
pub mod replay;
pub mod train;

pub use model::{DqnConfig, QNet};
pub use train::{train, TrainOptions, TrainReport};
