//! face `edit` and `synth`: the face engine's `EditJob` on a `FaceClip`, `N` variants with seeds
//! `seed, seed + 1, …` (as `inbetween face edit --variants N --seed S`), and its procedural capture
//! generator (`inbetween face synth`).
//!
//! What the CLI decides before it builds the job is decided by the face engine's own pieces, as
//! there (`infer::plan`: the `auto` method and what it loads, `EditResources`; the guidance read
//! from what was given, `GuideSource`; spans in seconds or frames).

use crate::clip::FaceClip;
use crate::errors::{invalid, JobError};
use crate::runner::run_job;
use inbetween_core::cancel::Cancel;
use inbetween_face::data::{BlendshapeClip, NUM_ARKIT};
use inbetween_face::edit::groups::parse_groups;
use inbetween_face::edit::ConstraintKind;
use inbetween_face::infer::keys::parse_keys_json;
use inbetween_face::infer::plan::{span_seconds, visemes_groups_note, EditResources, GuideSource, MethodChoice};
use inbetween_face::infer::{run_variants, EditJob, EditLimits, Guide, Variant};
use inbetween_face::visemes::PhonemeSpan;
use inbetween_io::Progress;
use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(face_edit, m)?)?;
    m.add_function(wrap_pyfunction!(face_synth, m)?)?;
    Ok(())
}

/// A span as Python gives it: `(start_s, end_s)` or the CLI's text (`4.0s..6.5s`, `240f..390f`).
#[derive(FromPyObject, Clone, Debug)]
pub enum SpanArg {
    Seconds(f64, f64),
    Text(String),
}

/// A timed phoneme: `(start_s, end_s, ARPAbet or MFA label)`.
pub type Phoneme = (f64, f64, String);

/// Everything `face.edit` was given, owned, so the same request runs from Python and from the bench.
#[derive(Clone, Debug, Default)]
pub struct EditRequest {
    pub spans: Vec<SpanArg>,
    pub keys_json: Option<String>,
    pub keys_path: Option<PathBuf>,
    pub guide: Option<BlendshapeClip>,
    pub guide_path: Option<PathBuf>,
    pub text: Option<String>,
    pub text_span: Option<SpanArg>,
    pub visemes_path: Option<PathBuf>,
    pub phonemes: Option<Vec<Phoneme>>,
    pub tier: Option<String>,
    pub groups: Option<String>,
    pub method: String,
    pub weights: Option<PathBuf>,
    pub library: Vec<BlendshapeClip>,
    pub variants: usize,
    pub seed: u64,
    pub max_rows: Option<usize>,
    pub max_mask_s: Option<f64>,
}

/// One variant: the job's outcome, its seed and how long the edit took.
fn span_of(s: &SpanArg, clip: &BlendshapeClip) -> Result<(f64, f64), JobError> {
    match s {
        SpanArg::Seconds(a, b) => Ok((*a, *b)),
        SpanArg::Text(t) => Ok(span_seconds(t, clip)?),
    }
}

/// The guidance of `r` (at most one kind) as the face engine reads it ([`GuideSource`]), the name
/// the job's messages give it, and notes for the report.
fn guidance(
    r: &EditRequest,
    clip: &BlendshapeClip,
    spans: &[(f64, f64)],
    limits: &EditLimits,
    notes: &mut Vec<String>,
) -> Result<(Guide, Option<String>), JobError> {
    let given: Vec<&str> = [
        (r.keys_json.is_some() || r.keys_path.is_some(), "keys"),
        (r.guide.is_some() || r.guide_path.is_some(), "guide"),
        (r.text.is_some(), "text"),
        (r.visemes_path.is_some() || r.phonemes.is_some(), "visemes"),
    ]
    .into_iter()
    .filter_map(|(on, name)| on.then_some(name))
    .collect();
    if given.len() > 1 {
        return Err(JobError::Failed(format!(
            "{} given together; an edit takes one guidance: keys, guide (a noisy take), text or visemes",
            given.join(" and ")
        )));
    }
    // What was given in memory is named by its argument in the job's messages.
    let (source, label) = if let Some(p) = &r.keys_path {
        (GuideSource::KeysFile(p), None)
    } else if let Some(j) = &r.keys_json {
        (GuideSource::Keys(parse_keys_json(j, "keys")?), Some("keys"))
    } else if let Some(g) = &r.guide {
        (GuideSource::Take(g.clone()), Some("guide"))
    } else if let Some(p) = &r.guide_path {
        (GuideSource::TakeFile(p), None)
    } else if let Some(p) = &r.visemes_path {
        (GuideSource::VisemesFile(p, r.tier.as_deref()), None)
    } else if let Some(list) = &r.phonemes {
        let spans = list.iter().map(|(a, b, p)| PhonemeSpan::new(*a, *b, p.clone())).collect();
        (GuideSource::Phonemes(spans), Some("visemes"))
    } else if let Some(text) = &r.text {
        let span = match &r.text_span {
            Some(t) => span_of(t, clip)?,
            None => *spans.first().ok_or_else(|| JobError::Failed("text: no span to speak it over".into()))?,
        };
        (GuideSource::Text(text, span), None)
    } else {
        (GuideSource::None, None)
    };
    let loaded = source.load(limits.max_rows)?;
    notes.extend(loaded.guessed_note());
    Ok((loaded.guide, loaded.file.or(label.map(String::from))))
}

/// Runs the edit `r` asks for on `clip`, once per variant, as `face edit` does.
pub fn edit(clip: &BlendshapeClip, r: &EditRequest, cancel: &Cancel, bar: &Progress) -> Result<Vec<Variant>, JobError> {
    let defaults = EditLimits::default();
    let limits = EditLimits {
        max_rows: r.max_rows.unwrap_or(defaults.max_rows),
        max_mask_s: r.max_mask_s.unwrap_or(defaults.max_mask_s),
    };
    if r.variants == 0 {
        return Err(JobError::Failed("variants 0: expected at least 1".into()));
    }
    let spans = r.spans.iter().map(|s| span_of(s, clip)).collect::<Result<Vec<_>, _>>()?;
    let channels = match r.groups.as_deref().map(str::trim) {
        None | Some("default") => None,
        Some(g) => Some(parse_groups(g).map_err(JobError::Failed)?),
    };
    let mut notes = Vec::new();
    let (guide, guide_file) = guidance(r, clip, &spans, &limits, &mut notes)?;
    let kind = guide.kind();
    if kind == ConstraintKind::Visemes {
        notes.push(visemes_groups_note(r.groups.as_deref(), "groups", "groups="));
    }
    let mut resources = EditResources::load_network(MethodChoice::parse(&r.method)?, kind, r.weights.as_deref())
        .map_err(|e| crate::errors::ctx(e.what)(e.source))?;
    resources.check_library_given(!r.library.is_empty()).map_err(|e| {
        JobError::Failed(inbetween_io::limits::name_fields(
            &e.to_string(),
            &[("library", "library"), ("method", "method")],
        ))
    })?;
    resources.load_library_clips(&r.library, channels.is_some(), |i| format!("library[{i}]"))?;
    let mut job = EditJob {
        clip,
        spans,
        channels,
        guide,
        method: resources.method(r.variants)?,
        seed: r.seed,
        limits,
        cancel: cancel.clone(),
        guide_file,
        library: resources.library.as_ref(),
    };
    Ok(run_variants(&mut job, r.variants, &notes, bar)?)
}

/// Runs `face edit` on `clip` (see `inbetween.face.edit`). Returns a list of (FaceClip, report dict).
#[pyfunction]
#[pyo3(signature = (clip, spans, keys_json=None, keys_path=None, guide=None, guide_path=None, text=None, text_span=None, visemes_path=None, phonemes=None, tier=None, groups=None, method="auto".to_string(), weights=None, library=None, variants=1, seed=1, max_rows=None, max_mask_s=None, progress=None))]
#[allow(clippy::too_many_arguments)]
fn face_edit<'py>(
    py: Python<'py>,
    clip: PyRef<'py, FaceClip>,
    spans: Vec<SpanArg>,
    keys_json: Option<String>,
    keys_path: Option<PathBuf>,
    guide: Option<PyRef<'py, FaceClip>>,
    guide_path: Option<PathBuf>,
    text: Option<String>,
    text_span: Option<SpanArg>,
    visemes_path: Option<PathBuf>,
    phonemes: Option<Vec<Phoneme>>,
    tier: Option<String>,
    groups: Option<String>,
    method: String,
    weights: Option<PathBuf>,
    library: Option<Vec<PyRef<'py, FaceClip>>>,
    variants: usize,
    seed: u64,
    max_rows: Option<usize>,
    max_mask_s: Option<f64>,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<Vec<(FaceClip, Bound<'py, PyDict>)>> {
    let request = EditRequest {
        spans,
        keys_json,
        keys_path,
        guide: guide.map(|g| g.clip.clone()),
        guide_path,
        text,
        text_span,
        visemes_path,
        phonemes,
        tier,
        groups,
        method,
        weights,
        library: library.unwrap_or_default().iter().map(|c| c.clip.clone()).collect(),
        variants,
        seed,
        max_rows,
        max_mask_s,
    };
    let input = &clip.clip;
    let edited = run_job(py, progress.as_ref(), |cancel, bar| edit(input, &request, cancel, bar))?;
    let mut out = Vec::with_capacity(edited.len());
    for Variant { outcome, report: r } in edited {
        let d = PyDict::new(py);
        d.set_item("variant", r.variant)?;
        d.set_item("seed", r.seed)?;
        d.set_item("method", &r.method)?;
        d.set_item("guidance", r.guidance)?;
        d.set_item("spans_s", &r.spans_s)?;
        d.set_item("model_fps", r.model_fps)?;
        d.set_item("segments", &r.segments)?;
        d.set_item("key_frames", &r.key_frames)?;
        d.set_item("masked_mse", r.masked_mse)?;
        d.set_item("difference_from_first", r.difference_from_first)?;
        d.set_item("changed_rows", r.changed_rows)?;
        d.set_item("changed_shapes", &r.changed_shapes)?;
        d.set_item("ms", r.ms)?;
        d.set_item("notes", &r.notes)?;
        d.set_item("text", r.to_string())?;
        // The model-rate frames move into their arrays (numpy owns them now, no copy); the mask's
        // flags are copied.
        let n = outcome.before.len();
        d.set_item("before", PyArray1::from_vec(py, outcome.before.into_flattened()).reshape([n, NUM_ARKIT])?)?;
        d.set_item("after", PyArray1::from_vec(py, outcome.after.into_flattened()).reshape([n, NUM_ARKIT])?)?;
        d.set_item("mask", PyArray1::from_slice(py, outcome.mask.flags()).reshape([n, NUM_ARKIT])?)?;
        // The edited clip is moved, not copied.
        let edited_clip = FaceClip { clip: outcome.clip, source: clip.source.clone(), live_link: clip.live_link };
        out.push((edited_clip, d));
    }
    Ok(out)
}

/// A procedural face capture (`inbetween face synth`): `seconds` of speech, blinks, expressions,
/// head and gaze at the model rate, with the phonemes spoken as `(start_s, end_s, phoneme)`.
#[pyfunction]
#[pyo3(signature = (seconds=10.0, seed=1))]
fn face_synth(py: Python<'_>, seconds: f64, seed: u64) -> PyResult<(FaceClip, Vec<Phoneme>)> {
    if !(seconds.is_finite() && seconds > 0.0) {
        return Err(invalid(format!("seconds {seconds}: expected a positive duration in seconds")));
    }
    use inbetween_face::procedural::{generate, ProceduralConfig};
    let p = py.detach(|| generate(&ProceduralConfig { duration_s: seconds, ..Default::default() }, seed));
    let phonemes = p.phonemes.iter().map(|(a, b, ph)| (*a, *b, ph.to_string())).collect();
    Ok((FaceClip { clip: p.clip, source: format!("synth-{seed}.csv"), live_link: true }, phonemes))
}
