//! Inference: the trained networks copied into plain Rust (no autodiff, no allocation per step,
//! batched matrix-vector products), style codes, and keyframed generation with the beyond-the-paper
//! extras: exact keyframes by residual correction and a causal one-frame-at-a-time mode.

use crate::dataset::{Behaviour, Dataset, Scene, BEHAVIOURS, DOWNSAMPLE};
use crate::features::{decode_camera, encode_camera, encode_character, CharacterFeatures, CAM_DIM, CHAR_ENC};
use crate::model::{CameraModel, ModelConfig, MAP_FRAMES, STYLE_STEPS};
use crate::toric::{to_pose, CameraPose, Lens, Toric};
use crate::CameraError;
use burn::nn::Linear;
use burn::tensor::Tensor;
use inbetween_nn::lstm::FusedLstm;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// A fully connected layer `y = x W + b` with W stored `[in][out]` row-major (burn's layout).
#[derive(Debug, Clone)]
pub struct Dense {
    pub w: Vec<f32>,
    pub b: Vec<f32>,
    pub n_in: usize,
    pub n_out: usize,
}

fn tensor_values<const D: usize>(t: Tensor<D>) -> Vec<f32> {
    t.into_data().convert::<f32>().try_into_vec::<f32>().expect("f32 parameters")
}

impl Dense {
    pub fn from_linear(l: &Linear) -> Dense {
        let w = l.weight.val();
        let [n_in, n_out] = w.dims();
        let b = l.bias.as_ref().map_or(vec![0.0; n_out], |b| tensor_values(b.val()));
        Dense { w: tensor_values(w), b, n_in, n_out }
    }

    /// `y[r] = x[r] W + b` for `rows` rows; the weight row is reused across rows while it is hot.
    pub fn forward(&self, x: &[f32], y: &mut [f32], rows: usize) {
        let (ni, no) = (self.n_in, self.n_out);
        for r in 0..rows {
            y[r * no..(r + 1) * no].copy_from_slice(&self.b);
        }
        for i in 0..ni {
            let wrow = &self.w[i * no..(i + 1) * no];
            for r in 0..rows {
                let xi = x[r * ni + i];
                if xi == 0.0 {
                    continue;
                }
                let yr = &mut y[r * no..(r + 1) * no];
                for (yj, wj) in yr.iter_mut().zip(wrow) {
                    *yj += xi * wj;
                }
            }
        }
    }
}

/// (Leaky) ReLU in place: `slope` is the negative slope, 0 for the plain ReLU.
fn relu(v: &mut [f32], slope: f32) {
    for x in v {
        if *x < 0.0 {
            *x *= slope;
        }
    }
}

fn sigmoid(x: f32) -> f32 {
    1.0 / (1.0 + (-x).exp())
}

/// The fused LSTM cell of `inbetween_nn` (gates i, f, o, g over `[x, h]`).
#[derive(Debug, Clone)]
pub struct FastLstm {
    pub gates: Dense,
    pub hidden: usize,
}

/// Recurrent state for `rows` trajectories.
#[derive(Debug, Clone, PartialEq)]
pub struct State {
    pub h: Vec<f32>,
    pub c: Vec<f32>,
}

impl State {
    pub fn zeros(rows: usize, hidden: usize) -> State {
        State { h: vec![0.0; rows * hidden], c: vec![0.0; rows * hidden] }
    }
}

impl FastLstm {
    pub fn from_burn(l: &FusedLstm) -> FastLstm {
        FastLstm { gates: Dense::from_linear(&l.gates), hidden: l.d_hidden }
    }

    /// One step for `rows` trajectories: `x` is `[rows][d_in]`.
    pub fn step(&self, x: &[f32], state: &mut State, rows: usize) {
        let hd = self.hidden;
        let d_in = self.gates.n_in - hd;
        let mut xh = vec![0.0; rows * (d_in + hd)];
        for r in 0..rows {
            xh[r * (d_in + hd)..r * (d_in + hd) + d_in].copy_from_slice(&x[r * d_in..(r + 1) * d_in]);
            xh[r * (d_in + hd) + d_in..(r + 1) * (d_in + hd)].copy_from_slice(&state.h[r * hd..(r + 1) * hd]);
        }
        let mut z = vec![0.0; rows * 4 * hd];
        self.gates.forward(&xh, &mut z, rows);
        for r in 0..rows {
            let zr = &z[r * 4 * hd..(r + 1) * 4 * hd];
            for k in 0..hd {
                let (i, f, o, g) = (sigmoid(zr[k]), sigmoid(zr[hd + k]), sigmoid(zr[2 * hd + k]), zr[3 * hd + k].tanh());
                let c = f * state.c[r * hd + k] + i * g;
                state.c[r * hd + k] = c;
                state.h[r * hd + k] = o * c.tanh();
            }
        }
    }
}

/// The three trained networks in plain Rust.
#[derive(Debug, Clone)]
pub struct FastModel {
    pub config: ModelConfig,
    pub ext_lstm: FastLstm,
    pub ext_out: Dense,
    pub enc1: Dense,
    pub enc2: Dense,
    pub gen_lstm: FastLstm,
    pub dec1: Dense,
    pub dec2: Dense,
    pub map1: Dense,
    pub map2: Dense,
    /// z_tta for tta = 0..=tta_max frames (Eq. 4–5).
    tta_table: Vec<Vec<f32>>,
}

/// Everything one generator step reads besides the state, for one trajectory.
#[derive(Debug, Clone, Copy)]
pub struct StepIn<'a> {
    pub style: &'a [f32],
    pub prev: [f32; CAM_DIM],
    pub character: [f32; CHAR_ENC],
    pub key: [f32; CAM_DIM + CHAR_ENC],
    /// Frames to the next keyframe.
    pub tta_frames: usize,
}

impl FastModel {
    pub fn from_burn(model: &CameraModel, config: ModelConfig) -> FastModel {
        let tta = config.tta();
        let tta_table = (0..=config.tta_max as usize).map(|t| tta.values(t as f32)).collect();
        FastModel {
            config,
            ext_lstm: FastLstm::from_burn(&model.extractor.lstm),
            ext_out: Dense::from_linear(&model.extractor.out),
            enc1: Dense::from_linear(&model.generator.enc1),
            enc2: Dense::from_linear(&model.generator.enc2),
            gen_lstm: FastLstm::from_burn(&model.generator.lstm),
            dec1: Dense::from_linear(&model.generator.dec1),
            dec2: Dense::from_linear(&model.generator.dec2),
            map1: Dense::from_linear(&model.mapping.fc1),
            map2: Dense::from_linear(&model.mapping.fc2),
            tta_table,
        }
    }

    /// Loads weights saved by `train::save_model` (burnpack) with their JSON summary beside them.
    pub fn load(weights: &Path) -> Result<FastModel, CameraError> {
        let summary: crate::train::TrainSummary = crate::read_json(&weights.with_extension("json"))?;
        let device = inbetween_nn::backend::cpu();
        let model = crate::train::load_model(&summary.config.model, weights, &device)?;
        Ok(FastModel::from_burn(&model, summary.config.model))
    }

    /// The committed weights of this crate (`crates/camera/weights/camera.bpk`).
    pub fn committed_weights_path() -> std::path::PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("weights").join("camera.bpk")
    }

    /// The committed weights, compiled into the binary so tools and the demo run from anywhere.
    pub fn committed() -> Result<FastModel, CameraError> {
        const WEIGHTS: &[u8] = include_bytes!("../weights/camera.bpk");
        const SUMMARY: &str = include_str!("../weights/camera.json");
        let origin = Self::committed_weights_path();
        let summary: crate::train::TrainSummary = serde_json::from_str(SUMMARY)
            .map_err(|e| CameraError::Parse { path: origin.with_extension("json"), line: e.line(), column: e.column(), message: e.to_string() })?;
        let device = inbetween_nn::backend::cpu();
        let model = crate::train::load_model_bytes(&summary.config.model, WEIGHTS.to_vec(), &origin, &device)?;
        Ok(FastModel::from_burn(&model, summary.config.model))
    }

    /// Style code z of a reference clip (§4.1): `steps` are (encoded x^v, x^c) at the 5-frame rate;
    /// the extractor reads the last [`STYLE_STEPS`] of them.
    pub fn extract_style(&self, chars: &[[f32; CHAR_ENC]], cams: &[[f32; CAM_DIM]]) -> Vec<f32> {
        let n = chars.len().min(cams.len());
        let start = n.saturating_sub(STYLE_STEPS);
        let mut state = State::zeros(1, self.config.hidden);
        let mut x = [0.0; CHAR_ENC + CAM_DIM];
        for t in start..n {
            x[..CHAR_ENC].copy_from_slice(&chars[t]);
            x[CHAR_ENC..].copy_from_slice(&cams[t]);
            self.ext_lstm.step(&x, &mut state, 1);
        }
        let mut z = vec![0.0; self.config.style_dim];
        self.ext_out.forward(&state.h, &mut z, 1);
        z
    }

    /// Hidden-state mapping H (Eq. 6) for one trajectory.
    pub fn map_state(&self, style: &[f32], frames: &[[f32; CAM_DIM]; MAP_FRAMES]) -> State {
        let mut x = style.to_vec();
        for f in frames {
            x.extend_from_slice(f);
        }
        let hd = self.config.hidden;
        let mut y1 = vec![0.0; hd];
        self.map1.forward(&x, &mut y1, 1);
        relu(&mut y1, self.config.leaky_slope);
        let mut y2 = vec![0.0; 2 * hd];
        self.map2.forward(&y1, &mut y2, 1);
        State { h: y2[..hd].to_vec(), c: y2[hd..].to_vec() }
    }

    /// One generator step (Eq. 3) for `inputs.len()` trajectories in lockstep; `state` holds all rows.
    pub fn step(&self, inputs: &[StepIn], state: &mut State) -> Vec<[f32; CAM_DIM]> {
        let rows = inputs.len();
        let n_in = self.enc1.n_in;
        let hd = self.config.hidden;
        let mut x = Vec::with_capacity(rows * n_in);
        for s in inputs {
            x.extend_from_slice(s.style);
            x.extend_from_slice(&s.prev);
            x.extend_from_slice(&s.character);
            x.extend_from_slice(&s.key);
            x.extend_from_slice(&self.tta_table[s.tta_frames.min(self.tta_table.len() - 1)]);
        }
        let mut e1 = vec![0.0; rows * hd];
        self.enc1.forward(&x, &mut e1, rows);
        relu(&mut e1, self.config.leaky_slope);
        let mut e2 = vec![0.0; rows * hd];
        self.enc2.forward(&e1, &mut e2, rows);
        relu(&mut e2, self.config.leaky_slope);
        self.gen_lstm.step(&e2, state, rows);
        let mut d1 = vec![0.0; rows * hd];
        self.dec1.forward(&state.h, &mut d1, rows);
        relu(&mut d1, self.config.leaky_slope);
        let mut d2 = vec![0.0; rows * CAM_DIM];
        self.dec2.forward(&d1, &mut d2, rows);
        inputs
            .iter()
            .enumerate()
            .map(|(r, s)| {
                let w = self.config.arrival_weight(s.tta_frames as f32);
                std::array::from_fn(|k| s.prev[k] + w * (s.key[k] - s.prev[k]) + d2[r * CAM_DIM + k])
            })
            .collect()
    }

    /// Style codes of the dataset's behaviours: the mean z over seeded sequences (main = A or B).
    pub fn behaviour_styles(&self, seed: u64, scenes: usize) -> Vec<NamedStyle> {
        let data = Dataset::generate(seed, scenes, crate::dataset::SCENE_FRAMES);
        let mut out = Vec::new();
        for b in BEHAVIOURS {
            for main_is_a in [true, false] {
                let codes: Vec<Vec<f32>> = data
                    .sequences
                    .iter()
                    .filter(|s| s.behaviour == b && s.main_is_a == main_is_a)
                    .map(|s| {
                        let (c, x) = s.encoded(DOWNSAMPLE);
                        self.extract_style(&c[..STYLE_STEPS], &x[..STYLE_STEPS])
                    })
                    .collect();
                let mut mean = vec![0.0; self.config.style_dim];
                for z in &codes {
                    for (m, v) in mean.iter_mut().zip(z) {
                        *m += v / codes.len() as f32;
                    }
                }
                out.push(NamedStyle { behaviour: b, main_is_a, code: mean });
            }
        }
        out
    }
}

/// A style code named after the behaviour it was averaged from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NamedStyle {
    pub behaviour: Behaviour,
    pub main_is_a: bool,
    pub code: Vec<f32>,
}

/// One user keyframe.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Keyframe {
    pub frame: usize,
    pub camera: Toric,
    /// The two characters framed from the previous key up to this one (names or indices; default
    /// the first two). Changing them between keys is a character transition.
    #[serde(default)]
    pub targets: Option<[String; 2]>,
    /// Desired camera velocity at this key (x^c units per second): resets the generator's state
    /// through H (§4.3) so the camera leaves the key with this speed and direction.
    #[serde(default)]
    pub velocity: Option<[f64; 6]>,
}

/// The keyframes file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Keys {
    /// The main character (name or index; default the first target).
    #[serde(default)]
    pub main: Option<String>,
    pub keys: Vec<Keyframe>,
}

/// A key resolved against a scene.
#[derive(Debug, Clone)]
struct ResolvedKey {
    frame: usize,
    camera: Toric,
    pair: (usize, usize),
    velocity: Option<[f64; 6]>,
}

impl Keys {
    pub fn load(path: &Path) -> Result<Keys, CameraError> {
        crate::read_json(path)
    }

    /// Checks the keys against a scene and resolves target names; errors name the key.
    fn resolve(&self, scene: &Scene, lens: &Lens, origin: &Path) -> Result<(Vec<ResolvedKey>, Option<usize>), CameraError> {
        if self.keys.is_empty() {
            return Err(CameraError::invalid(origin, "expected at least one keyframe"));
        }
        let n = scene.num_frames();
        let find = |k: usize, name: &str| {
            scene.character_index(name).ok_or_else(|| {
                let names: Vec<&str> = scene.characters.iter().map(|c| c.name.as_str()).collect();
                CameraError::invalid(origin, format!("key {k}: unknown target `{name}` (characters: {})", names.join(", ")))
            })
        };
        let mut out: Vec<ResolvedKey> = Vec::new();
        for (k, key) in self.keys.iter().enumerate() {
            if key.frame >= n {
                return Err(CameraError::invalid(origin, format!("key {k}: frame {} is past the scene's last frame {}", key.frame, n - 1)));
            }
            if let Some(prev) = out.last() {
                if key.frame <= prev.frame {
                    return Err(CameraError::invalid(origin, format!("key {k}: frame {} does not come after frame {}", key.frame, prev.frame)));
                }
            }
            let pair = match &key.targets {
                Some([a, b]) => (find(k, a)?, find(k, b)?),
                None => (0, 1),
            };
            if pair.0 == pair.1 {
                return Err(CameraError::invalid(origin, format!("key {k}: both targets are the same character")));
            }
            let (a, b) = (scene.characters[pair.0].frame(key.frame).target(), scene.characters[pair.1].frame(key.frame).target());
            to_pose(&key.camera, a, b, lens).map_err(|e| CameraError::invalid(origin, format!("key {k}: camera: {e}")))?;
            out.push(ResolvedKey { frame: key.frame, camera: key.camera, pair, velocity: key.velocity });
        }
        let main = match &self.main {
            Some(m) => Some(find(usize::MAX, m).map_err(|_| CameraError::invalid(origin, format!("main: unknown character `{m}`")))?),
            None => None,
        };
        Ok((out, main))
    }
}

/// Options of [`generate`].
#[derive(Debug, Clone, Copy)]
pub struct GenerateOptions {
    /// Add the blended key residuals so every keyframe is hit exactly (beyond the paper).
    pub exact_keys: bool,
    pub lens: Lens,
    /// At a key with no user velocity, restart the generator through H from the motion arriving
    /// there (otherwise the LSTM state runs on from the arrival).
    pub remap_at_keys: bool,
}

impl Default for GenerateOptions {
    fn default() -> Self {
        GenerateOptions { exact_keys: true, lens: Lens::default(), remap_at_keys: true }
    }
}

/// One generated frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CameraFrame {
    pub frame: usize,
    pub toric: Toric,
    pub targets: [usize; 2],
    pub pose: CameraPose,
}

/// How far the network's own output missed a keyframe (before correction).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct KeyResidual {
    pub frame: usize,
    /// ‖x̂^c − x^c_K‖₂ in Toric units.
    pub residual: f64,
}

/// A generated camera track.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CameraTrack {
    pub fps: f64,
    pub style: String,
    pub style_code: Vec<f32>,
    pub lens: Lens,
    pub frames: Vec<CameraFrame>,
    pub key_residuals: Vec<KeyResidual>,
    /// Largest residual left after correction (0 up to rounding when `exact_keys`).
    pub max_corrected_residual: f64,
}

impl CameraTrack {
    pub fn toric(&self) -> Vec<Toric> {
        self.frames.iter().map(|f| f.toric).collect()
    }
}

/// Catmull-Rom fill of values sampled every `step` frames (the last sample may be closer) to
/// every frame (§4.5 "filled with cubic interpolation").
pub fn cubic_fill(samples: &[(usize, [f64; 6])]) -> Vec<[f64; 6]> {
    let (first, last) = (samples[0].0, samples[samples.len() - 1].0);
    let mut out = Vec::with_capacity(last - first + 1);
    for s in 0..samples.len().saturating_sub(1) {
        let (f0, x0) = samples[s];
        let (f1, x1) = samples[s + 1];
        let h = (f1 - f0) as f64;
        let slope = |i: usize| -> [f64; 6] {
            let (fa, xa) = samples[i.saturating_sub(1)];
            let (fb, xb) = samples[(i + 1).min(samples.len() - 1)];
            let dt = (fb - fa).max(1) as f64;
            std::array::from_fn(|k| (xb[k] - xa[k]) / dt)
        };
        let (v0, v1) = (slope(s), slope(s + 1));
        for f in f0..f1 {
            let u = (f - f0) as f64 / h;
            out.push(std::array::from_fn(|k| inbetween_core::interp::hermite(x0[k], v0[k], x1[k], v1[k], h, u)));
        }
    }
    out.push(samples[samples.len() - 1].1);
    out
}

/// Adds to each frame the residuals of its two surrounding keys, blended linearly (Eq. 9), so the
/// track passes through every key; keys are frame offsets into `track`.
pub fn correct_to_keys(track: &mut [[f64; 6]], keys: &[(usize, [f64; 6])]) {
    let res: Vec<(usize, [f64; 6])> = keys.iter().map(|&(f, k)| (f, std::array::from_fn(|i| k[i] - track[f][i]))).collect();
    for (f, x) in track.iter_mut().enumerate() {
        let j = res.partition_point(|&(kf, _)| kf <= f);
        let add: [f64; 6] = match (j.checked_sub(1).map(|i| res[i]), res.get(j)) {
            (Some((fa, ra)), Some(&(fb, rb))) => {
                let l = (f - fa) as f64 / (fb - fa) as f64;
                std::array::from_fn(|i| (1.0 - l) * ra[i] + l * rb[i])
            }
            (Some((_, r)), None) | (None, Some(&(_, r))) => r,
            (None, None) => [0.0; 6],
        };
        for i in 0..6 {
            x[i] += add[i];
        }
    }
}

/// H's input for the motion arriving at a key: the last [`MAP_FRAMES`] network steps of a non-empty
/// `history` (x^c every 5th frame), padded at the front with its first step when it is shorter.
pub(crate) fn arriving_frames(history: &[[f32; CAM_DIM]]) -> [[f32; CAM_DIM]; MAP_FRAMES] {
    std::array::from_fn(|i| history[(history.len() + i).saturating_sub(MAP_FRAMES)])
}

/// Generates the camera between the first and last keyframe (to the scene's end with a single key)
/// with style code `style`: the network runs every 5th frame (§4.5), cubic fill in between, keys
/// snapped to that grid for the network and then hit exactly by correction.
pub fn generate(model: &FastModel, scene: &Scene, keys: &Keys, style: &[f32], style_name: &str, opts: &GenerateOptions, origin: &Path) -> Result<CameraTrack, CameraError> {
    let lens = opts.lens;
    let (keys, main) = keys.resolve(scene, &lens, origin)?;
    let first = keys[0].frame;
    let last = if keys.len() == 1 { scene.num_frames() - 1 } else { keys[keys.len() - 1].frame };
    let grid = |f: usize| first + ((f - first) as f64 / DOWNSAMPLE as f64).round() as usize * DOWNSAMPLE;
    let enc_char = |f: usize, pair: (usize, usize)| -> [f32; CHAR_ENC] {
        let main_is_a = main.is_none_or(|m| m == pair.0);
        let (a, b) = (scene.characters[pair.0].frame(f), scene.characters[pair.1].frame(f));
        encode_character(&CharacterFeatures::compute(&a, &b, main_is_a))
    };
    let key_of = |k: &ResolvedKey| -> [f32; CAM_DIM + CHAR_ENC] {
        let mut v = [0.0; CAM_DIM + CHAR_ENC];
        v[..CAM_DIM].copy_from_slice(&encode_camera(&k.camera));
        v[CAM_DIM..].copy_from_slice(&enc_char(k.frame, k.pair));
        v
    };
    let start = encode_camera(&keys[0].camera);
    let map_frames = |k: &ResolvedKey| -> [[f32; CAM_DIM]; MAP_FRAMES] {
        let v = k.velocity.unwrap_or([0.0; 6]);
        let dt = DOWNSAMPLE as f64 / scene.fps;
        std::array::from_fn(|i| {
            let back = (MAP_FRAMES - 1 - i) as f64 * dt;
            std::array::from_fn(|j| (k.camera.to_array()[j] - v[j] * back) as f32)
        })
    };
    let mut state = model.map_state(style, &map_frames(&keys[0]));
    let mut prev = start;
    let mut history: Vec<[f32; CAM_DIM]> = map_frames(&keys[0]).to_vec();
    let mut samples: Vec<(usize, [f64; 6])> = vec![(first, keys[0].camera.to_array())];
    let mut pairs: Vec<(usize, (usize, usize))> = vec![(first, keys[0].pair)];
    let mut residuals = vec![KeyResidual { frame: first, residual: 0.0 }];
    // With a single key the camera runs free to the end, aiming at that key forever (tta capped).
    let targets: Vec<&ResolvedKey> = if keys.len() == 1 { vec![&keys[0]] } else { keys[1..].iter().collect() };
    let mut f = first;
    for (ti, target) in targets.iter().enumerate() {
        let end = if keys.len() == 1 { last - (last - first) % DOWNSAMPLE } else { grid(target.frame).max(f + DOWNSAMPLE) };
        let kv = key_of(target);
        pairs.push((f + 1, target.pair));
        while f + DOWNSAMPLE <= end {
            f += DOWNSAMPLE;
            let tta_frames = if keys.len() == 1 { model.config.tta_max as usize } else { end - f };
            let input = StepIn { style, prev, character: enc_char(f.min(last), target.pair), key: kv, tta_frames };
            prev = model.step(&[input], &mut state)[0];
            history.push(prev);
            samples.push((f.min(last), decode_camera(&prev).to_array()));
        }
        if keys.len() > 1 {
            let hit = samples.last().expect("samples").1;
            let resid = (0..6).map(|i| (hit[i] - target.camera.to_array()[i]).powi(2)).sum::<f64>().sqrt();
            residuals.push(KeyResidual { frame: target.frame, residual: resid });
            // The key frame itself carries the network's value; exact correction moves it onto the key.
            let lastf = samples.len() - 1;
            samples[lastf].0 = target.frame.min(last).max(samples[lastf.saturating_sub(1)].0 + 1);
            if ti + 1 < targets.len() {
                if target.velocity.is_some() {
                    state = model.map_state(style, &map_frames(target));
                    prev = encode_camera(&target.camera);
                } else if opts.remap_at_keys {
                    // Training starts every segment from H, never from a state that has just arrived
                    // at a key (tta = 0); re-mapping the motion that arrives keeps the camera moving
                    // through the key instead of stopping and starting again.
                    state = model.map_state(style, &arriving_frames(&history));
                }
            }
        }
    }
    samples.dedup_by_key(|s| s.0);
    let mut track = cubic_fill(&samples);
    let key_offsets: Vec<(usize, [f64; 6])> =
        keys.iter().filter(|k| k.frame <= last).map(|k| (k.frame - first, k.camera.to_array())).collect();
    if opts.exact_keys {
        correct_to_keys(&mut track, &key_offsets);
    }
    let max_corrected_residual = key_offsets
        .iter()
        .map(|(o, k)| (0..6).map(|i| (track[*o][i] - k[i]).powi(2)).sum::<f64>().sqrt())
        .fold(0.0, f64::max);
    let mut frames = Vec::with_capacity(track.len());
    for (o, x) in track.iter().enumerate() {
        let frame = first + o;
        let pair = pairs.iter().rev().find(|(from, _)| *from <= frame).map_or(keys[0].pair, |p| p.1);
        let (a, b) = (scene.characters[pair.0].frame(frame).target(), scene.characters[pair.1].frame(frame).target());
        let toric = Toric::from_array(*x).clamped(&lens, 0.02);
        let pose = to_pose(&toric, a, b, &lens).map_err(|e| CameraError::Model(format!("frame {frame}: {e}")))?;
        frames.push(CameraFrame { frame, toric, targets: [pair.0, pair.1], pose });
    }
    Ok(CameraTrack {
        fps: scene.fps,
        style: style_name.to_string(),
        style_code: style.to_vec(),
        lens,
        frames,
        key_residuals: residuals,
        max_corrected_residual,
    })
}

/// A reference clip for style extraction: Eq. 1 and Eq. 2 features per frame (30 fps). A dataset
/// [`crate::dataset::Sequence`] file is one.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ReferenceClip {
    pub characters: Vec<CharacterFeatures>,
    pub camera: Vec<Toric>,
}

impl ReferenceClip {
    /// Style code of the clip; needs at least 50 frames (300 recommended, §4.5).
    pub fn style(&self, model: &FastModel, origin: &Path) -> Result<Vec<f32>, CameraError> {
        let n = self.characters.len().min(self.camera.len());
        if n < DOWNSAMPLE * 10 {
            return Err(CameraError::invalid(origin, format!("reference clip has {n} frames; at least {} are needed (300 recommended)", DOWNSAMPLE * 10)));
        }
        let chars: Vec<_> = (0..n).step_by(DOWNSAMPLE).map(|i| encode_character(&self.characters[i])).collect();
        let cams: Vec<_> = (0..n).step_by(DOWNSAMPLE).map(|i| encode_camera(&self.camera[i])).collect();
        Ok(model.extract_style(&chars, &cams))
    }
}

/// Keyframes taken from a relative-track filming of `scene` at `frames` (a plausible start to edit).
pub fn example_keys(scene: &Scene, frames: &[usize]) -> Keys {
    use rand::SeedableRng;
    let lens = Lens::default();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
    let params = crate::dataset::BehaviourParams::sample(&mut rng);
    let track = crate::dataset::film(scene, 0, 1, true, Behaviour::Relative, &params, &lens);
    Keys {
        main: Some(scene.characters[0].name.clone()),
        keys: frames.iter().map(|&f| Keyframe { frame: f, camera: track[f], targets: None, velocity: None }).collect(),
    }
}

/// Causal, one-frame-at-a-time generation for live use (beyond the paper): character features
/// arrive frame by frame and a camera comes back at once. The network runs on every 5th frame with
/// the features of that frame; frames in between extrapolate the last network step linearly, so
/// nothing waits for the future. Keys (placed ahead by the user) can be set at any time.
pub struct CausalCamera<'a> {
    model: &'a FastModel,
    style: Vec<f32>,
    state: State,
    frame: usize,
    last: [f32; CAM_DIM],
    velocity: [f32; CAM_DIM],
    key: Option<(usize, [f32; CAM_DIM + CHAR_ENC])>,
    /// The last [`MAP_FRAMES`] network steps, H's input when the next key is announced.
    recent: [[f32; CAM_DIM]; MAP_FRAMES],
}

impl<'a> CausalCamera<'a> {
    /// Starts at `start` (frame 0) with an optional velocity (x^c per second) through H.
    pub fn new(model: &'a FastModel, style: &[f32], start: &Toric, velocity: Option<[f64; 6]>, fps: f64) -> CausalCamera<'a> {
        let v = velocity.unwrap_or([0.0; 6]);
        let dt = DOWNSAMPLE as f64 / fps;
        let frames: [[f32; CAM_DIM]; MAP_FRAMES] = std::array::from_fn(|i| {
            let back = (MAP_FRAMES - 1 - i) as f64 * dt;
            std::array::from_fn(|j| (start.to_array()[j] - v[j] * back) as f32)
        });
        CausalCamera {
            model,
            style: style.to_vec(),
            state: model.map_state(style, &frames),
            frame: 0,
            last: encode_camera(start),
            velocity: std::array::from_fn(|j| (v[j] * dt) as f32),
            key: None,
            recent: frames,
        }
    }

    /// The next keyframe: its frame, camera and the character features expected there. Replacing a
    /// key restarts the generator through H from the motion so far, as `generate` does at its keys.
    pub fn set_key(&mut self, frame: usize, camera: &Toric, character: &CharacterFeatures) {
        if self.key.is_some() {
            self.state = self.model.map_state(&self.style, &self.recent);
        }
        let mut v = [0.0; CAM_DIM + CHAR_ENC];
        v[..CAM_DIM].copy_from_slice(&encode_camera(camera));
        v[CAM_DIM..].copy_from_slice(&encode_character(character));
        self.key = Some((frame, v));
    }

    /// Consumes the next frame's character features and returns that frame's camera.
    pub fn push(&mut self, character: &CharacterFeatures) -> Toric {
        self.frame += 1;
        let phase = self.frame % DOWNSAMPLE;
        if phase == 0 {
            let cap = self.model.config.tta_max as usize;
            let (tta_frames, key) = match self.key {
                Some((kf, v)) if kf >= self.frame => ((kf - self.frame).min(cap), v),
                Some((_, v)) => (0, v),
                None => {
                    let mut v = [0.0; CAM_DIM + CHAR_ENC];
                    v[..CAM_DIM].copy_from_slice(&self.last);
                    v[CAM_DIM..].copy_from_slice(&encode_character(character));
                    (cap, v)
                }
            };
            let input = StepIn { style: &self.style, prev: self.last, character: encode_character(character), key, tta_frames };
            let next = self.model.step(&[input], &mut self.state)[0];
            self.velocity = std::array::from_fn(|j| next[j] - self.last[j]);
            self.last = next;
            self.recent.rotate_left(1);
            self.recent[MAP_FRAMES - 1] = next;
            return decode_camera(&next);
        }
        let u = phase as f32 / DOWNSAMPLE as f32;
        decode_camera(&std::array::from_fn::<f32, CAM_DIM, _>(|j| self.last[j] + self.velocity[j] * u))
    }
}

/// A whole track through [`CausalCamera`]: frame by frame, each key announced once the previous one
/// has passed, no correction (a live camera cannot go back). Key residuals report the misses.
pub fn generate_causal(model: &FastModel, scene: &Scene, keys: &Keys, style: &[f32], style_name: &str, lens: &Lens, origin: &Path) -> Result<CameraTrack, CameraError> {
    let (keys, main) = keys.resolve(scene, lens, origin)?;
    let first = keys[0].frame;
    let last = if keys.len() == 1 { scene.num_frames() - 1 } else { keys[keys.len() - 1].frame };
    let feats = |f: usize, pair: (usize, usize)| {
        let main_is_a = main.is_none_or(|m| m == pair.0);
        CharacterFeatures::compute(&scene.characters[pair.0].frame(f), &scene.characters[pair.1].frame(f), main_is_a)
    };
    let mut live = CausalCamera::new(model, style, &keys[0].camera, keys[0].velocity, scene.fps);
    let mut next = 1;
    let mut frames = Vec::with_capacity(last - first + 1);
    let mut residuals = vec![KeyResidual { frame: first, residual: 0.0 }];
    let mut toric = keys[0].camera;
    for frame in first..=last {
        let target = keys.get(next).unwrap_or(&keys[keys.len() - 1]);
        if frame > first {
            // The live clock counts from the first key.
            if let Some(k) = keys.get(next) {
                live.set_key(k.frame - first, &k.camera, &feats(k.frame, k.pair));
            }
            toric = live.push(&feats(frame, target.pair));
        }
        if let Some(k) = keys.get(next) {
            if k.frame == frame {
                let r = (0..6).map(|i| (toric.to_array()[i] - k.camera.to_array()[i]).powi(2)).sum::<f64>().sqrt();
                residuals.push(KeyResidual { frame, residual: r });
                next += 1;
            }
        }
        let pair = target.pair;
        let (a, b) = (scene.characters[pair.0].frame(frame).target(), scene.characters[pair.1].frame(frame).target());
        let t = toric.clamped(lens, 0.02);
        let pose = to_pose(&t, a, b, lens).map_err(|e| CameraError::Model(format!("frame {frame}: {e}")))?;
        frames.push(CameraFrame { frame, toric: t, targets: [pair.0, pair.1], pose });
    }
    let max_corrected_residual = residuals.iter().map(|r| r.residual).fold(0.0, f64::max);
    Ok(CameraTrack { fps: scene.fps, style: style_name.to_string(), style_code: style.to_vec(), lens: *lens, frames, key_residuals: residuals, max_corrected_residual })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::generator::StepInput;
    use crate::train::rows;
    use glam::DVec3;

    fn small() -> (CameraModel, FastModel) {
        let device = inbetween_nn::backend::cpu();
        inbetween_nn::backend::seed(&device, 4);
        let cfg = ModelConfig { hidden: 16, tta_dim: 8, ..ModelConfig::default() };
        let model = cfg.init(&device);
        let fast = FastModel::from_burn(&model, cfg);
        (model, fast)
    }

    #[test]
    fn plain_rust_step_matches_burn() {
        let (model, fast) = small();
        let device = inbetween_nn::backend::cpu();
        let style = [0.3f32, -0.2, 0.1, 0.5];
        let prev = [-0.3f32, 0.1, 0.3, 0.1, 1.4, 0.2];
        let character = [0.4f32, 0.1, 0.99, -0.2, 0.98, 0.0, -1.0, 1.0];
        let key: [f32; 14] = std::array::from_fn(|i| (i as f32 * 0.37).sin());
        let frames = [prev; MAP_FRAMES];
        let mut state = fast.map_state(&style, &frames);
        let out = fast.step(&[StepIn { style: &style, prev, character, key, tta_frames: 35 }], &mut state)[0];

        let flat: Vec<f32> = frames.iter().flatten().copied().collect();
        let st = model.mapping.forward(rows(style.to_vec(), 4, &device), rows(flat, 30, &device));
        let tta = rows(fast.config.tta().values(35.0), fast.config.tta_dim, &device);
        let input = StepInput {
            style: rows(style.to_vec(), 4, &device),
            prev_camera: rows(prev.to_vec(), 6, &device),
            character: rows(character.to_vec(), 8, &device),
            key: rows(key.to_vec(), 14, &device),
            tta,
            arrival: rows(vec![fast.config.arrival_weight(35.0)], 1, &device),
        };
        let (cam, _) = model.generator.step(input, Some(st));
        let burn_out: Vec<f32> = cam.into_data().try_into_vec::<f32>().unwrap();
        for (a, b) in out.iter().zip(&burn_out) {
            assert!((a - b).abs() < 1e-5, "{out:?} vs {burn_out:?}");
        }
    }

    #[test]
    fn generation_hits_keys_exactly_and_reports_the_network_miss() {
        let (_, fast) = small();
        let scene = Scene::procedural(2, 200, 30.0);
        let keys = example_keys(&scene, &[0, 97, 199]);
        let track = generate(&fast, &scene, &keys, &[0.0; 4], "test", &GenerateOptions::default(), Path::new("k.json")).unwrap();
        assert_eq!(track.frames.len(), 200);
        assert_eq!(track.key_residuals.len(), 3);
        assert!(track.max_corrected_residual < 1e-9, "{}", track.max_corrected_residual);
        for k in &keys.keys {
            let got = track.frames[k.frame].toric.to_array();
            let want = k.camera.to_array();
            assert!((0..6).all(|i| (got[i] - want[i]).abs() < 1e-9), "key at {}", k.frame);
        }
        // Same inputs, same track.
        let again = generate(&fast, &scene, &keys, &[0.0; 4], "test", &GenerateOptions::default(), Path::new("k.json")).unwrap();
        assert_eq!(again, track);
    }

    #[test]
    fn per_key_targets_switch_the_framed_pair() {
        let (_, fast) = small();
        let scene = Scene::procedural(4, 120, 30.0);
        let mut keys = example_keys(&scene, &[0, 60, 119]);
        // Second segment frames the pair the other way round: a transition at frame 60.
        let lens = Lens::default();
        let (a, b) = (scene.characters[1].frame(119).target(), scene.characters[0].frame(119).target());
        let pose = CameraPose::look_at((a + b) * 0.5 + DVec3::new(0.0, 1.0, 0.0) + (b - a).cross(DVec3::Y).normalize() * 4.0, (a + b) * 0.5);
        keys.keys[2].camera = crate::toric::from_pose(&pose, a, b, &lens).unwrap();
        keys.keys[2].targets = Some(["B".into(), "A".into()]);
        let track = generate(&fast, &scene, &keys, &[0.0; 4], "t", &GenerateOptions::default(), Path::new("k")).unwrap();
        assert_eq!(track.frames[30].targets, [0, 1]);
        assert_eq!(track.frames[90].targets, [1, 0]);
        let end = &track.frames[119];
        assert!((end.pose.position - pose.position).length() < 1e-6, "the transition key is met in world space too");
    }

    #[test]
    fn bad_keys_are_clear_errors() {
        let (_, fast) = small();
        let scene = Scene::procedural(2, 100, 30.0);
        let mut keys = example_keys(&scene, &[0, 50]);
        keys.keys[1].frame = 150;
        let e = generate(&fast, &scene, &keys, &[0.0; 4], "t", &GenerateOptions::default(), Path::new("keys.json")).unwrap_err().to_string();
        assert!(e.contains("keys.json") && e.contains("key 1") && e.contains("frame 150"), "{e}");
        let mut keys = example_keys(&scene, &[0, 50]);
        keys.keys[0].targets = Some(["A".into(), "Zed".into()]);
        let e = generate(&fast, &scene, &keys, &[0.0; 4], "t", &GenerateOptions::default(), Path::new("keys.json")).unwrap_err().to_string();
        assert!(e.contains("key 0") && e.contains("Zed"), "{e}");
    }

    #[test]
    fn causal_mode_runs_the_network_every_fifth_frame_without_lookahead() {
        let (_, fast) = small();
        let scene = Scene::procedural(6, 60, 30.0);
        let feats = scene.character_features(0, 1, true);
        let keys = example_keys(&scene, &[0, 59]);
        let style = [0.1f32, 0.0, -0.2, 0.3];
        let mut live = CausalCamera::new(&fast, &style, &keys.keys[0].camera, None, 30.0);
        live.set_key(59, &keys.keys[1].camera, &feats[59]);
        let out: Vec<Toric> = (1..60).map(|f| live.push(&feats[f])).collect();
        // The same steps by hand.
        let mut state = fast.map_state(&style, &[encode_camera(&keys.keys[0].camera); MAP_FRAMES]);
        let mut prev = encode_camera(&keys.keys[0].camera);
        let mut key = [0.0; 14];
        key[..6].copy_from_slice(&encode_camera(&keys.keys[1].camera));
        key[6..].copy_from_slice(&encode_character(&feats[59]));
        for f in (5..60).step_by(5) {
            let input = StepIn { style: &style, prev, character: encode_character(&feats[f]), key, tta_frames: 59 - f };
            prev = fast.step(&[input], &mut state)[0];
            let got = encode_camera(&out[f - 1]);
            assert!((0..6).all(|j| (got[j] - prev[j]).abs() < 1e-6), "frame {f}");
        }
        assert!(out.iter().all(|t| t.theta.is_finite()));
    }

    #[test]
    fn causal_mode_restarts_through_h_from_its_last_steps_when_the_next_key_is_announced() {
        let (_, fast) = small();
        let scene = Scene::procedural(6, 60, 30.0);
        let feats = scene.character_features(0, 1, true);
        let keys = example_keys(&scene, &[0, 30, 59]);
        let style = [0.1f32, 0.0, -0.2, 0.3];
        let mut live = CausalCamera::new(&fast, &style, &keys.keys[0].camera, None, 30.0);
        live.set_key(30, &keys.keys[1].camera, &feats[30]);
        let out: Vec<Toric> = (1..=30).map(|f| live.push(&feats[f])).collect();
        let steps: [[f32; CAM_DIM]; MAP_FRAMES] = std::array::from_fn(|i| encode_camera(&out[10 + 5 * i - 1]));
        live.set_key(59, &keys.keys[2].camera, &feats[59]);
        let expected = fast.map_state(&style, &steps);
        let close = |a: &[f32], b: &[f32]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-5);
        assert!(close(&live.state.h, &expected.h) && close(&live.state.c, &expected.c), "H re-mapped the last five network steps");
    }

    #[test]
    fn velocity_at_a_key_changes_the_departure() {
        let (_, fast) = small();
        let scene = Scene::procedural(2, 120, 30.0);
        let keys = example_keys(&scene, &[0, 119]);
        let mut fast_start = keys.clone();
        fast_start.keys[0].velocity = Some([0.0, 0.0, 0.0, 0.0, 1.5, 0.0]);
        let o = GenerateOptions::default();
        let a = generate(&fast, &scene, &keys, &[0.0; 4], "t", &o, Path::new("k")).unwrap();
        let b = generate(&fast, &scene, &fast_start, &[0.0; 4], "t", &o, Path::new("k")).unwrap();
        assert_ne!(a.frames[10].toric, b.frames[10].toric, "H sees the velocity");
        assert_eq!(b.frames[0].toric, keys.keys[0].camera, "the key itself stays put");
    }

    #[test]
    fn committed_weights_load_and_hit_keys_closely() {
        let model = FastModel::committed().unwrap();
        assert_eq!(model.config.hidden, 256);
        let scene = Scene::procedural(3, 300, 30.0);
        let keys = example_keys(&scene, &[0, 150, 299]);
        let styles = model.behaviour_styles(777, 1);
        let opts = GenerateOptions { exact_keys: false, ..Default::default() };
        let track = generate(&model, &scene, &keys, &styles[2].code, "relative", &opts, Path::new("k")).unwrap();
        // The network alone (no correction) lands near its keys: the straight-line base reaches
        // the key at tta 0 and the trained correction must not throw it off.
        let worst = track.key_residuals.iter().map(|r| r.residual).fold(0.0, f64::max);
        assert!(worst < 0.3, "network key miss {worst}");
    }

    #[test]
    fn an_interior_key_restarts_the_generator_from_the_motion_arriving_there() {
        let model = FastModel::committed().unwrap();
        let scene = Scene::procedural(3, 300, 30.0);
        let keys = example_keys(&scene, &[0, 150, 299]);
        let orbit = &model.behaviour_styles(777, 1)[3].code;
        let run = |remap_at_keys| {
            let opts = GenerateOptions { exact_keys: false, remap_at_keys, ..Default::default() };
            generate(&model, &scene, &keys, orbit, "orbit", &opts, Path::new("k")).unwrap()
        };
        let (remapped, ran_on) = (run(true), run(false));
        // Up to the middle key nothing differs; after it only the state differs, and it must matter.
        assert_eq!(remapped.frames[..=145], ran_on.frames[..=145]);
        let after = |t: &CameraTrack| t.frames[200].toric.to_array();
        let moved = (0..6).map(|i| (after(&remapped)[i] - after(&ran_on)[i]).abs()).fold(0.0, f64::max);
        assert!(moved > 1e-4, "H's restart changes the second segment (by {moved})");
        let worst = remapped.key_residuals.iter().map(|r| r.residual).fold(0.0, f64::max);
        assert!(worst < 0.3, "the restarted segment still lands near its key: miss {worst}");
    }

    #[test]
    fn arriving_frames_are_the_last_five_steps_padded_at_the_front() {
        let steps: Vec<[f32; CAM_DIM]> = (0..7).map(|i| [i as f32; CAM_DIM]).collect();
        let firsts = |h: &[[f32; CAM_DIM]]| arriving_frames(h).map(|x| x[0]);
        assert_eq!(firsts(&steps), [2.0, 3.0, 4.0, 5.0, 6.0]);
        assert_eq!(firsts(&steps[..2]), [0.0, 0.0, 0.0, 0.0, 1.0]);
    }

    #[test]
    fn cubic_fill_passes_through_samples() {
        let samples: Vec<(usize, [f64; 6])> = (0..5).map(|i| (i * 5, [i as f64; 6])).collect();
        let filled = cubic_fill(&samples);
        assert_eq!(filled.len(), 21);
        for (f, x) in &samples {
            assert!((filled[*f][0] - x[0]).abs() < 1e-12);
        }
        assert!((filled[7][0] - 1.4).abs() < 1e-9, "linear data stays linear");
    }
}
