//! The jobs a batch runs, one per input, each a thin call of an engine's public job: the inputs it
//! takes (by extension), the outputs it writes (mirroring the input's path below the output
//! folder) and the options it reads. Nothing of an engine's policy is decided here: defaults come
//! from the engines' jobs.

use crate::manifest::{with_extension, Input};
use crate::BatchError;
use inbetween_core::cancel::Cancel;
use inbetween_io::{with_causes, write_atomic, OutputSet, Progress};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// A job a batch can run on each input.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Kind {
    /// A motion file → an `.ibk` file (`mocap compress`): `cmu/01_01.bvh` → `cmu/01_01.ibk`.
    MocapCompress,
    /// A motion file → its keyframes and their tangents as JSON (`SelectJob`'s report):
    /// `cmu/01_01.bvh` → `cmu/01_01.keys.json`.
    MocapKeys,
    /// A video → its analysis (flows, shots, the clip's trained RSFNet, cached so that a later
    /// `video resequence --cache-dir` starts at once): `a/clip.mp4` → `a/clip.analysis.json` and
    /// the folder `a/clip.rsfnet/`.
    VideoAnalyse,
    /// A story (`.txt`) → its animated scene (`script run`): `s/story.txt` → the folder `s/story/`.
    ScriptRun,
    /// A Live Link Face take (`.csv`) with one mask for every take → the edited take
    /// (`face edit`): `takes/a.csv` → `takes/a.csv` below the output folder.
    FaceEdit,
}

impl Kind {
    pub const ALL: [Kind; 5] =
        [Kind::MocapCompress, Kind::MocapKeys, Kind::VideoAnalyse, Kind::ScriptRun, Kind::FaceEdit];

    /// The job's name on the command line and in Python (`mocap-compress`, …).
    pub fn name(self) -> &'static str {
        match self {
            Kind::MocapCompress => "mocap-compress",
            Kind::MocapKeys => "mocap-keys",
            Kind::VideoAnalyse => "video-analyse",
            Kind::ScriptRun => "script-run",
            Kind::FaceEdit => "face-edit",
        }
    }

    /// A job by [`Kind::name`].
    pub fn parse(name: &str) -> Result<Kind, BatchError> {
        Kind::ALL.into_iter().find(|k| k.name() == name).ok_or_else(|| {
            let names: Vec<&str> = Kind::ALL.iter().map(|k| k.name()).collect();
            BatchError::Invalid(format!("unknown batch job '{name}': expected one of {}", names.join(", ")))
        })
    }

    /// The input extensions the job reads (lower case, no dot).
    pub fn extensions(self) -> &'static [&'static str] {
        match self {
            Kind::MocapCompress | Kind::MocapKeys => &["bvh", "amc"],
            Kind::VideoAnalyse => &["mp4", "gif"],
            Kind::ScriptRun => &["txt"],
            Kind::FaceEdit => &["csv"],
        }
    }

    /// The outputs of the input at `rel`, relative to the output folder.
    pub fn outputs(self, rel: &str) -> Vec<String> {
        match self {
            Kind::MocapCompress => vec![with_extension(rel, "ibk")],
            Kind::MocapKeys => vec![with_extension(rel, "keys.json")],
            Kind::VideoAnalyse => vec![with_extension(rel, "analysis.json"), with_extension(rel, "rsfnet")],
            Kind::ScriptRun => vec![with_extension(rel, "")],
            Kind::FaceEdit => vec![rel.to_string()],
        }
    }

    /// Which [`Options`] fields the job reads.
    fn reads(self) -> &'static [&'static str] {
        match self {
            Kind::MocapCompress => &["max_error_cm", "keys"],
            Kind::MocapKeys => &["max_error_cm", "keys", "method"],
            Kind::VideoAnalyse => &[],
            Kind::ScriptRun => &["seed"],
            Kind::FaceEdit => &["mask", "method", "seed"],
        }
    }
}

/// The options of a batch, the same for every input. A field the job does not read is an error
/// (so a typo or a flag meant for another job is not silently ignored).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Options {
    /// Error bound, cm: `mocap-compress` (every frame within it, version 4) and `mocap-keys` (the
    /// fewest keys within it).
    pub max_error_cm: Option<f64>,
    /// A key count: `mocap-compress` (version 2) and `mocap-keys`.
    pub keys: Option<usize>,
    /// `mocap-keys`: the selector (uniform, greedy, sidql, optimal; error_bounded with a bound);
    /// `face-edit`: the fill method (auto, network, retrieval, linear).
    pub method: Option<String>,
    /// `face-edit`: the spans to regenerate, as `face edit --mask` takes them (`4s..6.5s`).
    pub mask: Option<String>,
    /// `script-run`, `face-edit`: the seed (the engine's default when absent).
    pub seed: Option<u64>,
}

impl Options {
    /// The fields that are set, by name.
    fn set_fields(&self) -> Vec<&'static str> {
        let mut set = Vec::new();
        for (name, on) in [
            ("max_error_cm", self.max_error_cm.is_some()),
            ("keys", self.keys.is_some()),
            ("method", self.method.is_some()),
            ("mask", self.mask.is_some()),
            ("seed", self.seed.is_some()),
        ] {
            if on {
                set.push(name);
            }
        }
        set
    }

    /// Checks the options against `kind` before any input is read.
    pub fn validate(&self, kind: Kind) -> Result<(), BatchError> {
        for field in self.set_fields() {
            if !kind.reads().contains(&field) {
                return Err(BatchError::Invalid(format!(
                    "option `{field}` does not apply to {}; it reads {}",
                    kind.name(),
                    if kind.reads().is_empty() { "no option".to_string() } else { kind.reads().join(", ") }
                )));
            }
        }
        if let Some(cm) = self.max_error_cm {
            if !(cm.is_finite() && cm > 0.0) {
                return Err(BatchError::Invalid(format!("max_error_cm {cm}: expected a positive length in cm")));
            }
        }
        match kind {
            Kind::MocapCompress if self.max_error_cm.is_some() == self.keys.is_some() => Err(BatchError::Invalid(
                "mocap-compress needs either an error bound (`max_error_cm`) or a key count (`keys`)".into(),
            )),
            Kind::MocapKeys if self.max_error_cm.is_some() && self.keys.is_some() => Err(BatchError::Invalid(
                "mocap-keys takes an error bound (`max_error_cm`) or a key count (`keys`), not both".into(),
            )),
            Kind::MocapKeys if self.max_error_cm.is_none() && self.keys.is_none() => Err(BatchError::Invalid(
                "mocap-keys needs an error bound (`max_error_cm`) or a key count (`keys`)".into(),
            )),
            Kind::FaceEdit if self.mask.is_none() => {
                Err(BatchError::Invalid("face-edit needs a mask (the spans to regenerate, e.g. 4s..6.5s)".into()))
            }
            _ => Ok(()),
        }
    }
}

/// What one input produced: its outputs (relative to the output folder) and its job's report.
pub struct Produced {
    pub outputs: Vec<String>,
    pub report: serde_json::Value,
}

fn err(input: &Input, e: impl std::error::Error) -> String {
    let text = with_causes(&e);
    // Engine errors usually name the file already; make sure the line does.
    if text.contains(&input.path.display().to_string()) {
        text
    } else {
        format!("{}: {text}", input.path.display())
    }
}

fn json(value: impl Serialize) -> serde_json::Value {
    serde_json::to_value(value).unwrap_or_else(|e| serde_json::json!({ "unserialisable": e.to_string() }))
}

fn write(out: &Path, rel: &str, bytes: &[u8]) -> Result<(), String> {
    let path = out.join(rel);
    if let Some(parent) = path.parent() {
        std::fs::create_dir_all(parent).map_err(|e| format!("{}: {e}", parent.display()))?;
    }
    write_atomic(&path, bytes).map_err(|e| format!("{}: {e}", path.display()))
}

/// Runs `kind` on one input, writing its outputs below `out` (each atomically: a file by a
/// rename, a folder through a staging folder), and returns them with the job's report.
pub fn run(kind: Kind, input: &Input, out: &Path, options: &Options, cancel: &Cancel) -> Result<Produced, String> {
    cancel.check().map_err(|e| e.to_string())?;
    let outputs = kind.outputs(&input.rel);
    let report = match kind {
        Kind::MocapCompress => mocap_compress(input, out, &outputs[0], options)?,
        Kind::MocapKeys => mocap_keys(input, out, &outputs[0], options, cancel)?,
        Kind::VideoAnalyse => video_analyse(input, out, &outputs, cancel)?,
        Kind::ScriptRun => script_run(input, out, &outputs[0], options, cancel)?,
        Kind::FaceEdit => face_edit(input, out, &outputs[0], options, cancel)?,
    };
    Ok(Produced { outputs, report })
}

fn load_motion(input: &Input) -> Result<inbetween_core::Motion, String> {
    inbetween_io::load_motion(&input.path).map_err(|e| err(input, e))
}

fn mocap_compress(input: &Input, out: &Path, output: &str, options: &Options) -> Result<serde_json::Value, String> {
    use inbetween_mocap::codec::{Budget, CompressJob};
    let motion = load_motion(input)?;
    let budget = match (options.max_error_cm, options.keys) {
        (Some(cm), _) => Budget::MaxErrorCm(cm),
        (None, Some(k)) => Budget::Keys(k),
        (None, None) => unreachable!("validated"),
    };
    let job = CompressJob::for_motion(&motion, budget);
    let report = job.run(&motion).map_err(|e| err(input, e))?;
    write(out, output, report.bytes())?;
    Ok(serde_json::json!({
        "frames": motion.num_frames(),
        "joints": motion.skeleton.len(),
        "bytes": report.bytes().len(),
        "text": report.to_string(),
    }))
}

fn mocap_keys(
    input: &Input,
    out: &Path,
    output: &str,
    options: &Options,
    cancel: &Cancel,
) -> Result<serde_json::Value, String> {
    use inbetween_mocap::{PreparedClip, SelectJob, Selector};
    let motion = load_motion(input)?;
    let clip = PreparedClip::inferred(motion).map_err(|e| err(input, e))?;
    let method = match (&options.method, options.max_error_cm) {
        (Some(m), _) => Selector::parse(m).map_err(|e| e.to_string())?,
        (None, Some(_)) => Selector::ErrorBounded,
        (None, None) => SelectJob::default().method,
    };
    let job = SelectJob { method, k: options.keys, bound_cm: options.max_error_cm, ..SelectJob::default() };
    let report = job.run(&clip, cancel, &Progress::hidden()).map_err(|e| err(input, e))?;
    let full = serde_json::to_vec_pretty(&report).map_err(|e| e.to_string())?;
    write(out, output, &full)?;
    // The line keeps the summary; the key poses and per-frame errors are in the file.
    Ok(serde_json::json!({
        "method": report.method,
        "label": report.label(),
        "frames": clip.num_frames(),
        "keys": report.keys().frames(),
        "planned": json(report.planned),
        "max_cm": report.reconstruction.error.max_cm,
        "mean_cm": report.reconstruction.error.mean_cm,
        "select_ms": report.select_ms,
    }))
}

/// The video engine's `AnalyseJob` on one clip (its frame limit, decoding and analysis), the
/// metric cached beside the outputs.
fn video_analyse(input: &Input, out: &Path, outputs: &[String], cancel: &Cancel) -> Result<serde_json::Value, String> {
    use inbetween_video::job::AnalyseJob;
    let mut job = AnalyseJob::for_file(&input.path);
    job.config.cache_dir = out.join(&outputs[1]);
    let r = job.run(cancel, &Progress::hidden()).map_err(|e| err(input, e))?;
    let report = serde_json::json!({
        "frames": r.frames,
        "width": r.width,
        "height": r.height,
        "fps": r.fps,
        "decoder": r.decoder.as_deref().unwrap_or_default(),
        "shots": r.shots,
        "directed": r.directed,
        "metric": r.metric,
        "stages_s": r.stages,
    });
    let text = serde_json::to_vec_pretty(&report).map_err(|e| e.to_string())?;
    write(out, &outputs[0], &text)?;
    Ok(report)
}

fn script_run(
    input: &Input,
    out: &Path,
    output: &str,
    options: &Options,
    cancel: &Cancel,
) -> Result<serde_json::Value, String> {
    use inbetween_script::jobs::{read_script, run_story, RunJob};
    let text = read_script(&input.path).map_err(|e| err(input, e))?;
    let target = out.join(output);
    let mut set = OutputSet::new();
    let staging = set.dir(&target).map_err(|e| format!("{}: {e}", target.display()))?;
    let mut job = RunJob { cancel: cancel.clone(), ..RunJob::default() };
    job.scene.out_dir = staging.clone();
    if let Some(seed) = options.seed {
        job.scene.seed = seed;
        job.scene.config.seed = seed;
    }
    let r = run_story(&text, &input.path, &job).map_err(|e| err(input, e))?;
    set.commit().map_err(|e| format!("{}: {e}", target.display()))?;
    let files: Vec<String> = r
        .files
        .iter()
        .filter_map(|f| f.strip_prefix(&staging).ok())
        .map(|f| format!("{output}/{}", f.to_string_lossy().replace('\\', "/")))
        .collect();
    let frames = r.animation.frames();
    Ok(serde_json::json!({
        "objects": r.animation.scene.objects.len(),
        "characters": r.animation.characters.len(),
        "frames": frames,
        "fps": r.animation.fps,
        "seconds_of_animation": frames as f64 / r.animation.fps,
        "collided_boxes": [r.before.collided_boxes, r.after.collided_boxes],
        "contact_m": [r.before.contact, r.after.contact],
        "warnings": r.scene.diagnostics.iter().map(|d| d.to_string()).collect::<Vec<_>>(),
        "files": files,
    }))
}

fn face_edit(
    input: &Input,
    out: &Path,
    output: &str,
    options: &Options,
    cancel: &Cancel,
) -> Result<serde_json::Value, String> {
    use inbetween_face::data::{is_live_link, read_clip_limited, write_clip};
    use inbetween_face::edit::ConstraintKind;
    use inbetween_face::infer::plan::{span_seconds, EditResources, MethodChoice};
    use inbetween_face::infer::{EditJob, EditLimits, Guide};
    let limits = EditLimits::default();
    let clip = read_clip_limited(&input.path, limits.max_rows).map_err(|e| err(input, e))?;
    let mask = options.mask.as_deref().unwrap_or_default();
    let spans = mask
        .split(',')
        .map(|m| span_seconds(m.trim(), &clip))
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| format!("mask '{mask}' on {}: {}", input.path.display(), with_causes(&e)))?;
    // The unguided edit of `face edit --mask …` (no keys, take or visemes): the engine's auto rule.
    let kind = ConstraintKind::None;
    let method_name = options.method.as_deref().unwrap_or("auto");
    let choice = MethodChoice::parse(method_name).map_err(|e| e.to_string())?;
    let mut resources = EditResources::load_network(choice, kind, None).map_err(|e| with_causes(&e))?;
    resources.load_library(&[], false, limits.max_rows).map_err(|e| with_causes(&e))?;
    let job = EditJob {
        clip: &clip,
        spans: spans.clone(),
        channels: None,
        guide: Guide::None,
        method: resources.method(1).map_err(|e| with_causes(&e))?,
        seed: options.seed.unwrap_or(1),
        limits,
        cancel: cancel.clone(),
        guide_file: None,
        library: resources.library.as_ref(),
    };
    let method_used = job.method.name();
    let outcome = job.run().map_err(|e| err(input, e))?;
    let target = out.join(output);
    if let Some(parent) = target.parent() {
        std::fs::create_dir_all(parent).map_err(|e| format!("{}: {e}", parent.display()))?;
    }
    let live_link = is_live_link(&input.path);
    write_clip(&target, &outcome.clip, live_link).map_err(|e| with_causes(&e))?;
    Ok(serde_json::json!({
        "frames": clip.num_frames(),
        "fps": clip.measured_fps(),
        "spans_s": spans,
        "method": method_used,
        "seed": options.seed.unwrap_or(1),
        "live_link": live_link,
    }))
}
