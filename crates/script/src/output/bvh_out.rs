//! A character's motion as BVH. BVH has no unit and the reader/writer in `inbetween_io` accept no
//! comments, so the unit goes in a sidecar `<file>.json` next to it (`walk.bvh` →
//! `walk.bvh.json`): `{ "unit": "m", "fps": …, "frames": …, "joints": …, "up": "+Y",
//! "forward": "+Z" }`.

use std::path::{Path, PathBuf};

use inbetween_core::clip::Clip;
use serde_json::json;

use crate::error::ScriptError;

/// Path of the sidecar that states the BVH's length unit: the BVH path with `.json` appended.
pub fn bvh_sidecar_path(path: &Path) -> PathBuf {
    let mut s = path.as_os_str().to_owned();
    s.push(".json");
    PathBuf::from(s)
}

/// Writes `clip` (the common rig in metres, see [`crate::motion::rig`]) as BVH through
/// [`inbetween_io::bvh::write_bvh`] (the file boundary where poses become Euler channels), plus
/// its sidecar ([`bvh_sidecar_path`]); both atomic.
pub fn write_character_bvh(path: &Path, clip: &Clip) -> Result<(), ScriptError> {
    let motion = &clip.to_motion().map_err(|e| ScriptError::Invalid(format!("{}: {e}", path.display())))?;
    inbetween_io::bvh::write_bvh(path, motion)
        .map_err(|e| ScriptError::Asset { path: path.to_path_buf(), message: e.to_string() })?;
    let side = bvh_sidecar_path(path);
    let meta = json!({
        "unit": "m",
        "fps": motion.fps(),
        "frame_time": motion.frame_time,
        "frames": motion.num_frames(),
        "joints": motion.skeleton.len(),
        "up": "+Y",
        "forward": "+Z",
        "rotations": "degrees, each joint's CHANNELS order",
    });
    let text =
        serde_json::to_string_pretty(&meta).map_err(|e| ScriptError::Invalid(format!("BVH sidecar JSON: {e}")))?;
    inbetween_io::write_atomic(&side, text.as_bytes()).map_err(|e| ScriptError::io(&side, e))
}
