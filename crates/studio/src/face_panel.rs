//! The face panel (issue 24): open a Live Link Face CSV or a curve CSV/JSON (uploaded, named under
//! `--root`, or a built-in procedural take), mask a span, choose a constraint (none, keys, a noisy
//! guide file, visemes from text or a TextGrid / phoneme file) and the blendshape groups, and fill it
//! with the face engine's [`EditJob`]; undo and redo; export in the input's own layout. Uploads go
//! through the same parsers as `face edit`, so a bad file's message names file and line.
//!
//! Every edit applies to the current version of the take (edits compose); the page receives only the
//! rows the edit changed, so a 2 s span costs a few kilobytes however long the take.

use std::path::Path;
use std::sync::{Arc, Mutex};

use axum::body::Bytes;
use axum::extract::{Query, State};
use axum::routing::{get, post};
use axum::{Json, Router};
use inbetween_face::data::{
    parse_curve_csv, parse_curve_json, parse_live_link, to_curve_csv_string, to_curve_json_string, to_live_link_string,
    BlendshapeClip, ARKIT_NAMES, MODEL_FPS, NUM_ARKIT,
};
use inbetween_face::edit::distances::{distance_bases, distance_matrix, DISTANCE_NAMES};
use inbetween_face::edit::groups::{parse_groups, Group};
use inbetween_face::edit::MotionLibrary;
use inbetween_face::infer::plan::{viseme_runs, EditResources, GuideSource, MethodChoice};
use inbetween_face::infer::{EditJob, EditLimits, Guide, KeyPose, Method};
use inbetween_face::visemes::{parse_phoneme_csv, parse_textgrid, Viseme};
use serde::Deserialize;
use serde_json::{json, Value};

use crate::error::{Result, StudioError};
use crate::jobs::answer;
use crate::safety::{extension_of, list_under_root, resolve_under_root, Folder};
use crate::state::Shared;
use crate::upload::{clean_name, utf8, UploadQuery};

crate::state::panel_state!(AppState, face, FaceState);

/// The layout the take was read in, which export writes back.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Layout {
    LiveLink,
    CurveCsv,
    CurveJson,
}

/// The open take and its versions (index 0 is the file as opened).
struct Session {
    name: String,
    layout: Layout,
    versions: Vec<BlendshapeClip>,
    /// The version shown; versions after it are the redo stack.
    current: usize,
    /// The fills of the last edit made with variants (the version they can replace, the clips).
    variants: Option<(usize, Vec<BlendshapeClip>)>,
}

/// A guide file for the next edits.
enum GuideFile {
    Noisy(BlendshapeClip),
    Visemes(Vec<(f64, f64, Viseme)>),
}

/// The panel's take and its guide file (the networks and the default retrieval library edits reuse
/// are the face engine's, loaded once per process: `EditResources`).
#[derive(Default)]
pub struct FaceState {
    session: Mutex<Option<Session>>,
    guide: Mutex<Option<(String, Arc<GuideFile>)>>,
    version: std::sync::atomic::AtomicU64,
}

impl FaceState {
    fn next_version(&self) -> u64 {
        self.version.fetch_add(1, std::sync::atomic::Ordering::SeqCst) + 1
    }
}

fn face_err(e: inbetween_face::data::FaceError) -> StudioError {
    StudioError::Engine(e.to_string())
}

/// Built-in take: a procedural face (blinks, speech, expressions) of this many seconds, at the
/// procedural generator's 25 fps.
pub const BUILTIN: (&str, f64) = ("builtin:procedural", 12.0);

/// `GET /api/face/corpus`: face captures under `--root` (CSV and JSON files below a folder named
/// `face`) and the built-in take.
pub async fn corpus(State(st): State<Arc<AppState>>) -> Json<Value> {
    let in_face = |rel: &str| rel.split('/').any(|c| c == "face");
    let files = st.config.root.as_deref().map_or_else(Vec::new, |root| {
        let keep = |rel: &str| matches!(extension_of(rel).as_str(), "csv" | "json") && in_face(rel);
        list_under_root(root, 2000, keep, |_, _| Folder::Descend)
    });
    Json(json!({
        "root": st.config.root.as_ref().map(|p| p.display().to_string()),
        "files": files,
        "builtin": [BUILTIN.0],
    }))
}

#[derive(Deserialize)]
pub struct OpenRequest {
    /// `builtin:procedural`, or a path relative to `--root`.
    pub path: String,
}

/// `POST /api/face/open`: the built-in take or a file under `--root`.
pub async fn open_path(State(st): State<Arc<AppState>>, Json(req): Json<OpenRequest>) -> Result<Json<Value>> {
    let file =
        if req.path == BUILTIN.0 { None } else { Some(resolve_under_root(st.config.root.as_deref(), &req.path)?) };
    let state = st.clone();
    let id = st.jobs.spawn("face-open", move |job| {
        job.progress("reading the take", 0.1);
        let (name, layout, clip) = match file {
            None => {
                let cfg = inbetween_face::procedural::ProceduralConfig::with_duration(BUILTIN.1);
                (BUILTIN.0.to_string(), Layout::LiveLink, inbetween_face::procedural::generate(&cfg, 1).clip)
            }
            Some(path) => {
                let shown = req.path.clone();
                let bytes = std::fs::read(&path).map_err(|e| StudioError::io(&shown, e))?;
                let (layout, clip) = parse_take(&shown, &bytes)?;
                (shown, layout, clip)
            }
        };
        opened(&state, name, layout, clip)
    });
    Ok(Json(answer(&st.jobs, id).await))
}

/// `POST /api/face/upload?name=…`: a take's bytes (Live Link CSV, curve CSV or JSON).
pub async fn upload(State(st): State<Arc<AppState>>, q: Query<UploadQuery>, body: Bytes) -> Result<Json<Value>> {
    let name = clean_name(&q.name);
    let state = st.clone();
    let id = st.jobs.spawn("face-open", move |job| {
        job.progress("parsing", 0.1);
        let (layout, clip) = parse_take(&name, &body)?;
        opened(&state, name, layout, clip)
    });
    Ok(Json(answer(&st.jobs, id).await))
}

/// A take from its bytes, by extension: `.json` curves; `.csv` Live Link when its header is, else curves.
fn parse_take(name: &str, bytes: &[u8]) -> Result<(Layout, BlendshapeClip)> {
    let text = utf8(name, bytes)?;
    let ext = Path::new(name).extension().and_then(|x| x.to_str()).map(|x| x.to_ascii_lowercase());
    let (layout, clip) = match ext.as_deref() {
        Some("json") => (Layout::CurveJson, parse_curve_json(&text, name)),
        Some("csv") => {
            let first = text.trim_start_matches('\u{feff}').lines().find(|l| !l.trim_start().starts_with('#'));
            if first.is_some_and(|l| l.starts_with("Timecode")) {
                (Layout::LiveLink, parse_live_link(&text, name))
            } else {
                (Layout::CurveCsv, parse_curve_csv(&text, name))
            }
        }
        _ => {
            return Err(StudioError::BadRequest(format!(
                "{name}: expected a Live Link Face CSV, or a curve CSV or JSON (time_s and the 52 ARKit names)"
            )))
        }
    };
    let clip = clip.map_err(face_err)?;
    if clip.num_frames() < 2 {
        return Err(StudioError::Engine(format!("{name}: {} row(s); a take needs at least 2", clip.num_frames())));
    }
    Ok((layout, clip))
}

/// The 52 ARKit columns of `clip`, rows `a..b`, rounded to 5 decimals.
fn columns(
    clip: &BlendshapeClip,
    a: usize,
    b: usize,
    only: Option<&[bool; NUM_ARKIT]>,
) -> serde_json::Map<String, Value> {
    let mut out = serde_json::Map::new();
    for (c, name) in ARKIT_NAMES.iter().enumerate() {
        if only.is_some_and(|o| !o[c]) {
            continue;
        }
        let v: Vec<f64> = (a..b).map(|f| (f64::from(clip.arkit(f)[c]) * 1e5).round() / 1e5).collect();
        out.insert(name.to_string(), json!(v));
    }
    out
}

/// The take opened: its session replaces the old one; the page gets every column.
fn opened(st: &AppState, name: String, layout: Layout, clip: BlendshapeClip) -> Result<Value> {
    let n = clip.num_frames();
    let msg = format!("opened {name}: {n} rows at {:.3} fps, {:.2} s", clip.fps(), clip.duration());
    let v = st.face.next_version();
    let export = export_url(st, &name, layout, &clip, v);
    let out = json!({
        "ok": true,
        "message": msg,
        "name": name,
        "frames": n,
        "fps": clip.fps(),
        "duration_s": clip.duration(),
        "times": clip.times().iter().map(|t| t - clip.times()[0]).collect::<Vec<_>>(),
        "columns": columns(&clip, 0, n, None),
        "groups": ARKIT_NAMES.iter().map(|n| (n.to_string(), json!(Group::of_shape(n).name()))).collect::<serde_json::Map<_, _>>(),
        "distance_names": DISTANCE_NAMES,
        "distance_bases": distance_bases(),
        "distance_matrix": distance_matrix(),
        "files": {"export": export},
    });
    *st.face.session.lock().unwrap_or_else(|p| p.into_inner()) =
        Some(Session { name, layout, versions: vec![clip], current: 0, variants: None });
    Ok(out)
}

/// The URL of the current version in the input's layout (made on download).
fn export_url(st: &AppState, name: &str, layout: Layout, clip: &BlendshapeClip, version: u64) -> String {
    let stem = Path::new(name).file_stem().and_then(|s| s.to_str()).unwrap_or("take").replace(':', "-");
    let (ext, ctype) = match layout {
        Layout::CurveJson => ("json", "application/json"),
        _ => ("csv", "text/csv; charset=utf-8"),
    };
    let clip = clip.clone();
    st.put_lazy(
        &format!("face/{stem}-edited.{ext}"),
        ctype,
        move || match layout {
            Layout::LiveLink => to_live_link_string(&clip).unwrap_or_else(|_| to_curve_csv_string(&clip)).into_bytes(),
            Layout::CurveCsv => to_curve_csv_string(&clip).into_bytes(),
            Layout::CurveJson => to_curve_json_string(&clip).into_bytes(),
        },
        version,
    )
}

/// `POST /api/face/guide?name=…`: a noisy take (a clip file) or phoneme timings (`.TextGrid`, or a
/// CSV whose header is `start,end,phoneme`) for the next edits.
pub async fn guide(State(st): State<Arc<AppState>>, q: Query<UploadQuery>, body: Bytes) -> Result<Json<Value>> {
    let name = clean_name(&q.name);
    let state = st.clone();
    let id = st.jobs.spawn("face-guide", move |_| {
        let text = utf8(&name, &body)?;
        let ext = Path::new(&name).extension().and_then(|x| x.to_str()).map(|x| x.to_ascii_lowercase());
        let phonemes = ext.as_deref() == Some("textgrid")
            || text.trim_start_matches('\u{feff}').trim_start().to_ascii_lowercase().starts_with("start,");
        let (g, what) = if phonemes {
            let spans = if ext.as_deref() == Some("textgrid") {
                parse_textgrid(&text, &name, None)
            } else {
                parse_phoneme_csv(&text, &name)
            }
            .map_err(face_err)?;
            let runs = viseme_runs(&spans).map_err(face_err)?;
            let n = runs.len();
            (GuideFile::Visemes(runs), format!("{n} phonemes"))
        } else {
            let (_, clip) = parse_take(&name, &body)?;
            let what = format!("a noisy take of {} rows", clip.num_frames());
            (GuideFile::Noisy(clip), what)
        };
        *state.face.guide.lock().unwrap_or_else(|p| p.into_inner()) = Some((name.clone(), Arc::new(g)));
        Ok(json!({"ok": true, "message": format!("guide {name}: {what}"), "guide": name, "phonemes": phonemes}))
    });
    Ok(Json(answer(&st.jobs, id).await))
}

/// One key of the page: a time and the shapes it sets.
#[derive(Deserialize)]
pub struct KeyRequest {
    pub time_s: f64,
    pub shapes: std::collections::BTreeMap<String, f32>,
}

#[derive(Deserialize)]
pub struct EditRequest {
    /// The span, seconds from the take's first row.
    pub start_s: f64,
    pub end_s: f64,
    /// `none`, `keys`, `noisy` (the uploaded guide), `visemes` (the uploaded phonemes) or `text`.
    #[serde(default = "default_constraint")]
    pub constraint: String,
    /// Words spoken over the span (constraint `text`).
    #[serde(default)]
    pub text: String,
    /// Keys (constraint `keys`).
    #[serde(default)]
    pub keys: Vec<KeyRequest>,
    /// Groups to regenerate (`all`, `mouth,jaw`, …); `default` (or absent): every group, visemes
    /// guiding the speech groups and the rest filled unguided (the face engine's default).
    #[serde(default = "default_groups")]
    pub groups: String,
    /// `auto` (the face bench's best: retrieval unguided or noisy, the network otherwise), `network`,
    /// `retrieval`, `linear` or `cubic`.
    #[serde(default = "default_method")]
    pub method: String,
    #[serde(default = "default_seed")]
    pub seed: u64,
    /// Fills made with seeds `seed`, `seed + 1`, … (1 to [`MAX_VARIANTS`]); the first becomes the new
    /// version and [`pick`] swaps in another.
    #[serde(default = "default_variants")]
    pub variants: u32,
}

/// Most fills one edit request makes.
pub const MAX_VARIANTS: u32 = 6;

/// An edit without a constraint is unguided.
fn default_constraint() -> String {
    "none".into()
}
/// Every group, the face engine's default split (see `groups`).
fn default_groups() -> String {
    "default".into()
}
/// The face engine's rule picks the method.
fn default_method() -> String {
    "auto".into()
}
/// The CLI's `face edit --seed` default.
fn default_seed() -> u64 {
    1
}
/// One fill.
fn default_variants() -> u32 {
    1
}

/// `POST /api/face/edit`: fill the span of the current version; the new version replaces the redo stack.
pub async fn edit(State(st): State<Arc<AppState>>, Json(req): Json<EditRequest>) -> Result<Json<Value>> {
    let state = st.clone();
    let id = st.jobs.spawn("face-edit", move |job| {
        let (name, layout, clip) = {
            let s = state.face.session.lock().unwrap_or_else(|p| p.into_inner());
            let s = s.as_ref().ok_or_else(no_take)?;
            (s.name.clone(), s.layout, s.versions[s.current].clone())
        };
        let channels = match req.groups.trim() {
            "" | "default" => None,
            g => Some(parse_groups(g).map_err(StudioError::BadRequest)?),
        };
        if !(1..=MAX_VARIANTS).contains(&req.variants) {
            return Err(StudioError::BadRequest(format!("variants {}: expected 1 to {MAX_VARIANTS}", req.variants)));
        }
        let guide = match req.constraint.as_str() {
            "none" => Guide::None,
            "keys" => {
                let mut keys = Vec::new();
                for (i, k) in req.keys.iter().enumerate() {
                    let mut shapes = Vec::new();
                    for (shape, v) in &k.shapes {
                        let c = inbetween_face::data::arkit_index(shape).ok_or_else(|| {
                            StudioError::BadRequest(format!("key {i}: '{shape}' is not an ARKit blendshape name"))
                        })?;
                        shapes.push((c, *v));
                    }
                    keys.push(KeyPose { time_s: k.time_s, shapes });
                }
                Guide::Keys(keys)
            }
            "text" => {
                let source = GuideSource::Text(&req.text, (req.start_s, req.end_s));
                source.load(EditLimits::default().max_rows).map_err(face_err)?.guide
            }
            "noisy" | "visemes" => {
                let g = state.face.guide.lock().unwrap_or_else(|p| p.into_inner()).clone();
                match (req.constraint.as_str(), g.as_ref().map(|g| g.1.as_ref())) {
                    ("noisy", Some(GuideFile::Noisy(c))) => Guide::Noisy(c.clone()),
                    ("visemes", Some(GuideFile::Visemes(v))) => Guide::Visemes(v.clone()),
                    _ => {
                        return Err(StudioError::BadRequest(format!(
                            "constraint '{}' needs its file: open {} as the guide first",
                            req.constraint,
                            if req.constraint == "noisy" {
                                "a noisy take of the same performance"
                            } else {
                                "a TextGrid or phoneme CSV"
                            }
                        )))
                    }
                }
            }
            other => {
                return Err(StudioError::BadRequest(format!(
                    "constraint '{other}': expected none, keys, noisy, visemes or text"
                )))
            }
        };
        let choice = MethodChoice::parse(&req.method).map_err(|e| StudioError::BadRequest(e.to_string()))?;
        let mut resources = EditResources::load_network(choice, guide.kind(), None)
            .map_err(|e| StudioError::Engine(format!("{}: {}", e.what, e.source)))?;
        resources.load_library(&[], channels.is_some(), EditLimits::default().max_rows).map_err(face_err)?;
        let method_name = resources.chosen.name();
        let n = req.variants as usize;
        let method = resources.method(n).map_err(face_err)?;
        let mut fills = Vec::with_capacity(n);
        for k in 0..n {
            job.progress(&format!("filling the span (variant {} of {n})", k + 1), 0.2 + 0.7 * k as f64 / n as f64);
            let seed = req.seed + k as u64;
            fills.push(fill(&clip, &req, channels, guide.clone(), method, seed, resources.library.as_ref(), job)?);
        }
        let first = &fills[0];
        let v = state.face.next_version();
        let export = export_url(&state, &name, layout, &first.clip, v);
        let model_frames = first.model_frames;
        let same = fills.iter().skip(1).filter(|f| f.clip.values() == first.clip.values()).count();
        let mut msg = format!(
            "{method_name} fill of {:.2} s..{:.2} s ({model_frames} frames at {MODEL_FPS} fps), masked error against \
             what was there: MSE {:.5}",
            req.start_s, req.end_s, first.mse
        );
        if n > 1 {
            msg += &format!("; {n} variants (seeds {}..{})", req.seed, req.seed + n as u64 - 1);
            if same > 0 {
                msg += &format!(", {same} the same as the first ({method_name} fills do not depend on the seed)");
            }
        }
        let (a, b) = first.rows;
        let first_columns = columns(&first.clip, a, b, Some(&first.changed));
        // Each variant's changed rows and columns (the first's as the answer's own), only with variants.
        let variants: Option<Vec<Value>> = (n > 1).then(|| {
            fills
                .iter()
                .enumerate()
                .map(|(k, f)| {
                    let cols = if k == 0 {
                        first_columns.clone()
                    } else {
                        columns(&f.clip, f.rows.0, f.rows.1, Some(&f.changed))
                    };
                    json!({
                        "variant": k + 1,
                        "seed": req.seed + k as u64,
                        "masked_mse": f.mse,
                        "rows": [f.rows.0, f.rows.1],
                        "columns": cols,
                    })
                })
                .collect()
        });
        let mse = first.mse;
        let mut s = state.face.session.lock().unwrap_or_else(|p| p.into_inner());
        let s = s.as_mut().ok_or_else(|| StudioError::BadRequest("the take was closed during the edit".into()))?;
        s.versions.truncate(s.current + 1);
        s.versions.push(fills[0].clip.clone());
        s.current += 1;
        s.variants = (n > 1).then(|| (s.current, fills.into_iter().map(|f| f.clip).collect()));
        Ok(json!({
            "ok": true,
            "message": msg,
            "method": method_name,
            "masked_mse": mse,
            "rows": [a, b],
            "columns": first_columns,
            "mask": [req.start_s, req.end_s],
            "version": s.current,
            "versions": s.versions.len(),
            "variants": variants,
            "files": {"export": export},
        }))
    });
    Ok(Json(answer(&st.jobs, id).await))
}

/// One fill of an edit: the new clip, its masked error against what was there (model rate), the
/// input rows it changed (`a..b`) and which channels.
struct Fill {
    clip: BlendshapeClip,
    mse: f64,
    model_frames: usize,
    rows: (usize, usize),
    changed: [bool; NUM_ARKIT],
}

#[allow(clippy::too_many_arguments)]
fn fill(
    clip: &BlendshapeClip,
    req: &EditRequest,
    channels: Option<[bool; NUM_ARKIT]>,
    guide: Guide,
    method: Method,
    seed: u64,
    library: Option<&MotionLibrary>,
    job: &crate::jobs::Job,
) -> Result<Fill> {
    let out = EditJob {
        clip,
        spans: vec![(req.start_s, req.end_s)],
        channels,
        guide,
        method,
        seed,
        limits: EditLimits::default(),
        cancel: job.token().clone(),
        guide_file: None,
        library,
    }
    .run()
    .map_err(face_err)?;
    // The masked error against what was there, at the model rate.
    let mse = out.masked_mse();
    // Rows the edit changed, and the changed columns there.
    let (rows, changed) = out.changed(clip);
    let rows = (rows.start, rows.end);
    let model_frames = out.mask.segments().iter().map(|s| s.len()).sum::<usize>();
    Ok(Fill { clip: out.clip, mse, model_frames, rows, changed })
}

#[derive(Deserialize)]
pub struct PickRequest {
    /// 1-based, as the edit's answer numbers its variants.
    pub variant: usize,
}

/// `POST /api/face/pick`: the version made by the last edit with variants becomes its variant
/// `variant` (in place: undo goes back to before the edit); answers like [`history`].
pub async fn pick(State(st): State<Arc<AppState>>, Json(req): Json<PickRequest>) -> Result<Json<Value>> {
    let mut s = st.face.session.lock().unwrap_or_else(|p| p.into_inner());
    let s = s.as_mut().ok_or_else(no_take)?;
    let (at, clips) = s
        .variants
        .as_ref()
        .ok_or_else(|| StudioError::BadRequest("no variants to pick from: generate with variants 2 or more".into()))?;
    if *at != s.current {
        return Err(StudioError::BadRequest(format!(
            "the variants belong to version {at}, version {} is shown: redo or generate again",
            s.current
        )));
    }
    let Some(clip) = req.variant.checked_sub(1).and_then(|k| clips.get(k)) else {
        return Err(StudioError::BadRequest(format!("variant {}: expected 1 to {}", req.variant, clips.len())));
    };
    s.versions[s.current] = clip.clone();
    let message = format!("variant {} of {} as version {}", req.variant, clips.len(), s.current);
    let mut answer = shown(&st, s, "face-pick", message);
    answer["variant"] = json!(req.variant);
    Ok(Json(answer))
}

/// The error of a request that needs a take before one is open.
fn no_take() -> StudioError {
    StudioError::BadRequest("open a face take first".into())
}

/// The answer of a history step or a pick: every column of the version now shown.
fn shown(st: &AppState, s: &Session, kind: &str, message: String) -> Value {
    let clip = &s.versions[s.current];
    let export = export_url(st, &s.name, s.layout, clip, st.face.next_version());
    json!({
        "ok": true,
        "kind": kind,
        "message": message,
        "rows": [0, clip.num_frames()],
        "columns": columns(clip, 0, clip.num_frames(), None),
        "version": s.current,
        "versions": s.versions.len(),
        "files": {"export": export},
    })
}

#[derive(Deserialize)]
pub struct StepRequest {
    /// `undo` or `redo`.
    pub step: String,
}

/// `POST /api/face/history`: undo or redo; answers with every column of the version now shown.
pub async fn history(State(st): State<Arc<AppState>>, Json(req): Json<StepRequest>) -> Result<Json<Value>> {
    let mut s = st.face.session.lock().unwrap_or_else(|p| p.into_inner());
    let s = s.as_mut().ok_or_else(no_take)?;
    match req.step.as_str() {
        "undo" if s.current > 0 => s.current -= 1,
        "redo" if s.current + 1 < s.versions.len() => s.current += 1,
        "undo" | "redo" => {}
        other => return Err(StudioError::BadRequest(format!("step '{other}': expected undo or redo"))),
    }
    let message = format!("{}: version {} of {}", req.step, s.current, s.versions.len() - 1);
    Ok(Json(shown(&st, s, &format!("face-{}", req.step), message)))
}

/// The panel's routes, nested under `/api/face` by the server.
pub fn router(shared: Arc<Shared>) -> Router {
    Router::new()
        .route("/corpus", get(corpus))
        .route("/open", post(open_path))
        .route("/upload", post(upload))
        .route("/guide", post(guide))
        .route("/edit", post(edit))
        .route("/history", post(history))
        .route("/pick", post(pick))
        .with_state(AppState::new(shared))
}
