//! One trajectory of the generator (§4.2–4.3), stepped at the network rate (every 5th frame):
//! the autoregressive loop x^c_i = G(z, x^c_{i−1}, x^v_i, K, tta, h_{i−1}) with its LSTM state,
//! restarted through H (Eq. 6) at keys. Offline generation ([`super::GenerateJob`]), the causal
//! mode ([`super::CausalCamera`]), the bench and the diagnostics all step through this one type.

use super::networks::{FastModel, Scratch, StepIn};
use super::{key_vector, Cam, Chr, KeyVec};
use crate::dataset::DOWNSAMPLE;
use crate::model::MAP_FRAMES;
use inbetween_nn::runtime::LstmState;

/// The generator running along one trajectory: state, last output, the last [`MAP_FRAMES`]
/// outputs (H's input when it restarts) and the step buffers, so a step allocates nothing.
#[derive(Debug, Clone)]
pub struct Rollout<'m> {
    model: &'m FastModel,
    style: Vec<f32>,
    state: LstmState,
    prev: Cam,
    recent: [Cam; MAP_FRAMES],
    scratch: Scratch,
}

impl<'m> Rollout<'m> {
    /// Starts on the last of `frames` with the state H maps from style code `style` and `frames`
    /// (Eq. 6): the camera leaves with the motion those five steps show.
    pub fn mapped(model: &'m FastModel, style: &[f32], frames: &[Cam; MAP_FRAMES]) -> Rollout<'m> {
        let mut r = Rollout::with_state(model, style, LstmState::zeros(1, model.config.hidden), frames[MAP_FRAMES - 1]);
        r.restart_from(frames);
        r
    }

    /// Starts at `start` with a given state (Table 1's zero, Gaussian and warm-start rows).
    pub fn with_state(model: &'m FastModel, style: &[f32], state: LstmState, start: Cam) -> Rollout<'m> {
        Rollout {
            model,
            style: style.to_vec(),
            state,
            prev: start,
            recent: [start; MAP_FRAMES],
            scratch: Scratch::for_rows(model, 1),
        }
    }

    /// One network step: the camera `tta_frames` frames before key `key`, with the characters
    /// `character` at this step. Returns (and remembers) the new x^c.
    pub fn step(&mut self, character: &Chr, key: &KeyVec, tta_frames: usize) -> Cam {
        let input = StepIn { style: &self.style, prev: self.prev, character: *character, key: *key, tta_frames };
        let next = self.model.step_into(&[input], &mut self.state, &mut self.scratch)[0];
        self.prev = next;
        self.recent.rotate_left(1);
        self.recent[MAP_FRAMES - 1] = next;
        next
    }

    /// Restarts the state through H from the motion arriving here (the last five steps). Training
    /// starts every segment from H, never from a state that has just arrived at a key (tta = 0),
    /// so at an interior key this keeps the camera moving through it instead of stopping.
    pub fn restart_from_arrival(&mut self) {
        let frames = self.recent;
        self.model.map_state_into(&self.style, &frames, &mut self.state, &mut self.scratch);
    }

    /// Restarts through H from `frames` and continues from their last step (a key given with a
    /// velocity, see [`super::velocity_frames`]).
    pub fn restart_from(&mut self, frames: &[Cam; MAP_FRAMES]) {
        self.model.map_state_into(&self.style, frames, &mut self.state, &mut self.scratch);
        self.recent = *frames;
        self.prev = frames[MAP_FRAMES - 1];
    }

    /// Replaces the previous output (teacher forcing: the warm start reads ground truth).
    pub fn set_prev(&mut self, prev: Cam) {
        self.prev = prev;
    }

    /// Steps `1..=last` from the current camera (step 0) through keys at step indices (the last
    /// key at `last`); `chars[t]` are the characters at step t. At each interior key the state
    /// restarts from the arriving motion. Returns all `last + 1` steps, step 0 first.
    pub fn through_keys(&mut self, chars: &[Chr], keys: &[(usize, Cam)]) -> Vec<Cam> {
        let last = keys.last().map_or(0, |k| k.0);
        let mut out = Vec::with_capacity(last + 1);
        out.push(self.prev);
        let mut next_key = 0;
        for t in 1..=last {
            while keys[next_key].0 < t {
                next_key += 1;
            }
            let (ki, kc) = keys[next_key];
            out.push(self.step(&chars[t], &key_vector(&kc, &chars[ki]), (ki - t) * DOWNSAMPLE));
            if t == ki && t < last {
                self.restart_from_arrival();
            }
        }
        out
    }

    pub fn prev(&self) -> Cam {
        self.prev
    }

    pub fn state(&self) -> &LstmState {
        &self.state
    }

    /// The step buffers (the last step's layer outputs, for diagnostics).
    pub fn scratch(&self) -> &Scratch {
        &self.scratch
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tiny() -> FastModel {
        crate::infer::test_model(8, 6)
    }

    #[test]
    fn restart_from_arrival_maps_the_last_five_steps() {
        let m = tiny();
        let z = [0.1f32, -0.1, 0.2, 0.0];
        let mut r = Rollout::mapped(&m, &z, &[[0.0, 0.0, 0.1, 0.0, 1.5, 0.2]; MAP_FRAMES]);
        let key = key_vector(&[0.3, 0.0, 0.4, 0.1, 2.0, 0.1], &[0.5; 8]);
        let outs: Vec<Cam> = (0..7).map(|t| r.step(&[0.4; 8], &key, 60 - 5 * t)).collect();
        r.restart_from_arrival();
        let want = m.map_state(&z, &std::array::from_fn(|i| outs[2 + i]));
        assert_eq!(r.state(), &want);
        assert_eq!(r.prev(), outs[6], "a restart keeps the camera where it is");
    }

    #[test]
    fn through_keys_equals_stepping_by_hand() {
        let m = tiny();
        let z = [0.0f32, 0.3, 0.0, -0.2];
        let start: Cam = [0.0, 0.0, 0.1, 0.0, 1.5, 0.2];
        let chars: Vec<Chr> = (0..9).map(|t| [t as f32 * 0.1; 8]).collect();
        let keys = [(4, [0.1, 0.0, 0.2, 0.0, 1.7, 0.2]), (8, [0.2, 0.1, 0.3, 0.0, 1.9, 0.1])];
        let all = Rollout::mapped(&m, &z, &[start; MAP_FRAMES]).through_keys(&chars, &keys);
        assert_eq!(all.len(), 9);
        let mut r = Rollout::mapped(&m, &z, &[start; MAP_FRAMES]);
        for t in 1..=8 {
            let (ki, kc) = if t <= 4 { keys[0] } else { keys[1] };
            assert_eq!(r.step(&chars[t], &key_vector(&kc, &chars[ki]), (ki - t) * DOWNSAMPLE), all[t], "step {t}");
            if t == 4 {
                r.restart_from_arrival();
            }
        }
    }
}
