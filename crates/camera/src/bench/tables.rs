//! The bench's rows and the paper's own numbers they are printed beside.

use serde::{Deserialize, Serialize};

#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Table1Row {
    pub behaviour: String,
    pub zero: f64,
    pub gaussian: f64,
    pub warm_start: f64,
    pub mapped: f64,
    /// No network: straight Toric line from the start to the key (the baseline to beat).
    #[serde(default)]
    pub lerp: f64,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Table2Row {
    pub displacement: f64,
    pub sd_ours: f64,
    pub sd_only_style: f64,
    pub sd_interpolation: f64,
    pub td_ours: f64,
    pub td_only_style: f64,
    pub td_interpolation: f64,
    pub kd_ours: f64,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct RailsRow {
    pub behaviour: String,
    pub ours_error: f64,
    /// Mean smallest key count for the spline to match us (capped cases count as the cap).
    pub spline_keys: f64,
    pub capped: usize,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Speed {
    /// End to end (network every 5th frame, cubic fill, world poses), one 900-frame track.
    pub single_frames_per_s: f64,
    /// Network only, 16 trajectories in lockstep, output frames (5 per step).
    pub batched_frames_per_s: f64,
    pub batch: usize,
}

/// The paper's Table 1 (behaviour; zero, Gaussian, warm start, mapped H), beside ours.
pub const PAPER_TABLE1: [(&str, f64, f64, f64, f64); 4] = [
    ("direct", 0.162, 0.146, 0.173, 0.107),
    ("relative", 0.081, 0.074, 0.088, 0.050),
    ("side", 0.045, 0.045, 0.071, 0.025),
    ("orbit", 0.263, 0.263, 0.116, 0.049),
];

/// The paper's Table 1 average row (zero, Gaussian, warm start, mapped H).
pub const PAPER_TABLE1_AVERAGE: [f64; 4] = [0.138, 0.132, 0.112, 0.057];

/// The paper's Table 2 "ours" rows for a displaced key (δ in radians; SD, TD, KD).
pub const PAPER_TABLE2: [(f64, f64, f64, f64); 10] = [
    (0.0, 1.009, 0.065, 0.016),
    (0.1, 1.009, 0.069, 0.021),
    (0.3, 1.015, 0.089, 0.051),
    (0.5, 1.025, 0.115, 0.085),
    (0.9, 1.058, 0.175, 0.154),
    (1.2, 1.082, 0.219, 0.192),
    (1.4, 1.1, 0.24, 0.216),
    (1.6, 1.12, 0.263, 0.235),
    (1.8, 1.157, 0.302, 0.251),
    (2.0, 1.211, 0.359, 0.277),
];
