//! The benchmark of the issue: Table 1 (hidden-state initialisation), Table 2 (SD / TD / KD under
//! keyframe displacement), the §6.3 spline comparison, the style-space PCA (Fig. 4) and generation
//! speed. Everything runs on a held-out seeded evaluation set (a seed the training never uses).
//!
//! Protocols (in downsampled steps of 5 frames; errors are ‖Δx^c‖₂ over the 6 Toric values):
//! - **Table 1**: a 45-step window per sequence: 5 ground-truth steps of context, then 40 generated
//!   steps (200 frames) to a keyframe on the last one; z from the extractor on the 60 steps from
//!   the window's start. The hidden state starts at zero, as N(0, 1) noise, warm-started (zero, then
//!   the generator reads the 5 ground-truth steps) or mapped by H (Eq. 6). Error = mean over the
//!   generated steps. The paper trains a separate network for the warm start; we reuse ours. The
//!   `lerp` column is the same error for the straight Toric line from the start to the key.
//! - **Table 2**: 60-step segments with keys at both ends; the end key's θ is displaced by δ
//!   (random sign, kept inside the valid arc). *Ours*: generate with z and the displaced key
//!   (KD = miss at that key), correct onto it (Eq. 9), re-extract z_r, regenerate with z_r and the
//!   true keys: TD = mean error to the ground truth, SD (Eq. 8) = S(Z_r, Z)/S(Z, Z) per behaviour.
//!   *Only style*: generate with the true keys, then bend onto the displaced key by Eq. 9 alone.
//!   *Toric interpolation*: straight lines in Toric space between the keys (no network).
//! - **§6.3**: our track with 3 keys (start, middle, end) vs a Catmull-Rom spline through n evenly
//!   spaced ground-truth keys: the smallest n whose spline error is at most ours.

use crate::dataset::{Behaviour, Dataset, BEHAVIOURS, DOWNSAMPLE};
use crate::infer::{cam_distance, key_vector, Cam, Chr, FastModel, Rollout, Scratch, StepIn};
use crate::model::{MAP_FRAMES, STYLE_STEPS};
use crate::toric::Lens;
use crate::CameraError;
use inbetween_core::curve::{Curve, Samples, Track};
use inbetween_io::report::{num, Report, Table};
use inbetween_io::Progress;
use inbetween_nn::runtime::LstmState;
use inbetween_render::plot::{grouped_bar_chart, line_plot, scatter_plot, Series};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Which benchmark size to run.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct BenchConfig {
    pub seed: u64,
    pub scenes: usize,
    pub windows_per_sequence: usize,
    pub displacements: Vec<f64>,
    pub max_spline_keys: usize,
    pub speed_seconds: f64,
}

impl BenchConfig {
    pub fn full() -> BenchConfig {
        BenchConfig {
            seed: 9001,
            scenes: 12,
            windows_per_sequence: 3,
            displacements: vec![0.0, 0.1, 0.3, 0.5, 0.9, 1.2, 1.4, 1.6, 1.8, 2.0],
            max_spline_keys: 40,
            speed_seconds: 2.0,
        }
    }

    /// Under a minute on 2 cores.
    pub fn quick() -> BenchConfig {
        BenchConfig {
            scenes: 3,
            windows_per_sequence: 1,
            displacements: vec![0.0, 0.5, 1.0, 2.0],
            speed_seconds: 0.7,
            ..BenchConfig::full()
        }
    }
}

#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Table1Row {
    pub behaviour: String,
    pub zero: f64,
    pub gaussian: f64,
    pub warm_start: f64,
    pub mapped: f64,
    /// No network: straight Toric line from the start to the key (the baseline to beat).
    #[serde(default)]
    pub lerp: f64,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Table2Row {
    pub displacement: f64,
    pub sd_ours: f64,
    pub sd_only_style: f64,
    pub sd_interpolation: f64,
    pub td_ours: f64,
    pub td_only_style: f64,
    pub td_interpolation: f64,
    pub kd_ours: f64,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct RailsRow {
    pub behaviour: String,
    pub ours_error: f64,
    /// Mean smallest key count for the spline to match us (capped cases count as the cap).
    pub spline_keys: f64,
    pub capped: usize,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Speed {
    /// End to end (network every 5th frame, cubic fill, world poses), one 900-frame track.
    pub single_frames_per_s: f64,
    /// Network only, 16 trajectories in lockstep, output frames (5 per step).
    pub batched_frames_per_s: f64,
    pub batch: usize,
}

/// Everything the bench prints and writes.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct BenchReport {
    pub config: BenchConfig,
    pub sequences: usize,
    pub table1: Vec<Table1Row>,
    pub table2: Vec<Table2Row>,
    pub rails: Vec<RailsRow>,
    pub speed: Speed,
    /// How much the style code changes a track: mean distance between the tracks generated through
    /// the same keys with each behaviour's mean style code (0 = style ignored).
    pub style_spread: f64,
    /// (behaviour, main is A, z) of every evaluation sequence, for the PCA plot.
    pub styles: Vec<(Behaviour, bool, Vec<f32>)>,
}

/// An evaluation sequence at the network rate.
struct EvalSeq {
    behaviour: Behaviour,
    main_is_a: bool,
    chars: Vec<Chr>,
    cams: Vec<Cam>,
}

fn mean_err(a: &[Cam], b: &[Cam]) -> f64 {
    a.iter().zip(b).map(|(x, y)| cam_distance(x, y)).sum::<f64>() / a.len().max(1) as f64
}

/// Generates from the last of the five `context` steps (H's input) through `keys` (step indices
/// into `chars`, the last key last); returns all steps, the start first.
fn roll(model: &FastModel, z: &[f32], context: &[Cam], chars: &[Chr], keys: &[(usize, Cam)]) -> Vec<Cam> {
    let frames: [Cam; MAP_FRAMES] = std::array::from_fn(|i| context[i]);
    Rollout::mapped(model, z, &frames).through_keys(chars, keys)
}

fn style_of(model: &FastModel, chars: &[Chr], cams: &[Cam]) -> Vec<f32> {
    model.extract_style(chars, cams)
}

/// Bends `track` onto `keys` (index, value) by linearly blended residuals (Eq. 9).
fn bend(track: &mut [Cam], keys: &[(usize, Cam)]) {
    let values = track.iter().map(|c| c.map(|v| v as f64)).collect();
    let Ok(samples) = Samples::new(0.0, 1.0, values) else { return };
    let k64: Vec<(f64, [f64; 6])> = keys.iter().map(|(i, c)| (*i as f64, c.map(|v| v as f64))).collect();
    let bent = samples.corrected_to_keys(&k64);
    for (i, d) in track.iter_mut().enumerate() {
        *d = bent.sample_clamped(i as f64).map(|v| v as f32);
    }
}

fn table1(
    model: &FastModel,
    seqs: &[EvalSeq],
    cfg: &BenchConfig,
    rng: &mut ChaCha8Rng,
    progress: &Progress,
) -> Vec<Table1Row> {
    let gap = 40;
    let hd = model.config.hidden;
    let mut sums = vec![[0.0f64; 5]; BEHAVIOURS.len()];
    let mut counts = vec![0usize; BEHAVIOURS.len()];
    for s in seqs {
        for _ in 0..cfg.windows_per_sequence {
            let s0 = rng.random_range(0..=s.cams.len() - STYLE_STEPS.max(MAP_FRAMES + gap));
            let z = style_of(model, &s.chars[s0..s0 + STYLE_STEPS], &s.cams[s0..s0 + STYLE_STEPS]);
            let base = s0 + MAP_FRAMES - 1;
            let chars = &s.chars[base..=base + gap];
            let truth = &s.cams[base..=base + gap];
            let keys = [(gap, truth[gap])];
            let gaussian =
                LstmState { h: (0..hd).map(|_| normal(rng)).collect(), c: (0..hd).map(|_| normal(rng)).collect() };
            // Warm start: from a zero state the generator reads the context steps (teacher forced).
            let mut warm = Rollout::with_state(model, &z, LstmState::zeros(1, hd), s.cams[s0]);
            let key = key_vector(&truth[gap], &chars[gap]);
            for t in s0 + 1..=base {
                warm.set_prev(s.cams[t - 1]);
                warm.step(&s.chars[t], &key, (base + gap - t) * DOWNSAMPLE);
            }
            let b = s.behaviour.index();
            let starts = [LstmState::zeros(1, hd), gaussian, warm.state().clone()];
            for (m, st) in starts.into_iter().enumerate() {
                let out = Rollout::with_state(model, &z, st, truth[0]).through_keys(chars, &keys);
                sums[b][m] += mean_err(&out[1..], &truth[1..]);
            }
            let out = roll(model, &z, &s.cams[s0..s0 + MAP_FRAMES], chars, &keys);
            sums[b][3] += mean_err(&out[1..], &truth[1..]);
            sums[b][4] += mean_err(&lerp_track(&truth[0], &truth[gap], gap)[1..], &truth[1..]);
            counts[b] += 1;
            progress.inc(1);
        }
    }
    BEHAVIOURS
        .iter()
        .map(|b| {
            let i = b.index();
            let n = counts[i].max(1) as f64;
            Table1Row {
                behaviour: b.name().into(),
                zero: sums[i][0] / n,
                gaussian: sums[i][1] / n,
                warm_start: sums[i][2] / n,
                mapped: sums[i][3] / n,
                lerp: sums[i][4] / n,
            }
        })
        .collect()
}

/// Standard normal (seeded through `rng`).
fn normal(rng: &mut ChaCha8Rng) -> f32 {
    inbetween_core::seed::normal(rng) as f32
}

/// θ displaced by δ with a random sign, kept inside the valid arc (the other sign when needed).
fn displaced(key: &Cam, delta: f64, lens: &Lens, rng: &mut ChaCha8Rng) -> Cam {
    let toric = crate::features::decode_camera(key);
    let max = toric.theta_max(lens) - 0.05;
    let th = toric.theta;
    let sign = if rng.random_bool(0.5) { 1.0 } else { -1.0 };
    let first = th + sign * delta;
    let theta = if first > 0.05 && first < max { first } else { (th - sign * delta).clamp(0.05, max) };
    let mut out = *key;
    out[4] = theta as f32;
    out
}

fn set_distance(u: &[Vec<f32>], v: &[Vec<f32>]) -> f64 {
    let mut total = 0.0;
    for a in u {
        for b in v {
            total += a.iter().zip(b).map(|(x, y)| ((x - y) as f64).powi(2)).sum::<f64>().sqrt();
        }
    }
    total / (u.len() * v.len()).max(1) as f64
}

/// SD (Eq. 8) averaged over behaviours.
fn silhouette(pairs: &[(Behaviour, Vec<f32>, Vec<f32>)]) -> f64 {
    let mut sds = Vec::new();
    for b in BEHAVIOURS {
        let z: Vec<Vec<f32>> = pairs.iter().filter(|p| p.0 == b).map(|p| p.1.clone()).collect();
        let zr: Vec<Vec<f32>> = pairs.iter().filter(|p| p.0 == b).map(|p| p.2.clone()).collect();
        if z.len() > 1 {
            sds.push(set_distance(&zr, &z) / set_distance(&z, &z).max(1e-12));
        }
    }
    sds.iter().sum::<f64>() / sds.len().max(1) as f64
}

fn lerp_track(a: &Cam, b: &Cam, n: usize) -> Vec<Cam> {
    (0..=n).map(|t| std::array::from_fn(|k| a[k] + (b[k] - a[k]) * t as f32 / n as f32)).collect()
}

fn table2(
    model: &FastModel,
    seqs: &[EvalSeq],
    cfg: &BenchConfig,
    lens: &Lens,
    rng: &mut ChaCha8Rng,
    progress: &Progress,
) -> Vec<Table2Row> {
    let len = STYLE_STEPS;
    // One segment per sequence, shared by every δ.
    let segs: Vec<(usize, Vec<f32>)> = seqs
        .iter()
        .map(|s| {
            let s0 = rng.random_range(0..=s.cams.len() - (len + MAP_FRAMES));
            let base = s0 + MAP_FRAMES - 1;
            (s0, style_of(model, &s.chars[base + 1..=base + len], &s.cams[base + 1..=base + len]))
        })
        .collect();
    let mut rows = Vec::new();
    for &delta in &cfg.displacements {
        let (mut ours, mut only, mut interp) = (Vec::new(), Vec::new(), Vec::new());
        let (mut td, mut kd) = ([0.0f64; 3], 0.0);
        for (s, (s0, z)) in seqs.iter().zip(&segs) {
            let base = s0 + MAP_FRAMES - 1;
            let chars = &s.chars[base..=base + len];
            let truth = &s.cams[base..=base + len];
            let true_keys = [(len, truth[len])];
            let key_d = displaced(&truth[len], delta, lens, rng);
            let disp_keys = [(0, truth[0]), (len, key_d)];
            let ctx = &s.cams[*s0..s0 + MAP_FRAMES];
            let regenerate = |zr: &[f32]| roll(model, zr, ctx, chars, &true_keys);
            // Ours.
            let mut x1 = roll(model, z, ctx, chars, &[(len, key_d)]);
            kd += cam_distance(&x1[len], &key_d);
            bend(&mut x1, &disp_keys);
            let zr = style_of(model, &chars[1..], &x1[1..]);
            td[0] += mean_err(&regenerate(&zr)[1..], &truth[1..]);
            ours.push((s.behaviour, z.clone(), zr));
            // Only style.
            let mut x2 = roll(model, z, ctx, chars, &true_keys);
            bend(&mut x2, &disp_keys);
            let zr = style_of(model, &chars[1..], &x2[1..]);
            td[1] += mean_err(&regenerate(&zr)[1..], &truth[1..]);
            only.push((s.behaviour, z.clone(), zr));
            // Plain Toric interpolation.
            let x3 = lerp_track(&truth[0], &key_d, len);
            let zr = style_of(model, &chars[1..], &x3[1..]);
            td[2] += mean_err(&lerp_track(&truth[0], &truth[len], len)[1..], &truth[1..]);
            interp.push((s.behaviour, z.clone(), zr));
            progress.inc(1);
        }
        let n = seqs.len().max(1) as f64;
        rows.push(Table2Row {
            displacement: delta,
            sd_ours: silhouette(&ours),
            sd_only_style: silhouette(&only),
            sd_interpolation: silhouette(&interp),
            td_ours: td[0] / n,
            td_only_style: td[1] / n,
            td_interpolation: td[2] / n,
            kd_ours: kd / n,
        });
    }
    rows
}

fn rails(
    model: &FastModel,
    seqs: &[EvalSeq],
    cfg: &BenchConfig,
    rng: &mut ChaCha8Rng,
    progress: &Progress,
) -> Vec<RailsRow> {
    let len = STYLE_STEPS;
    let mut acc = vec![(0.0f64, 0.0f64, 0usize, 0usize); BEHAVIOURS.len()];
    for s in seqs {
        let s0 = rng.random_range(0..=s.cams.len() - (len + MAP_FRAMES));
        let base = s0 + MAP_FRAMES - 1;
        let chars = &s.chars[base..=base + len];
        let truth = &s.cams[base..=base + len];
        let z = style_of(model, &chars[1..], &truth[1..]);
        let keys = [(len / 2, truth[len / 2]), (len, truth[len])];
        let mut ours = roll(model, &z, &s.cams[s0..s0 + MAP_FRAMES], chars, &keys);
        bend(&mut ours, &[(0, truth[0]), keys[0], keys[1]]);
        let e_ours = mean_err(&ours, truth);
        let mut needed = cfg.max_spline_keys;
        let mut capped = 1;
        for n in 2..=cfg.max_spline_keys {
            let idx: Vec<usize> = (0..n).map(|i| (i * len + (n - 1) / 2) / (n - 1)).collect();
            let times: Vec<f64> = idx.iter().map(|&i| i as f64).collect();
            let values: Vec<[f64; 6]> = idx.iter().map(|&i| truth[i].map(|v| v as f64)).collect();
            let Ok(curve) = Track::catmull_rom(&times, &values) else { continue };
            let spline: Vec<Cam> = (0..=len).map(|t| curve.sample_clamped(t as f64).map(|v| v as f32)).collect();
            if mean_err(&spline, truth) <= e_ours {
                needed = n;
                capped = 0;
                break;
            }
        }
        let a = &mut acc[s.behaviour.index()];
        a.0 += e_ours;
        a.1 += needed as f64;
        a.2 += 1;
        a.3 += capped;
        progress.inc(1);
    }
    BEHAVIOURS
        .iter()
        .map(|b| {
            let a = acc[b.index()];
            let n = a.2.max(1) as f64;
            RailsRow { behaviour: b.name().into(), ours_error: a.0 / n, spline_keys: a.1 / n, capped: a.3 }
        })
        .collect()
}

/// Mean pairwise distance between tracks through the same two keys (60 steps) generated with each
/// behaviour's mean style code.
fn style_spread(
    model: &FastModel,
    seqs: &[EvalSeq],
    styles: &[(Behaviour, bool, Vec<f32>)],
    rng: &mut ChaCha8Rng,
    progress: &Progress,
) -> f64 {
    let len = STYLE_STEPS;
    let codes: Vec<Vec<f32>> = BEHAVIOURS
        .iter()
        .map(|b| {
            let zs: Vec<&Vec<f32>> = styles.iter().filter(|s| s.0 == *b).map(|s| &s.2).collect();
            (0..model.config.style_dim).map(|k| zs.iter().map(|z| z[k]).sum::<f32>() / zs.len().max(1) as f32).collect()
        })
        .collect();
    let (mut total, mut n) = (0.0, 0usize);
    for s in seqs {
        let s0 = rng.random_range(0..=s.cams.len() - (len + MAP_FRAMES));
        let base = s0 + MAP_FRAMES - 1;
        let chars = &s.chars[base..=base + len];
        let truth = &s.cams[base..=base + len];
        let tracks: Vec<Vec<Cam>> =
            codes.iter().map(|z| roll(model, z, &[truth[0]; MAP_FRAMES], chars, &[(len, truth[len])])).collect();
        for i in 0..tracks.len() {
            for j in i + 1..tracks.len() {
                total += mean_err(&tracks[i], &tracks[j]);
                n += 1;
            }
        }
        progress.inc(1);
    }
    total / n.max(1) as f64
}

fn speed(model: &FastModel, seconds: f64) -> Speed {
    let scene = crate::dataset::Scene::procedural(42, 900, 30.0);
    let keys = crate::infer::example_keys(&scene, &[0, 299, 599, 899]);
    let style = crate::infer::Style { name: "bench".into(), code: vec![0.0; model.config.style_dim] };
    let job = crate::infer::GenerateJob {
        model,
        scene: &scene,
        keys: &keys,
        style: &style,
        options: Default::default(),
        origin: std::path::Path::new("bench"),
    };
    let t0 = Instant::now();
    let mut frames = 0usize;
    while t0.elapsed().as_secs_f64() < seconds * 0.5 || frames == 0 {
        // The built-in scene and keys are valid; a failure would leave the count at 0 and stop.
        let Ok(track) = job.run() else { break };
        frames += track.frames.len();
    }
    let single = frames as f64 / t0.elapsed().as_secs_f64();
    let batch = 16;
    let mut state = LstmState::zeros(batch, model.config.hidden);
    let input = StepIn {
        style: &style.code,
        prev: [-0.3, 0.1, 0.3, 0.1, 1.5, 0.2],
        character: [0.4, 0.0, 1.0, 0.0, 1.0, 0.0, -1.0, 1.0],
        key: [0.1; 14],
        tta_frames: 100,
    };
    let inputs = vec![input; batch];
    let mut scratch = Scratch::for_rows(model, batch);
    let t1 = Instant::now();
    let mut steps = 0usize;
    while t1.elapsed().as_secs_f64() < seconds * 0.5 || steps == 0 {
        for _ in 0..20 {
            model.step_into(&inputs, &mut state, &mut scratch);
        }
        steps += 20;
    }
    let batched = (steps * batch * DOWNSAMPLE) as f64 / t1.elapsed().as_secs_f64();
    Speed { single_frames_per_s: single, batched_frames_per_s: batched, batch }
}

/// The held-out sequences of `scenes` procedural scenes (seed `seed`), downsampled and encoded.
fn eval_sequences(seed: u64, scenes: usize) -> Vec<EvalSeq> {
    Dataset::generate(seed, scenes, crate::dataset::SCENE_FRAMES)
        .sequences
        .iter()
        .map(|s| {
            let (chars, cams) = s.encoded(DOWNSAMPLE);
            EvalSeq { behaviour: s.behaviour, main_is_a: s.main_is_a, chars, cams }
        })
        .collect()
}

/// Runs the whole benchmark, advancing `progress` through its phases (style codes, Table 1,
/// Table 2, §6.3, speed); the caller finishes the bar.
pub fn run(model: &FastModel, cfg: &BenchConfig, progress: &Progress) -> BenchReport {
    let lens = Lens::default();
    let seqs = eval_sequences(cfg.seed, cfg.scenes);
    let mut rng = ChaCha8Rng::seed_from_u64(cfg.seed);
    progress.phase(2 * seqs.len() as u64, "style codes");
    let styles: Vec<(Behaviour, bool, Vec<f32>)> = seqs
        .iter()
        .map(|s| {
            progress.inc(1);
            (s.behaviour, s.main_is_a, style_of(model, &s.chars[..STYLE_STEPS], &s.cams[..STYLE_STEPS]))
        })
        .collect();
    let style_spread = style_spread(model, &seqs, &styles, &mut ChaCha8Rng::seed_from_u64(cfg.seed ^ 0x51), progress);
    progress.phase((seqs.len() * cfg.windows_per_sequence) as u64, "Table 1");
    let table1 = table1(model, &seqs, cfg, &mut rng, progress);
    progress.phase((seqs.len() * cfg.displacements.len()) as u64, "Table 2");
    let table2 = table2(model, &seqs, cfg, &lens, &mut rng, progress);
    progress.phase(seqs.len() as u64, "§6.3 rails");
    let rails = rails(model, &seqs, cfg, &mut rng, progress);
    progress.phase(1, "speed");
    let speed = speed(model, cfg.speed_seconds);
    progress.inc(1);
    BenchReport { config: cfg.clone(), sequences: seqs.len(), table1, table2, rails, speed, style_spread, styles }
}

/// The first two principal components of the style codes (power iteration on the covariance).
pub fn pca2(codes: &[Vec<f32>]) -> Vec<(f64, f64)> {
    let d = codes.first().map_or(0, |c| c.len());
    let n = codes.len().max(1) as f64;
    let mean: Vec<f64> = (0..d).map(|k| codes.iter().map(|c| c[k] as f64).sum::<f64>() / n).collect();
    let centred: Vec<Vec<f64>> = codes.iter().map(|c| (0..d).map(|k| c[k] as f64 - mean[k]).collect()).collect();
    let mut cov = vec![vec![0.0; d]; d];
    for c in &centred {
        for i in 0..d {
            for j in 0..d {
                cov[i][j] += c[i] * c[j] / n;
            }
        }
    }
    let mut axes: Vec<Vec<f64>> = Vec::new();
    for _ in 0..2.min(d) {
        let mut v: Vec<f64> = (0..d).map(|k| 1.0 + k as f64 * 0.1).collect();
        for _ in 0..200 {
            let mut w: Vec<f64> = (0..d).map(|i| (0..d).map(|j| cov[i][j] * v[j]).sum()).collect();
            for a in &axes {
                let p: f64 = w.iter().zip(a).map(|(x, y)| x * y).sum();
                for (wi, ai) in w.iter_mut().zip(a) {
                    *wi -= p * ai;
                }
            }
            let norm = w.iter().map(|x| x * x).sum::<f64>().sqrt().max(1e-12);
            v = w.iter().map(|x| x / norm).collect();
        }
        axes.push(v);
    }
    let proj = |c: &Vec<f64>, a: Option<&Vec<f64>>| a.map_or(0.0, |a| c.iter().zip(a).map(|(x, y)| x * y).sum());
    centred.iter().map(|c| (proj(c, axes.first()), proj(c, axes.get(1)))).collect()
}

/// The paper's Table 1 (behaviour; zero, Gaussian, warm start, mapped H), beside ours.
pub const PAPER_TABLE1: [(&str, f64, f64, f64, f64); 4] = [
    ("direct", 0.162, 0.146, 0.173, 0.107),
    ("relative", 0.081, 0.074, 0.088, 0.050),
    ("side", 0.045, 0.045, 0.071, 0.025),
    ("orbit", 0.263, 0.263, 0.116, 0.049),
];

/// The paper's Table 1 average row (zero, Gaussian, warm start, mapped H).
pub const PAPER_TABLE1_AVERAGE: [f64; 4] = [0.138, 0.132, 0.112, 0.057];

/// The paper's Table 2 "ours" rows for a displaced key (δ in radians; SD, TD, KD).
pub const PAPER_TABLE2: [(f64, f64, f64, f64); 10] = [
    (0.0, 1.009, 0.065, 0.016),
    (0.1, 1.009, 0.069, 0.021),
    (0.3, 1.015, 0.089, 0.051),
    (0.5, 1.025, 0.115, 0.085),
    (0.9, 1.058, 0.175, 0.154),
    (1.2, 1.082, 0.219, 0.192),
    (1.4, 1.1, 0.24, 0.216),
    (1.6, 1.12, 0.263, 0.235),
    (1.8, 1.157, 0.302, 0.251),
    (2.0, 1.211, 0.359, 0.277),
];

/// A chart's PNG bytes (see [`inbetween_render::rendered_bytes`]), so that [`Report::write`]
/// writes it atomically with the rest.
fn chart_bytes(
    name: &str,
    draw: impl FnOnce(&Path) -> Result<(), inbetween_render::RenderError>,
) -> Result<Vec<u8>, CameraError> {
    inbetween_render::rendered_bytes(name, draw).map_err(|e| CameraError::invalid(Path::new(name), e.to_string()))
}

impl BenchReport {
    /// Table 1 (`table1.csv`): ours by initialisation and the straight line, the paper's beside.
    pub fn table1(&self) -> Table {
        let headers = [
            "behaviour",
            "zero",
            "gaussian",
            "warm_start",
            "mapped",
            "toric_lerp",
            "paper_zero",
            "paper_gaussian",
            "paper_warm_start",
            "paper_mapped",
        ];
        let mut t = Table::new(
            "table1",
            "Table 1: trajectory error (Toric units) by hidden-state initialisation, 40 generated steps to a keyframe",
            &headers,
        );
        let mut avg = [0.0; 5];
        for r in &self.table1 {
            let ours = [r.zero, r.gaussian, r.warm_start, r.mapped, r.lerp];
            let paper =
                PAPER_TABLE1.iter().find(|p| p.0 == r.behaviour).map_or([f64::NAN; 4], |p| [p.1, p.2, p.3, p.4]);
            let mut cells = vec![r.behaviour.clone()];
            cells.extend(ours.iter().map(|v| num(*v, 4)));
            cells.extend(paper.iter().map(|v| if v.is_nan() { num(*v, 0) } else { v.to_string() }));
            t.row(cells);
            for (a, v) in avg.iter_mut().zip(ours) {
                *a += v / self.table1.len() as f64;
            }
        }
        let [pz, pg, pw, pm] = PAPER_TABLE1_AVERAGE;
        t.note(format!(
            "average: zero {}, gaussian {}, warm_start {}, mapped {}, toric_lerp {}; paper {pz} / {pg} / {pw} / {pm}",
            num(avg[0], 3),
            num(avg[1], 3),
            num(avg[2], 3),
            num(avg[3], 3),
            num(avg[4], 3)
        ));
        t.note("toric_lerp: no network, the straight Toric line from the start to the key (the baseline to beat)");
        t.note("warm_start reuses our network (the paper trains one per initialisation); paper_*: the paper's Table 1");
        t
    }

    /// Table 2 (`table2.csv`): SD (Eq. 8), TD and KD against the key displacement δ.
    pub fn table2(&self) -> Table {
        let headers = [
            "displacement",
            "sd_ours",
            "sd_only_style",
            "sd_interpolation",
            "td_ours",
            "td_only_style",
            "td_interpolation",
            "kd_ours",
        ];
        let mut t = Table::new("table2", "Table 2: keyframe displacement δ (rad on θ): SD (Eq. 8), TD, KD", &headers);
        for r in &self.table2 {
            let values = [
                r.sd_ours,
                r.sd_only_style,
                r.sd_interpolation,
                r.td_ours,
                r.td_only_style,
                r.td_interpolation,
                r.kd_ours,
            ];
            t.row(std::iter::once(r.displacement.to_string()).chain(values.iter().map(|v| num(*v, 4))));
        }
        let paper = |f: fn(&(f64, f64, f64, f64)) -> f64| {
            PAPER_TABLE2.iter().map(|p| f(p).to_string()).collect::<Vec<_>>().join(" / ")
        };
        let deltas = PAPER_TABLE2.iter().map(|p| p.0.to_string()).collect::<Vec<_>>().join(" / ");
        t.note(format!("paper (its Table 2 \"ours\" rows) at δ = {deltas}:"));
        t.note(format!("paper SD: {}", paper(|p| p.1)));
        t.note(format!("paper TD: {}", paper(|p| p.2)));
        t.note(format!("paper KD: {}", paper(|p| p.3)));
        t.note("SD divides distances measured by each model's own extractor: SD of different weights are on different scales");
        t
    }

    /// §6.3 (`rails.csv`): how many spline keys match our 3-key track.
    pub fn rails_table(&self) -> Table {
        let title =
            "§6.3: keys a Catmull-Rom spline through the ground truth needs to match our 3-key track (300 frames)";
        let mut t = Table::new("rails", title, &["behaviour", "ours_error", "spline_keys", "capped"]);
        for r in &self.rails {
            t.row([r.behaviour.clone(), num(r.ours_error, 4), num(r.spline_keys, 2), r.capped.to_string()]);
        }
        t.note(format!(
            "capped: sequences no spline of up to {} keys matched (counted as {})",
            self.config.max_spline_keys, self.config.max_spline_keys
        ));
        t.note("paper: up to 20 keys for camera-on-rails");
        t
    }

    /// Generation speed (`speed.csv`), frames per second on this machine.
    pub fn speed_table(&self) -> Table {
        let mut t = Table::new("speed", "Speed: frames per second, one thread", &["measure", "frames_per_s", "paper"]);
        t.row(["end to end, one 900-frame track", &num(self.speed.single_frames_per_s, 0), "> 2000"]);
        t.row([
            &format!("network only, {} trajectories batched", self.speed.batch),
            &num(self.speed.batched_frames_per_s, 0),
            "",
        ]);
        t.note("end to end: network every 5th frame, cubic fill, world poses; batched: output frames (5 per step)");
        t
    }

    /// The whole report: the tables, the style effect, `report.json` and the charts (Table 1,
    /// Table 2's TD and SD, the style PCA of Fig. 4) as PNG files.
    pub fn report(&self) -> Result<Report, CameraError> {
        let mut r = Report::new(
            "report",
            &format!("camera bench: {} held-out sequences (seed {})", self.sequences, self.config.seed),
        );
        r.table(self.table1()).table(self.table2()).table(self.rails_table());
        r.text(format!(
            "style effect: tracks through the same keys with the {} behaviour codes differ by {} on average",
            BEHAVIOURS.len(),
            num(self.style_spread, 4)
        ));
        r.table(self.speed_table());
        r.json("report.json", self).map_err(io_error)?;
        r.file("table1.png", self.table1_png()?);
        let (td, sd) = self.table2_pngs()?;
        r.file("table2_td.png", td).file("table2_sd.png", sd);
        r.file("style_pca.png", self.style_pca_png()?);
        Ok(r)
    }

    /// Writes [`BenchReport::report`] into `dir` atomically: report.txt, report.md, the table CSVs,
    /// report.json and the PNG charts. Returns the paths written.
    pub fn write(&self, dir: &Path) -> Result<Vec<PathBuf>, CameraError> {
        self.report()?.write(dir).map_err(io_error)
    }

    fn table1_png(&self) -> Result<Vec<u8>, CameraError> {
        let groups: Vec<String> = self.table1.iter().map(|r| r.behaviour.clone()).collect();
        let col = |f: fn(&Table1Row) -> f64| self.table1.iter().map(f).collect::<Vec<f64>>();
        let series = [
            ("zero".into(), col(|r| r.zero)),
            ("gaussian".into(), col(|r| r.gaussian)),
            ("warm start".into(), col(|r| r.warm_start)),
            ("mapped (H)".into(), col(|r| r.mapped)),
            ("Toric lerp".into(), col(|r| r.lerp)),
            ("paper mapped".into(), PAPER_TABLE1.iter().map(|p| p.4).collect()),
        ];
        chart_bytes("table1.png", |p| {
            grouped_bar_chart(
                p,
                "Table 1: trajectory error by hidden-state initialisation",
                "error (Toric units)",
                &groups,
                &series,
            )
        })
    }

    fn table2_pngs(&self) -> Result<(Vec<u8>, Vec<u8>), CameraError> {
        let series = |name: &str, f: fn(&Table2Row) -> f64| {
            Series::new(name, self.table2.iter().map(|r| (r.displacement, f(r))).collect())
        };
        let td = [
            series("ours", |r| r.td_ours),
            series("only style", |r| r.td_only_style),
            series("Toric lerp", |r| r.td_interpolation),
            series("KD ours", |r| r.kd_ours),
        ];
        let sd = [
            series("ours", |r| r.sd_ours),
            series("only style", |r| r.sd_only_style),
            series("Toric lerp", |r| r.sd_interpolation),
        ];
        Ok((
            chart_bytes("table2_td.png", |p| {
                line_plot(p, "Table 2: TD vs keyframe displacement", "δ (rad)", "TD", &td)
            })?,
            chart_bytes("table2_sd.png", |p| {
                line_plot(p, "Table 2: SD vs keyframe displacement", "δ (rad)", "SD", &sd)
            })?,
        ))
    }

    fn style_pca_png(&self) -> Result<Vec<u8>, CameraError> {
        let codes: Vec<Vec<f32>> = self.styles.iter().map(|s| s.2.clone()).collect();
        let pts = pca2(&codes);
        let mut series = Vec::new();
        for b in BEHAVIOURS {
            for main_is_a in [true, false] {
                let points = self
                    .styles
                    .iter()
                    .zip(&pts)
                    .filter(|(s, _)| s.0 == b && s.1 == main_is_a)
                    .map(|(_, p)| *p)
                    .collect();
                let base = [[31, 119, 180], [44, 160, 44], [255, 127, 14], [214, 39, 40]][b.index()];
                let color = if main_is_a { base } else { base.map(|c: u8| c / 2 + 100) };
                let mut s =
                    Series::new(format!("{} ({} main)", b.name(), if main_is_a { "left" } else { "right" }), points);
                s.color = Some(color);
                series.push(s);
            }
        }
        chart_bytes("style_pca.png", |p| scatter_plot(p, "Style codes z, PCA (Fig. 4)", "PC 1", "PC 2", &series))
    }
}

fn io_error(e: inbetween_io::IoError) -> CameraError {
    match e {
        inbetween_io::IoError::Io { path, source } => CameraError::Io { path, source },
        other => CameraError::invalid(Path::new("camera bench"), other.to_string()),
    }
}

#[cfg(test)]
mod tests;
