//! Per-frame viseme tracks and their one-hot encoding, the viseme constraint of §3.1 ("one-hot vectors
//! representing pronounced visemes at each frame", 18 classes of Table 1).

use super::spans::{shown, validate_spans, PhonemeSpan};
use super::{phoneme_viseme, Viseme, NUM_VISEMES};
use crate::data::FaceError;

/// The viseme at each of `n_frames` frames: frame `i` at `t0 + i / fps` seconds takes the class of the
/// span covering it (`start_s <= t < end_s`); frames no span covers are [`Viseme::Sil`].
///
/// Errors when `fps` is not a positive finite number, `t0` is not finite, or the spans break the rules
/// of [`validate_spans`] (unsorted, overlapping, non-finite, or an unknown label, which the message
/// names).
pub fn viseme_frames(spans: &[PhonemeSpan], fps: f64, t0: f64, n_frames: usize) -> Result<Vec<Viseme>, FaceError> {
    if !(fps.is_finite() && fps > 0.0) {
        return Err(FaceError::Invalid(format!("frame rate {fps}; expected a positive number of frames per second")));
    }
    if !t0.is_finite() {
        return Err(FaceError::Invalid(format!("first frame time {t0}; expected a finite time in seconds")));
    }
    validate_spans(spans)?;
    let classes: Vec<Viseme> = spans
        .iter()
        .map(|s| {
            phoneme_viseme(&s.phoneme)
                .ok_or_else(|| FaceError::Invalid(format!("unknown phoneme {}", shown(&s.phoneme))))
        })
        .collect::<Result<_, _>>()?;
    let mut out = Vec::with_capacity(n_frames);
    let mut k = 0;
    for i in 0..n_frames {
        let t = t0 + i as f64 / fps;
        while k < spans.len() && spans[k].end_s <= t {
            k += 1;
        }
        let covered = k < spans.len() && spans[k].start_s <= t;
        out.push(if covered { classes[k] } else { Viseme::Sil });
    }
    Ok(out)
}

/// One-hot rows, `visemes.len() × NUM_VISEMES` row-major: row `i` has 1 at `visemes[i].index()`.
pub fn one_hot(visemes: &[Viseme]) -> Vec<f32> {
    let mut out = vec![0.0; visemes.len() * NUM_VISEMES];
    for (row, v) in out.chunks_exact_mut(NUM_VISEMES).zip(visemes) {
        row[v.index()] = 1.0;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_take_the_covering_span_and_silence_elsewhere() {
        let spans =
            vec![PhonemeSpan::new(0.5, 1.0, "M"), PhonemeSpan::new(1.0, 1.25, "ɪ"), PhonemeSpan::new(1.5, 2.0, "sp")];
        // 4 fps from 0.25 s: 0.25 0.5 0.75 1.0 1.25 1.5 1.75 2.0
        let got = viseme_frames(&spans, 4.0, 0.25, 8).unwrap();
        use Viseme::*;
        assert_eq!(got, [Sil, MBP, MBP, IhIy, Sil, Sil, Sil, Sil]);
        assert!(viseme_frames(&spans, 25.0, 0.0, 0).unwrap().is_empty());
        assert_eq!(viseme_frames(&[], 25.0, 0.0, 3).unwrap(), [Sil; 3]);
    }

    #[test]
    fn bad_arguments_and_unknown_labels_are_errors() {
        let spans = vec![PhonemeSpan::new(0.0, 1.0, "B"), PhonemeSpan::new(1.0, 2.0, "ZZ9")];
        let e = viseme_frames(&spans, 25.0, 0.0, 10).unwrap_err().to_string();
        assert!(e.contains("unknown phoneme 'ZZ9'"), "{e}");
        for (fps, t0) in [(0.0, 0.0), (-25.0, 0.0), (f64::NAN, 0.0), (25.0, f64::INFINITY)] {
            assert!(viseme_frames(&spans[..1], fps, t0, 3).is_err());
        }
        let unsorted = vec![PhonemeSpan::new(1.0, 2.0, "B"), PhonemeSpan::new(0.0, 1.0, "M")];
        assert!(viseme_frames(&unsorted, 25.0, 0.0, 3).unwrap_err().to_string().contains("span 1"));
    }

    #[test]
    fn one_hot_rows_have_a_single_one_at_the_class_channel() {
        let v = [Viseme::Sil, Viseme::R, Viseme::MBP];
        let m = one_hot(&v);
        assert_eq!(m.len(), 3 * NUM_VISEMES);
        for (row, v) in m.chunks_exact(NUM_VISEMES).zip(v) {
            assert_eq!(row.iter().sum::<f32>(), 1.0);
            assert_eq!(row[v.index()], 1.0);
        }
        assert_eq!(m[NUM_VISEMES - 1 + NUM_VISEMES], 1.0, "R is the last channel");
    }
}
