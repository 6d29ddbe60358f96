//! Length units of motion files. A BVH (or an ASF without `:units length`) stores lengths in no
//! declared unit: the CMU conversions use CMU units (1 unit = 5.6444 cm), Character Creator, Daz or
//! Mixamo rigs centimetres, some exporters metres, millimetres or inches. Errors reported in cm and
//! error bounds given in cm are only meaningful once the unit is known, so every mocap command
//! either takes it from the user (`--unit`) or infers it here from the skeleton's rest pose against
//! human proportions, and says which one it chose and why ([`UnitChoice::reason`]).
//!
//! ```
//! use inbetween_core::units::LengthUnit;
//! let u: LengthUnit = "cmu".parse().unwrap();
//! assert_eq!(u.cm_per_unit(), inbetween_core::procedural::CM_PER_CMU_UNIT);
//! assert_eq!("2.5".parse::<LengthUnit>().unwrap().cm_per_unit(), 2.5);
//! let guess = LengthUnit::infer(&inbetween_core::procedural::standard_skeleton());
//! assert_eq!(guess.unit, LengthUnit::Cmu);
//! ```

use crate::motion::Motion;
use crate::procedural::CM_PER_CMU_UNIT;
use crate::skeleton::{Joint, Skeleton};
use glam::DVec3;
use std::fmt;
use std::str::FromStr;

/// A length unit, as centimetres per unit of the file.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LengthUnit {
    Centimetre,
    Metre,
    Millimetre,
    Inch,
    /// CMU mocap units: (1/0.45) inch = 5.6444 cm (CMU FAQ).
    Cmu,
    /// Any other unit, as centimetres per unit (positive, finite).
    CmPerUnit(f64),
}

/// The units [`LengthUnit::infer`] chooses between.
pub const CANDIDATES: [LengthUnit; 5] =
    [LengthUnit::Millimetre, LengthUnit::Centimetre, LengthUnit::Inch, LengthUnit::Cmu, LengthUnit::Metre];

/// Size of an adult's rest pose, in cm, that inference compares against: standing height or T-pose
/// arm span, which are about equal (Vitruvian proportion).
pub const HUMAN_SIZE_CM: f64 = 170.0;

/// A human-sized rest pose spans roughly this range of cm (children to tall adults, with or
/// without a head end site); outside it the reason says the guess is uncertain.
pub const HUMAN_SIZE_RANGE_CM: (f64, f64) = (90.0, 260.0);

impl LengthUnit {
    pub fn cm_per_unit(self) -> f64 {
        match self {
            LengthUnit::Centimetre => 1.0,
            LengthUnit::Metre => 100.0,
            LengthUnit::Millimetre => 0.1,
            LengthUnit::Inch => 2.54,
            LengthUnit::Cmu => CM_PER_CMU_UNIT,
            LengthUnit::CmPerUnit(c) => c,
        }
    }

    /// Short name as `--unit` accepts it (`cm`, `m`, `mm`, `in`, `cmu`, or the number of cm).
    pub fn name(self) -> String {
        match self {
            LengthUnit::Centimetre => "cm".into(),
            LengthUnit::Metre => "m".into(),
            LengthUnit::Millimetre => "mm".into(),
            LengthUnit::Inch => "in".into(),
            LengthUnit::Cmu => "cmu".into(),
            LengthUnit::CmPerUnit(c) => format!("{c}"),
        }
    }

    /// Infers the unit of a skeleton from its rest pose: the largest extent of the rest pose (joints
    /// and end sites; the height, or the arm span of a T-pose) read in each of [`CANDIDATES`], and
    /// the unit that makes it closest to [`HUMAN_SIZE_CM`] (on a log scale) wins.
    pub fn infer(skeleton: &Skeleton) -> UnitChoice {
        let size = rest_pose_extent(skeleton);
        if !(size.is_finite() && size > 1e-9) {
            return UnitChoice {
                unit: LengthUnit::Centimetre,
                reason: format!(
                    "the rest pose has no size ({} units): cannot infer the unit, assuming cm (give `unit`)",
                    fmt_num(size)
                ),
            };
        }
        let off = |u: LengthUnit| (size * u.cm_per_unit() / HUMAN_SIZE_CM).ln().abs();
        let unit = CANDIDATES.into_iter().min_by(|a, b| off(*a).total_cmp(&off(*b))).expect("candidates");
        let cm = size * unit.cm_per_unit();
        let label = if unit == LengthUnit::Cmu { "CMU units".to_string() } else { unit.describe() };
        let mut reason = format!(
            "rest-pose height {} units ≈ {cm:.0} cm in {label}, the reading closest to an adult's {HUMAN_SIZE_CM:.0} cm among mm, cm, in, CMU units and m",
            fmt_num(size),
        );
        if cm < HUMAN_SIZE_RANGE_CM.0 || cm > HUMAN_SIZE_RANGE_CM.1 {
            reason.push_str("; not human-sized in any unit, so this is a guess: give `unit` if it is wrong");
        }
        UnitChoice { unit, reason }
    }

    /// "CMU units (5.6444 cm)", "cm", "2.5 cm per unit", for reports.
    pub fn describe(self) -> String {
        match self {
            LengthUnit::Cmu => format!("CMU units ({CM_PER_CMU_UNIT} cm)"),
            LengthUnit::Centimetre => "cm".into(),
            LengthUnit::Metre => "m".into(),
            LengthUnit::Millimetre => "mm".into(),
            LengthUnit::Inch => "inches".into(),
            LengthUnit::CmPerUnit(c) => format!("units of {c} cm"),
        }
    }
}

fn fmt_num(v: f64) -> String {
    if v.abs() >= 100.0 {
        format!("{v:.0}")
    } else {
        format!("{v:.1}")
    }
}

impl fmt::Display for LengthUnit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.describe())
    }
}

/// A `--unit` value that is neither a unit name nor a positive number.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("'{0}' is not a length unit: expected cm, m, mm, in, cmu (CMU mocap units, 5.6444 cm) or the number of cm per unit, e.g. 2.54")]
pub struct ParseUnitError(pub String);

impl FromStr for LengthUnit {
    type Err = ParseUnitError;

    fn from_str(s: &str) -> Result<LengthUnit, ParseUnitError> {
        let t = s.trim().to_ascii_lowercase();
        Ok(match t.as_str() {
            "cm" | "centimetre" | "centimeter" | "centimetres" | "centimeters" => LengthUnit::Centimetre,
            "m" | "metre" | "meter" | "metres" | "meters" => LengthUnit::Metre,
            "mm" | "millimetre" | "millimeter" | "millimetres" | "millimeters" => LengthUnit::Millimetre,
            "in" | "inch" | "inches" => LengthUnit::Inch,
            "cmu" => LengthUnit::Cmu,
            other => match other.parse::<f64>() {
                Ok(c) if c.is_finite() && c > 0.0 => LengthUnit::CmPerUnit(c),
                _ => return Err(ParseUnitError(s.to_string())),
            },
        })
    }
}

/// A unit and why it was chosen (inferred, known from the corpus, or given by the user).
#[derive(Clone, Debug, PartialEq)]
pub struct UnitChoice {
    pub unit: LengthUnit,
    pub reason: String,
}

impl UnitChoice {
    /// The user's unit when given, otherwise the one inferred from `skeleton`.
    pub fn resolve(given: Option<LengthUnit>, skeleton: &Skeleton) -> UnitChoice {
        match given {
            Some(unit) => UnitChoice::given(unit),
            None => LengthUnit::infer(skeleton),
        }
    }

    /// A unit the user gave (the `unit` option; the CLI's `--unit`).
    pub fn given(unit: LengthUnit) -> UnitChoice {
        UnitChoice { unit, reason: "given with `unit`".into() }
    }

    pub fn cm_per_unit(&self) -> f64 {
        self.unit.cm_per_unit()
    }
}

impl fmt::Display for UnitChoice {
    /// "length unit: CMU units (5.6444 cm): rest-pose height …".
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "length unit: {} ({})", self.unit.describe(), self.reason)
    }
}

/// Largest extent of the rest pose (all joints at their offsets, identity rotations, plus end
/// sites) along x, y or z, in the file's units.
pub fn rest_pose_extent(skeleton: &Skeleton) -> f64 {
    let mut global: Vec<DVec3> = Vec::with_capacity(skeleton.len());
    let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    for j in skeleton.joints() {
        let p = j.parent.map(|p| global[p]).unwrap_or(DVec3::ZERO)
            + if j.parent.is_some() { j.offset } else { DVec3::ZERO };
        global.push(p);
        for q in std::iter::once(p).chain(j.end_site.map(|e| p + e)) {
            lo = lo.min(q);
            hi = hi.max(q);
        }
    }
    (hi - lo).max_element()
}

/// The clip with every length multiplied by `factor`: joint offsets, end sites and position
/// channels (rotations unchanged). `scale_motion(m, u.cm_per_unit())` converts a clip in unit `u`
/// to centimetres.
pub fn scale_motion(motion: &Motion, factor: f64) -> Motion {
    let joints: Vec<Joint> = motion
        .skeleton
        .joints()
        .iter()
        .map(|j| Joint { offset: j.offset * factor, end_site: j.end_site.map(|e| e * factor), ..j.clone() })
        .collect();
    let skeleton = Skeleton::new(joints).expect("scaling keeps a valid hierarchy");
    let nc = skeleton.num_channels();
    let mut data = motion.data().to_vec();
    for (j, joint) in skeleton.joints().iter().enumerate() {
        let start = skeleton.channel_start(j);
        for (k, c) in joint.channels.iter().enumerate() {
            if !c.is_rotation() {
                for f in 0..motion.num_frames() {
                    data[f * nc + start + k] *= factor;
                }
            }
        }
    }
    Motion::new(skeleton, motion.frame_time, data).expect("scaling by a finite factor keeps values finite")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::procedural::{gait, standard_skeleton, GaitParams};

    #[test]
    fn parses_names_and_numbers_and_refuses_the_rest() {
        assert_eq!("cm".parse::<LengthUnit>().unwrap(), LengthUnit::Centimetre);
        assert_eq!(" M ".parse::<LengthUnit>().unwrap(), LengthUnit::Metre);
        assert_eq!("in".parse::<LengthUnit>().unwrap().cm_per_unit(), 2.54);
        assert_eq!("CMU".parse::<LengthUnit>().unwrap().cm_per_unit(), 5.6444);
        assert_eq!("0.5".parse::<LengthUnit>().unwrap(), LengthUnit::CmPerUnit(0.5));
        for bad in ["feet", "", "-1", "0", "nan", "inf"] {
            let e = bad.parse::<LengthUnit>().unwrap_err().to_string();
            assert!(e.contains("expected cm, m, mm, in, cmu"), "{bad}: {e}");
        }
        for u in CANDIDATES {
            assert_eq!(u.name().parse::<LengthUnit>().unwrap(), u, "{u}");
        }
    }

    #[test]
    fn the_same_skeleton_in_each_unit_is_recognised_with_a_reason() {
        let sk = standard_skeleton();
        let size = rest_pose_extent(&sk);
        // Feet at -16.6, head top at 10.1 CMU units: 26.7 units ≈ 151 cm.
        assert!((size - 26.7).abs() < 1e-9, "{size}");
        for unit in CANDIDATES {
            let m = scale_motion(
                &gait(&GaitParams { frames: 3, ..GaitParams::walk() }),
                CM_PER_CMU_UNIT / unit.cm_per_unit(),
            );
            let guess = LengthUnit::infer(&m.skeleton);
            assert_eq!(guess.unit, unit, "{}", guess.reason);
            assert!(guess.reason.contains("≈ 151 cm"), "{}", guess.reason);
            assert!(!guess.reason.contains("guess"), "{}", guess.reason);
        }
        let cmu = LengthUnit::infer(&sk);
        assert!(cmu.reason.starts_with("rest-pose height 26.7 units ≈ 151 cm in CMU units"), "{}", cmu.reason);
        assert_eq!(UnitChoice::resolve(Some(LengthUnit::Inch), &sk).reason, "given with `unit`");
    }

    #[test]
    fn a_point_skeleton_or_a_giant_says_it_is_guessing() {
        let mut j = standard_skeleton().joints()[0].clone();
        j.end_site = None;
        let point = Skeleton::new(vec![j]).unwrap();
        let g = LengthUnit::infer(&point);
        assert_eq!(g.unit, LengthUnit::Centimetre);
        assert!(g.reason.contains("cannot infer"), "{}", g.reason);
        let giant = scale_motion(&gait(&GaitParams { frames: 2, ..GaitParams::walk() }), 1e4);
        assert!(LengthUnit::infer(&giant.skeleton).reason.contains("give `unit`"));
    }

    #[test]
    fn scaling_scales_positions_and_keeps_rotations() {
        let m = gait(&GaitParams { frames: 5, ..GaitParams::walk() });
        let s = scale_motion(&m, 2.0);
        let (a, b) = (crate::positions_clip(&m), crate::positions_clip(&s));
        for (fa, fb) in a.iter().zip(&b) {
            for (pa, pb) in fa.iter().zip(fb) {
                assert!((*pa * 2.0 - *pb).length() < 1e-9);
            }
        }
        assert_eq!(m.pose(3).rotations, s.pose(3).rotations);
    }
}
