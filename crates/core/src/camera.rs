//! A camera over the frames of a clip, as the two engines that place one hand it on. The script
//! engine aims each shot's camera at a point ([`AimedCamera`]: eye, target, vertical field of
//! view); the camera engine poses its camera in Toric space ([`PosedCamera`]: a world
//! [`CameraPose`] from [`crate::toric::to_pose`] and its [`Lens`]). A [`CameraTrack`] holds one of
//! them per frame with the rate it was sampled at. Conventions as in [`crate::toric`]: the world
//! is right-handed with +Y up, a camera looks down its local −Z with +Y up.

use crate::toric::{CameraPose, Lens};
use glam::{DVec2, DVec3, Vec3};
use serde::{Deserialize, Serialize};

/// A camera aimed at a point, upright (world +Y up, no roll): where it stands, the point it looks
/// at and its vertical field of view in degrees, in f32 as the glTF and preview outputs store them.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AimedCamera {
    /// Position, metres.
    pub eye: Vec3,
    /// The point it looks at, metres.
    pub target: Vec3,
    /// Vertical field of view, degrees.
    pub fovy_deg: f32,
}

impl AimedCamera {
    /// The world pose: at the eye, looking at the target ([`CameraPose::look_at`], in f64).
    pub fn pose(&self) -> CameraPose {
        CameraPose::look_at(self.eye.as_dvec3(), self.target.as_dvec3())
    }

    /// The lens of this field of view at `aspect` (width / height).
    pub fn lens(&self, aspect: f64) -> Lens {
        Lens { fovy: (self.fovy_deg as f64).to_radians(), aspect }
    }

    /// The pose and the lens at `aspect` (width / height).
    pub fn posed(&self, aspect: f64) -> PosedCamera {
        PosedCamera { pose: self.pose(), lens: self.lens(aspect) }
    }

    /// Whether the field of view lies strictly between 0° and 180°.
    pub fn fov_is_valid(&self) -> bool {
        self.fovy_deg.is_finite() && self.fovy_deg > 0.0 && self.fovy_deg < 180.0
    }

    /// Whether the eye and the target are finite.
    pub fn is_finite(&self) -> bool {
        self.eye.is_finite() && self.target.is_finite()
    }
}

/// A camera posed in the world with its lens.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PosedCamera {
    pub pose: CameraPose,
    pub lens: Lens,
}

impl PosedCamera {
    /// Screen position (normalised, [−1, 1]² when on screen) of a world point, `None` behind the
    /// camera.
    pub fn project(&self, world: DVec3) -> Option<DVec2> {
        self.pose.project(&self.lens, world)
    }
}

/// A camera at every frame from `first_frame` on, sampled at `fps`: `frames[i]` is frame
/// `first_frame + i`, at `(first_frame + i) / fps` seconds.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CameraTrack<C> {
    /// Frames per second.
    pub fps: f64,
    pub first_frame: usize,
    pub frames: Vec<C>,
}

impl<C: Copy> CameraTrack<C> {
    /// The camera at clip frame `frame`, `None` outside the track.
    pub fn at(&self, frame: usize) -> Option<C> {
        frame.checked_sub(self.first_frame).and_then(|i| self.frames.get(i).copied())
    }

    /// Seconds from the clip's start to `frames[i]`.
    pub fn seconds(&self, i: usize) -> f64 {
        (self.first_frame + i) as f64 / self.fps
    }

    /// The same frames through `f` (another kind of camera).
    pub fn map<D>(&self, f: impl FnMut(C) -> D) -> CameraTrack<D> {
        CameraTrack {
            fps: self.fps,
            first_frame: self.first_frame,
            frames: self.frames.iter().copied().map(f).collect(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_aimed_camera_sees_its_target_at_the_screen_centre_and_its_eye_level_upright() {
        let cam = AimedCamera { eye: Vec3::new(1.0, 1.6, 4.0), target: Vec3::new(0.5, 1.2, 0.0), fovy_deg: 50.0 };
        let posed = cam.posed(1.5);
        assert!((posed.lens.fovy - 50f64.to_radians()).abs() < 1e-12);
        let centre = posed.project(cam.target.as_dvec3()).unwrap();
        assert!(centre.length() < 1e-9, "target at {centre}");
        // No roll: the camera's right vector is horizontal.
        assert!((posed.pose.rotation * DVec3::X).y.abs() < 1e-9);
        assert!(posed.project(DVec3::new(1.0, 1.6, 8.0)).is_none(), "a point behind the eye");
        assert!(cam.fov_is_valid() && cam.is_finite());
        assert!(!AimedCamera { fovy_deg: 180.0, ..cam }.fov_is_valid());
        assert!(!AimedCamera { eye: Vec3::new(f32::NAN, 0.0, 0.0), ..cam }.is_finite());
    }

    #[test]
    fn a_track_answers_frames_from_its_first_and_times_them_at_its_rate() {
        let cam = AimedCamera { eye: Vec3::Z, target: Vec3::ZERO, fovy_deg: 40.0 };
        let track = CameraTrack { fps: 30.0, first_frame: 5, frames: vec![cam, AimedCamera { fovy_deg: 60.0, ..cam }] };
        assert_eq!(track.at(4), None);
        assert_eq!(track.at(6).map(|c| c.fovy_deg), Some(60.0));
        assert_eq!(track.at(7), None);
        assert_eq!(track.seconds(1), 6.0 / 30.0);
        let fovs = track.map(|c| c.fovy_deg);
        assert_eq!((fovs.first_frame, fovs.frames), (5, vec![40.0, 60.0]));
    }
}
