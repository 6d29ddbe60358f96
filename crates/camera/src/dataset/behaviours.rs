//! The four camera behaviours of the synthetic dataset (§4.5), each a rule in Toric space that ties
//! the camera to the characters (A = screen-left target, B = screen-right, "main" = the one M names).
//!
//! Notation: α is the angle between the rays through `p_A` and `p_B`, β = θ/2 the angle at A
//! between AB and the camera (the torus arc runs over β ∈ (0, π − α)), β_B = π − α − β the same
//! angle seen from B. All behaviours share a per-scene framing — `p_A = (c − w, h)`,
//! `p_B = (c + w, h)` with `c` shifted so the main character sits nearer the centre — a constant
//! pitch φ, and a first-order lag of `lag` seconds on β (an operator reacting, not a rig).
//!
//! - **Relative track**: β = `arc`·(π − α) constant: the camera is rigid in the frame of the pair,
//!   so it dollies in and out as they approach or part and the framing never changes.
//! - **Direct track**: the camera stays in front of the main character: seen from the main
//!   character, the camera sits `offset` radians from the other character towards the camera side,
//!   plus however far the main character's torso turns towards that side (σ, clamped to the arc).
//!   Turning the torso swings the camera round to keep the face in view. σ is folded,
//!   σ' = atan2(sin σ, |cos σ|), so a character turning its back (σ through ±π) brings the camera
//!   back towards its rest offset instead of flipping it across the arc (a discontinuity no
//!   network can predict from the character features).
//! - **Side track**: the camera sits on the bisector of AB (β = (π − α)/2, a profile two-shot) at a
//!   constant world distance `distance` from their midpoint and does not zoom: the screen separation
//!   w follows the characters' distance (α = 2·atan(d_AB / 2·distance)) instead of the camera.
//! - **Orbit track**: β swings sinusoidally over the arc, β = (π − α)(½ + `amplitude`·sin(2πt/T + ψ)),
//!   from one character's shoulder to the other's, whatever the characters do; its phase is not
//!   visible in the character features, which is what the hidden-state mapping H is for (§4.3).

use crate::dataset::scene::Scene;
use crate::toric::{Lens, Toric};
use glam::{DVec2, DVec3};
use rand::Rng;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// A camera behaviour of the synthetic dataset.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Behaviour {
    Direct,
    Relative,
    Side,
    Orbit,
}

pub const BEHAVIOURS: [Behaviour; 4] = [Behaviour::Direct, Behaviour::Relative, Behaviour::Side, Behaviour::Orbit];

impl Behaviour {
    pub fn name(self) -> &'static str {
        match self {
            Behaviour::Direct => "direct",
            Behaviour::Relative => "relative",
            Behaviour::Side => "side",
            Behaviour::Orbit => "orbit",
        }
    }

    pub fn parse(s: &str) -> Option<Behaviour> {
        BEHAVIOURS.into_iter().find(|b| b.name() == s.to_ascii_lowercase())
    }

    pub fn index(self) -> usize {
        BEHAVIOURS.iter().position(|&b| b == self).unwrap_or(0)
    }
}

/// Per-scene parameters of a behaviour (every field is drawn by [`BehaviourParams::sample`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct BehaviourParams {
    /// Half the screen distance between the targets, w.
    pub half_width: f64,
    /// How far the framing centre moves towards the main character, in screen units.
    pub centre_shift: f64,
    /// Screen height of both targets, h.
    pub height: f64,
    /// Camera pitch φ (radians, > 0 above the targets).
    pub pitch: f64,
    /// Relative track: β as a fraction of the arc.
    pub arc: f64,
    /// Direct track: angular offset from the line of the characters, radians.
    pub offset: f64,
    /// Side track: world distance from the pair's midpoint, metres.
    pub distance: f64,
    /// Orbit track: period T (seconds), amplitude (fraction of the arc), phase ψ.
    pub period: f64,
    pub amplitude: f64,
    pub phase: f64,
    /// Lag of the camera operator on β, seconds.
    pub lag: f64,
}

impl BehaviourParams {
    pub fn sample(rng: &mut impl Rng) -> BehaviourParams {
        BehaviourParams {
            half_width: rng.random_range(0.2..0.45),
            centre_shift: rng.random_range(0.0..0.15),
            height: rng.random_range(-0.05..0.25),
            pitch: rng.random_range(0.05..0.45),
            arc: rng.random_range(0.2..0.8),
            offset: rng.random_range(0.2..0.5),
            distance: rng.random_range(2.5..6.0),
            period: rng.random_range(4.0..10.0),
            amplitude: rng.random_range(0.25..0.42),
            phase: rng.random_range(0.0..2.0 * PI),
            lag: rng.random_range(0.2..0.8),
        }
    }
}

/// Screen half-width w for which the rays through `(c ± w, h)` meet at angle `alpha` (bisection:
/// the angle grows monotonically with w).
pub fn half_width_for_angle(lens: &Lens, centre: f64, height: f64, alpha: f64) -> f64 {
    let angle = |w: f64| lens.ray_angle(DVec2::new(centre - w, height), DVec2::new(centre + w, height));
    let (mut lo, mut hi) = (1e-4, 0.98);
    if angle(hi) <= alpha {
        return hi;
    }
    for _ in 0..50 {
        let mid = 0.5 * (lo + hi);
        if angle(mid) < alpha {
            lo = mid
        } else {
            hi = mid
        }
    }
    0.5 * (lo + hi)
}

/// Horizontal unit vectors: `t` along A→B and `s` towards the camera side (φ = 0 half-plane).
fn horizontal_frame(a: DVec3, b: DVec3) -> (DVec3, DVec3) {
    let ab = b - a;
    let t = DVec3::new(ab.x, 0.0, ab.z).try_normalize().unwrap_or(DVec3::X);
    (t, t.cross(DVec3::Y))
}

/// Films the pair (screen-left `a`, screen-right `b`) of `scene` with `behaviour`: x^c per frame.
pub fn film(
    scene: &Scene,
    a: usize,
    b: usize,
    main_is_a: bool,
    behaviour: Behaviour,
    p: &BehaviourParams,
    lens: &Lens,
) -> Vec<Toric> {
    let dt = 1.0 / scene.fps;
    let follow = 1.0 - (-dt / p.lag.max(1e-3)).exp();
    let centre = if main_is_a { p.centre_shift } else { -p.centre_shift };
    let framing = |w: f64| (DVec2::new(centre - w, p.height), DVec2::new(centre + w, p.height));
    let (ca, cb) = (&scene.characters[a], &scene.characters[b]);
    let mut smooth: Option<(f64, f64)> = None; // (β as a fraction of the arc, w)
    let mut out = Vec::with_capacity(scene.num_frames());
    for f in 0..scene.num_frames() {
        let (fa, fb) = (ca.frame(f), cb.frame(f));
        let (t, s) = horizontal_frame(fa.target(), fb.target());
        let mut w = p.half_width;
        let arc_of = |w: f64| {
            let (pa, pb) = framing(w);
            PI - lens.ray_angle(pa, pb)
        };
        let fraction = match behaviour {
            Behaviour::Relative => p.arc,
            Behaviour::Direct => {
                let (front, towards_other) = if main_is_a { (fa.front(), t) } else { (fb.front(), -t) };
                // Torso yaw towards the camera side, folded so that a character turning its back
                // (σ through ±π) does not flip the camera from one end of the arc to the other:
                // σ' = atan2(sin σ, |cos σ|) equals σ while the torso faces the other character
                // (|σ| ≤ π/2) and returns to 0 as it turns fully away, continuously.
                let sigma = front.dot(s).atan2(front.dot(towards_other).abs());
                let arc = arc_of(w);
                let beta_main = (p.offset + sigma).clamp(0.15, arc - 0.15);
                let frac_main = beta_main / arc;
                if main_is_a {
                    frac_main
                } else {
                    1.0 - frac_main
                }
            }
            Behaviour::Side => {
                let d = (fb.target() - fa.target()).length();
                let alpha = 2.0 * (d / (2.0 * p.distance)).atan();
                w = half_width_for_angle(lens, centre, p.height, alpha).clamp(0.1, 0.85);
                0.5
            }
            Behaviour::Orbit => {
                let time = f as f64 * dt;
                0.5 + p.amplitude * (2.0 * PI * time / p.period + p.phase).sin()
            }
        };
        let (frac, w) = match smooth {
            None => (fraction, w),
            Some((sf, sw)) => (sf + (fraction - sf) * follow, sw + (w - sw) * follow),
        };
        smooth = Some((frac, w));
        let (pa, pb) = framing(w);
        let theta = 2.0 * frac * arc_of(w);
        out.push(Toric { pa, pb, theta, phi: p.pitch });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::toric::to_pose;
    use rand::SeedableRng;

    /// Bound on the direct track's θ change per frame with the shortest lag (radians).
    const DIRECT_MAX_STEP: f64 = 0.25;

    fn params(seed: u64) -> BehaviourParams {
        BehaviourParams::sample(&mut rand_chacha::ChaCha8Rng::seed_from_u64(seed))
    }

    #[test]
    fn every_behaviour_gives_valid_poses_that_frame_the_targets() {
        let lens = Lens::default();
        let scene = Scene::procedural(3, 450, 30.0);
        for beh in BEHAVIOURS {
            for main_is_a in [true, false] {
                let p = params(11);
                let track = film(&scene, 0, 1, main_is_a, beh, &p, &lens);
                assert_eq!(track.len(), 450);
                for (f, x) in track.iter().enumerate() {
                    let (a, b) = (scene.characters[0].frame(f).target(), scene.characters[1].frame(f).target());
                    let pose = to_pose(x, a, b, &lens).unwrap_or_else(|e| panic!("{beh:?} frame {f}: {e}"));
                    let pa = pose.project(&lens, a).unwrap();
                    assert!((pa - x.pa).length() < 1e-6 && pa.x < pose.project(&lens, b).unwrap().x);
                }
            }
        }
    }

    #[test]
    fn behaviours_have_their_defining_properties() {
        let lens = Lens::default();
        let scene = Scene::procedural(5, 900, 30.0);
        let p = params(2);
        let rel = film(&scene, 0, 1, true, Behaviour::Relative, &p, &lens);
        assert!(rel.windows(2).all(|w| w[0] == w[1]), "relative track is constant in Toric space");
        let side = film(&scene, 0, 1, true, Behaviour::Side, &p, &lens);
        let widths: Vec<f64> = side.iter().map(|x| x.pb.x - x.pa.x).collect();
        let d: Vec<f64> = scene.character_features(0, 1, true).iter().map(|x| x.d_ab).collect();
        assert!(correlation(&widths, &d) > 0.8, "side track: screen separation follows d_AB");
        let orbit = film(&scene, 0, 1, true, Behaviour::Orbit, &p, &lens);
        let th: Vec<f64> = orbit.iter().map(|x| x.theta).collect();
        let range = th.iter().cloned().fold(f64::MIN, f64::max) - th.iter().cloned().fold(f64::MAX, f64::min);
        assert!(range > 1.0, "orbit track sweeps the arc, range {range}");
        let direct = film(&scene, 0, 1, true, Behaviour::Direct, &p, &lens);
        let th: Vec<f64> = direct.iter().map(|x| x.theta).collect();
        let s_a: Vec<f64> = scene.character_features(0, 1, true).iter().map(|x| x.s_a).collect();
        assert!(correlation(&th, &s_a).abs() > 0.3, "direct track follows the main character's torso");
    }

    #[test]
    fn direct_track_does_not_flip_when_the_main_character_turns_away() {
        // Before σ was folded, a torso turning through ±π threw the camera across the whole arc
        // within a few frames; now θ moves only as fast as the torso turns (plus the lag).
        let lens = Lens::default();
        let mut worst: f64 = 0.0;
        for seed in 0..6 {
            let scene = Scene::procedural(seed, 900, 30.0);
            let p = BehaviourParams { lag: 0.2, ..params(seed) };
            for main_is_a in [true, false] {
                let th: Vec<f64> =
                    film(&scene, 0, 1, main_is_a, Behaviour::Direct, &p, &lens).iter().map(|x| x.theta).collect();
                worst = th.windows(2).map(|w| (w[1] - w[0]).abs()).fold(worst, f64::max);
            }
        }
        assert!(worst < DIRECT_MAX_STEP, "largest θ change in one frame {worst}");
    }

    #[test]
    fn names_round_trip() {
        for b in BEHAVIOURS {
            assert_eq!(Behaviour::parse(b.name()), Some(b));
        }
        assert_eq!(Behaviour::parse("ORBIT"), Some(Behaviour::Orbit));
        assert_eq!(Behaviour::parse("dolly"), None);
    }

    fn correlation(x: &[f64], y: &[f64]) -> f64 {
        let n = x.len() as f64;
        let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
        let cov: f64 = x.iter().zip(y).map(|(a, b)| (a - mx) * (b - my)).sum();
        let vx: f64 = x.iter().map(|a| (a - mx).powi(2)).sum();
        let vy: f64 = y.iter().map(|b| (b - my).powi(2)).sum();
        cov / (vx * vy).sqrt().max(1e-12)
    }
}
