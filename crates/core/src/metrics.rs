//! Error metrics between two animations of the same skeleton.

use crate::rotation::angle_between;
use glam::{DQuat, DVec3};

/// Mean and maximum of a set of errors.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ErrorStats {
    pub mean: f64,
    pub max: f64,
    pub count: usize,
}

impl ErrorStats {
    pub fn from_errors(errors: impl IntoIterator<Item = f64>) -> ErrorStats {
        let (mut sum, mut max, mut count) = (0.0, 0.0f64, 0);
        for e in errors {
            sum += e;
            max = max.max(e);
            count += 1;
        }
        ErrorStats { mean: if count == 0 { 0.0 } else { sum / count as f64 }, max, count }
    }

    /// Combines two statistics as if their errors were pooled.
    pub fn merge(self, other: ErrorStats) -> ErrorStats {
        let count = self.count + other.count;
        let mean = if count == 0 {
            0.0
        } else {
            (self.mean * self.count as f64 + other.mean * other.count as f64) / count as f64
        };
        ErrorStats { mean, max: self.max.max(other.max), count }
    }
}

/// Mean per-joint position error (MPJPE) and its maximum over `[frame][joint]` positions.
/// Panics if the shapes differ: callers compare animations of one skeleton.
pub fn position_error(a: &[Vec<DVec3>], b: &[Vec<DVec3>]) -> ErrorStats {
    assert_eq!(a.len(), b.len(), "frame counts differ");
    ErrorStats::from_errors(a.iter().zip(b).flat_map(|(fa, fb)| {
        assert_eq!(fa.len(), fb.len(), "joint counts differ");
        fa.iter().zip(fb).map(|(pa, pb)| pa.distance(*pb))
    }))
}

/// Geodesic angle error (radians) between `[frame][joint]` rotations.
pub fn rotation_error(a: &[Vec<DQuat>], b: &[Vec<DQuat>]) -> ErrorStats {
    assert_eq!(a.len(), b.len(), "frame counts differ");
    ErrorStats::from_errors(a.iter().zip(b).flat_map(|(fa, fb)| {
        assert_eq!(fa.len(), fb.len(), "joint counts differ");
        fa.iter().zip(fb).map(|(qa, qb)| angle_between(*qa, *qb))
    }))
}

/// Absolute difference of angles in radians, wrapped to [0, π] (for azimuths such as φ).
pub fn wrapped_angle_difference(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(std::f64::consts::TAU);
    d.min(std::f64::consts::TAU - d)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn position_error_mean_and_max() {
        let a = vec![vec![DVec3::ZERO, DVec3::ZERO]];
        let b = vec![vec![DVec3::new(3.0, 4.0, 0.0), DVec3::new(1.0, 0.0, 0.0)]];
        let e = position_error(&a, &b);
        assert_eq!((e.mean, e.max, e.count), (3.0, 5.0, 2));
        let merged = e.merge(ErrorStats::from_errors([0.0, 0.0]));
        assert_eq!((merged.mean, merged.max, merged.count), (1.5, 5.0, 4));
    }

    #[test]
    fn wrapped_difference_crosses_pi() {
        let d = wrapped_angle_difference(3.1, -3.1);
        assert!((d - (std::f64::consts::TAU - 6.2)).abs() < 1e-12);
    }

    #[test]
    fn rotation_error_is_geodesic() {
        let a = vec![vec![DQuat::IDENTITY]];
        let b = vec![vec![DQuat::from_rotation_x(0.5)]];
        assert!((rotation_error(&a, &b).mean - 0.5).abs() < 1e-12);
    }
}
