//! The train/test split of the real Live Link captures, by file: the networks trained on the captures
//! ([`crate::corpus::real_pool`]) see only [`TRAIN_FILES`]; the bench holds out [`TEST_FILES`].

/// Held-out capture files (relative to `face/neurosync/`): one file of each emotion that has two or
/// more takes, so every emotion is still seen in training.
pub const TEST_FILES: [&str; 2] =
    ["livelink/Fearful/MySlate_162_iPhone_cal.csv", "livelink/Sad/MySlate_168_iPhone_cal.csv"];

/// Training capture files: every Live Link capture not in [`TEST_FILES`].
pub const TRAIN_FILES: [&str; 6] = [
    "livelink/Angry/MySlate_164_iPhone_cal.csv",
    "livelink/Angry/MySlate_165_iPhone_cal.csv",
    "livelink/Angry/MySlate_166_iPhone_cal.csv",
    "livelink/Fearful/MySlate_161_iPhone_cal.csv",
    "livelink/Happy/Happy.csv",
    "livelink/Sad/MySlate_167_iPhone_cal.csv",
];
