//! The three trained networks of §4 in plain Rust ([`inbetween_nn::runtime`] layers: no autodiff,
//! checked equal to burn, no allocation per step): the extractor's style code (§4.1), the mapping
//! H (Eq. 6) and the generator step (Eq. 3, with our arrival-base residual).

use super::{Cam, KeyVec};
use crate::features::{CAM_DIM, CHAR_ENC};
use crate::model::{CameraModel, ModelConfig, MAP_FRAMES, STYLE_STEPS};
use inbetween_nn::runtime::{leaky_relu, Dense, Lstm, LstmScratch, LstmState};

/// The three trained networks in plain Rust.
#[derive(Debug, Clone)]
pub struct FastModel {
    pub config: ModelConfig,
    pub ext_lstm: Lstm,
    pub ext_out: Dense,
    pub enc1: Dense,
    pub enc2: Dense,
    pub gen_lstm: Lstm,
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
    /// x^c_{i−1}.
    pub prev: Cam,
    /// Encoded x^v_i.
    pub character: [f32; CHAR_ENC],
    /// K: the next key's x^c and encoded x^v ([`super::key_vector`]).
    pub key: KeyVec,
    /// Frames to the next keyframe.
    pub tta_frames: usize,
}

/// The buffers of [`FastModel::step_into`] and [`FastModel::map_state_into`]: they grow to the
/// largest batch seen and are reused, so steps after the first allocate nothing.
#[derive(Debug, Clone, Default)]
pub struct Scratch {
    x: Vec<f32>,
    e1: Vec<f32>,
    e2: Vec<f32>,
    d1: Vec<f32>,
    d2: Vec<f32>,
    lstm: LstmScratch,
    out: Vec<Cam>,
}

impl Scratch {
    /// Buffers sized for `rows` trajectories of `model`.
    pub fn for_rows(model: &FastModel, rows: usize) -> Scratch {
        let mut s = Scratch { lstm: LstmScratch::for_rows(&model.gen_lstm, rows), ..Scratch::default() };
        s.reserve(model, rows);
        s
    }

    fn reserve(&mut self, model: &FastModel, rows: usize) {
        let hd = model.config.hidden;
        let grow = |v: &mut Vec<f32>, n: usize| {
            if v.len() < n {
                v.resize(n, 0.0);
            }
        };
        grow(&mut self.x, rows * model.enc1.n_in.max(model.map1.n_in));
        grow(&mut self.e1, rows * hd);
        grow(&mut self.e2, rows * hd.max(model.map2.n_out));
        grow(&mut self.d1, rows * hd);
        grow(&mut self.d2, rows * CAM_DIM);
        if self.out.len() < rows {
            self.out.resize(rows, [0.0; CAM_DIM]);
        }
    }

    /// The last step's layer outputs for row 0 after activation: (enc1, enc2, dec1, the decoder's
    /// correction Δ). For diagnostics (`examples/activations.rs`).
    pub fn layers(&self, model: &FastModel) -> (&[f32], &[f32], &[f32], &[f32]) {
        let hd = model.config.hidden;
        (&self.e1[..hd], &self.e2[..hd], &self.d1[..hd], &self.d2[..CAM_DIM])
    }
}

impl FastModel {
    pub fn from_burn(model: &CameraModel, config: ModelConfig) -> FastModel {
        let tta = config.tta();
        let tta_table = (0..=config.tta_max as usize).map(|t| tta.values(t as f32)).collect();
        FastModel {
            config,
            ext_lstm: Lstm::from_fused(&model.extractor.lstm),
            ext_out: Dense::from_linear(&model.extractor.out),
            enc1: Dense::from_linear(&model.generator.enc1),
            enc2: Dense::from_linear(&model.generator.enc2),
            gen_lstm: Lstm::from_fused(&model.generator.lstm),
            dec1: Dense::from_linear(&model.generator.dec1),
            dec2: Dense::from_linear(&model.generator.dec2),
            map1: Dense::from_linear(&model.mapping.fc1),
            map2: Dense::from_linear(&model.mapping.fc2),
            tta_table,
        }
    }

    /// Style code z of a reference clip (§4.1): `chars` and `cams` are encoded x^v and x^c at the
    /// 5-frame rate; the extractor reads the last [`STYLE_STEPS`] of them.
    pub fn extract_style(&self, chars: &[[f32; CHAR_ENC]], cams: &[Cam]) -> Vec<f32> {
        let n = chars.len().min(cams.len());
        let start = n.saturating_sub(STYLE_STEPS);
        let mut state = LstmState::zeros(1, self.config.hidden);
        let mut scratch = LstmScratch::for_rows(&self.ext_lstm, 1);
        let mut x = [0.0; CHAR_ENC + CAM_DIM];
        for t in start..n {
            x[..CHAR_ENC].copy_from_slice(&chars[t]);
            x[CHAR_ENC..].copy_from_slice(&cams[t]);
            self.ext_lstm.step(&x, &mut state, 1, &mut scratch);
        }
        let mut z = vec![0.0; self.config.style_dim];
        self.ext_out.forward(&state.h, &mut z, 1);
        z
    }

    /// Hidden-state mapping H (Eq. 6) for one trajectory: (h, c) from z and five x^c steps.
    pub fn map_state(&self, style: &[f32], frames: &[Cam; MAP_FRAMES]) -> LstmState {
        let mut state = LstmState::zeros(1, self.config.hidden);
        self.map_state_into(style, frames, &mut state, &mut Scratch::default());
        state
    }

    /// [`FastModel::map_state`] into an existing one-row state, without allocating once `scratch`
    /// has its size.
    pub fn map_state_into(
        &self,
        style: &[f32],
        frames: &[Cam; MAP_FRAMES],
        state: &mut LstmState,
        scratch: &mut Scratch,
    ) {
        scratch.reserve(self, 1);
        let hd = self.config.hidden;
        let sd = style.len();
        let x = &mut scratch.x[..sd + MAP_FRAMES * CAM_DIM];
        x[..sd].copy_from_slice(style);
        for (i, f) in frames.iter().enumerate() {
            x[sd + i * CAM_DIM..sd + (i + 1) * CAM_DIM].copy_from_slice(f);
        }
        let y1 = &mut scratch.e1[..hd];
        self.map1.forward(x, y1, 1);
        leaky_relu(y1, self.config.leaky_slope);
        let y2 = &mut scratch.e2[..2 * hd];
        self.map2.forward(y1, y2, 1);
        state.h[..hd].copy_from_slice(&y2[..hd]);
        state.c[..hd].copy_from_slice(&y2[hd..]);
    }

    /// One generator step (Eq. 3) for `inputs.len()` trajectories in lockstep; `state` holds all
    /// rows. x^c_i = x^c_{i−1} + w·(x^c_K − x^c_{i−1}) + Δ (w: [`ModelConfig::arrival_weight`]).
    /// Returns the new x^c per row, borrowed from `scratch`; allocates nothing once `scratch` has
    /// its size.
    pub fn step_into<'s>(&self, inputs: &[StepIn], state: &mut LstmState, scratch: &'s mut Scratch) -> &'s [Cam] {
        let rows = inputs.len();
        scratch.reserve(self, rows);
        let (n_in, hd, slope) = (self.enc1.n_in, self.config.hidden, self.config.leaky_slope);
        let x = &mut scratch.x[..rows * n_in];
        for (r, s) in inputs.iter().enumerate() {
            let tta = &self.tta_table[s.tta_frames.min(self.tta_table.len() - 1)];
            let mut o = r * n_in;
            for part in [s.style, &s.prev[..], &s.character[..], &s.key[..], &tta[..]] {
                x[o..o + part.len()].copy_from_slice(part);
                o += part.len();
            }
        }
        let e1 = &mut scratch.e1[..rows * hd];
        self.enc1.forward(x, e1, rows);
        leaky_relu(e1, slope);
        let e2 = &mut scratch.e2[..rows * hd];
        self.enc2.forward(e1, e2, rows);
        leaky_relu(e2, slope);
        self.gen_lstm.step(e2, state, rows, &mut scratch.lstm);
        let d1 = &mut scratch.d1[..rows * hd];
        self.dec1.forward(&state.h, d1, rows);
        leaky_relu(d1, slope);
        let d2 = &mut scratch.d2[..rows * CAM_DIM];
        self.dec2.forward(d1, d2, rows);
        for (r, s) in inputs.iter().enumerate() {
            let w = self.config.arrival_weight(s.tta_frames as f32);
            scratch.out[r] = std::array::from_fn(|k| s.prev[k] + w * (s.key[k] - s.prev[k]) + d2[r * CAM_DIM + k]);
        }
        &scratch.out[..rows]
    }

    /// [`FastModel::step_into`] with fresh buffers (tests, one-off calls).
    pub fn step(&self, inputs: &[StepIn], state: &mut LstmState) -> Vec<Cam> {
        self.step_into(inputs, state, &mut Scratch::default()).to_vec()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::generator::StepInput;
    use crate::train::rows;

    #[test]
    fn plain_rust_step_matches_burn() {
        let device = inbetween_nn::backend::cpu();
        let cfg = ModelConfig { hidden: 16, tta_dim: 8, ..ModelConfig::default() };
        let model = inbetween_nn::backend::seeded_module(&device, 4, |d| cfg.init(d));
        let fast = FastModel::from_burn(&model, cfg);
        let style = [0.3f32, -0.2, 0.1, 0.5];
        let prev = [-0.3f32, 0.1, 0.3, 0.1, 1.4, 0.2];
        let character = [0.4f32, 0.1, 0.99, -0.2, 0.98, 0.0, -1.0, 1.0];
        let key: KeyVec = std::array::from_fn(|i| (i as f32 * 0.37).sin());
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
    fn batched_rows_equal_single_rows() {
        let device = inbetween_nn::backend::cpu();
        let cfg = ModelConfig { hidden: 16, tta_dim: 8, ..ModelConfig::default() };
        let fast = FastModel::from_burn(&inbetween_nn::backend::seeded_module(&device, 5, |d| cfg.init(d)), cfg);
        let style = [0.1f32, 0.2, -0.3, 0.0];
        let input = |i: usize| StepIn {
            style: &style,
            prev: [i as f32 * 0.1; 6],
            character: [0.5; 8],
            key: [0.2; 14],
            tta_frames: 10 * i,
        };
        let inputs = [input(0), input(1), input(2)];
        let mut batched = LstmState::zeros(3, 16);
        let together = fast.step(&inputs, &mut batched);
        for (r, inp) in inputs.iter().enumerate() {
            let mut one = LstmState::zeros(1, 16);
            assert_eq!(fast.step(&[*inp], &mut one)[0], together[r], "row {r}");
        }
    }
}
