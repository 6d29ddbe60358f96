//! Speech: a phoneme sequence with timings (so every frame has an exact viseme label, §3.1 "Visemes"),
//! and the mouth and jaw motion it drives.
//!
//! **Phonemes.** Utterances of phrases of random "words" made of ARPAbet syllables (onset consonant or
//! cluster, vowel, optional coda); consonants last 50–100 ms and vowels 80–200 ms (stressed ones
//! longer), scaled by a per-utterance speaking rate; phrases are separated by short pauses and
//! utterances by longer silences, so that about `speech_fraction` of the clip is speech. Silence is
//! the label `sil`; the phone list covers the whole clip without gaps.
//!
//! **Articulation.** Each viseme class has a target over the mouth parameters ([`P_JAW`] …) and a
//! dominance (strength) for the jaw and for the lips. The mouth at time t is the dominance-weighted
//! mean of the targets of nearby phones (Cohen & Massaro's coarticulation model): a phone's dominance
//! is its strength inside its own interval and decays exponentially with the distance to it, more
//! slowly before the phone than after, so the mouth anticipates upcoming phones. Bilabials (M, B, P)
//! and labiodentals (F, V) dominate the lips strongly, so they are reached even between open vowels;
//! velars and alveolars barely touch the lips, which take the shape of the neighbouring vowels.
//! A separate lip-closure signal (1 for bilabials, 0.8 in silence) removes the lip-parting shapes and
//! makes `MouthClose` cancel the remaining centre lip gap of `crate::edit::distances` (see
//! `close_lips` in [`super`]), so the lips meet at a bilabial.

use super::random::Rand;
use crate::visemes::Viseme;

/// A timed phone: `[start, end)` in seconds, its ARPAbet label (`"sil"` for silence) and articulation
/// amplitude (stress and per-utterance scale).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Phone {
    pub start: f64,
    pub end: f64,
    pub label: &'static str,
    pub viseme: Viseme,
    /// Jaw amplitude factor (stress × utterance loudness).
    pub jaw_amp: f64,
    /// Lip amplitude factor (utterance articulation).
    pub lip_amp: f64,
    /// Whether this is the stressed vowel of an emphasised word (brows may co-move, §4.3.3 observes
    /// "raising eyebrows at the same time").
    pub emphasis: bool,
}

const VOWELS: [&str; 15] = ["AA", "AE", "AH", "AO", "AW", "AY", "EH", "ER", "EY", "IH", "IY", "OW", "OY", "UH", "UW"];
/// Vowel weights (rough English frequencies: schwa-like AH and IH most common).
const VOWEL_WEIGHTS: [f64; 15] = [4.0, 4.0, 10.0, 3.0, 1.0, 2.0, 4.0, 3.0, 2.0, 8.0, 5.0, 2.0, 0.5, 1.0, 3.0];
const ONSETS: [&str; 22] = [
    "B", "P", "M", "F", "V", "TH", "DH", "S", "Z", "SH", "CH", "JH", "T", "D", "N", "L", "K", "G", "HH", "W", "R", "Y",
];
const ONSET_WEIGHTS: [f64; 22] =
    [4.0, 4.0, 4.0, 3.0, 2.0, 1.0, 4.0, 4.0, 1.0, 2.0, 1.0, 1.0, 6.0, 5.0, 5.0, 4.0, 4.0, 2.0, 3.0, 3.0, 3.0, 1.0];
const CLUSTERS: [[&str; 2]; 10] = [
    ["S", "T"],
    ["S", "P"],
    ["S", "K"],
    ["P", "L"],
    ["B", "R"],
    ["T", "R"],
    ["K", "L"],
    ["F", "R"],
    ["G", "R"],
    ["S", "M"],
];
const CODAS: [&str; 12] = ["T", "D", "N", "S", "Z", "K", "M", "P", "L", "R", "NG", "V"];
const CODA_CLUSTERS: [[&str; 2]; 6] = [["N", "T"], ["S", "T"], ["N", "D"], ["K", "S"], ["M", "P"], ["L", "D"]];

/// Timing and rhythm constants.
const CONSONANT_S: (f64, f64) = (0.05, 0.10);
const VOWEL_S: (f64, f64) = (0.08, 0.20);
const PHRASE_PAUSE_S: (f64, f64) = (0.15, 0.6);
const UTTERANCE_S: (f64, f64) = (1.5, 6.0);

/// Builds the phone sequence covering `[0, duration)`.
pub fn phones(rng: &mut Rand, duration: f64, speech_fraction: f64, rate: f64, emphasis_prob: f64) -> Vec<Phone> {
    let mut out = Vec::new();
    let f = speech_fraction.clamp(0.0, 1.0);
    let mean_utterance = 0.5 * (UTTERANCE_S.0 + UTTERANCE_S.1);
    // Mean silence between utterances so that speech takes the fraction f of the time.
    let mean_silence = if f > 0.0 { mean_utterance * (1.0 - f) / f } else { f64::INFINITY };
    let mut t = if f >= 1.0 { 0.1 } else { rng.range(0.2, 0.3 + mean_silence.min(4.0)) };
    push_sil(&mut out, 0.0, t);
    while t < duration && f > 0.0 {
        let end = (t + rng.range(UTTERANCE_S.0, UTTERANCE_S.1)).min(duration);
        t = utterance(rng, &mut out, t, end, rate, emphasis_prob);
        let gap = if f >= 1.0 {
            rng.range(PHRASE_PAUSE_S.0, PHRASE_PAUSE_S.1)
        } else {
            0.3 + rng.exp((mean_silence - 0.3).max(0.05))
        };
        let next = (t + gap).min(duration);
        push_sil(&mut out, t, next);
        t = next;
    }
    if t < duration {
        push_sil(&mut out, t, duration);
    }
    // The last phone ends exactly at the clip end (speech may have run past it).
    out.retain(|p| p.start < duration);
    if let Some(last) = out.last_mut() {
        last.end = duration;
    }
    out
}

/// Appends silence `[a, b)`, merging with a preceding silence.
fn push_sil(out: &mut Vec<Phone>, a: f64, b: f64) {
    if b <= a {
        return;
    }
    if let Some(last) = out.last_mut() {
        if last.viseme == Viseme::Sil {
            last.end = b;
            return;
        }
    }
    out.push(Phone {
        start: a,
        end: b,
        label: "sil",
        viseme: Viseme::Sil,
        jaw_amp: 1.0,
        lip_amp: 1.0,
        emphasis: false,
    });
}

/// One utterance from `t` until about `end`: phrases separated by pauses. Returns when it ends.
fn utterance(rng: &mut Rand, out: &mut Vec<Phone>, mut t: f64, end: f64, rate: f64, emphasis_prob: f64) -> f64 {
    let speed = rate * rng.range(0.85, 1.15);
    let loud = rng.range(0.6, 1.4);
    let lips = rng.range(0.7, 1.3);
    loop {
        let words = 2 + rng.index(6);
        for _ in 0..words {
            let emph = rng.chance(emphasis_prob);
            t = word(rng, out, t, speed, loud, lips, emph);
        }
        if t >= end {
            return t;
        }
        let pause = rng.range(PHRASE_PAUSE_S.0, PHRASE_PAUSE_S.1);
        push_sil(out, t, t + pause);
        t += pause;
    }
}

/// One word of 1–3 syllables, one of them stressed. Returns the end time.
fn word(rng: &mut Rand, out: &mut Vec<Phone>, mut t: f64, speed: f64, loud: f64, lips: f64, emphasis: bool) -> f64 {
    let syllables = 1 + rng.weighted(&[0.55, 0.3, 0.15]);
    let stressed = rng.index(syllables);
    for s in 0..syllables {
        let stress = s == stressed;
        let mut labels: Vec<&'static str> = Vec::with_capacity(6);
        match rng.weighted(&[0.15, 0.7, 0.15]) {
            0 => {}
            1 => labels.push(ONSETS[rng.weighted(&ONSET_WEIGHTS)]),
            _ => labels.extend(rng.pick(&CLUSTERS)),
        }
        let vowel_at = labels.len();
        labels.push(VOWELS[rng.weighted(&VOWEL_WEIGHTS)]);
        match rng.weighted(&[0.5, 0.4, 0.1]) {
            0 => {}
            1 => labels.push(*rng.pick(&CODAS)),
            _ => labels.extend(rng.pick(&CODA_CLUSTERS)),
        }
        for (i, label) in labels.into_iter().enumerate() {
            let vowel = i == vowel_at;
            let (lo, hi) = if vowel { VOWEL_S } else { CONSONANT_S };
            // Stressed vowels draw from the upper part of the range.
            let d = if vowel && stress { rng.range(0.5 * (lo + hi), hi) } else { rng.range(lo, hi) };
            let d = d / speed;
            let jaw_amp = loud
                * if vowel && stress {
                    1.15
                } else if vowel {
                    0.8
                } else {
                    1.0
                };
            let viseme = Viseme::from_arpabet(label).unwrap_or(Viseme::Sil);
            out.push(Phone {
                start: t,
                end: t + d,
                label,
                viseme,
                jaw_amp: jaw_amp * if emphasis && vowel && stress { 1.2 } else { 1.0 },
                lip_amp: lips,
                emphasis: emphasis && vowel && stress,
            });
            t += d;
        }
    }
    t
}

/// Mouth parameters driven by speech.
pub const P_JAW: usize = 0;
pub const P_FUNNEL: usize = 1;
pub const P_PUCKER: usize = 2;
pub const P_STRETCH: usize = 3;
pub const P_UPPER_UP: usize = 4;
pub const P_LOWER_DOWN: usize = 5;
pub const P_ROLL_LOWER: usize = 6;
pub const P_ROLL_UPPER: usize = 7;
pub const P_SHRUG_LOWER: usize = 8;
pub const P_SMILE: usize = 9;
pub const P_TONGUE: usize = 10;
pub const P_PRESS: usize = 11;
/// Lip closure (1 = lips sealed, `MouthClose` cancels `JawOpen`).
pub const P_CLOSURE: usize = 12;
/// Number of mouth parameters.
pub const NUM_PARAMS: usize = 13;

/// Articulation target of a viseme class over the mouth parameters, and its dominance for the jaw
/// and for the lips. The targets are in ARKit weight units for an average-loudness utterance; their
/// scale is calibrated on the real captures (see [`super::calibrate`] and the module docs of
/// [`super`]): the real JawOpen rarely passes 0.3 (95th percentile 0.20; the jaw targets were scaled
/// by 0.6 to bring the procedural mean JawOpen to the real one), MouthLowerDown goes to about
/// 0.6, MouthFunnel to 0.36 and MouthPucker only to 0.06.
pub fn target(v: Viseme) -> ([f32; NUM_PARAMS], f64, f64) {
    // [jaw, funnel, pucker, stretch, upperUp, lowerDown, rollLower, rollUpper, shrugLower, smile, tongue, press, closure]
    let (t, jaw_dom, lip_dom): ([f32; NUM_PARAMS], f64, f64) = match v {
        Viseme::Sil => ([0.012, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.8], 0.6, 0.6),
        Viseme::AoOy => ([0.156, 0.30, 0.04, 0.0, 0.06, 0.30, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0], 1.0, 1.0),
        Viseme::AaAeAy => ([0.192, 0.02, 0.0, 0.10, 0.14, 0.45, 0.0, 0.0, 0.0, 0.03, 0.0, 0.0, 0.0], 1.0, 1.0),
        Viseme::EhEy => ([0.132, 0.0, 0.0, 0.14, 0.14, 0.36, 0.0, 0.0, 0.0, 0.06, 0.0, 0.0, 0.0], 1.0, 1.0),
        Viseme::IhIy => ([0.072, 0.0, 0.0, 0.22, 0.10, 0.22, 0.0, 0.0, 0.0, 0.10, 0.0, 0.0, 0.0], 1.0, 1.0),
        Viseme::OhOw => ([0.132, 0.42, 0.06, 0.0, 0.04, 0.20, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0], 1.0, 1.2),
        Viseme::AhEr => ([0.12, 0.06, 0.0, 0.04, 0.08, 0.30, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0], 1.0, 0.8),
        Viseme::UwAwUh => ([0.072, 0.36, 0.10, 0.0, 0.03, 0.06, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0], 1.0, 1.5),
        Viseme::Jh => ([0.048, 0.26, 0.05, 0.0, 0.10, 0.14, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0], 1.0, 2.0),
        Viseme::GKH => ([0.096, 0.0, 0.0, 0.0, 0.0, 0.14, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0], 0.5, 0.2),
        Viseme::LNTD => ([0.06, 0.0, 0.0, 0.0, 0.04, 0.14, 0.0, 0.0, 0.0, 0.0, 0.02, 0.0, 0.0], 0.7, 0.3),
        Viseme::SZ => ([0.024, 0.0, 0.0, 0.18, 0.10, 0.10, 0.0, 0.0, 0.0, 0.04, 0.0, 0.0, 0.0], 2.0, 1.5),
        Viseme::ShChZh => ([0.036, 0.40, 0.06, 0.0, 0.14, 0.14, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0], 1.5, 3.0),
        Viseme::ThDh => ([0.054, 0.0, 0.0, 0.04, 0.04, 0.14, 0.0, 0.0, 0.0, 0.0, 0.15, 0.0, 0.0], 1.0, 1.0),
        Viseme::FV => ([0.03, 0.0, 0.0, 0.04, 0.12, 0.0, 0.40, 0.0, 0.15, 0.0, 0.0, 0.0, 0.0], 1.0, 6.0),
        Viseme::MBP => ([0.018, 0.0, 0.0, 0.0, 0.0, 0.0, 0.04, 0.02, 0.10, 0.0, 0.0, 0.06, 1.0], 1.5, 8.0),
        Viseme::W => ([0.042, 0.30, 0.12, 0.0, 0.0, 0.04, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0], 0.8, 4.0),
        Viseme::R => ([0.054, 0.22, 0.05, 0.0, 0.04, 0.10, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0], 1.0, 2.0),
    };
    (t, jaw_dom, lip_dom)
}

/// Dominance decay rate before a phone (anticipation), 1/s.
const THETA_BEFORE: f64 = 22.0;
/// Dominance decay rate after a phone (carry-over), 1/s.
const THETA_AFTER: f64 = 32.0;
/// Phones farther than this from t are ignored (their dominance is below e^-7 of their strength).
const REACH_S: f64 = 0.32;

/// Mouth parameters at each of `times`, blended from the phones by dominance (see module docs).
/// `phones` must be sorted and contiguous; the result is `times.len() × NUM_PARAMS`, frame-major.
pub fn articulate(phones: &[Phone], times: &[f64]) -> Vec<[f32; NUM_PARAMS]> {
    let targets: Vec<([f32; NUM_PARAMS], f64, f64)> = phones.iter().map(|p| target(p.viseme)).collect();
    let mut out = Vec::with_capacity(times.len());
    let mut first = 0usize; // first phone that can still reach t
    for &t in times {
        while first < phones.len() && phones[first].end + REACH_S < t {
            first += 1;
        }
        let (mut jaw_w, mut jaw) = (0.0f64, 0.0f64);
        let mut lip_w = 0.0f64;
        let mut lips = [0.0f64; NUM_PARAMS];
        for (p, (tgt, jd, ld)) in phones[first..].iter().zip(&targets[first..]) {
            if p.start - REACH_S > t {
                break;
            }
            let decay = if t < p.start {
                (-(p.start - t) * THETA_BEFORE).exp()
            } else if t > p.end {
                (-(t - p.end) * THETA_AFTER).exp()
            } else {
                1.0
            };
            let wj = jd * decay;
            jaw_w += wj;
            jaw += wj * tgt[P_JAW] as f64 * p.jaw_amp;
            let wl = ld * decay;
            lip_w += wl;
            for k in 1..NUM_PARAMS {
                let amp = if k == P_CLOSURE { 1.0 } else { p.lip_amp };
                lips[k] += wl * tgt[k] as f64 * amp;
            }
        }
        let mut m = [0.0f32; NUM_PARAMS];
        if jaw_w > 0.0 {
            m[P_JAW] = (jaw / jaw_w) as f32;
        }
        if lip_w > 0.0 {
            for k in 1..NUM_PARAMS {
                m[k] = (lips[k] / lip_w) as f32;
            }
        }
        out.push(m);
    }
    out
}

/// Index of the phone containing each time (`phones` contiguous from 0; times past the end get the
/// last phone).
pub fn phone_at(phones: &[Phone], times: &[f64]) -> Vec<usize> {
    let mut out = Vec::with_capacity(times.len());
    let mut i = 0usize;
    for &t in times {
        while i + 1 < phones.len() && phones[i].end <= t {
            i += 1;
        }
        out.push(i);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn phones_are_contiguous_cover_the_clip_and_have_realistic_durations() {
        let mut rng = Rand::new(3, 0);
        let ph = phones(&mut rng, 30.0, 0.6, 1.0, 0.2);
        assert_eq!(ph[0].start, 0.0);
        assert_eq!(ph.last().unwrap().end, 30.0);
        for w in ph.windows(2) {
            assert_eq!(w[0].end, w[1].start);
        }
        let speech: f64 = ph.iter().filter(|p| p.viseme != Viseme::Sil).map(|p| p.end - p.start).sum();
        assert!(speech > 6.0 && speech < 27.0, "speech {speech} s of 30");
        for p in ph.iter().filter(|p| p.viseme != Viseme::Sil && p.end < 30.0) {
            let d = p.end - p.start;
            assert!((0.04..=0.24).contains(&d), "{} lasts {d}", p.label);
            assert_eq!(Viseme::from_arpabet(p.label), Some(p.viseme));
        }
        assert!(ph.iter().any(|p| p.viseme == Viseme::MBP));
    }

    #[test]
    fn silence_only_when_speech_fraction_is_zero() {
        let ph = phones(&mut Rand::new(1, 0), 10.0, 0.0, 1.0, 0.2);
        assert_eq!(ph.len(), 1);
        assert_eq!((ph[0].label, ph[0].start, ph[0].end), ("sil", 0.0, 10.0));
    }
}
