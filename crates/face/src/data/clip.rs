//! [`BlendshapeClip`]: blendshape curves sampled at (not necessarily uniform) frame times.

use super::names::{arkit_index, head_eye_index, ARKIT_NAMES, HEAD_EYE_NAMES, NUM_ARKIT, NUM_HEAD_EYE};
use crate::error::FaceError;

/// Blendshape curves: per frame, the 52 ARKit weights in [`ARKIT_NAMES`] order, then the 9 head/eye
/// rotations in [`HEAD_EYE_NAMES`] order when present, then extra channels kept by name (the NeuroSync
/// emotion columns, or any column of a curve file).
///
/// Invariants (checked by [`BlendshapeClip::new`]): at least one frame; times finite and strictly
/// increasing (seconds; a Live Link Face clip keeps its timecode, e.g. 53882.7 s for 14:58:02); every
/// value finite; extra names non-empty, unique, distinct from the ARKit and head/eye names
/// (case-insensitively) and free of `,`, `"`, control characters and leading/trailing spaces, so every
/// clip can be written as CSV. `fps` is the nominal rate (60 for Live Link Face, the resampling rate
/// after [`Self::resample`]); the times are authoritative, see [`Self::measured_fps`].
#[derive(Clone, Debug, PartialEq)]
pub struct BlendshapeClip {
    fps: f64,
    times: Vec<f64>,
    head_eye: bool,
    extras: Vec<String>,
    /// Frame-major: `values[f * stride + c]`.
    values: Vec<f32>,
}

impl BlendshapeClip {
    /// A clip of ARKit frames at the model's rate ([`super::MODEL_FPS`], times from 0): what the
    /// networks and the generators produce. Panics on no frame or a non-finite weight.
    pub fn from_model_frames(frames: &[[f32; NUM_ARKIT]]) -> Self {
        let fps = super::MODEL_FPS;
        let times = (0..frames.len()).map(|f| f as f64 / fps).collect();
        Self::new(fps, times, false, vec![], frames.iter().flatten().copied().collect())
            .expect("frames make a valid clip")
    }

    /// Builds a clip from frame-major values (`times.len() * num_channels` of them, channels in the
    /// layout above) and checks every invariant.
    pub fn new(
        fps: f64,
        times: Vec<f64>,
        head_eye: bool,
        extras: Vec<String>,
        values: Vec<f32>,
    ) -> Result<Self, FaceError> {
        let invalid = |m: String| Err(FaceError::clip(m));
        if !(fps.is_finite() && fps > 0.0) {
            return invalid(format!("fps must be a positive number, got {fps}"));
        }
        if times.is_empty() {
            return invalid("a clip needs at least one frame".into());
        }
        for (i, t) in times.iter().enumerate() {
            if !t.is_finite() {
                return invalid(format!("time of frame {i} is {t}; expected a finite number of seconds"));
            }
            if i > 0 && *t <= times[i - 1] {
                return invalid(format!(
                    "time of frame {i} ({t} s) is not after frame {} ({} s); expected strictly increasing times",
                    i - 1,
                    times[i - 1]
                ));
            }
        }
        for (i, name) in extras.iter().enumerate() {
            if let Some(problem) = extra_name_problem(name) {
                return invalid(format!("extra channel {i} {name:?}: {problem}"));
            }
            if extras[..i].iter().any(|n| n.eq_ignore_ascii_case(name)) {
                return invalid(format!("extra channel {name:?} appears twice"));
            }
        }
        let stride = NUM_ARKIT + if head_eye { NUM_HEAD_EYE } else { 0 } + extras.len();
        if values.len() != times.len() * stride {
            return invalid(format!(
                "{} values for {} frames × {stride} channels; expected {}",
                values.len(),
                times.len(),
                times.len() * stride
            ));
        }
        if let Some(i) = values.iter().position(|v| !v.is_finite()) {
            return invalid(format!(
                "value of frame {}, channel {} is {}; expected a finite number",
                i / stride,
                i % stride,
                values[i]
            ));
        }
        Ok(BlendshapeClip { fps, times, head_eye, extras, values })
    }

    /// Builds a clip from named channels in any order (ARKit and head/eye names case-insensitive).
    /// All 52 ARKit channels are required; head/eye all nine or none; other names become extras in the
    /// order given.
    pub fn from_named(fps: f64, times: Vec<f64>, channels: Vec<(String, Vec<f32>)>) -> Result<Self, FaceError> {
        let names: Vec<&str> = channels.iter().map(|(n, _)| n.as_str()).collect();
        let layout = Layout::from_names(&names, |_| true).map_err(|(_, m)| FaceError::clip(m))?;
        let n = times.len();
        for (name, v) in &channels {
            if v.len() != n {
                return Err(FaceError::clip(format!(
                    "channel {name:?} has {} values; expected {n} (one per time)",
                    v.len()
                )));
            }
        }
        let stride = layout.stride();
        let mut values = vec![0.0f32; n * stride];
        for (c, (_, v)) in channels.iter().enumerate() {
            let slot = layout.slot[c];
            for (f, x) in v.iter().enumerate() {
                values[f * stride + slot] = *x;
            }
        }
        BlendshapeClip::new(fps, times, layout.head_eye, layout.extras, values)
    }

    /// Nominal frame rate (frames per second).
    pub fn fps(&self) -> f64 {
        self.fps
    }

    /// Sets the nominal frame rate (the times are unchanged).
    pub fn set_fps(&mut self, fps: f64) -> Result<(), FaceError> {
        if !(fps.is_finite() && fps > 0.0) {
            return Err(FaceError::clip(format!("fps must be a positive number, got {fps}")));
        }
        self.fps = fps;
        Ok(())
    }

    /// Frame times in seconds, strictly increasing.
    pub fn times(&self) -> &[f64] {
        &self.times
    }

    /// Number of frames.
    pub fn num_frames(&self) -> usize {
        self.times.len()
    }

    /// Channels per frame: 52, plus 9 with head/eye, plus the extras.
    pub fn num_channels(&self) -> usize {
        NUM_ARKIT + if self.head_eye { NUM_HEAD_EYE } else { 0 } + self.extras.len()
    }

    /// Whether the 9 head/eye rotation channels are present.
    pub fn has_head_eye(&self) -> bool {
        self.head_eye
    }

    /// Names of the extra channels, in channel order.
    pub fn extra_names(&self) -> &[String] {
        &self.extras
    }

    /// All channel names in channel order.
    pub fn channel_names(&self) -> Vec<&str> {
        let mut v: Vec<&str> = ARKIT_NAMES.to_vec();
        if self.head_eye {
            v.extend(HEAD_EYE_NAMES);
        }
        v.extend(self.extras.iter().map(String::as_str));
        v
    }

    /// Channel index of a name (case-insensitive).
    pub fn channel_index(&self, name: &str) -> Option<usize> {
        if let Some(i) = arkit_index(name) {
            return Some(i);
        }
        if let Some(i) = head_eye_index(name) {
            return self.head_eye.then_some(NUM_ARKIT + i);
        }
        let base = NUM_ARKIT + if self.head_eye { NUM_HEAD_EYE } else { 0 };
        self.extras.iter().position(|n| n.eq_ignore_ascii_case(name)).map(|i| base + i)
    }

    /// All values of one frame, in channel order.
    pub fn frame(&self, f: usize) -> &[f32] {
        let s = self.num_channels();
        &self.values[f * s..(f + 1) * s]
    }

    /// The 52 ARKit weights of one frame.
    pub fn arkit(&self, f: usize) -> &[f32] {
        &self.frame(f)[..NUM_ARKIT]
    }

    /// The 52 ARKit weights of every frame.
    pub fn arkit_frames(&self) -> Vec<[f32; NUM_ARKIT]> {
        (0..self.num_frames()).map(|f| self.arkit(f).try_into().expect("52 ARKit values")).collect()
    }

    /// The 9 head/eye rotations of one frame, when present.
    pub fn head_eye(&self, f: usize) -> Option<&[f32]> {
        self.head_eye.then(|| &self.frame(f)[NUM_ARKIT..NUM_ARKIT + NUM_HEAD_EYE])
    }

    /// One channel over time.
    pub fn channel(&self, c: usize) -> Vec<f32> {
        let s = self.num_channels();
        (0..self.num_frames()).map(|f| self.values[f * s + c]).collect()
    }

    /// All values, frame-major (`values()[f * num_channels() + c]`).
    pub fn values(&self) -> &[f32] {
        &self.values
    }

    /// Duration from the first to the last frame, in seconds.
    pub fn duration(&self) -> f64 {
        self.times[self.times.len() - 1] - self.times[0]
    }

    /// Frames per second measured from the times: `(frames − 1) / duration` (the nominal `fps` for a
    /// single frame). The Live Link Face captures measure 59.904 fps against a nominal 60.
    pub fn measured_fps(&self) -> f64 {
        if self.times.len() < 2 {
            self.fps
        } else {
            (self.times.len() - 1) as f64 / self.duration()
        }
    }
}

/// Why a name cannot be an extra channel, if it cannot.
fn extra_name_problem(name: &str) -> Option<&'static str> {
    if name.is_empty() {
        Some("empty name")
    } else if name.trim() != name {
        Some("leading or trailing spaces")
    } else if name.chars().any(|c| c == ',' || c == '"' || c.is_control()) {
        Some("contains ',', '\"' or a control character")
    } else if name.starts_with('#') {
        Some("starts with '#'")
    } else if arkit_index(name).is_some() || head_eye_index(name).is_some() {
        Some("collides with an ARKit or head/eye name")
    } else {
        None
    }
}

/// Where each input column goes in a clip's channel layout.
pub(crate) struct Layout {
    pub head_eye: bool,
    pub extras: Vec<String>,
    /// Per input column, its channel index.
    pub slot: Vec<usize>,
}

impl Layout {
    pub fn stride(&self) -> usize {
        NUM_ARKIT + if self.head_eye { NUM_HEAD_EYE } else { 0 } + self.extras.len()
    }

    /// Maps input column names to channels. `extra_ok` says which non-ARKit, non-head/eye names are
    /// allowed. Errors carry the 0-based input column they concern, if one.
    pub fn from_names(names: &[&str], extra_ok: impl Fn(&str) -> bool) -> Result<Layout, (Option<usize>, String)> {
        let mut arkit_at = [usize::MAX; NUM_ARKIT];
        let mut head_at = [usize::MAX; NUM_HEAD_EYE];
        let mut extras: Vec<(usize, String)> = Vec::new();
        for (c, name) in names.iter().enumerate() {
            let dup = |first: usize| {
                Err((Some(c), format!("duplicate column '{name}' (first at column index {})", first + 1)))
            };
            if let Some(i) = arkit_index(name) {
                if arkit_at[i] != usize::MAX {
                    return dup(arkit_at[i]);
                }
                arkit_at[i] = c;
            } else if let Some(i) = head_eye_index(name) {
                if head_at[i] != usize::MAX {
                    return dup(head_at[i]);
                }
                head_at[i] = c;
            } else if extra_ok(name) {
                if let Some(p) = extra_name_problem(name) {
                    return Err((Some(c), format!("column name '{name}': {p}")));
                }
                if let Some((first, _)) = extras.iter().find(|(_, n)| n.eq_ignore_ascii_case(name)) {
                    return dup(*first);
                }
                extras.push((c, name.to_string()));
            } else {
                return Err((Some(c), format!("unknown column '{name}'")));
            }
        }
        let missing: Vec<&str> =
            (0..NUM_ARKIT).filter(|&i| arkit_at[i] == usize::MAX).map(|i| ARKIT_NAMES[i]).collect();
        if !missing.is_empty() {
            return Err((None, format!("missing {} of the 52 ARKit columns: {}", missing.len(), list(&missing))));
        }
        let present = head_at.iter().filter(|&&c| c != usize::MAX).count();
        if present != 0 && present != NUM_HEAD_EYE {
            let missing: Vec<&str> =
                (0..NUM_HEAD_EYE).filter(|&i| head_at[i] == usize::MAX).map(|i| HEAD_EYE_NAMES[i]).collect();
            return Err((None, format!("head/eye columns come all 9 or none; missing {}", list(&missing))));
        }
        let head_eye = present == NUM_HEAD_EYE;
        let base = NUM_ARKIT + if head_eye { NUM_HEAD_EYE } else { 0 };
        let mut slot = vec![0usize; names.len()];
        for (i, &c) in arkit_at.iter().enumerate() {
            slot[c] = i;
        }
        if head_eye {
            for (i, &c) in head_at.iter().enumerate() {
                slot[c] = NUM_ARKIT + i;
            }
        }
        for (k, (c, _)) in extras.iter().enumerate() {
            slot[*c] = base + k;
        }
        Ok(Layout { head_eye, extras: extras.into_iter().map(|(_, n)| n).collect(), slot })
    }
}

fn list(names: &[&str]) -> String {
    if names.len() <= 6 {
        names.join(", ")
    } else {
        format!("{}, … ({} more)", names[..6].join(", "), names.len() - 6)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn named(extra: &[&str], head: bool) -> Vec<(String, Vec<f32>)> {
        let mut v: Vec<(String, Vec<f32>)> = Vec::new();
        for (i, n) in ARKIT_NAMES.iter().enumerate().rev() {
            v.push((n.to_string(), vec![i as f32 / 100.0, 0.5]));
        }
        if head {
            for n in HEAD_EYE_NAMES {
                v.push((n.to_lowercase(), vec![-0.1, 0.1]));
            }
        }
        for n in extra {
            v.push((n.to_string(), vec![1.0, 2.0]));
        }
        v
    }

    #[test]
    fn from_named_reorders_to_canonical_layout() {
        let c = BlendshapeClip::from_named(60.0, vec![0.0, 0.5], named(&["Neutral", "custom"], true)).unwrap();
        assert_eq!(c.num_channels(), 52 + 9 + 2);
        assert_eq!(c.channel_names()[0], "EyeBlinkLeft");
        assert_eq!(c.channel_names()[61], "Neutral");
        assert_eq!(c.arkit(0)[17], 0.17);
        assert_eq!(c.head_eye(1).unwrap()[0], 0.1);
        assert_eq!(c.channel_index("CUSTOM"), Some(62));
        assert_eq!(c.channel(62), vec![1.0, 2.0]);
        assert_eq!(c.measured_fps(), 2.0);
    }

    #[test]
    fn invariants_are_checked() {
        let mut n = named(&[], false);
        n.retain(|(name, _)| name != "EyeLookOutLeft");
        let e = BlendshapeClip::from_named(60.0, vec![0.0, 0.5], n).unwrap_err().to_string();
        assert!(e.contains("missing 1 of the 52 ARKit columns: EyeLookOutLeft"), "{e}");
        let mut n = named(&[], true);
        n.pop();
        let e = BlendshapeClip::from_named(60.0, vec![0.0, 0.5], n).unwrap_err().to_string();
        assert!(e.contains("all 9 or none; missing RightEyeRoll"), "{e}");
        let e = BlendshapeClip::from_named(60.0, vec![0.5, 0.5], named(&[], false)).unwrap_err().to_string();
        assert!(e.contains("strictly increasing"), "{e}");
        let e = BlendshapeClip::from_named(60.0, vec![0.0], named(&[], false)).unwrap_err().to_string();
        assert!(e.contains("has 2 values; expected 1"), "{e}");
        let e = BlendshapeClip::from_named(60.0, vec![0.0, 1.0], named(&["a,b"], false)).unwrap_err().to_string();
        assert!(e.contains("contains ','"), "{e}");
        let e = BlendshapeClip::new(60.0, vec![0.0], false, vec![], vec![f32::NAN; 52]).unwrap_err().to_string();
        assert!(e.contains("expected a finite number"), "{e}");
        assert!(BlendshapeClip::new(0.0, vec![0.0], false, vec![], vec![0.0; 52]).is_err());
        assert!(BlendshapeClip::new(60.0, vec![], false, vec![], vec![]).is_err());
    }
}
