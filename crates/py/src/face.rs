//! face `edit` and `synth`: the face engine's `EditJob` on a `FaceClip`, `N` variants with seeds
//! `seed, seed + 1, …` (as `inbetween face edit --variants N --seed S`), and its procedural capture
//! generator (`inbetween face synth`).
//!
//! What the CLI decides before it builds the job is decided here the same way, from the face
//! engine's own rules (`infer::plan`: the `auto` method, spans in seconds or frames, viseme runs;
//! `EditJob::channel_split`: which shapes the guidance leaves to an unguided fill).

use crate::clip::FaceClip;
use crate::errors::{invalid, JobError};
use crate::runner::run_job;
use inbetween_core::cancel::Cancel;
use inbetween_face::data::{read_clip_limited, BlendshapeClip, MODEL_FPS, NUM_ARKIT};
use inbetween_face::edit::groups::parse_groups;
use inbetween_face::edit::{ConstraintKind, MotionLibrary, RetrievalOptions};
use inbetween_face::infer::keys::parse_keys_json;
use inbetween_face::infer::plan::{span_seconds, viseme_runs, MethodChoice, SPEECH_GROUPS};
use inbetween_face::infer::{
    read_keys, EditJob, EditLimits, EditOutcome, Guide, Inpainter, Method, DEFAULT_LIBRARY_S, DEFAULT_LIBRARY_SEED,
};
use inbetween_face::visemes::{read_viseme_source, text_to_phonemes, validate_spans, PhonemeSpan};
use inbetween_face::weights;
use inbetween_io::Progress;
use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;
use std::sync::OnceLock;
use std::time::Instant;

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
pub struct Variant {
    pub outcome: EditOutcome,
    pub seed: u64,
    pub ms: f64,
}

/// What [`edit`] made: the variants and what is the same for all of them.
pub struct Edited {
    pub variants: Vec<Variant>,
    pub method: String,
    pub guidance: &'static str,
    pub spans_s: Vec<(f64, f64)>,
    pub notes: Vec<String>,
}

/// The procedural retrieval library `face edit` uses without `--library` (fixed seed, so the same on
/// every call), made once per process.
fn default_library() -> &'static MotionLibrary {
    static LIBRARY: OnceLock<MotionLibrary> = OnceLock::new();
    LIBRARY.get_or_init(|| MotionLibrary::procedural(DEFAULT_LIBRARY_S, DEFAULT_LIBRARY_SEED))
}

fn span_of(s: &SpanArg, clip: &BlendshapeClip) -> Result<(f64, f64), JobError> {
    match s {
        SpanArg::Seconds(a, b) => Ok((*a, *b)),
        SpanArg::Text(t) => Ok(span_seconds(t, clip)?),
    }
}

/// The guidance of `r` (at most one kind), the file it came from and notes for the report.
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
    let shown = |p: &PathBuf| Some(p.display().to_string());
    Ok(if let Some(p) = &r.keys_path {
        (Guide::Keys(read_keys(p)?), shown(p))
    } else if let Some(j) = &r.keys_json {
        (Guide::Keys(parse_keys_json(j, "keys")?), Some("keys".into()))
    } else if let Some(g) = &r.guide {
        (Guide::Noisy(g.clone()), Some("guide".into()))
    } else if let Some(p) = &r.guide_path {
        (Guide::Noisy(read_clip_limited(p, limits.max_rows)?), shown(p))
    } else if let Some(p) = &r.visemes_path {
        (Guide::Visemes(viseme_runs(&read_viseme_source(p, r.tier.as_deref())?)?), shown(p))
    } else if let Some(list) = &r.phonemes {
        let spans: Vec<PhonemeSpan> = list.iter().map(|(a, b, p)| PhonemeSpan::new(*a, *b, p.clone())).collect();
        validate_spans(&spans)?;
        (Guide::Visemes(viseme_runs(&spans)?), Some("visemes".into()))
    } else if let Some(text) = &r.text {
        let (s, e) = match &r.text_span {
            Some(t) => span_of(t, clip)?,
            None => *spans.first().ok_or_else(|| JobError::Failed("text: no span to speak it over".into()))?,
        };
        let ph = text_to_phonemes(text, s, e)?;
        if !ph.guessed_words.is_empty() {
            notes.push(format!(
                "not in CMUdict, pronounced by our letter-to-sound rules: {}",
                ph.guessed_words.join(", ")
            ));
        }
        (Guide::Visemes(viseme_runs(&ph.spans)?), None)
    } else {
        (Guide::None, None)
    })
}

/// Runs the edit `r` asks for on `clip`, once per variant, as `face edit` does.
pub fn edit(clip: &BlendshapeClip, r: &EditRequest, cancel: &Cancel, bar: &Progress) -> Result<Edited, JobError> {
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
        let speech = SPEECH_GROUPS.map(|g| g.name()).join(", ");
        notes.push(match &r.groups {
            Some(g) => format!("groups {g}: the visemes guide these groups (default: {speech}; the rest unguided)"),
            None => format!("the visemes guide {speech}; eyes and brows are filled unguided (groups= overrides)"),
        });
    }
    let chosen = MethodChoice::parse(&r.method)?.resolve(kind, r.weights.is_some());
    if !r.library.is_empty() && chosen != MethodChoice::Retrieval {
        return Err(JobError::Failed(format!(
            "library is read only by method='retrieval' (method '{}' resolved to {} for {} guidance)",
            r.method,
            chosen.name(),
            kind.name()
        )));
    }
    let net = match chosen {
        MethodChoice::Network => Some(match &r.weights {
            Some(w) => weights::load(w).map_err(crate::errors::ctx(format!("loading face weights {}", w.display())))?,
            None => weights::committed(kind)
                .map_err(crate::errors::ctx(format!("loading the committed {} network", kind.name())))?,
        }),
        _ => None,
    };
    let own;
    let library: &MotionLibrary = if r.library.is_empty() {
        default_library()
    } else {
        let mut lib = MotionLibrary::default();
        for (i, c) in r.library.iter().enumerate() {
            let at_model_rate = c.resample(MODEL_FPS).map_err(crate::errors::ctx(format!("library[{i}]")))?;
            lib.push(at_model_rate.arkit_frames());
        }
        own = lib;
        &own
    };
    let method = match (chosen, &net) {
        (MethodChoice::Linear, _) => Method::Linear,
        (MethodChoice::Cubic, _) => Method::Cubic,
        (MethodChoice::Retrieval, _) => Method::Retrieval(library, RetrievalOptions::for_variants(kind, r.variants)),
        (MethodChoice::Network, Some(n)) => Method::Network(n as &dyn Inpainter),
        (other, _) => return Err(JobError::Failed(format!("method {} could not be prepared", other.name()))),
    };
    let mut job = EditJob {
        clip,
        spans: spans.clone(),
        channels,
        guide,
        method,
        seed: r.seed,
        limits,
        cancel: cancel.clone(),
        guide_file,
        library: None,
    };
    // Retrieval draws from the library, and so do the shapes the guidance leaves unguided.
    let unguided_rest = job.channel_split().1.iter().any(|c| *c);
    job.library = match chosen {
        MethodChoice::Retrieval => Some(library),
        _ if unguided_rest => Some(default_library()),
        _ => None,
    };
    job.validate()?;
    bar.phase(r.variants as u64, "editing the face");
    let mut variants = Vec::with_capacity(r.variants);
    for k in 0..r.variants {
        job.seed = r.seed + k as u64;
        let t = Instant::now();
        let outcome = job.run()?;
        variants.push(Variant { outcome, seed: job.seed, ms: t.elapsed().as_secs_f64() * 1000.0 });
        bar.inc(1);
    }
    Ok(Edited { variants, method: job.method.name(), guidance: kind.name(), spans_s: spans, notes })
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
    let spread: Vec<Option<f64>> = match edited.variants.first() {
        Some(f) => edited.variants.iter().map(|v| Some(v.outcome.mean_abs_difference(&f.outcome))).collect(),
        None => Vec::new(),
    };
    let mut out = Vec::with_capacity(edited.variants.len());
    for (k, v) in edited.variants.into_iter().enumerate() {
        let o = &v.outcome;
        let d = PyDict::new(py);
        d.set_item("variant", k + 1)?;
        d.set_item("seed", v.seed)?;
        d.set_item("method", &edited.method)?;
        d.set_item("guidance", edited.guidance)?;
        d.set_item("spans_s", &edited.spans_s)?;
        d.set_item("model_fps", MODEL_FPS)?;
        d.set_item("segments", o.mask.segments().iter().map(|s| (s.start, s.end)).collect::<Vec<_>>())?;
        d.set_item("key_frames", o.keys.iter().map(|(f, _)| *f).collect::<Vec<_>>())?;
        d.set_item("masked_mse", o.masked_mse())?;
        d.set_item("difference_from_first", spread[k].filter(|_| k > 0))?;
        let (rows, shapes) = o.changed(input);
        d.set_item("changed_rows", (rows.start, rows.end))?;
        let names = inbetween_face::data::ARKIT_NAMES;
        d.set_item("changed_shapes", (0..NUM_ARKIT).filter(|c| shapes[*c]).map(|c| names[c]).collect::<Vec<_>>())?;
        d.set_item("ms", v.ms)?;
        d.set_item("notes", &edited.notes)?;
        let n = o.before.len();
        let flat = |fr: &[[f32; NUM_ARKIT]]| fr.iter().flatten().copied().collect::<Vec<f32>>();
        d.set_item("before", PyArray1::from_vec(py, flat(&o.before)).reshape([n, NUM_ARKIT])?)?;
        d.set_item("after", PyArray1::from_vec(py, flat(&o.after)).reshape([n, NUM_ARKIT])?)?;
        let mask: Vec<bool> = (0..n).flat_map(|f| o.mask.frame(f).to_vec()).collect();
        d.set_item("mask", PyArray1::from_vec(py, mask).reshape([n, NUM_ARKIT])?)?;
        // The edited clip is moved, not copied.
        let edited_clip = FaceClip { clip: v.outcome.clip, source: clip.source.clone(), live_link: clip.live_link };
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
