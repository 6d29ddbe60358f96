//! Head motion and eye gaze.
//!
//! - **Head**: `HeadYaw/Pitch/Roll` as a sum of a few random slow sinusoids (0.05–0.6 Hz) — small,
//!   smooth noise. (The real Live Link captures have all-zero head columns, so the amplitudes are
//!   plausible values, not calibrated ones.)
//! - **Gaze**: fixations held 0.3 s plus an exponential time, then a saccade (30–60 ms, smooth) to a new
//!   target; targets and the resting pitch follow the real captures (eye yaw std 0.11 rad, pitch mean
//!   −0.06 rad, std 0.09; positive yaw looks to the subject's right, positive pitch down). A slight
//!   vergence and fixation jitter make the two eyes differ.
//! - **EyeLook shapes** follow the eye angles with the gains fitted on the real captures (shape ≈ gain ×
//!   angle, radians): `EyeLookInLeft` 1.75 × yaw⁺, `EyeLookOutLeft` 1.5 × yaw⁻, `EyeLookOutRight`
//!   1.75 × yaw⁺, `EyeLookInRight` 1.65 × yaw⁻, `EyeLookDown*` 1.65 × pitch⁺, `EyeLookUp*` 2.35 × pitch⁻.

use super::random::Rand;
use inbetween_core::interp::smoothstep;

/// Look-shape gains per radian (see module docs).
pub const GAIN_IN_LEFT: f64 = 1.75;
pub const GAIN_OUT_LEFT: f64 = 1.5;
pub const GAIN_OUT_RIGHT: f64 = 1.75;
pub const GAIN_IN_RIGHT: f64 = 1.65;
pub const GAIN_DOWN: f64 = 1.65;
pub const GAIN_UP: f64 = 2.35;

/// Resting eye pitch (rad; negative looks up) and gaze spread of the real captures.
const PITCH_REST: f64 = -0.06;
const YAW_STD: f64 = 0.11;
const PITCH_STD: f64 = 0.07;

/// Head angles (yaw, pitch, roll) at each of `times`, scaled by `amount` (1 = default amplitude,
/// about 0.05 rad).
pub fn head(rng: &mut Rand, times: &[f64], amount: f64) -> Vec<[f32; 3]> {
    let mut waves = [[(0.0f64, 0.0f64, 0.0f64); 3]; 3]; // per axis: (amplitude, frequency, phase)
    let scale = [0.05, 0.035, 0.025];
    for (axis, w) in waves.iter_mut().enumerate() {
        for wave in w.iter_mut() {
            *wave = (
                amount * scale[axis] * rng.range(0.3, 1.0),
                rng.range(0.05, 0.6),
                rng.range(0.0, std::f64::consts::TAU),
            );
        }
    }
    let offset = [0.02 * rng.normal(), 0.02 * rng.normal(), 0.01 * rng.normal()];
    times
        .iter()
        .map(|&t| {
            let mut a = [0.0f32; 3];
            for axis in 0..3 {
                let v: f64 =
                    waves[axis].iter().map(|(amp, f, ph)| amp * (std::f64::consts::TAU * f * t + ph).sin()).sum();
                a[axis] = (v + amount * offset[axis]) as f32;
            }
            a
        })
        .collect()
}

/// Eye angles per frame: `[left yaw, left pitch, left roll, right yaw, right pitch, right roll]`.
pub fn eyes(rng: &mut Rand, times: &[f64]) -> Vec<[f32; 6]> {
    let Some(&end) = times.last() else { return Vec::new() };
    // Fixation sequence: (saccade start, saccade duration, yaw, pitch).
    let target = |rng: &mut Rand| {
        let yaw = (YAW_STD * rng.normal()).clamp(-0.35, 0.35);
        let pitch = (PITCH_REST + PITCH_STD * rng.normal()).clamp(-0.3, 0.3);
        (yaw, pitch)
    };
    let mut fixations = vec![(f64::NEG_INFINITY, 0.04, target(rng))];
    let mut t = rng.range(0.0, 1.0);
    while t <= end {
        fixations.push((t, rng.range(0.03, 0.06), target(rng)));
        t += 0.3 + rng.exp(1.0);
    }
    let vergence = rng.range(0.0, 0.03);
    let roll = (0.01 * rng.normal(), 0.01 * rng.normal());
    let mut jitter = [0.0f64; 4];
    let mut k = 0usize;
    times
        .iter()
        .map(|&t| {
            while k + 1 < fixations.len() && fixations[k + 1].0 <= t {
                k += 1;
            }
            let (start, dur, (yaw, pitch)) = fixations[k];
            let (pyaw, ppitch) = if k > 0 { fixations[k - 1].2 } else { (yaw, pitch) };
            let s = smoothstep((t - start) / dur);
            let (y, p) = (pyaw + (yaw - pyaw) * s, ppitch + (pitch - ppitch) * s);
            for j in &mut jitter {
                *j = 0.7 * *j + 0.004 * rng.normal();
            }
            [
                (y + vergence + jitter[0]) as f32,
                (p + jitter[1]) as f32,
                roll.0 as f32,
                (y - vergence + jitter[2]) as f32,
                (p + jitter[3]) as f32,
                roll.1 as f32,
            ]
        })
        .collect()
}

/// The eight `EyeLook*` weights of one frame from its eye angles, in the order
/// `[DownLeft, InLeft, OutLeft, UpLeft, DownRight, InRight, OutRight, UpRight]`.
pub fn look_shapes(e: &[f32; 6]) -> [f32; 8] {
    let (ly, lp, ry, rp) = (e[0] as f64, e[1] as f64, e[3] as f64, e[4] as f64);
    [
        GAIN_DOWN * lp.max(0.0),
        GAIN_IN_LEFT * ly.max(0.0),
        GAIN_OUT_LEFT * (-ly).max(0.0),
        GAIN_UP * (-lp).max(0.0),
        GAIN_DOWN * rp.max(0.0),
        GAIN_IN_RIGHT * (-ry).max(0.0),
        GAIN_OUT_RIGHT * ry.max(0.0),
        GAIN_UP * (-rp).max(0.0),
    ]
    .map(|x| x.clamp(0.0, 1.0) as f32)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn look_shapes_follow_the_angles() {
        // Looking to the subject's right and down: left eye in, right eye out, both down.
        let s = look_shapes(&[0.2, 0.1, 0.0, 0.2, 0.1, 0.0]);
        assert!(s[1] > 0.3 && s[6] > 0.3 && s[2] == 0.0 && s[5] == 0.0);
        assert!(s[0] > 0.1 && s[4] > 0.1 && s[3] == 0.0 && s[7] == 0.0);
    }

    #[test]
    fn gaze_holds_then_jumps() {
        let times: Vec<f64> = (0..1500).map(|i| i as f64 / 25.0).collect();
        let e = eyes(&mut Rand::new(2, 0), &times);
        let big_steps = e.windows(2).filter(|w| (w[1][0] - w[0][0]).abs() > 0.05).count();
        let still = e.windows(2).filter(|w| (w[1][0] - w[0][0]).abs() < 0.02).count();
        assert!(big_steps > 10 && still > 1000, "{big_steps} saccade frames, {still} fixation frames");
        let h = head(&mut Rand::new(2, 1), &times, 1.0);
        assert!(h.iter().all(|a| a.iter().all(|x| x.abs() < 0.3)));
    }
}
