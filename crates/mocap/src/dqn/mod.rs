//! The SIDQL deep Q-network (§4): the keyframe MDP ([`env`](mod@env)), the Q-network ([`model`]), the replay
//! memory ([`replay`]), training with main and target networks on the shared loop ([`train`](mod@train)) and
//! the trained policy, which needs no training code ([`policy`]); [`TrainJob`] runs training as
//! `inbetween mocap train` does.

pub mod env;
pub mod job;
pub mod model;
pub mod options;
pub mod policy;
pub mod replay;
pub mod train;

pub use job::{TrainJob, TrainJobReport};
pub use model::{DqnConfig, QNet, QRuntime};
pub use options::{TrainOptions, DEFAULT_POLICY_PATH};
pub use policy::{Finish, PolicyInfo, SidqlPolicy};
pub use train::{train, TrainReport, Trained};
