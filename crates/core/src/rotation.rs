//! Rotations on glam's f64 types: all six Euler orders, the axis-angle map and angle errors.
//!
//! Convention: an order such as `Zyx` names the rotation axes in the sequence they appear in a BVH
//! `CHANNELS` line (`Zrotation Yrotation Xrotation`) and composes them left to right as intrinsic
//! rotations, `R = Rz(z) * Ry(y) * Rx(x)`: the BVH and ASF/AMC meaning.

use glam::{DMat3, DQuat, DVec3};
use serde::{Deserialize, Serialize};

/// A coordinate axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Axis {
    X,
    Y,
    Z,
}

impl Axis {
    /// Unit vector along this axis.
    pub fn unit(self) -> DVec3 {
        match self {
            Axis::X => DVec3::X,
            Axis::Y => DVec3::Y,
            Axis::Z => DVec3::Z,
        }
    }

    /// Component index (x = 0, y = 1, z = 2).
    pub fn index(self) -> usize {
        match self {
            Axis::X => 0,
            Axis::Y => 1,
            Axis::Z => 2,
        }
    }

    /// Rotation of `angle` radians about this axis.
    pub fn rotation(self, angle: f64) -> DQuat {
        DQuat::from_axis_angle(self.unit(), angle)
    }
}

/// The six Tait–Bryan orders, named by the sequence of axes as written in a BVH channel line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum EulerOrder {
    Xyz,
    Xzy,
    Yxz,
    Yzx,
    Zxy,
    Zyx,
}

impl EulerOrder {
    pub const ALL: [EulerOrder; 6] =
        [EulerOrder::Xyz, EulerOrder::Xzy, EulerOrder::Yxz, EulerOrder::Yzx, EulerOrder::Zxy, EulerOrder::Zyx];

    /// The axes in channel order.
    pub fn axes(self) -> [Axis; 3] {
        use Axis::*;
        match self {
            EulerOrder::Xyz => [X, Y, Z],
            EulerOrder::Xzy => [X, Z, Y],
            EulerOrder::Yxz => [Y, X, Z],
            EulerOrder::Yzx => [Y, Z, X],
            EulerOrder::Zxy => [Z, X, Y],
            EulerOrder::Zyx => [Z, Y, X],
        }
    }

    /// The order whose axes are `axes`, if they are a permutation of X, Y, Z.
    pub fn from_axes(axes: [Axis; 3]) -> Option<EulerOrder> {
        EulerOrder::ALL.into_iter().find(|o| o.axes() == axes)
    }

    /// Parses "XYZ", "zyx", … (ASF `axis` fields and user options).
    pub fn parse(s: &str) -> Option<EulerOrder> {
        let mut axes = [Axis::X; 3];
        let chars: Vec<char> = s.trim().chars().collect();
        if chars.len() != 3 {
            return None;
        }
        for (slot, c) in axes.iter_mut().zip(chars) {
            *slot = match c.to_ascii_uppercase() {
                'X' => Axis::X,
                'Y' => Axis::Y,
                'Z' => Axis::Z,
                _ => return None,
            };
        }
        EulerOrder::from_axes(axes)
    }

    /// Upper-case name, e.g. "ZYX".
    pub fn name(self) -> &'static str {
        match self {
            EulerOrder::Xyz => "XYZ",
            EulerOrder::Xzy => "XZY",
            EulerOrder::Yxz => "YXZ",
            EulerOrder::Yzx => "YZX",
            EulerOrder::Zxy => "ZXY",
            EulerOrder::Zyx => "ZYX",
        }
    }

    /// `R = R_a0(angles[0]) * R_a1(angles[1]) * R_a2(angles[2])`, angles in radians, in channel order.
    pub fn to_quat(self, angles: [f64; 3]) -> DQuat {
        let [a, b, c] = self.axes();
        a.rotation(angles[0]) * b.rotation(angles[1]) * c.rotation(angles[2])
    }

    /// Inverse of [`EulerOrder::to_quat`]: angles in channel order, middle angle in [-π/2, π/2].
    /// At gimbal lock (middle angle ±π/2) the last angle is set to zero.
    pub fn from_quat(self, q: DQuat) -> [f64; 3] {
        let m = DMat3::from_quat(q.normalize());
        let [a, b, c] = self.axes();
        let (i, j, k) = (a.index(), b.index(), c.index());
        // Sign of the permutation (i, j, k): +1 for cyclic orders (XYZ, YZX, ZXY).
        let s = if (j + 3 - i) % 3 == 1 { 1.0 } else { -1.0 };
        // m.col(col)[row] is element (row, col).
        let e = |row: usize, col: usize| m.col(col)[row];
        let sin_b = (s * e(i, k)).clamp(-1.0, 1.0);
        let beta = sin_b.asin();
        if sin_b.abs() < 1.0 - 1e-12 {
            let alpha = (-s * e(j, k)).atan2(e(k, k));
            let gamma = (-s * e(i, j)).atan2(e(i, i));
            [alpha, beta, gamma]
        } else {
            // Gimbal lock: only alpha ± gamma is defined; put it all in alpha.
            let alpha = (s * e(k, j)).atan2(e(j, j));
            [alpha, beta, 0.0]
        }
    }
}

/// Rotation vector (axis × angle, angle in [0, π]) of a unit quaternion: the quaternion log times two.
pub fn quat_to_rotvec(q: DQuat) -> DVec3 {
    let q = if q.w < 0.0 { -q } else { q };
    let v = DVec3::new(q.x, q.y, q.z);
    let s = v.length();
    if s < 1e-12 {
        // Small-angle limit of 2·atan2(s, w)/s is 2/w.
        return v * (2.0 / q.w.max(1e-300));
    }
    v * (2.0 * s.atan2(q.w) / s)
}

/// Unit quaternion of a rotation vector: the exponential map.
pub fn rotvec_to_quat(v: DVec3) -> DQuat {
    let angle = v.length();
    if angle < 1e-12 {
        let h = v * 0.5;
        return DQuat::from_xyzw(h.x, h.y, h.z, 1.0).normalize();
    }
    DQuat::from_axis_angle(v / angle, angle)
}

/// Geodesic angle between two rotations, in radians, in [0, π].
pub fn angle_between(a: DQuat, b: DQuat) -> f64 {
    // atan2 of the relative rotation keeps full precision near zero, where acos of the dot does not.
    let r = a.inverse() * b;
    let s = DVec3::new(r.x, r.y, r.z).length();
    2.0 * s.atan2(r.w.abs())
}

/// Flips quaternion signs along a sequence so that neighbours lie in the same hemisphere,
/// which interpolation and finite differences need.
pub fn make_continuous(quats: &mut [DQuat]) {
    for i in 1..quats.len() {
        if quats[i - 1].dot(quats[i]) < 0.0 {
            quats[i] = -quats[i];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn zyx_matches_glam_intrinsic_convention() {
        let angles = [0.3, -0.7, 1.1];
        let ours = EulerOrder::Zyx.to_quat(angles);
        let glam = DQuat::from_euler(glam::EulerRot::ZYX, 0.3, -0.7, 1.1);
        assert!(angle_between(ours, glam) < 1e-12);
    }

    #[test]
    fn parse_and_name_agree() {
        for o in EulerOrder::ALL {
            assert_eq!(EulerOrder::parse(o.name()), Some(o));
            assert_eq!(EulerOrder::parse(&o.name().to_lowercase()), Some(o));
        }
        assert_eq!(EulerOrder::parse("XXY"), None);
        assert_eq!(EulerOrder::parse("XY"), None);
    }

    #[test]
    fn gimbal_lock_still_reconstructs_the_rotation() {
        for o in EulerOrder::ALL {
            let q = o.to_quat([0.4, std::f64::consts::FRAC_PI_2, -0.2]);
            let back = o.to_quat(o.from_quat(q));
            assert!(angle_between(q, back) < 1e-6, "{o:?}");
        }
    }

    #[test]
    fn rotvec_small_angles_are_stable() {
        let v = DVec3::new(1e-14, -2e-14, 3e-15);
        let back = quat_to_rotvec(rotvec_to_quat(v));
        assert!((back - v).length() < 1e-20);
    }

    proptest! {
        // A fixed seed: the same cases on every run (the project's tests are deterministic).
        #![proptest_config(ProptestConfig { rng_seed: proptest::test_runner::RngSeed::Fixed(crate::seed::PROPTEST_SEED), ..ProptestConfig::default() })]
        #[test]
        fn euler_round_trip_all_orders(a in -3.1f64..3.1, b in -1.5f64..1.5, c in -3.1f64..3.1) {
            for o in EulerOrder::ALL {
                let q = o.to_quat([a, b, c]);
                let angles = o.from_quat(q);
                prop_assert!((angles[0] - a).abs() < 1e-9, "{o:?} {angles:?}");
                prop_assert!((angles[1] - b).abs() < 1e-9);
                prop_assert!((angles[2] - c).abs() < 1e-9);
            }
        }

        #[test]
        fn rotvec_round_trip(x in -3.0f64..3.0, y in -3.0f64..3.0, z in -3.0f64..3.0) {
            let v = DVec3::new(x, y, z);
            prop_assume!(v.length() < std::f64::consts::PI - 1e-6);
            let back = quat_to_rotvec(rotvec_to_quat(v));
            prop_assert!((back - v).length() < 1e-9);
        }
    }
}
