//! Angle helpers shared by every engine.

use std::f64::consts::{PI, TAU};

/// Wraps an angle (radians) into (−π, π]: the shortest signed turn that equals `a`. Exact for
/// angles already in range (they come back bit for bit), which procedural data relies on.
#[inline]
pub fn wrap_angle(a: f64) -> f64 {
    let x = a % TAU;
    if x <= -PI {
        x + TAU
    } else if x > PI {
        x - TAU
    } else {
        x
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wraps_into_the_half_open_interval_and_keeps_the_direction() {
        for i in -4000..4000 {
            let a = i as f64 * 0.01;
            let w = wrap_angle(a);
            assert!(w > -PI && w <= PI, "{a} -> {w}");
            let turns = (a - w) / TAU;
            assert!((turns - turns.round()).abs() < 1e-9, "{a} -> {w} is not a whole number of turns away");
        }
        assert_eq!(wrap_angle(PI), PI);
        assert_eq!(wrap_angle(-PI), PI);
        assert!((wrap_angle(3.0 * PI) - PI).abs() < 1e-12);
        assert_eq!(wrap_angle(0.0), 0.0);
        for a in [0.1, -3.0, 2.5, 1e-300, -PI + 1e-12] {
            assert_eq!(wrap_angle(a).to_bits(), a.to_bits(), "{a} is in range and must come back unchanged");
        }
    }
}
