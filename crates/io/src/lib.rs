//! File formats: BVH, ASF/AMC, and the shared file helpers (atomic writes, locating shared data).

pub mod data;
pub mod fsutil;

pub use data::shared_data_dir;
pub use fsutil::write_atomic;
