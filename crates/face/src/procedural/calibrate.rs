//! Statistics of a face animation, measured the same way on real captures and on procedural clips,
//! so the generator's constants can be calibrated on the real ones (issue 10, Training: "calibrate its
//! statistics (blink rate and duration, jaw spectrum, inter-shape correlations) on the real captures").
//!
//! Every measure works on the clip resampled to the model rate ([`MODEL_FPS`], §4.1):
//! - **blinks**: runs of the mean of `EyeBlinkLeft`/`EyeBlinkRight` above [`BLINK_THRESHOLD`]; a blink's
//!   duration is the time between its up- and down-crossing, both interpolated linearly between frames
//!   (runs touching a clip end are not counted);
//! - **JawOpen spectrum**: Welch's method ([`WELCH_SEGMENT`]-frame Hann-windowed segments, half
//!   overlap, each segment's mean removed), power pooled over every segment of every clip; the fraction
//!   of power (DC excluded) in each band of [`JAW_BANDS_HZ`] and the frequency of the largest bin;
//! - **shapes**: mean and standard deviation of each of [`KEY_SHAPES`], pooled over all frames;
//! - **correlations**: Pearson correlation of each pair of [`CORRELATION_PAIRS`], pooled over all frames.
//!
//! [`measure`] measures one clip, [`measure_all`] pools several (a corpus), [`comparison_table`] puts
//! real and procedural statistics side by side in an [`inbetween_io::report::Table`].

use crate::data::{arkit_index, BlendshapeClip, FaceError, MODEL_FPS};
use inbetween_io::report::{num, Table};

/// Blink threshold on the mean of the two `EyeBlink*` weights. Chosen on the real captures: their
/// blinks peak at 0.5–0.95 (the two "Fearful" takes only at about 0.5) and the open-eye level stays
/// under 0.3 (90th percentile 0.0–0.26 per take).
pub const BLINK_THRESHOLD: f32 = 0.35;

/// Welch segment length in frames (5.12 s at 25 fps; bins 0.195 Hz apart).
pub const WELCH_SEGMENT: usize = 128;

/// JawOpen spectrum bands in Hz (the last ends at the 12.5 Hz Nyquist frequency of 25 fps).
pub const JAW_BANDS_HZ: [(f64, f64); 4] = [(0.0, 1.0), (1.0, 3.0), (3.0, 6.0), (6.0, 12.5)];

/// Shapes whose mean and standard deviation are reported.
pub const KEY_SHAPES: [&str; 16] = [
    "EyeBlinkLeft",
    "EyeSquintLeft",
    "EyeWideLeft",
    "EyeLookUpLeft",
    "EyeLookInLeft",
    "JawOpen",
    "MouthClose",
    "MouthFunnel",
    "MouthPucker",
    "MouthSmileLeft",
    "MouthFrownLeft",
    "MouthLowerDownLeft",
    "MouthUpperUpLeft",
    "BrowInnerUp",
    "BrowDownLeft",
    "CheekSquintLeft",
];

/// Shape pairs whose correlation is reported.
pub const CORRELATION_PAIRS: [(&str, &str); 8] = [
    ("EyeBlinkLeft", "EyeBlinkRight"),
    ("JawOpen", "MouthClose"),
    ("MouthSmileLeft", "MouthSmileRight"),
    ("BrowInnerUp", "BrowOuterUpLeft"),
    ("JawOpen", "MouthLowerDownLeft"),
    ("MouthSmileLeft", "CheekSquintLeft"),
    ("BrowDownLeft", "BrowInnerUp"),
    ("JawOpen", "MouthFunnel"),
];

/// Mean and standard deviation of one shape.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShapeStat {
    pub name: &'static str,
    pub mean: f64,
    pub std: f64,
}

/// Pearson correlation of two shapes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PairCorr {
    pub a: &'static str,
    pub b: &'static str,
    pub r: f64,
}

/// Statistics of one clip or a pooled set of clips (see the module docs for how each is measured).
#[derive(Clone, Debug, PartialEq)]
pub struct FaceStats {
    /// Number of clips pooled.
    pub clips: usize,
    /// Total duration in seconds (frames / 25).
    pub duration_s: f64,
    /// Blinks counted.
    pub blinks: usize,
    /// Blinks per minute.
    pub blink_rate_per_min: f64,
    /// Mean blink duration above [`BLINK_THRESHOLD`], seconds (NaN without blinks).
    pub blink_duration_s: f64,
    /// Fraction of the JawOpen power (DC excluded) in each band of [`JAW_BANDS_HZ`].
    pub jaw_bands: [f64; 4],
    /// Frequency of the largest JawOpen Welch bin (DC excluded), Hz.
    pub jaw_dominant_hz: f64,
    /// One entry per [`KEY_SHAPES`] name, in that order.
    pub shapes: Vec<ShapeStat>,
    /// One entry per [`CORRELATION_PAIRS`] pair, in that order (NaN when a shape is constant).
    pub correlations: Vec<PairCorr>,
}

impl FaceStats {
    /// Index of the band of [`JAW_BANDS_HZ`] holding the most JawOpen power.
    pub fn dominant_band(&self) -> usize {
        let mut best = 0;
        for (i, p) in self.jaw_bands.iter().enumerate() {
            if *p > self.jaw_bands[best] {
                best = i;
            }
        }
        best
    }

    /// Mean and std of a key shape by name.
    pub fn shape(&self, name: &str) -> Option<&ShapeStat> {
        self.shapes.iter().find(|s| s.name.eq_ignore_ascii_case(name))
    }

    /// Correlation of a listed pair (either order).
    pub fn correlation(&self, a: &str, b: &str) -> Option<f64> {
        self.correlations.iter().find(|p| (p.a == a && p.b == b) || (p.a == b && p.b == a)).map(|p| p.r)
    }

    /// The statistics as a two-column table (`statistic`, `value`).
    pub fn table(&self, name: &str, title: &str) -> Table {
        let mut t = Table::new(name, title, &["statistic", "value"]);
        for (label, value) in stat_rows(self) {
            t.row([label, value]);
        }
        t
    }
}

/// Real statistics beside one or more procedural sets (`statistic`, `real`, then one column per
/// `(name, stats)`).
pub fn comparison_table(real: &FaceStats, procedural: &[(&str, &FaceStats)]) -> Table {
    let mut headers = vec!["statistic", "real"];
    headers.extend(procedural.iter().map(|(n, _)| *n));
    let mut t =
        Table::new("face_procedural_calibration", "Procedural face animation vs real captures (25 fps)", &headers);
    let columns: Vec<Vec<(String, String)>> = procedural.iter().map(|(_, s)| stat_rows(s)).collect();
    for (i, (label, r)) in stat_rows(real).into_iter().enumerate() {
        let mut row = vec![label, r];
        row.extend(columns.iter().map(|c| c[i].1.clone()));
        t.row(row);
    }
    t.note(format!("real: {} clips, {:.0} s", real.clips, real.duration_s));
    for (name, s) in procedural {
        t.note(format!("{name}: {} clips, {:.0} s", s.clips, s.duration_s));
    }
    t.note(format!(
        "blinks: mean EyeBlinkL/R above {BLINK_THRESHOLD}; jaw spectrum: Welch, {WELCH_SEGMENT}-frame Hann segments"
    ));
    t
}

/// Label and formatted value of every statistic, in a fixed order.
fn stat_rows(s: &FaceStats) -> Vec<(String, String)> {
    let mut rows = vec![
        ("blinks per minute".to_string(), num(s.blink_rate_per_min, 1)),
        ("blink duration (ms)".to_string(), num(s.blink_duration_s * 1e3, 0)),
    ];
    for ((lo, hi), p) in JAW_BANDS_HZ.iter().zip(&s.jaw_bands) {
        rows.push((format!("JawOpen power {lo}–{hi} Hz"), num(*p, 3)));
    }
    rows.push(("JawOpen dominant frequency (Hz)".to_string(), num(s.jaw_dominant_hz, 2)));
    for sh in &s.shapes {
        rows.push((format!("{} mean ± std", sh.name), format!("{} ± {}", num(sh.mean, 3), num(sh.std, 3))));
    }
    for c in &s.correlations {
        rows.push((format!("corr {} / {}", c.a, c.b), num(c.r, 2)));
    }
    rows
}

/// Statistics of one clip (resampled to [`MODEL_FPS`] first).
pub fn measure(clip: &BlendshapeClip) -> Result<FaceStats, FaceError> {
    measure_all(std::slice::from_ref(clip))
}

/// Statistics pooled over several clips (each resampled to [`MODEL_FPS`] first): blink rate over the
/// total duration, blink duration over all blinks, spectrum over all Welch segments, means,
/// deviations and correlations over all frames.
pub fn measure_all(clips: &[BlendshapeClip]) -> Result<FaceStats, FaceError> {
    let mut acc = Accumulator::new();
    for clip in clips {
        let uniform = if is_uniform_at(clip, MODEL_FPS) { clip.clone() } else { clip.resample(MODEL_FPS)? };
        acc.add(&uniform);
    }
    Ok(acc.finish())
}

/// Whether a clip's frames already lie on a `fps` grid (no resampling needed).
fn is_uniform_at(clip: &BlendshapeClip, fps: f64) -> bool {
    let t = clip.times();
    t.iter().enumerate().all(|(i, x)| (x - t[0] - i as f64 / fps).abs() < 1e-6)
}

/// Sufficient statistics, summed clip by clip.
struct Accumulator {
    clips: usize,
    frames: usize,
    blinks: usize,
    blink_time: f64,
    blink_timed: usize,
    psd: Vec<f64>,
    /// Per key shape: Σx, Σx².
    shape_sums: Vec<(f64, f64)>,
    /// Per pair: Σa, Σb, Σa², Σb², Σab.
    pair_sums: Vec<[f64; 5]>,
}

impl Accumulator {
    fn new() -> Self {
        Accumulator {
            clips: 0,
            frames: 0,
            blinks: 0,
            blink_time: 0.0,
            blink_timed: 0,
            psd: vec![0.0; WELCH_SEGMENT / 2 + 1],
            shape_sums: vec![(0.0, 0.0); KEY_SHAPES.len()],
            pair_sums: vec![[0.0; 5]; CORRELATION_PAIRS.len()],
        }
    }

    fn add(&mut self, clip: &BlendshapeClip) {
        let channel =
            |name: &str| -> Vec<f32> { clip.channel(arkit_index(name).expect("statistics name ARKit shapes")) };
        self.clips += 1;
        self.frames += clip.num_frames();
        let (l, r) = (channel("EyeBlinkLeft"), channel("EyeBlinkRight"));
        let blink: Vec<f32> = l.iter().zip(&r).map(|(a, b)| 0.5 * (a + b)).collect();
        for d in blink_durations(&blink, BLINK_THRESHOLD, MODEL_FPS) {
            self.blinks += 1;
            self.blink_time += d;
            self.blink_timed += 1;
        }
        welch_accumulate(&channel("JawOpen"), &mut self.psd);
        for (k, name) in KEY_SHAPES.iter().enumerate() {
            for x in channel(name) {
                let x = x as f64;
                self.shape_sums[k].0 += x;
                self.shape_sums[k].1 += x * x;
            }
        }
        for (k, (a, b)) in CORRELATION_PAIRS.iter().enumerate() {
            let s = &mut self.pair_sums[k];
            for (x, y) in channel(a).into_iter().zip(channel(b)) {
                let (x, y) = (x as f64, y as f64);
                s[0] += x;
                s[1] += y;
                s[2] += x * x;
                s[3] += y * y;
                s[4] += x * y;
            }
        }
    }

    fn finish(self) -> FaceStats {
        let n = self.frames.max(1) as f64;
        let duration_s = self.frames as f64 / MODEL_FPS;
        let (jaw_bands, jaw_dominant_hz) = bands_and_peak(&self.psd);
        let shapes = KEY_SHAPES
            .iter()
            .zip(&self.shape_sums)
            .map(|(name, (s, s2))| {
                let mean = s / n;
                ShapeStat { name, mean, std: (s2 / n - mean * mean).max(0.0).sqrt() }
            })
            .collect();
        let correlations = CORRELATION_PAIRS
            .iter()
            .zip(&self.pair_sums)
            .map(|((a, b), s)| {
                let (ma, mb) = (s[0] / n, s[1] / n);
                let cov = s[4] / n - ma * mb;
                let (va, vb) = (s[2] / n - ma * ma, s[3] / n - mb * mb);
                let r = if va > 1e-12 && vb > 1e-12 { cov / (va * vb).sqrt() } else { f64::NAN };
                PairCorr { a, b, r }
            })
            .collect();
        FaceStats {
            clips: self.clips,
            duration_s,
            blinks: self.blinks,
            blink_rate_per_min: if duration_s > 0.0 { self.blinks as f64 / duration_s * 60.0 } else { f64::NAN },
            blink_duration_s: if self.blink_timed > 0 { self.blink_time / self.blink_timed as f64 } else { f64::NAN },
            jaw_bands,
            jaw_dominant_hz,
            shapes,
            correlations,
        }
    }
}

/// Durations (s) of the runs of `x` above `threshold`, crossings interpolated linearly between
/// frames `1/fps` apart. Runs that start at the first frame or are still open at the last are skipped.
pub fn blink_durations(x: &[f32], threshold: f32, fps: f64) -> Vec<f64> {
    let mut out = Vec::new();
    let mut up: Option<f64> = None;
    for i in 1..x.len() {
        let (a, b) = (x[i - 1], x[i]);
        let frac = |a: f32, b: f32| ((threshold - a) / (b - a)) as f64;
        if a <= threshold && b > threshold {
            up = Some((i - 1) as f64 + frac(a, b));
        } else if a > threshold && b <= threshold {
            if let Some(u) = up.take() {
                let down = (i - 1) as f64 + frac(a, b);
                out.push((down - u) / fps);
            }
        }
    }
    out
}

/// Adds the Welch periodogram of `x` (segments of [`WELCH_SEGMENT`] frames, half overlap, Hann
/// window, segment mean removed) to `psd` (one value per bin 0..=N/2). A clip shorter than one segment
/// contributes one zero-padded segment.
fn welch_accumulate(x: &[f32], psd: &mut [f64]) {
    let n = WELCH_SEGMENT;
    if x.len() < 8 {
        return;
    }
    let window: Vec<f64> = (0..n).map(|i| 0.5 - 0.5 * (std::f64::consts::TAU * i as f64 / n as f64).cos()).collect();
    let mut starts: Vec<usize> = (0..).map(|k| k * n / 2).take_while(|s| s + n <= x.len()).collect();
    if starts.is_empty() {
        starts.push(0);
    }
    let mut seg = vec![0.0f64; n];
    for s in starts {
        let len = n.min(x.len() - s);
        let mean = x[s..s + len].iter().map(|v| *v as f64).sum::<f64>() / len as f64;
        for i in 0..n {
            seg[i] = if i < len { (x[s + i] as f64 - mean) * window[i] } else { 0.0 };
        }
        for (k, p) in psd.iter_mut().enumerate() {
            let (mut re, mut im) = (0.0, 0.0);
            let w = std::f64::consts::TAU * k as f64 / n as f64;
            let (c, sn) = (w.cos(), w.sin());
            let (mut cr, mut ci) = (1.0f64, 0.0f64); // e^{-i w j} by rotation
            for v in &seg {
                re += v * cr;
                im -= v * ci;
                let t = cr * c - ci * sn;
                ci = ci * c + cr * sn;
                cr = t;
            }
            *p += re * re + im * im;
        }
    }
}

/// Band fractions (DC bin excluded) and the frequency of the largest non-DC bin of a Welch spectrum.
fn bands_and_peak(psd: &[f64]) -> ([f64; 4], f64) {
    let df = MODEL_FPS / WELCH_SEGMENT as f64;
    let mut bands = [0.0f64; 4];
    let mut total = 0.0;
    let mut peak = (0.0f64, f64::NAN);
    for (k, p) in psd.iter().enumerate().skip(1) {
        let f = k as f64 * df;
        let b = JAW_BANDS_HZ.iter().position(|(lo, hi)| f >= *lo && f < *hi).unwrap_or(JAW_BANDS_HZ.len() - 1);
        bands[b] += p;
        total += p;
        if *p > peak.0 {
            peak = (*p, f);
        }
    }
    if total > 0.0 {
        for b in &mut bands {
            *b /= total;
        }
    } else {
        bands = [f64::NAN; 4];
    }
    (bands, peak.1)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::{NUM_ARKIT, NUM_HEAD_EYE};

    /// A 25 fps clip with `f(frame, channel)` as values (52 ARKit + 9 head/eye).
    fn synth(frames: usize, f: impl Fn(usize, usize) -> f32) -> BlendshapeClip {
        let stride = NUM_ARKIT + NUM_HEAD_EYE;
        let values = (0..frames * stride).map(|i| f(i / stride, i % stride)).collect();
        let times = (0..frames).map(|i| i as f64 / 25.0).collect();
        BlendshapeClip::new(25.0, times, true, vec![], values).unwrap()
    }

    #[test]
    fn blink_durations_interpolate_crossings() {
        // 0 → 1 → 0 triangle over frames 1..3: crossings of 0.5 at 1.5 and 2.5 → 1 frame = 40 ms.
        let d = blink_durations(&[0.0, 0.0, 1.0, 0.0, 0.0], 0.5, 25.0);
        assert_eq!(d.len(), 1);
        assert!((d[0] - 0.04).abs() < 1e-9);
        // A run open at the end is not a blink.
        assert!(blink_durations(&[0.0, 1.0, 1.0], 0.5, 25.0).is_empty());
    }

    #[test]
    fn sine_jaw_lands_in_its_band_and_pairs_correlate() {
        let (jaw, close, blink_l, blink_r) = (
            arkit_index("JawOpen").unwrap(),
            arkit_index("MouthClose").unwrap(),
            arkit_index("EyeBlinkLeft").unwrap(),
            arkit_index("EyeBlinkRight").unwrap(),
        );
        // JawOpen: 4 Hz sine; MouthClose = 0.5 − JawOpen; a blink (0.9 for 3 frames) every 75 frames.
        let clip = synth(1500, |f, c| {
            let s = 0.25 + 0.2 * (std::f64::consts::TAU * 4.0 * f as f64 / 25.0).sin() as f32;
            match c {
                c if c == jaw => s,
                c if c == close => 0.5 - s,
                c if c == blink_l || c == blink_r => {
                    if f % 75 >= 30 && f % 75 < 33 {
                        0.9
                    } else {
                        0.05
                    }
                }
                _ => 0.1,
            }
        });
        let s = measure(&clip).unwrap();
        assert_eq!(s.dominant_band(), 2, "4 Hz lies in the 3–6 Hz band: {:?}", s.jaw_bands);
        assert!((s.jaw_dominant_hz - 4.0).abs() < 0.2, "{}", s.jaw_dominant_hz);
        assert!(s.jaw_bands[2] > 0.9);
        assert_eq!(s.blinks, 20);
        assert!((s.blink_rate_per_min - 20.0 * 60.0 / 60.0).abs() < 1e-9);
        assert!((s.blink_duration_s - 0.12).abs() < 0.02, "{}", s.blink_duration_s);
        assert!((s.correlation("JawOpen", "MouthClose").unwrap() + 1.0).abs() < 1e-6);
        assert!((s.correlation("EyeBlinkRight", "EyeBlinkLeft").unwrap() - 1.0).abs() < 1e-6);
        assert!(s.correlation("MouthSmileLeft", "MouthSmileRight").unwrap().is_nan(), "constant shapes");
        assert!((s.shape("JawOpen").unwrap().mean - 0.25).abs() < 1e-3);
        let text = comparison_table(&s, &[("again", &s)]).to_text();
        assert!(text.contains("blinks per minute") && text.contains("corr JawOpen / MouthClose"), "{text}");
    }
}

#[cfg(test)]
mod real_data {
    //! The generator's statistics against the real Live Link Face captures (skipped without data).
    use super::*;
    use crate::data::read_live_link;
    use crate::procedural::{generate, ProceduralConfig};
    use inbetween_core::seed::derive;
    use inbetween_io::data::with_shared_data;
    use std::path::{Path, PathBuf};

    fn csv_files(dir: &Path, out: &mut Vec<PathBuf>) {
        let Ok(rd) = std::fs::read_dir(dir) else { return };
        let mut entries: Vec<PathBuf> = rd.filter_map(|e| e.ok().map(|e| e.path())).collect();
        entries.sort();
        for p in entries {
            if p.is_dir() {
                csv_files(&p, out);
            } else if p.extension().is_some_and(|e| e.eq_ignore_ascii_case("csv")) {
                out.push(p);
            }
        }
    }

    /// `n` clips of 30 s from the generator with `speech_fraction`, the rest default.
    fn procedural(speech_fraction: f64, n: usize, seed: u64) -> FaceStats {
        let cfg = ProceduralConfig { speech_fraction, ..ProceduralConfig::with_duration(30.0) };
        let clips: Vec<BlendshapeClip> = (0..n).map(|i| generate(&cfg, derive(seed, i as u64)).clip).collect();
        measure_all(&clips).unwrap()
    }

    /// The tolerances of the calibration (module docs of `procedural`): blink rate and duration within
    /// ×1.5, JawOpen dominant band the same or a neighbour, correlation signs equal, means within ×3 (or
    /// 0.03) and deviations within ×5.
    fn assert_close(name: &str, ours: &FaceStats, real: &FaceStats) {
        let within = |a: f64, b: f64, k: f64| a / b >= 1.0 / k && a / b <= k;
        assert!(
            within(ours.blink_rate_per_min, real.blink_rate_per_min, 1.5),
            "{name}: blink rate {} vs real {}",
            ours.blink_rate_per_min,
            real.blink_rate_per_min
        );
        assert!(
            within(ours.blink_duration_s, real.blink_duration_s, 1.5),
            "{name}: blink duration {} vs real {}",
            ours.blink_duration_s,
            real.blink_duration_s
        );
        assert!(
            ours.dominant_band().abs_diff(real.dominant_band()) <= 1,
            "{name}: JawOpen dominant band {:?} vs real {:?}",
            ours.jaw_bands,
            real.jaw_bands
        );
        for (o, r) in ours.shapes.iter().zip(&real.shapes) {
            assert!(
                (o.mean - r.mean).abs() < 0.03 || within(o.mean, r.mean, 3.0),
                "{name}: {} mean {} vs real {}",
                o.name,
                o.mean,
                r.mean
            );
            assert!(within(o.std, r.std, 5.0), "{name}: {} std {} vs real {}", o.name, o.std, r.std);
        }
        for (o, r) in ours.correlations.iter().zip(&real.correlations) {
            assert!(o.r.signum() == r.r.signum(), "{name}: corr {} / {}: {} vs real {}", o.a, o.b, o.r, r.r);
        }
    }

    #[test]
    fn procedural_statistics_match_real_captures() {
        with_shared_data("face procedural calibration", |data| {
            let mut files = Vec::new();
            csv_files(&data.join("face/neurosync/livelink"), &mut files);
            assert_eq!(files.len(), 8, "the 8 Live Link Face captures");
            let clips: Vec<BlendshapeClip> =
                files.iter().map(|p| read_live_link(p).unwrap_or_else(|e| panic!("{e}"))).collect();
            let real = measure_all(&clips).unwrap();
            let quiet = procedural(0.0, 20, 2024);
            let talking = procedural(ProceduralConfig::default().speech_fraction, 20, 2025);
            println!(
                "{}",
                comparison_table(&real, &[("procedural, no speech", &quiet), ("procedural, default", &talking)])
                    .to_text()
            );
            // The real captures are expressions without speech (97 % of the JawOpen power under 1 Hz):
            // the speechless generator is the like-for-like comparison; the default one (60 % speech)
            // must stay within the same tolerances, with more syllable-rate jaw power.
            assert_close("no speech", &quiet, &real);
            assert_close("default", &talking, &real);
            assert!(
                talking.jaw_bands[1] + talking.jaw_bands[2] > 2.0 * (real.jaw_bands[1] + real.jaw_bands[2]),
                "speech adds syllable-rate jaw motion"
            );
        });
    }
}
