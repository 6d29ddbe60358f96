//! The bench's protocols and measurements (see the module above for each): the held-out evaluation
//! sequences, Table 1's initialisations, Table 2's displaced keys, the §6.3 spline rails, the style
//! spread and generation speed.

use crate::dataset::{Behaviour, Dataset, BEHAVIOURS, DOWNSAMPLE};
use crate::infer::{cam_distance, key_vector, Cam, Chr, FastModel, Rollout, Scratch, StepIn};
use crate::model::{MAP_FRAMES, STYLE_STEPS};
use crate::toric::Lens;
use inbetween_core::curve::{Curve, Samples, Track};
use inbetween_io::Progress;
use inbetween_nn::runtime::LstmState;
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};
use std::time::Instant;

use super::tables::*;

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

/// An evaluation sequence at the network rate.
pub(super) struct EvalSeq {
    pub(super) behaviour: Behaviour,
    pub(super) main_is_a: bool,
    pub(super) chars: Vec<Chr>,
    pub(super) cams: Vec<Cam>,
}

pub(super) fn mean_err(a: &[Cam], b: &[Cam]) -> f64 {
    a.iter().zip(b).map(|(x, y)| cam_distance(x, y)).sum::<f64>() / a.len().max(1) as f64
}

/// Generates from the last of the five `context` steps (H's input) through `keys` (step indices
/// into `chars`, the last key last); returns all steps, the start first.
pub(super) fn roll(model: &FastModel, z: &[f32], context: &[Cam], chars: &[Chr], keys: &[(usize, Cam)]) -> Vec<Cam> {
    let frames: [Cam; MAP_FRAMES] = std::array::from_fn(|i| context[i]);
    Rollout::mapped(model, z, &frames).through_keys(chars, keys)
}

pub(super) fn style_of(model: &FastModel, chars: &[Chr], cams: &[Cam]) -> Vec<f32> {
    model.extract_style(chars, cams)
}

/// Bends `track` onto `keys` (index, value) by linearly blended residuals (Eq. 9).
pub(super) fn bend(track: &mut [Cam], keys: &[(usize, Cam)]) {
    let values = track.iter().map(|c| c.map(|v| v as f64)).collect();
    let Ok(samples) = Samples::new(0.0, 1.0, values) else { return };
    let k64: Vec<(f64, [f64; 6])> = keys.iter().map(|(i, c)| (*i as f64, c.map(|v| v as f64))).collect();
    let bent = samples.corrected_to_keys(&k64);
    for (i, d) in track.iter_mut().enumerate() {
        *d = bent.sample_clamped(i as f64).map(|v| v as f32);
    }
}

pub(super) fn table1(
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
pub(super) fn normal(rng: &mut ChaCha8Rng) -> f32 {
    inbetween_core::seed::normal(rng) as f32
}

/// θ displaced by δ with a random sign, kept inside the valid arc (the other sign when needed).
pub(super) fn displaced(key: &Cam, delta: f64, lens: &Lens, rng: &mut ChaCha8Rng) -> Cam {
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

pub(super) fn set_distance(u: &[Vec<f32>], v: &[Vec<f32>]) -> f64 {
    let mut total = 0.0;
    for a in u {
        for b in v {
            total += a.iter().zip(b).map(|(x, y)| ((x - y) as f64).powi(2)).sum::<f64>().sqrt();
        }
    }
    total / (u.len() * v.len()).max(1) as f64
}

/// SD (Eq. 8) averaged over behaviours.
pub(super) fn silhouette(pairs: &[(Behaviour, Vec<f32>, Vec<f32>)]) -> f64 {
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

pub(super) fn lerp_track(a: &Cam, b: &Cam, n: usize) -> Vec<Cam> {
    (0..=n).map(|t| std::array::from_fn(|k| a[k] + (b[k] - a[k]) * t as f32 / n as f32)).collect()
}

pub(super) fn table2(
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

pub(super) fn rails(
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
pub(super) fn style_spread(
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

pub(super) fn speed(model: &FastModel, seconds: f64) -> Speed {
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
pub(super) fn eval_sequences(seed: u64, scenes: usize) -> Vec<EvalSeq> {
    Dataset::generate(seed, scenes, crate::dataset::SCENE_FRAMES)
        .sequences
        .iter()
        .map(|s| {
            let (chars, cams) = s.encoded(DOWNSAMPLE);
            EvalSeq { behaviour: s.behaviour, main_is_a: s.main_is_a, chars, cams }
        })
        .collect()
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
