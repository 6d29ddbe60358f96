//! Cinematic features of Jiang et al. 2020, used by the paper (§3.1): character features x^v (Eq. 1)
//! from the two characters' root and shoulder positions, camera features x^c (Eq. 2) in Toric space.

use crate::toric::Toric;
use glam::DVec3;
use serde::{Deserialize, Serialize};

/// Height of the framing target above the shoulder midpoint (≈ the face), metres.
pub const TARGET_ABOVE_SHOULDERS: f64 = 0.15;

/// One character at one frame: root (pelvis) and both shoulders, world metres, +Y up.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CharacterFrame {
    pub root: DVec3,
    pub shoulder_l: DVec3,
    pub shoulder_r: DVec3,
}

impl CharacterFrame {
    /// Horizontal torso front: orthogonal to the shoulder segment (Y × (right − left)).
    pub fn front(&self) -> DVec3 {
        let across = self.shoulder_r - self.shoulder_l;
        let f = DVec3::Y.cross(across);
        DVec3::new(f.x, 0.0, f.z).try_normalize().unwrap_or(DVec3::Z)
    }

    /// The point the camera frames: just above the shoulder midpoint.
    pub fn target(&self) -> DVec3 {
        (self.shoulder_l + self.shoulder_r) * 0.5 + DVec3::Y * TARGET_ABOVE_SHOULDERS
    }
}

/// Wraps an angle into (−π, π] (the shared helper; exact for angles already in range, which the
/// procedural scenes rely on).
pub use inbetween_core::angle::wrap_angle;

/// Signed angle about +Y (counter-clockwise seen from above) from `from` to `to`, horizontal parts only.
pub fn yaw_between(from: DVec3, to: DVec3) -> f64 {
    let a = from.z.atan2(from.x);
    let b = to.z.atan2(to.x);
    // atan2(z, x) grows clockwise seen from above (+Y towards the viewer); negate for CCW.
    wrap_angle(-(b - a))
}

/// Character features x^v = (d_AB, s_A, s_B, s_AB, M) of Eq. 1. A and B are the screen-left and
/// screen-right characters; M says which one is the main character.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CharacterFeatures {
    /// 3D distance between the two framing targets, metres.
    pub d_ab: f64,
    /// Signed yaw from the direction A→B to A's torso front, radians in (−π, π].
    pub s_a: f64,
    /// Signed yaw from the direction B→A to B's torso front (0 when B faces A).
    pub s_b: f64,
    /// Signed yaw from A's front to B's front.
    pub s_ab: f64,
    /// 1 when A is the main character, 0 when B is.
    pub main_is_a: bool,
}

impl CharacterFeatures {
    /// Eq. 1 for one frame.
    pub fn compute(a: &CharacterFrame, b: &CharacterFrame, main_is_a: bool) -> CharacterFeatures {
        let ab = b.target() - a.target();
        let (fa, fb) = (a.front(), b.front());
        CharacterFeatures {
            d_ab: ab.length(),
            s_a: yaw_between(ab, fa),
            s_b: yaw_between(-ab, fb),
            s_ab: yaw_between(fa, fb),
            main_is_a,
        }
    }

    /// `[d_AB, s_A, s_B, s_AB, M]`.
    pub fn to_array(&self) -> [f64; 5] {
        [self.d_ab, self.s_a, self.s_b, self.s_ab, if self.main_is_a { 1.0 } else { 0.0 }]
    }

    pub fn from_array(x: [f64; 5]) -> CharacterFeatures {
        CharacterFeatures { d_ab: x[0], s_a: x[1], s_b: x[2], s_ab: x[3], main_is_a: x[4] > 0.5 }
    }
}

/// Camera features x^c of Eq. 2 are exactly the Toric coordinates.
pub type CameraFeatures = Toric;

/// Number of network inputs per character-feature frame: d/5, then (sin, cos) of each angle so the
/// wrap at ±π is continuous, then M.
pub const CHAR_ENC: usize = 8;
/// Number of camera features (Eq. 2).
pub const CAM_DIM: usize = 6;

/// Encodes x^v for the networks (see [`CHAR_ENC`]).
pub fn encode_character(x: &CharacterFeatures) -> [f32; CHAR_ENC] {
    let sc = |a: f64| [a.sin() as f32, a.cos() as f32];
    let [sa, ca] = sc(x.s_a);
    let [sb, cb] = sc(x.s_b);
    let [sab, cab] = sc(x.s_ab);
    [(x.d_ab / 5.0) as f32, sa, ca, sb, cb, sab, cab, if x.main_is_a { 1.0 } else { 0.0 }]
}

/// x^c as network values (Eq. 2 order).
pub fn encode_camera(x: &Toric) -> [f32; CAM_DIM] {
    x.to_array().map(|v| v as f32)
}

pub fn decode_camera(x: &[f32]) -> Toric {
    Toric::from_array([x[0], x[1], x[2], x[3], x[4], x[5]].map(|v| v as f64))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    fn standing(at: DVec3, facing_yaw: f64) -> CharacterFrame {
        let front = DVec3::new(facing_yaw.sin(), 0.0, facing_yaw.cos());
        let right = front.cross(DVec3::Y);
        let sh = at + DVec3::Y * 1.45;
        CharacterFrame { root: at + DVec3::Y, shoulder_l: sh - right * 0.2, shoulder_r: sh + right * 0.2 }
    }

    #[test]
    fn front_is_orthogonal_to_shoulders_and_follows_facing() {
        let c = standing(DVec3::ZERO, 0.3);
        let f = c.front();
        assert!((f - DVec3::new(0.3f64.sin(), 0.0, 0.3f64.cos())).length() < 1e-12);
        assert!(f.dot(c.shoulder_r - c.shoulder_l).abs() < 1e-12);
    }

    #[test]
    fn facing_each_other_gives_zero_angles() {
        // A at origin facing +X (yaw π/2), B at x = 2 facing −X.
        let a = standing(DVec3::ZERO, PI / 2.0);
        let b = standing(DVec3::new(2.0, 0.0, 0.0), -PI / 2.0);
        let x = CharacterFeatures::compute(&a, &b, true);
        assert!((x.d_ab - 2.0).abs() < 1e-12);
        assert!(x.s_a.abs() < 1e-9 && x.s_b.abs() < 1e-9);
        assert!((x.s_ab.abs() - PI).abs() < 1e-9, "opposite fronts: |s_AB| = π, got {}", x.s_ab);
        assert_eq!(x.to_array()[4], 1.0);
    }

    #[test]
    fn turning_counter_clockwise_gives_positive_angle() {
        let a = standing(DVec3::ZERO, PI / 2.0 + 0.4); // seen from above, +yaw about Y is CCW
        let b = standing(DVec3::new(2.0, 0.0, 0.0), -PI / 2.0);
        let x = CharacterFeatures::compute(&a, &b, false);
        assert!((x.s_a - 0.4).abs() < 1e-9, "s_A = {}", x.s_a);
        assert!(!x.main_is_a);
    }

    #[test]
    fn plus_and_minus_pi_encode_alike() {
        let enc = encode_character(&CharacterFeatures { d_ab: 5.0, s_a: PI, s_b: -PI, s_ab: 0.0, main_is_a: true });
        assert!((enc[1] - enc[3]).abs() < 1e-6 && (enc[2] - enc[4]).abs() < 1e-6, "±π encode alike");
    }
}
