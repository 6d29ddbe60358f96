//! Interpolation primitives: linear, smoothstep, cubic Hermite (values + derivatives), quaternion
//! slerp and quaternion Hermite (values + angular velocities).
//!
//! Parameters: `u ∈ [0, 1]` is the normalised time inside a segment of duration `h` seconds, and
//! every derivative is per second, so segments of different lengths share one convention.

use crate::rotation::{quat_to_rotvec, rotvec_to_quat};
use glam::{DQuat, DVec3};

/// Cubic Hermite basis `(h00, h10, h01, h11)` at `u`.
#[inline]
pub fn hermite_basis(u: f64) -> (f64, f64, f64, f64) {
    let u2 = u * u;
    let u3 = u2 * u;
    (2.0 * u3 - 3.0 * u2 + 1.0, u3 - 2.0 * u2 + u, -2.0 * u3 + 3.0 * u2, u3 - u2)
}

/// Linear interpolation.
#[inline]
pub fn lerp(a: f64, b: f64, u: f64) -> f64 {
    a + (b - a) * u
}

/// The smoothstep ease `3x² − 2x³` of `x` clamped to `[0, 1]`: 0 at 0, 1 at 1, zero slope at both
/// ends (the Hermite cubic from 0 to 1 with zero tangents, `h01` of [`hermite_basis`]). The weight
/// of cross-fades ([`crate::curve::CrossFade`]), blinks and expression onsets.
#[inline]
pub fn smoothstep(x: f64) -> f64 {
    let x = x.clamp(0.0, 1.0);
    x * x * (3.0 - 2.0 * x)
}

/// The cubic with value `p0`, slope `v0` at the start and `p1`, `v1` at the end of a segment `h` long.
#[inline]
pub fn hermite(p0: f64, v0: f64, p1: f64, v1: f64, h: f64, u: f64) -> f64 {
    let (h00, h10, h01, h11) = hermite_basis(u);
    h00 * p0 + h10 * h * v0 + h01 * p1 + h11 * h * v1
}

/// Derivative (per second) of [`hermite`].
#[inline]
pub fn hermite_derivative(p0: f64, v0: f64, p1: f64, v1: f64, h: f64, u: f64) -> f64 {
    let u2 = u * u;
    let d00 = 6.0 * u2 - 6.0 * u;
    let d10 = 3.0 * u2 - 4.0 * u + 1.0;
    let d01 = -6.0 * u2 + 6.0 * u;
    let d11 = 3.0 * u2 - 2.0 * u;
    (d00 * p0 + d01 * p1) / h + d10 * v0 + d11 * v1
}

/// [`hermite`] for vectors.
#[inline]
pub fn hermite_vec3(p0: DVec3, v0: DVec3, p1: DVec3, v1: DVec3, h: f64, u: f64) -> DVec3 {
    let (h00, h10, h01, h11) = hermite_basis(u);
    p0 * h00 + v0 * (h10 * h) + p1 * h01 + v1 * (h11 * h)
}

/// Spherical linear interpolation along the shorter arc.
#[inline]
pub fn slerp(a: DQuat, b: DQuat, u: f64) -> DQuat {
    a.slerp(b, u)
}

/// Body-frame angular velocity (rad/s) that turns `a` into `b` in `dt` seconds at a constant rate:
/// `log(a⁻¹ b) / dt` as a rotation vector.
pub fn angular_velocity(a: DQuat, b: DQuat, dt: f64) -> DVec3 {
    quat_to_rotvec(a.inverse() * b) / dt
}

/// Quaternion Hermite curve in the cumulative form of Kim, Kim & Shin (1995): value `q0` with
/// body-frame angular velocity `w0` at the start, `q1` with `w1` at the end, segment `h` seconds.
/// It passes through both ends exactly and matches both angular velocities; with zero velocities
/// it reduces to an ease-in/ease-out slerp.
pub fn hermite_quat(q0: DQuat, w0: DVec3, q1: DQuat, w1: DVec3, h: f64, u: f64) -> DQuat {
    let q1 = if q0.dot(q1) < 0.0 { -q1 } else { q1 };
    let a = w0 * (h / 3.0);
    let c = w1 * (h / 3.0);
    let b = quat_to_rotvec(rotvec_to_quat(-a) * q0.inverse() * q1 * rotvec_to_quat(-c));
    let one_minus = 1.0 - u;
    let beta1 = 1.0 - one_minus * one_minus * one_minus;
    let beta2 = 3.0 * u * u - 2.0 * u * u * u;
    let beta3 = u * u * u;
    (q0 * rotvec_to_quat(a * beta1) * rotvec_to_quat(b * beta2) * rotvec_to_quat(c * beta3)).normalize()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rotation::angle_between;

    #[test]
    fn smoothstep_eases_from_zero_to_one_with_flat_ends() {
        assert_eq!(smoothstep(-1.0), 0.0);
        assert_eq!(smoothstep(0.0), 0.0);
        assert_eq!(smoothstep(0.5), 0.5);
        assert_eq!(smoothstep(1.0), 1.0);
        assert_eq!(smoothstep(7.0), 1.0);
        // It is the Hermite cubic from 0 to 1 with zero slopes.
        for i in 0..=10 {
            let u = i as f64 / 10.0;
            assert!((smoothstep(u) - hermite(0.0, 0.0, 1.0, 0.0, 1.0, u)).abs() < 1e-15);
        }
        let e = 1e-7;
        assert!(smoothstep(e) < 1e-12 && 1.0 - smoothstep(1.0 - e) < 1e-12, "flat at both ends");
    }

    #[test]
    fn hermite_matches_ends_and_slopes() {
        let (p0, v0, p1, v1, h) = (1.0, -2.0, 3.0, 0.5, 0.4);
        assert!((hermite(p0, v0, p1, v1, h, 0.0) - p0).abs() < 1e-12);
        assert!((hermite(p0, v0, p1, v1, h, 1.0) - p1).abs() < 1e-12);
        assert!((hermite_derivative(p0, v0, p1, v1, h, 0.0) - v0).abs() < 1e-12);
        assert!((hermite_derivative(p0, v0, p1, v1, h, 1.0) - v1).abs() < 1e-12);
        // Numerical derivative agrees with the analytic one inside the segment.
        let e = 1e-6;
        let num = (hermite(p0, v0, p1, v1, h, 0.3 + e) - hermite(p0, v0, p1, v1, h, 0.3 - e)) / (2.0 * e * h);
        assert!((num - hermite_derivative(p0, v0, p1, v1, h, 0.3)).abs() < 1e-6);
    }

    #[test]
    fn hermite_reproduces_cubics_exactly() {
        let f = |t: f64| 2.0 * t * t * t - t * t + 0.5 * t - 3.0;
        let df = |t: f64| 6.0 * t * t - 2.0 * t + 0.5;
        let (t0, t1) = (0.2, 0.9);
        for i in 0..=10 {
            let u = i as f64 / 10.0;
            let got = hermite(f(t0), df(t0), f(t1), df(t1), t1 - t0, u);
            assert!((got - f(t0 + u * (t1 - t0))).abs() < 1e-12);
        }
    }

    #[test]
    fn quat_hermite_matches_ends_and_angular_velocities() {
        let q0 = DQuat::from_euler(glam::EulerRot::ZYX, 0.3, 0.2, -0.4);
        let q1 = DQuat::from_euler(glam::EulerRot::ZYX, -0.5, 0.6, 0.1);
        let w0 = DVec3::new(0.5, -1.0, 2.0);
        let w1 = DVec3::new(-1.5, 0.3, 0.2);
        let h = 0.5;
        assert!(angle_between(hermite_quat(q0, w0, q1, w1, h, 0.0), q0) < 1e-12);
        assert!(angle_between(hermite_quat(q0, w0, q1, w1, h, 1.0), q1) < 1e-9);
        let e = 1e-6;
        let start = angular_velocity(q0, hermite_quat(q0, w0, q1, w1, h, e), e * h);
        assert!((start - w0).length() < 1e-4, "{start:?}");
        let end = angular_velocity(hermite_quat(q0, w0, q1, w1, h, 1.0 - e), q1, e * h);
        assert!((end - w1).length() < 1e-4, "{end:?}");
    }

    #[test]
    fn quat_hermite_with_constant_rate_is_the_geodesic() {
        let axis = DVec3::new(1.0, 2.0, -0.5).normalize();
        let w = axis * 1.2;
        let h = 0.75;
        let q0 = DQuat::from_axis_angle(DVec3::Y, 0.4);
        let q1 = q0 * rotvec_to_quat(w * h);
        for i in 0..=8 {
            let u = i as f64 / 8.0;
            let expected = q0 * rotvec_to_quat(w * h * u);
            assert!(angle_between(hermite_quat(q0, w, q1, w, h, u), expected) < 1e-9);
        }
    }
}
