//! The procedural face-animation generator the committed weights are trained on (issue 10, Training:
//! "blinks, speech-like jaw/lip motion driven by a phoneme sequence (so it has exact viseme labels),
//! expression onsets and offsets, head motion"), and its calibration on real captures ([`calibrate`]).
//!
//! [`generate`] turns a [`ProceduralConfig`] and a seed into a [`ProceduralClip`]: a
//! [`BlendshapeClip`] (52 ARKit weights + 9 head/eye rotations, frame `i` at `i / fps`), the exact
//! viseme of every frame (§3.1, Table 1) and the phoneme list it came from. Components, each drawing
//! from its own seeded stream:
//! - speech ([`speech`]): ARPAbet syllables, phrases and pauses; dominance-blended coarticulation
//!   drives jaw and lips, and bilabials close the lips;
//! - blinks ([`blinks`]): refractory renewal process, fast close and slow reopening, both eyes;
//! - expressions ([`expressions`]): smile, frown, brow raise/furrow, squint, sneer, cheek puff with
//!   onset/hold/offset, plus brow raises on emphasised syllables;
//! - head and gaze ([`gaze`]): smooth head noise, saccades between fixations, `EyeLook*` shapes
//!   consistent with the eye angles;
//! - a per-clip resting face (the real captures sit well above 0 on many shapes) and tracker-like
//!   micro-noise; every ARKit weight is clamped to [0, 1].
//!
//! ## Calibration (numbers measured on the real captures, data not copied)
//! `../shared/data/face/neurosync/livelink/**.csv`: 8 Live Link Face takes, 267 s, resampled to 25 fps
//! and measured with [`calibrate::measure_all`]; the test `procedural_statistics_match_real_captures`
//! prints the full table beside the generator's (20 clips × 30 s without speech, and 20 with the
//! default 60 % speech) and checks the tolerances.
//! - Blinks: 20.7 per minute, 106 ms above [`calibrate::BLINK_THRESHOLD`]; closing in about 65 ms,
//!   reopening in about 140 ms at 60 fps → [`DEFAULT_BLINK_RATE`] and the timings of [`blinks`].
//! - The takes are acted emotions **without speech**: JawOpen holds 97.4 % of its power under 1 Hz
//!   (2.3 % in 1–3 Hz), is 0 in half the frames and moves slowly with MouthFunnel (r 0.84) and
//!   MouthClose (r 0.80). So they calibrate the non-speech parts (resting face, moods, open-mouth and
//!   bared-teeth expressions, slow jaw drift with sealed lips); speech timing follows phonetic ranges
//!   (consonants 50–100 ms, vowels 80–200 ms) and its jaw amplitude the real JawOpen range.
//! - Resting levels (pooled means): EyeSquint 0.20, EyeLookUp 0.18, MouthSmile 0.17, BrowDown 0.12,
//!   CheekSquint 0.11, EyeWide 0.11, BrowInnerUp 0.11, MouthShrugLower 0.08, MouthStretchLeft 0.08,
//!   MouthRollLower 0.08, NoseSneer 0.07 → [`REST_LEVELS`]; each take holds one emotion → a mood
//!   expression held over 60 % of the clips.
//! - Mouth ranges (95th percentiles): JawOpen 0.20, MouthLowerDown 0.58, MouthUpperUp 0.28,
//!   MouthFunnel 0.36, MouthPucker 0.06, MouthClose 0.12, MouthPress max 0.07 → the articulation
//!   targets of [`speech::target`] and the expression gains.
//! - Eye angles (yaw std 0.11 rad, pitch mean −0.06) and `EyeLook*` gains (≈ 1.5–2.4 per radian) →
//!   [`gaze`]. The head columns of the takes are all 0, so head motion is not calibrated.
//!
//! Generation is cheap (a 60 s clip takes about 4 ms in the test profile), so training can draw
//! thousands of clips ([`generate_corpus`]).

pub mod blinks;
pub mod calibrate;
pub mod expressions;
pub mod gaze;
mod random;
pub mod speech;

use crate::data::{arkit_index, BlendshapeClip, FaceError, MODEL_FPS, NUM_ARKIT, NUM_HEAD_EYE};
use crate::visemes::Viseme;
use random::Rand;
use speech::{Phone, NUM_PARAMS, P_CLOSURE};

/// Blinks per minute asked of the blink process (double blinks come on top). The real captures
/// measure 20.7 per minute at the [`calibrate::BLINK_THRESHOLD`]; some procedural blinks are partial
/// and stay under it, double blinks add some: the measured procedural rate is 21–24.
pub const DEFAULT_BLINK_RATE: f64 = 21.5;

/// Settings of the generator. Every field has a default ([`ProceduralConfig::default`]); [`generate`]
/// clamps out-of-range values (see [`ProceduralConfig::validate`] to reject them instead).
#[derive(Clone, Debug, PartialEq)]
pub struct ProceduralConfig {
    /// Clip length, seconds (default 10).
    pub duration_s: f64,
    /// Frame rate (default [`MODEL_FPS`] = 25).
    pub fps: f64,
    /// Fraction of the time spent speaking, 0..1 (default 0.6).
    pub speech_fraction: f64,
    /// Speaking-rate factor: phoneme durations are divided by it (default 1).
    pub speech_rate: f64,
    /// Blinks per minute (default [`DEFAULT_BLINK_RATE`]).
    pub blink_rate_per_min: f64,
    /// Expression events per minute (default 8).
    pub expression_rate_per_min: f64,
    /// Scale of expression amplitudes (default 1).
    pub expression_amplitude: f64,
    /// Fraction of words said with emphasis (default 0.2).
    pub emphasis: f64,
    /// Probability that an emphasised syllable raises the brows (default 0.5).
    pub brow_speech_coupling: f64,
    /// Head-motion amplitude scale (default 1, about 0.05 rad; 0 keeps the head still like the real
    /// captures, whose head columns are zero).
    pub head_motion: f64,
    /// Standard deviation of the tracker-like micro-noise on every ARKit weight (default 0.006).
    pub micro_noise: f64,
}

impl Default for ProceduralConfig {
    fn default() -> Self {
        ProceduralConfig {
            duration_s: 10.0,
            fps: MODEL_FPS,
            speech_fraction: 0.6,
            speech_rate: 1.0,
            blink_rate_per_min: DEFAULT_BLINK_RATE,
            expression_rate_per_min: 8.0,
            expression_amplitude: 1.0,
            emphasis: 0.2,
            brow_speech_coupling: 0.5,
            head_motion: 1.0,
            micro_noise: 0.006,
        }
    }
}

/// Longest clip [`generate`] makes (longer requests are clamped), seconds.
pub const MAX_DURATION_S: f64 = 3600.0;

impl ProceduralConfig {
    /// A default configuration of the given length.
    pub fn with_duration(duration_s: f64) -> Self {
        ProceduralConfig { duration_s, ..Default::default() }
    }

    /// Checks every field: positive finite duration (≤ [`MAX_DURATION_S`]) and fps (≤ 1000),
    /// fractions and probabilities in [0, 1], non-negative finite rates and scales, positive speech rate.
    pub fn validate(&self) -> Result<(), FaceError> {
        let bad = |m: String| Err(FaceError::Invalid(m));
        if !(self.duration_s.is_finite() && self.duration_s > 0.0 && self.duration_s <= MAX_DURATION_S) {
            return bad(format!("duration_s must be in (0, {MAX_DURATION_S}] s, got {}", self.duration_s));
        }
        if !(self.fps.is_finite() && self.fps > 0.0 && self.fps <= 1000.0) {
            return bad(format!("fps must be in (0, 1000], got {}", self.fps));
        }
        if !(self.speech_rate.is_finite() && self.speech_rate > 0.0) {
            return bad(format!("speech_rate must be a positive number, got {}", self.speech_rate));
        }
        for (name, v) in [
            ("speech_fraction", self.speech_fraction),
            ("emphasis", self.emphasis),
            ("brow_speech_coupling", self.brow_speech_coupling),
        ] {
            if !(0.0..=1.0).contains(&v) {
                return bad(format!("{name} must be in [0, 1], got {v}"));
            }
        }
        for (name, v) in [
            ("blink_rate_per_min", self.blink_rate_per_min),
            ("expression_rate_per_min", self.expression_rate_per_min),
            ("expression_amplitude", self.expression_amplitude),
            ("head_motion", self.head_motion),
            ("micro_noise", self.micro_noise),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return bad(format!("{name} must be a non-negative number, got {v}"));
            }
        }
        Ok(())
    }

    /// A copy with every field brought into its valid range (NaN and invalid values become defaults).
    fn sanitized(&self) -> ProceduralConfig {
        let d = ProceduralConfig::default();
        let pos = |v: f64, max: f64, def: f64| if v.is_finite() && v > 0.0 { v.min(max) } else { def };
        let unit = |v: f64, def: f64| if v.is_nan() { def } else { v.clamp(0.0, 1.0) };
        let nonneg = |v: f64, def: f64| if v.is_finite() && v >= 0.0 { v } else { def };
        ProceduralConfig {
            duration_s: pos(self.duration_s, MAX_DURATION_S, d.duration_s),
            fps: pos(self.fps, 1000.0, d.fps),
            speech_fraction: unit(self.speech_fraction, d.speech_fraction),
            speech_rate: pos(self.speech_rate, 10.0, d.speech_rate),
            blink_rate_per_min: nonneg(self.blink_rate_per_min, d.blink_rate_per_min).min(120.0),
            expression_rate_per_min: nonneg(self.expression_rate_per_min, d.expression_rate_per_min).min(120.0),
            expression_amplitude: nonneg(self.expression_amplitude, d.expression_amplitude),
            emphasis: unit(self.emphasis, d.emphasis),
            brow_speech_coupling: unit(self.brow_speech_coupling, d.brow_speech_coupling),
            head_motion: nonneg(self.head_motion, d.head_motion),
            micro_noise: nonneg(self.micro_noise, d.micro_noise).min(0.5),
        }
    }
}

/// A generated clip with its exact labels.
#[derive(Clone, Debug, PartialEq)]
pub struct ProceduralClip {
    /// 52 ARKit weights in [0, 1] + 9 head/eye rotations, frame `i` at `i / fps`.
    pub clip: BlendshapeClip,
    /// Viseme of every frame: the class of the phoneme whose interval `[start, end)` holds the frame.
    pub visemes: Vec<Viseme>,
    /// `(start_s, end_s, ARPAbet label)`, contiguous from 0 to the clip duration; silence is `"sil"`.
    pub phonemes: Vec<(f64, f64, &'static str)>,
}

impl ProceduralClip {
    /// Writes the clip at `out` (Live Link Face CSV when `live_link`, else curve CSV/JSON by
    /// extension) and its phoneme timing beside it (`out` with `.phonemes.csv`), both or neither
    /// (`face synth`). Returns the line saying what was written.
    pub fn write(&self, out: &std::path::Path, live_link: bool) -> Result<String, FaceError> {
        let mut set = inbetween_io::OutputSet::new();
        let timing = out.with_extension("phonemes.csv");
        let staged = |set: &mut inbetween_io::OutputSet, p: &std::path::Path| {
            set.file(p).map_err(|source| FaceError::Io { file: p.display().to_string(), source })
        };
        crate::data::write_clip(&staged(&mut set, out)?, &self.clip, live_link)?;
        let spans: Vec<crate::visemes::PhonemeSpan> = (self.phonemes.iter())
            .map(|(s, e, ph)| crate::visemes::PhonemeSpan { start_s: *s, end_s: *e, phoneme: ph.to_string() })
            .collect();
        crate::visemes::write_phoneme_timing(&staged(&mut set, &timing)?, &spans)?;
        set.commit().map_err(|e| FaceError::Output {
            what: format!("moving {} and {} into place", out.display(), timing.display()),
            source: Box::new(e),
        })?;
        let frames = self.clip.num_frames();
        Ok(format!(
            "wrote {} ({frames} frames at {MODEL_FPS} fps) and its phoneme timing {}",
            out.display(),
            timing.display()
        ))
    }
}

/// Resting face: `(shape, maximum)`: each clip draws a level uniformly in `[0, maximum]` (left/right
/// pairs nearly equal), so the corpus mean is about half the maximum — the real captures' pooled means
/// (module docs). `CheekSquint*` rest at [`CHEEK_PER_SMILE`] × the resting smile plus up to 0.06
/// (real correlation of MouthSmileLeft and CheekSquintLeft: 0.93).
pub const REST_LEVELS: [(&str, f32); 22] = [
    ("EyeSquintLeft", 0.3),
    ("EyeSquintRight", 0.3),
    ("EyeWideLeft", 0.16),
    ("EyeWideRight", 0.16),
    ("BrowDownLeft", 0.16),
    ("BrowDownRight", 0.16),
    ("BrowInnerUp", 0.08),
    ("MouthSmileLeft", 0.16),
    ("MouthSmileRight", 0.16),
    ("MouthStretchLeft", 0.12),
    ("MouthStretchRight", 0.08),
    ("MouthRollLower", 0.12),
    ("MouthShrugLower", 0.12),
    ("MouthShrugUpper", 0.09),
    ("NoseSneerLeft", 0.1),
    ("NoseSneerRight", 0.09),
    ("JawForward", 0.05),
    ("JawRight", 0.06),
    ("MouthRight", 0.04),
    ("MouthDimpleLeft", 0.04),
    ("MouthDimpleRight", 0.04),
    ("MouthPressLeft", 0.02),
];

/// Resting `CheekSquint*` per unit of resting `MouthSmile*`.
pub const CHEEK_PER_SMILE: f32 = 0.6;

/// Random streams of one clip.
const STREAM_SPEECH: u64 = 1;
const STREAM_BLINKS: u64 = 2;
const STREAM_EXPRESSIONS: u64 = 3;
const STREAM_HEAD: u64 = 4;
const STREAM_EYES: u64 = 5;
const STREAM_REST: u64 = 6;
const STREAM_NOISE: u64 = 7;
const STREAM_DRIFT: u64 = 8;

/// Generates one clip (see the module docs). Deterministic in `(config, seed)`; out-of-range settings
/// are clamped, never a panic.
pub fn generate(config: &ProceduralConfig, seed: u64) -> ProceduralClip {
    let cfg = config.sanitized();
    let n = ((cfg.duration_s * cfg.fps).round() as usize).max(1);
    let times: Vec<f64> = (0..n).map(|i| i as f64 / cfg.fps).collect();
    let duration = cfg.duration_s.max(times[n - 1] + 1e-9);
    let stride = NUM_ARKIT + NUM_HEAD_EYE;
    let mut w = vec![0.0f32; n * stride];
    let ix = Indices::get();

    // Resting face and a possible mood expression held over the clip.
    let mut rng = Rand::new(seed, STREAM_REST);
    rest_face(&mut rng, &ix, &mut w, n, stride);

    // Speech.
    let mut rng = Rand::new(seed, STREAM_SPEECH);
    let phones = speech::phones(&mut rng, duration, cfg.speech_fraction, cfg.speech_rate, cfg.emphasis);
    let mouth = speech::articulate(&phones, &times);
    let stretch_asym = 1.0 + 0.15 * rng.normal().clamp(-2.0, 2.0) as f32;
    for (f, m) in mouth.iter().enumerate() {
        mouth_to_shapes(m, &ix, &mut w[f * stride..f * stride + NUM_ARKIT], stretch_asym);
    }

    // Expressions (events + brows on emphasis).
    let mut rng = Rand::new(seed, STREAM_EXPRESSIONS);
    let mut events = expressions::schedule(
        &mut rng,
        duration,
        cfg.expression_rate_per_min,
        cfg.expression_amplitude,
        &phones,
        cfg.brow_speech_coupling,
    );
    if rng.chance(0.6) {
        // A mood: one expression held over the whole clip, as each real take holds one emotion.
        // Lip-parting moods only in clips without speech.
        use expressions::Expression as E;
        let speechless = phones.iter().all(|p| p.viseme == Viseme::Sil);
        let kinds: &[E] = if speechless {
            &[
                E::Smile,
                E::Frown,
                E::BrowRaise,
                E::BrowFurrow,
                E::Squint,
                E::Sneer,
                E::Worry,
                E::OpenMouth,
                E::BareTeeth,
            ]
        } else {
            &[E::Smile, E::Frown, E::BrowRaise, E::BrowFurrow, E::Squint, E::Sneer, E::Worry]
        };
        let kind = *rng.pick(kinds);
        events.push(expressions::Event {
            kind,
            t0: -1.0,
            onset_s: 0.5,
            hold_s: duration + 2.0,
            offset_s: 0.5,
            amp: cfg.expression_amplitude * rng.range(0.1, 0.5),
            asym: rng.range(-0.1, 0.1),
        });
    }
    expressions::render(&events, &times, &mut w, stride);
    let open_mouth = expressions::lip_parting_envelope(&events, &times);

    // Slow jaw drift (the real JawOpen holds 97 % of its power under 1 Hz): the jaw sags and recovers
    // with the lips kept together outside speech (MouthClose follows, correlation 0.80 on the real
    // captures).
    let drift = jaw_drift(&mut Rand::new(seed, STREAM_DRIFT), &times);
    for (f, d) in drift.iter().enumerate() {
        w[f * stride + ix.jaw] += d;
    }

    // Blinks.
    let mut rng = Rand::new(seed, STREAM_BLINKS);
    let blink_events = blinks::schedule(&mut rng, duration, cfg.blink_rate_per_min);
    for (f, (l, r)) in blinks::render(&blink_events, &times).into_iter().enumerate() {
        w[f * stride + ix.blink_l] += l;
        w[f * stride + ix.blink_r] += r;
    }

    // Head and gaze.
    let head = gaze::head(&mut Rand::new(seed, STREAM_HEAD), &times, cfg.head_motion);
    let eyes = gaze::eyes(&mut Rand::new(seed, STREAM_EYES), &times);
    for f in 0..n {
        let row = &mut w[f * stride..(f + 1) * stride];
        let look = gaze::look_shapes(&eyes[f]);
        for (c, v) in ix.look.iter().zip(look) {
            row[*c] += v;
        }
        // Looking down lowers the upper lids a little.
        row[ix.blink_l] += 0.25 * look[0];
        row[ix.blink_r] += 0.25 * look[4];
        row[NUM_ARKIT..NUM_ARKIT + 3].copy_from_slice(&head[f]);
        row[NUM_ARKIT + 3..NUM_ARKIT + 9].copy_from_slice(&eyes[f]);
    }

    // Tracker micro-noise, then lip closure (so bilabials stay closed), then [0, 1].
    add_micro_noise(&mut Rand::new(seed, STREAM_NOISE), &mut w, n, stride, cfg.micro_noise as f32);
    for (f, m) in mouth.iter().enumerate() {
        // A lip-parting expression (only ever outside speech) undoes the resting lip closure.
        close_lips(m[P_CLOSURE] * (1.0 - open_mouth[f]), &ix, &mut w[f * stride..f * stride + NUM_ARKIT]);
    }
    for f in 0..n {
        for v in &mut w[f * stride..f * stride + NUM_ARKIT] {
            *v = v.clamp(0.0, 1.0);
        }
    }

    let clip = BlendshapeClip::new(cfg.fps, times.clone(), true, Vec::new(), w)
        .expect("generated values are finite and the times increase");
    let visemes = speech::phone_at(&phones, &times).into_iter().map(|i| phones[i].viseme).collect();
    let phonemes = phones.iter().map(|p: &Phone| (p.start, p.end, p.label)).collect();
    ProceduralClip { clip, visemes, phonemes }
}

/// `n_clips` clips of `duration_s` seconds for training, clip `i` seeded with `derive(seed, i)`, with
/// the per-clip variation of [`generate_corpus_with`] around the default configuration.
pub fn generate_corpus(n_clips: usize, duration_s: f64, seed: u64) -> Vec<ProceduralClip> {
    generate_corpus_with(&ProceduralConfig::with_duration(duration_s), n_clips, seed)
}

/// `n_clips` clips around `config`: each clip draws its speech fraction (none for one clip in five,
/// like the real captures, which show no speech; otherwise ×0.5–1.5 the configured one, capped at 1),
/// speaking rate (×0.85–1.2), blink rate (×0.6–1.4) and expression rate
/// (×0.4–1.6), so a corpus spans talkative and quiet, calm and expressive clips.
pub fn generate_corpus_with(config: &ProceduralConfig, n_clips: usize, seed: u64) -> Vec<ProceduralClip> {
    (0..n_clips)
        .map(|i| {
            let clip_seed = inbetween_core::seed::derive(seed, i as u64);
            let mut rng = Rand::new(clip_seed, 0);
            let cfg = ProceduralConfig {
                speech_fraction: if rng.chance(0.2) {
                    0.0
                } else {
                    (config.speech_fraction * rng.range(0.5, 1.5)).clamp(0.0, 1.0)
                },
                speech_rate: config.speech_rate * rng.range(0.85, 1.2),
                blink_rate_per_min: config.blink_rate_per_min * rng.range(0.6, 1.4),
                expression_rate_per_min: config.expression_rate_per_min * rng.range(0.4, 1.6),
                ..config.clone()
            };
            generate(&cfg, clip_seed)
        })
        .collect()
}

/// ARKit channel indices the generator writes, looked up once.
struct Indices {
    jaw: usize,
    close: usize,
    funnel: usize,
    pucker: usize,
    stretch: [usize; 2],
    upper_up: [usize; 2],
    lower_down: [usize; 2],
    roll_lower: usize,
    roll_upper: usize,
    shrug_lower: usize,
    smile: [usize; 2],
    cheek_squint: [usize; 2],
    tongue: usize,
    press: [usize; 2],
    blink_l: usize,
    blink_r: usize,
    /// `[DownLeft, InLeft, OutLeft, UpLeft, DownRight, InRight, OutRight, UpRight]` (see
    /// [`gaze::look_shapes`]).
    look: [usize; 8],
    rest: Vec<(usize, f32)>,
    /// The centre lip gap as `gap_base + Σ k · weight` (column `lip_gap_center` of
    /// [`crate::edit::distances::distance_matrix`]).
    gap_base: f32,
    gap: Vec<(usize, f32)>,
}

impl Indices {
    fn get() -> Indices {
        use crate::edit::distances::{distance_bases, distance_matrix, DISTANCE_NAMES, NUM_DISTANCES};
        let matrix = distance_matrix();
        let gap_col =
            DISTANCE_NAMES.iter().position(|n| *n == "lip_gap_center").expect("the centre lip gap is a key distance");
        let i = |n: &str| arkit_index(n).expect("generator shapes are ARKit names");
        Indices {
            jaw: i("JawOpen"),
            close: i("MouthClose"),
            funnel: i("MouthFunnel"),
            pucker: i("MouthPucker"),
            stretch: [i("MouthStretchLeft"), i("MouthStretchRight")],
            upper_up: [i("MouthUpperUpLeft"), i("MouthUpperUpRight")],
            lower_down: [i("MouthLowerDownLeft"), i("MouthLowerDownRight")],
            roll_lower: i("MouthRollLower"),
            roll_upper: i("MouthRollUpper"),
            shrug_lower: i("MouthShrugLower"),
            smile: [i("MouthSmileLeft"), i("MouthSmileRight")],
            cheek_squint: [i("CheekSquintLeft"), i("CheekSquintRight")],
            tongue: i("TongueOut"),
            press: [i("MouthPressLeft"), i("MouthPressRight")],
            blink_l: i("EyeBlinkLeft"),
            blink_r: i("EyeBlinkRight"),
            look: [
                i("EyeLookDownLeft"),
                i("EyeLookInLeft"),
                i("EyeLookOutLeft"),
                i("EyeLookUpLeft"),
                i("EyeLookDownRight"),
                i("EyeLookInRight"),
                i("EyeLookOutRight"),
                i("EyeLookUpRight"),
            ],
            rest: REST_LEVELS.iter().map(|(n, v)| (i(n), *v)).collect(),
            gap_base: distance_bases()[gap_col],
            gap: (0..NUM_ARKIT).map(|c| (c, matrix[c * NUM_DISTANCES + gap_col])).filter(|(_, k)| *k != 0.0).collect(),
        }
    }
}

/// Slow jaw drift at each time: a per-clip level (0–0.08) times a sum of three slow sinusoids
/// (0.03–0.3 Hz) mapped to [0, 1].
fn jaw_drift(rng: &mut Rand, times: &[f64]) -> Vec<f32> {
    let level = rng.range(0.0, 0.08);
    let waves: Vec<(f64, f64)> =
        (0..3).map(|_| (rng.range(0.03, 0.3), rng.range(0.0, std::f64::consts::TAU))).collect();
    times
        .iter()
        .map(|&t| {
            let s: f64 = waves.iter().map(|(f, ph)| (std::f64::consts::TAU * f * t + ph).sin()).sum::<f64>() / 3.0;
            (level * (0.5 + 0.5 * s)) as f32
        })
        .collect()
}

/// Writes the per-clip resting levels into every frame.
fn rest_face(rng: &mut Rand, ix: &Indices, w: &mut [f32], n: usize, stride: usize) {
    let mut levels = [0.0f32; NUM_ARKIT];
    let mut shared = 0.0f32;
    for (k, (c, max)) in ix.rest.iter().enumerate() {
        // Left/right pairs are listed together: the right one reuses the left draw, ±10 %.
        let is_right = k > 0 && REST_LEVELS[k].0.ends_with("Right") && REST_LEVELS[k - 1].0.ends_with("Left");
        let u = if is_right { (shared * rng.range(0.9, 1.1) as f32).min(1.0) } else { rng.unit() as f32 };
        shared = u;
        levels[*c] = u * max;
    }
    let extra = rng.range(0.0, 0.06) as f32;
    for s in 0..2 {
        levels[ix.cheek_squint[s]] = CHEEK_PER_SMILE * levels[ix.smile[s]] + extra;
    }
    for f in 0..n {
        w[f * stride..f * stride + NUM_ARKIT].iter_mut().zip(&levels).for_each(|(x, l)| *x += l);
    }
}

/// Adds the speech mouth parameters of one frame to its ARKit weights.
fn mouth_to_shapes(m: &[f32; NUM_PARAMS], ix: &Indices, row: &mut [f32], stretch_asym: f32) {
    use speech::*;
    row[ix.jaw] += m[P_JAW];
    row[ix.funnel] += m[P_FUNNEL];
    row[ix.pucker] += m[P_PUCKER];
    row[ix.stretch[0]] += m[P_STRETCH] * stretch_asym;
    row[ix.stretch[1]] += m[P_STRETCH] / stretch_asym;
    for s in 0..2 {
        row[ix.upper_up[s]] += m[P_UPPER_UP];
        row[ix.lower_down[s]] += m[P_LOWER_DOWN];
        row[ix.smile[s]] += m[P_SMILE];
        row[ix.press[s]] += m[P_PRESS];
    }
    row[ix.roll_lower] += m[P_ROLL_LOWER];
    row[ix.roll_upper] += m[P_ROLL_UPPER];
    row[ix.shrug_lower] += m[P_SHRUG_LOWER];
    row[ix.tongue] += m[P_TONGUE];
}

/// Lip closure `l` (0..1): the lip-parting shapes fade by `1 − l`, then `MouthClose` takes the share `l`
/// of the centre lip gap the other shapes leave (`lip_gap_center` of [`crate::edit::distances`]),
/// never more than `JawOpen`; so at `l = 1` the centre gap is 0, or slightly below when rolled or
/// pressed lips already close it.
fn close_lips(l: f32, ix: &Indices, row: &mut [f32]) {
    let l = l.clamp(0.0, 1.0);
    let keep = 1.0 - l;
    for s in 0..2 {
        row[ix.upper_up[s]] *= keep;
        row[ix.lower_down[s]] *= keep;
    }
    row[ix.funnel] *= keep;
    let jaw = row[ix.jaw].clamp(0.0, 1.0);
    let own = row[ix.close];
    row[ix.close] = 0.0;
    let gap: f32 = ix.gap_base + ix.gap.iter().map(|(c, k)| k * row[*c]).sum::<f32>();
    row[ix.close] = (keep * own + l * gap.max(0.0)).min(jaw);
}

/// Adds AR(1) noise (correlation 0.5 frame to frame, standard deviation `sigma`) to every ARKit weight.
fn add_micro_noise(rng: &mut Rand, w: &mut [f32], n: usize, stride: usize, sigma: f32) {
    if sigma <= 0.0 {
        return;
    }
    const RHO: f32 = 0.5;
    let innov = sigma * (1.0 - RHO * RHO).sqrt();
    let mut state = [0.0f32; NUM_ARKIT];
    for s in &mut state {
        *s = sigma * rng.normal() as f32;
    }
    for f in 0..n {
        for (c, s) in state.iter_mut().enumerate() {
            *s = RHO * *s + innov * rng.normal() as f32;
            w[f * stride + c] += *s;
        }
    }
}

#[cfg(test)]
mod tests;
