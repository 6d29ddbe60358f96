//! Expressions: events with an onset, a hold and an offset (smooth ramps) that add a weighted set of
//! ARKit shapes: smile, frown, brow raise, brow furrow, squint, sneer, cheek puff. Each event has a
//! random amplitude and a small left/right asymmetry. Brows also co-move with speech emphasis (short
//! raises on the stressed vowel of some words, as the paper observes in §4.3.3).

use super::random::Rand;
use super::speech::Phone;
use crate::data::arkit_index;
use inbetween_core::interp::smoothstep;

/// An expression type: the shapes it moves and their gains (left/right pairs share a side flag).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Expression {
    Smile,
    Frown,
    BrowRaise,
    BrowFurrow,
    Squint,
    Sneer,
    CheekPuff,
    /// Jaw dropped with rounded lips and raised brows (surprise, a gasp, "oh"); only in silences.
    OpenMouth,
    /// Inner brows up with a slight frown (sadness, worry).
    Worry,
    /// Lips drawn back from the teeth with a sneer (anger; the real "Angry" takes hold MouthLowerDown
    /// up to 0.68 and MouthUpperUp up to 0.45 without speaking); only in silences.
    BareTeeth,
}

impl Expression {
    /// Every type, in the order of [`WEIGHTS`].
    pub const ALL: [Expression; 10] = [
        Expression::Smile,
        Expression::Frown,
        Expression::BrowRaise,
        Expression::BrowFurrow,
        Expression::Squint,
        Expression::Sneer,
        Expression::CheekPuff,
        Expression::OpenMouth,
        Expression::Worry,
        Expression::BareTeeth,
    ];

    /// Whether this expression parts the lips (then it is placed only where nobody speaks, and the
    /// resting lip closure gives way to it).
    pub fn parts_lips(self) -> bool {
        self.lip_parting() > 0.0
    }

    /// How much of the resting lip closure this expression undoes at full envelope: all for bared teeth
    /// (MouthClose stays at 0 in the real "Angry" takes), half for an open mouth (the real gasps keep
    /// MouthClose up to 0.11 with JawOpen 0.17 and MouthFunnel 0.27).
    pub fn lip_parting(self) -> f32 {
        match self {
            Expression::BareTeeth => 1.0,
            Expression::OpenMouth => 0.5,
            _ => 0.0,
        }
    }

    /// `(shape, gain, side)`: side −1 left, +1 right, 0 centre. Negative gains relax an antagonist
    /// (a raise lowers `BrowDown*`, a furrow lowers `BrowInnerUp`; the real captures correlate the
    /// two at −0.07); the generator clamps at 0 afterwards.
    pub fn shapes(self) -> &'static [(&'static str, f32, i8)] {
        match self {
            Expression::Smile => &[
                ("MouthSmileLeft", 1.0, -1),
                ("MouthSmileRight", 1.0, 1),
                ("CheekSquintLeft", 0.5, -1),
                ("CheekSquintRight", 0.5, 1),
                ("EyeSquintLeft", 0.3, -1),
                ("EyeSquintRight", 0.3, 1),
                ("MouthDimpleLeft", 0.2, -1),
                ("MouthDimpleRight", 0.2, 1),
                ("MouthUpperUpLeft", 0.1, -1),
                ("MouthUpperUpRight", 0.1, 1),
            ],
            Expression::Frown => &[
                ("MouthFrownLeft", 1.0, -1),
                ("MouthFrownRight", 1.0, 1),
                ("MouthShrugLower", 0.4, 0),
                ("MouthStretchLeft", 0.2, -1),
                ("MouthStretchRight", 0.2, 1),
                ("BrowDownLeft", 0.3, -1),
                ("BrowDownRight", 0.3, 1),
                ("BrowInnerUp", 0.3, 0),
            ],
            Expression::BrowRaise => &[
                ("BrowInnerUp", 1.0, 0),
                ("BrowOuterUpLeft", 0.8, -1),
                ("BrowOuterUpRight", 0.8, 1),
                ("EyeWideLeft", 0.4, -1),
                ("EyeWideRight", 0.4, 1),
                ("BrowDownLeft", -0.4, -1),
                ("BrowDownRight", -0.4, 1),
            ],
            Expression::BrowFurrow => &[
                ("BrowDownLeft", 1.0, -1),
                ("BrowDownRight", 1.0, 1),
                ("BrowInnerUp", -0.4, 0),
                ("EyeSquintLeft", 0.3, -1),
                ("EyeSquintRight", 0.3, 1),
                ("NoseSneerLeft", 0.2, -1),
                ("NoseSneerRight", 0.2, 1),
            ],
            Expression::Squint => &[
                ("EyeSquintLeft", 1.0, -1),
                ("EyeSquintRight", 1.0, 1),
                ("CheekSquintLeft", 0.5, -1),
                ("CheekSquintRight", 0.5, 1),
                ("BrowDownLeft", 0.2, -1),
                ("BrowDownRight", 0.2, 1),
            ],
            Expression::Sneer => &[
                ("NoseSneerLeft", 1.0, -1),
                ("NoseSneerRight", 1.0, 1),
                ("MouthUpperUpLeft", 0.4, -1),
                ("MouthUpperUpRight", 0.4, 1),
                ("BrowDownLeft", 0.3, -1),
                ("BrowDownRight", 0.3, 1),
                ("CheekSquintLeft", 0.2, -1),
                ("CheekSquintRight", 0.2, 1),
            ],
            Expression::CheekPuff => &[("CheekPuff", 1.0, 0), ("MouthPressLeft", 0.2, -1), ("MouthPressRight", 0.2, 1)],
            Expression::OpenMouth => &[
                ("JawOpen", 0.6, 0),
                ("MouthFunnel", 1.0, 0),
                ("MouthPucker", 0.2, 0),
                ("MouthLowerDownLeft", 0.3, -1),
                ("MouthLowerDownRight", 0.3, 1),
                ("BrowInnerUp", 0.4, 0),
                ("BrowOuterUpLeft", 0.3, -1),
                ("BrowOuterUpRight", 0.3, 1),
                ("EyeWideLeft", 0.3, -1),
                ("EyeWideRight", 0.3, 1),
            ],
            Expression::Worry => &[
                ("BrowInnerUp", 1.0, 0),
                ("MouthFrownLeft", 0.3, -1),
                ("MouthFrownRight", 0.3, 1),
                ("MouthShrugLower", 0.2, 0),
            ],
            Expression::BareTeeth => &[
                ("MouthLowerDownLeft", 0.9, -1),
                ("MouthLowerDownRight", 0.9, 1),
                ("MouthUpperUpLeft", 0.6, -1),
                ("MouthUpperUpRight", 0.6, 1),
                ("MouthSmileLeft", 0.5, -1),
                ("MouthSmileRight", 0.5, 1),
                ("MouthStretchLeft", 0.3, -1),
                ("MouthStretchRight", 0.3, 1),
                ("NoseSneerLeft", 0.3, -1),
                ("NoseSneerRight", 0.3, 1),
                ("BrowDownLeft", 0.3, -1),
                ("BrowDownRight", 0.3, 1),
                ("JawOpen", 0.08, 0),
            ],
        }
    }
}

/// Relative frequency of each type (cheek puffs are rare: the real captures never pass 0.033; open
/// mouths are common: the real JawOpen moves mostly slowly, with MouthFunnel, correlation 0.84).
const WEIGHTS: [f64; 10] = [3.0, 2.0, 1.5, 2.0, 1.5, 1.5, 0.2, 2.5, 1.0, 2.0];

/// One expression event.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Event {
    pub kind: Expression,
    pub t0: f64,
    pub onset_s: f64,
    pub hold_s: f64,
    pub offset_s: f64,
    pub amp: f64,
    /// Left gain 1 − asym, right 1 + asym.
    pub asym: f64,
}

impl Event {
    /// End time, seconds.
    pub fn end(&self) -> f64 {
        self.t0 + self.onset_s + self.hold_s + self.offset_s
    }

    /// Envelope 0..1 at time `t`.
    pub fn envelope(&self, t: f64) -> f64 {
        let x = t - self.t0;
        if x <= 0.0 {
            0.0
        } else if x < self.onset_s {
            smoothstep(x / self.onset_s)
        } else if x < self.onset_s + self.hold_s {
            1.0
        } else {
            1.0 - smoothstep((x - self.onset_s - self.hold_s) / self.offset_s)
        }
    }
}

/// Expression events over `[0, duration)` at about `rate_per_min` per minute (Poisson), amplitudes
/// scaled by `amp_scale`; then short brow raises on emphasised vowels with probability `brow_speech`.
pub fn schedule(
    rng: &mut Rand,
    duration: f64,
    rate_per_min: f64,
    amp_scale: f64,
    phones: &[Phone],
    brow_speech: f64,
) -> Vec<Event> {
    let mut out = Vec::new();
    if rate_per_min > 0.0 && rate_per_min.is_finite() {
        let mut t = rng.exp(60.0 / rate_per_min) - 1.0;
        while t < duration {
            let kind = Expression::ALL[rng.weighted(&WEIGHTS)];
            let hold = if kind == Expression::CheekPuff { rng.range(0.2, 0.8) } else { rng.range(0.4, 3.0) };
            let e = Event {
                kind,
                t0: t,
                onset_s: rng.range(0.2, 0.6),
                hold_s: hold,
                offset_s: rng.range(0.3, 1.0),
                amp: amp_scale * rng.range(0.2, 0.75),
                asym: rng.range(-0.15, 0.15),
            };
            // Lips part only where nobody speaks (speech owns the lips and the jaw).
            if !kind.parts_lips() || !overlaps_speech(phones, e.t0, e.end()) {
                out.push(e);
            }
            t += rng.exp(60.0 / rate_per_min);
        }
    }
    for p in phones.iter().filter(|p| p.emphasis) {
        if rng.chance(brow_speech) {
            out.push(Event {
                kind: Expression::BrowRaise,
                t0: p.start - rng.range(0.05, 0.15),
                onset_s: rng.range(0.1, 0.2),
                hold_s: rng.range(0.05, 0.25),
                offset_s: rng.range(0.25, 0.5),
                amp: amp_scale * rng.range(0.15, 0.4),
                asym: rng.range(-0.1, 0.1),
            });
        }
    }
    out.sort_by(|a, b| a.t0.total_cmp(&b.t0));
    out
}

/// Whether any non-silent phone overlaps `[a, b]`.
fn overlaps_speech(phones: &[Phone], a: f64, b: f64) -> bool {
    phones.iter().any(|p| p.viseme != crate::visemes::Viseme::Sil && p.start < b && p.end > a)
}

/// Per frame, the largest envelope × [`Expression::lip_parting`] of the lip-parting events (0..1):
/// the share of the resting lip closure undone by an expression.
pub fn lip_parting_envelope(events: &[Event], times: &[f64]) -> Vec<f32> {
    let mut out = vec![0.0f32; times.len()];
    for e in events.iter().filter(|e| e.kind.parts_lips()) {
        for (o, t) in out.iter_mut().zip(times) {
            *o = o.max(e.envelope(*t) as f32 * e.kind.lip_parting());
        }
    }
    out
}

/// Adds the events to frame-major ARKit weights (`weights[f * stride + c]`, first 52 channels).
pub fn render(events: &[Event], times: &[f64], weights: &mut [f32], stride: usize) {
    for e in events {
        let resolved: Vec<(usize, f32, i8)> = e
            .kind
            .shapes()
            .iter()
            .map(|(n, g, s)| (arkit_index(n).expect("expression shapes are ARKit names"), *g, *s))
            .collect();
        let (a, b) = (e.t0, e.end());
        let f0 = times.partition_point(|t| *t < a);
        for (f, &t) in times.iter().enumerate().skip(f0) {
            if t > b {
                break;
            }
            let env = (e.envelope(t) * e.amp) as f32;
            for &(c, g, side) in &resolved {
                let side_gain = 1.0 + e.asym as f32 * side as f32;
                weights[f * stride + c] += env * g * side_gain;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn envelope_rises_holds_and_falls() {
        let e =
            Event { kind: Expression::Smile, t0: 1.0, onset_s: 0.5, hold_s: 1.0, offset_s: 0.5, amp: 0.5, asym: 0.0 };
        assert_eq!(e.envelope(0.9), 0.0);
        assert!((e.envelope(1.25) - 0.5).abs() < 1e-9);
        assert_eq!(e.envelope(2.0), 1.0);
        assert_eq!(e.envelope(3.1), 0.0);
        let times: Vec<f64> = (0..100).map(|i| i as f64 / 25.0).collect();
        let mut w = vec![0.0f32; 100 * 52];
        render(&[e], &times, &mut w, 52);
        let smile = arkit_index("MouthSmileLeft").unwrap();
        assert!((w[50 * 52 + smile] - 0.5).abs() < 1e-6);
        assert_eq!(w[10 * 52 + smile], 0.0);
    }
}
