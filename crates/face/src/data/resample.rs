//! Resampling to the model rate and back: linear interpolation per channel.
//!
//! The paper resamples every animation to 25 fps (§4.1, the rate of B3D(AC)²) before training and
//! editing; an edited clip goes back to the capture's own frame times with [`BlendshapeClip::resample_at`].

use super::clip::BlendshapeClip;
use crate::error::FaceError;

/// The model's frame rate (paper §4.1: 25 fps).
pub const MODEL_FPS: f64 = 25.0;

impl BlendshapeClip {
    /// Resamples onto a uniform grid `t0 + k / fps` (`t0` the first frame time) covering the clip
    /// (the last grid time is at or before the last frame, within 1e-9 s), linear per channel. The
    /// result's nominal rate is `fps`.
    pub fn resample(&self, fps: f64) -> Result<BlendshapeClip, FaceError> {
        if !(fps.is_finite() && fps > 0.0) {
            return Err(FaceError::Invalid(format!("resampling rate must be a positive number, got {fps}")));
        }
        let t0 = self.times()[0];
        let steps = (self.duration() * fps + 1e-9).floor();
        if steps > 1e8 {
            return Err(FaceError::Invalid(format!(
                "resampling {} s at {fps} fps gives more than 1e8 frames",
                self.duration()
            )));
        }
        let times: Vec<f64> = (0..=steps as usize).map(|k| t0 + k as f64 / fps).collect();
        self.resample_at(&times, fps)
    }

    /// Samples the clip at the given times (strictly increasing; outside the clip the first or last
    /// frame is held), linear per channel; the result's nominal rate is `fps`. With the original
    /// times this takes a resampled clip back to the capture's frames.
    pub fn resample_at(&self, times: &[f64], fps: f64) -> Result<BlendshapeClip, FaceError> {
        let n = self.num_channels();
        let mut values = Vec::with_capacity(times.len() * n);
        let src = self.times();
        let mut seg = 0usize; // src[seg] <= t < src[seg + 1] for the current t, when inside
        for &t in times {
            if !t.is_finite() {
                return Err(FaceError::Invalid(format!("sample time {t} is not a finite number")));
            }
            if t <= src[0] {
                values.extend_from_slice(self.frame(0));
                continue;
            }
            if t >= src[src.len() - 1] {
                values.extend_from_slice(self.frame(src.len() - 1));
                continue;
            }
            if src[seg] > t {
                seg = 0; // times not increasing: the constructor below reports it; stay correct meanwhile
            }
            while src[seg + 1] <= t {
                seg += 1;
            }
            let w = ((t - src[seg]) / (src[seg + 1] - src[seg])) as f32;
            let (a, b) = (self.frame(seg), self.frame(seg + 1));
            values.extend(a.iter().zip(b).map(|(x, y)| x + (y - x) * w));
        }
        BlendshapeClip::new(fps, times.to_vec(), self.has_head_eye(), self.extra_names().to_vec(), values)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// Channel c: 0.5 + 0.4 sin(2π (0.5 + 0.1 c) t); extra channel "lin": 2t + 1.
    fn analytic(times: &[f64]) -> BlendshapeClip {
        let f = |c: usize, t: f64| 0.5 + 0.4 * (2.0 * PI * (0.5 + 0.1 * c as f64) * t).sin();
        let mut values = Vec::new();
        for &t in times {
            for c in 0..52 {
                values.push(f(c, t) as f32);
            }
            values.push((2.0 * t + 1.0) as f32);
        }
        BlendshapeClip::new(60.0, times.to_vec(), false, vec!["lin".into()], values).unwrap()
    }

    #[test]
    fn to_model_rate_and_back_matches_the_analytic_curve() {
        let src_times: Vec<f64> = (0..=600).map(|k| 1.5 + k as f64 / 60.0).collect(); // 10 s at 60 fps
        let clip = analytic(&src_times);
        let low = clip.resample(MODEL_FPS).unwrap();
        assert_eq!(low.num_frames(), 251);
        assert_eq!(low.fps(), 25.0);
        assert!((low.times()[250] - 11.5).abs() < 1e-9);
        let exact = analytic(low.times());
        // Linear interpolation error ≤ h²/8 · max|f''| = (1/60)²/8 · 0.4 (2π·5.6)² ≈ 0.0069 for the
        // fastest channel (5.6 Hz); the slowest (0.5 Hz) ≈ 5.5e-5. f32 rounding adds ~1e-7.
        for c in 0..52 {
            let w = 2.0 * PI * (0.5 + 0.1 * c as f64);
            let bound = (1.0 / 60.0f64).powi(2) / 8.0 * 0.4 * w * w + 1e-6;
            let err =
                low.channel(c).iter().zip(exact.channel(c)).map(|(a, b)| (a - b).abs() as f64).fold(0.0, f64::max);
            assert!(err <= bound, "channel {c}: error {err} > bound {bound}");
        }
        // A linear channel is reproduced exactly (to f32).
        for (a, b) in low.channel(52).iter().zip(exact.channel(52)) {
            assert!((a - b).abs() < 2e-6, "{a} vs {b}");
        }
        // And back to the 60 fps times: the error is bounded by the 25 fps interpolation error.
        let back = low.resample_at(clip.times(), 60.0).unwrap();
        assert_eq!(back.times(), clip.times());
        for c in [0usize, 10, 51] {
            let w = 2.0 * PI * (0.5 + 0.1 * c as f64);
            let bound = 2.0 * (1.0 / 25.0f64).powi(2) / 8.0 * 0.4 * w * w + 1e-6;
            let err =
                back.channel(c).iter().zip(clip.channel(c)).map(|(a, b)| (a - b).abs() as f64).fold(0.0, f64::max);
            assert!(err <= bound, "channel {c}: round-trip error {err} > bound {bound}");
        }
        for (a, b) in back.channel(52).iter().zip(clip.channel(52)) {
            assert!((a - b).abs() < 4e-6);
        }
    }

    #[test]
    fn edges_and_arguments() {
        let one = analytic(&[2.0]);
        let r = one.resample(25.0).unwrap();
        assert_eq!(r.num_frames(), 1);
        assert_eq!(r.values(), one.values());
        let clip = analytic(&[0.0, 0.1, 0.3]);
        let r = clip.resample_at(&[-1.0, 0.0, 0.05, 0.2, 0.3, 9.0], 10.0).unwrap();
        assert_eq!(r.frame(0), clip.frame(0));
        assert_eq!(r.frame(5), clip.frame(2));
        assert!((r.channel(52)[2] - 1.1).abs() < 1e-6);
        assert!((r.channel(52)[3] - 1.4).abs() < 1e-6);
        assert!(clip.resample(0.0).is_err());
        assert!(clip.resample(f64::NAN).is_err());
        assert!(clip.resample(1e12).is_err());
        assert!(clip.resample_at(&[0.2, 0.1], 10.0).is_err());
        assert!(clip.resample_at(&[f64::NAN], 10.0).is_err());
        // Non-uniform source times (NeuroSync's millisecond timecodes) interpolate per segment.
        let r = clip.resample(20.0).unwrap();
        assert_eq!(r.num_frames(), 7);
        assert!((r.channel(52)[5] - 1.5).abs() < 1e-6);
    }
}
