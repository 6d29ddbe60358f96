//! An edit's variants: the [`EditJob`] run once per seed (`seed, seed + 1, …`, as `inbetween face
//! edit --variants N`) and what each one did, measured on its outcome: the per-variant report a front
//! end shows (the Python package's `face.edit`), built where the edit runs.

use std::fmt;
use std::time::Instant;

use serde::Serialize;

use crate::data::{FaceError, ARKIT_NAMES, MODEL_FPS, NUM_ARKIT};
use crate::infer::{EditJob, EditOutcome};
use inbetween_io::Progress;

/// What one variant of an edit did.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct VariantReport {
    /// 1-based.
    pub variant: usize,
    pub seed: u64,
    /// The method that ran: "retrieval", "network (keyframes)", "linear", …
    pub method: String,
    /// The guidance: "unguided", "keyframes", "noisy" or "visemes".
    pub guidance: &'static str,
    /// The edited spans, seconds from the first frame.
    pub spans_s: Vec<(f64, f64)>,
    /// The rate the engine edits at, fps ([`MODEL_FPS`]); segments and key frames are at it.
    pub model_fps: f64,
    /// The spans as model-rate frames (start, end exclusive).
    pub segments: Vec<(usize, usize)>,
    /// Model-rate frames of the keys.
    pub key_frames: Vec<usize>,
    /// Mean squared difference from what was there over the regenerated entries, weight²
    /// ([`EditOutcome::masked_mse`]).
    pub masked_mse: f64,
    /// Mean |difference| from variant 1 inside the spans, blendshape weight
    /// ([`EditOutcome::mean_abs_difference`]); None for variant 1.
    pub difference_from_first: Option<f64>,
    /// Input rows the edit changed, `(first, last + 1)` in the capture's own frames; (0, 0) when
    /// none ([`EditOutcome::changed`]).
    pub changed_rows: (usize, usize),
    /// ARKit shapes with a changed value.
    pub changed_shapes: Vec<&'static str>,
    /// Time of this variant's edit, ms.
    pub ms: f64,
    /// Notes on how the request was read (a guessed format, the groups visemes guide).
    pub notes: Vec<String>,
}

impl fmt::Display for VariantReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let spans: Vec<String> = self.spans_s.iter().map(|(a, b)| format!("{a:.2} s..{b:.2} s")).collect();
        let (a, b) = self.changed_rows;
        write!(
            f,
            "variant {} (seed {}): {}, {}, spans {}; masked MSE {:.5} against what was there; rows {a}..{b} \
             changed ({} shapes) in {:.1} ms",
            self.variant,
            self.seed,
            self.method,
            self.guidance,
            spans.join(", "),
            self.masked_mse,
            self.changed_shapes.len(),
            self.ms
        )?;
        if let Some(d) = self.difference_from_first {
            write!(f, "; mean |difference| from variant 1 inside the spans {d:.4}")?;
        }
        for n in &self.notes {
            write!(f, "\nnote: {n}")?;
        }
        Ok(())
    }
}

/// One variant: the edit and its report.
#[derive(Clone, Debug)]
pub struct Variant {
    pub outcome: EditOutcome,
    pub report: VariantReport,
}

/// Runs `job` `variants` times (at least once) with the seeds `job.seed, job.seed + 1, …` (one
/// progress step each) and reports each edit, `notes` in every report; `job.seed` is left at the
/// last variant's.
pub fn run_variants(
    job: &mut EditJob,
    variants: usize,
    notes: &[String],
    progress: &Progress,
) -> Result<Vec<Variant>, FaceError> {
    let variants = variants.max(1);
    job.validate()?;
    progress.phase(variants as u64, "editing the face");
    let first_seed = job.seed;
    let mut out: Vec<Variant> = Vec::with_capacity(variants);
    for k in 0..variants {
        job.seed = first_seed + k as u64;
        let t = Instant::now();
        let outcome = job.run()?;
        let ms = t.elapsed().as_secs_f64() * 1000.0;
        let (rows, shapes) = outcome.changed(job.clip);
        let report = VariantReport {
            variant: k + 1,
            seed: job.seed,
            method: job.method.name(),
            guidance: job.guide.kind().name(),
            spans_s: job.spans.clone(),
            model_fps: MODEL_FPS,
            segments: outcome.mask.segments().iter().map(|s| (s.start, s.end)).collect(),
            key_frames: outcome.keys.iter().map(|(f, _)| *f).collect(),
            masked_mse: outcome.masked_mse(),
            difference_from_first: out.first().map(|f| outcome.mean_abs_difference(&f.outcome)),
            changed_rows: (rows.start, rows.end),
            changed_shapes: (0..NUM_ARKIT).filter(|c| shapes[*c]).map(|c| ARKIT_NAMES[c]).collect(),
            ms,
            notes: notes.to_vec(),
        };
        out.push(Variant { outcome, report });
        progress.inc(1);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::procedural::{generate, ProceduralConfig};

    /// Three variants of a linear fill: seeds 7, 8, 9, numbered 1..3; the spans' rows changed and
    /// nothing else; a spread of exactly 0 from variant 1 (the method draws nothing) and none for
    /// variant 1; the text names all of it; 0 variants is refused.
    #[test]
    fn variants_are_seeded_in_turn_and_report_what_changed() {
        let clip = generate(&ProceduralConfig { duration_s: 6.0, ..Default::default() }, 3).clip;
        let mut job = crate::infer::linear_test_job(&clip);
        let made = run_variants(&mut job, 3, &["a note".into()], &Progress::hidden()).unwrap();
        assert_eq!(
            made.iter().map(|v| (v.report.variant, v.report.seed)).collect::<Vec<_>>(),
            [(1, 7), (2, 8), (3, 9)]
        );
        assert_eq!(job.seed, 9);
        let r = &made[1].report;
        assert_eq!((r.difference_from_first, made[0].report.difference_from_first), (Some(0.0), None));
        let (a, b) = r.changed_rows;
        let fps = clip.measured_fps();
        assert!(a as f64 >= 2.0 * fps - 1.0 && (b as f64) <= 3.5 * fps + 2.0 && b > a, "rows {a}..{b}");
        assert!(!r.changed_shapes.is_empty() && r.masked_mse > 0.0);
        assert_eq!(r.segments.len(), 1);
        let text = r.to_string();
        assert!(text.starts_with("variant 2 (seed 8): linear, unguided, spans 2.00 s..3.50 s; masked MSE"), "{text}");
        assert!(text.contains("from variant 1 inside the spans 0.0000\nnote: a note"), "{text}");
        job.seed = 7;
        assert_eq!(run_variants(&mut job, 0, &[], &Progress::hidden()).unwrap().len(), 1);
    }
}
