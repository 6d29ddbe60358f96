//! What generation returns, offline ([`super::GenerateJob`]) and live ([`super::CausalCamera`])
//! alike: the generated track (its frames with their Toric coordinates and targets, the misses at
//! keys), whose camera per frame is a core [`CameraTrack`] of [`PosedCamera`]s. Both modes build on this module and
//! neither imports the other's internals.

use crate::dataset::Scene;
use crate::toric::{to_pose, CameraPose, Lens, Toric};
use crate::CameraError;
use inbetween_core::camera::{CameraTrack, PosedCamera};
use serde::{Deserialize, Serialize};

/// One generated frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CameraFrame {
    pub frame: usize,
    pub toric: Toric,
    pub targets: [usize; 2],
    pub pose: CameraPose,
}

/// How far the network's own output missed a keyframe (before correction).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct KeyResidual {
    pub frame: usize,
    /// ‖x̂^c − x^c_K‖₂ in Toric units.
    pub residual: f64,
}

/// A generated camera track: the camera per frame and how the network got there (style, Toric
/// coordinates, key misses).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GeneratedTrack {
    pub fps: f64,
    pub style: String,
    pub style_code: Vec<f32>,
    pub lens: Lens,
    pub frames: Vec<CameraFrame>,
    pub key_residuals: Vec<KeyResidual>,
    /// Largest residual left after correction (0 up to rounding when `exact_keys`).
    pub max_corrected_residual: f64,
}

impl GeneratedTrack {
    pub fn toric(&self) -> Vec<Toric> {
        self.frames.iter().map(|f| f.toric).collect()
    }

    /// The camera of every frame (pose and lens) at the track's rate, from its first frame
    /// (frames are consecutive).
    pub fn camera(&self) -> CameraTrack<PosedCamera> {
        CameraTrack {
            fps: self.fps,
            first_frame: self.frames.first().map_or(0, |f| f.frame),
            frames: self.frames.iter().map(|f| PosedCamera { pose: f.pose, lens: self.lens }).collect(),
        }
    }

    /// The largest network miss at a key (before correction).
    pub fn worst_key_miss(&self) -> f64 {
        self.key_residuals.iter().map(|r| r.residual).fold(0.0, f64::max)
    }
}

/// One output frame: `toric` clamped to the lens, posed in the world on `pair`'s targets.
pub(super) fn camera_frame(
    scene: &Scene,
    frame: usize,
    pair: (usize, usize),
    toric: Toric,
    lens: &Lens,
) -> Result<CameraFrame, CameraError> {
    let (a, b) = (scene.characters[pair.0].frame(frame).target(), scene.characters[pair.1].frame(frame).target());
    let toric = toric.clamped(lens, 0.02);
    let pose = to_pose(&toric, a, b, lens).map_err(|e| CameraError::Model(format!("frame {frame}: {e}")))?;
    Ok(CameraFrame { frame, toric, targets: [pair.0, pair.1], pose })
}
