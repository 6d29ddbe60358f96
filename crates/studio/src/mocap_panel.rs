//! The mocap panel: open a take (BVH, or an ASF + AMC pair; uploaded, or named under `--root`, or
//! the built-in procedural walk), choose keys with one of the mocap engine's selectors (uniform,
//! greedy, SIDQL, optimal, or the fewest keys under an error bound), see the reconstruction and
//! its per-frame error, and compress to `.ibk`. Uploads go through the same parsers as the CLI
//! (`inbetween_io::parse_bvh`, `parse_asf_amc`), so a bad file's message names file and line.

use std::path::Path;
use std::sync::{Arc, Mutex};

use axum::body::Bytes;
use axum::extract::{Query, State};
use axum::routing::{get, post};
use axum::{Json, Router};
use inbetween_core::procedural::{gait, GaitParams};
use inbetween_core::units::UnitChoice;
use inbetween_core::Motion;
use inbetween_io::motion_gltf::{motion_glb, poses_glb};
use inbetween_io::Progress;
use inbetween_mocap::codec::Budget;
use inbetween_mocap::{CompressJob, CompressReport, DecompressJob, PreparedClip, SelectJob, Selector};
use serde::Deserialize;
use serde_json::{json, Value};

use crate::error::{Result, StudioError};
use crate::jobs::{answer, Job};
use crate::safety::{extension_of, list_under_root, resolve_under_root, Folder};
use crate::state::Shared;
use crate::upload::{failed_now, utf8, UploadQuery};

crate::state::panel_state!(AppState, mocap, MocapState);

/// The open take: its name and the clip prepared for the keys jobs once when it opens (so a K
/// change pays only for its selection and reconstruction).
struct Take {
    name: String,
    clip: PreparedClip,
}

/// The panel's take and an ASF waiting for its AMC.
#[derive(Default)]
pub struct MocapState {
    take: Mutex<Option<Arc<Take>>>,
    pending_asf: Mutex<Option<(String, String)>>,
    version: std::sync::atomic::AtomicU64,
}

impl MocapState {
    fn next_version(&self) -> u64 {
        self.version.fetch_add(1, std::sync::atomic::Ordering::SeqCst) + 1
    }
}

/// Built-in takes (no files needed): procedural walks of the core crate.
pub const BUILTIN: &[(&str, usize)] = &[("builtin:walk", 240), ("builtin:walk-1000", 1000)];

/// `GET /api/mocap/corpus`: BVH and AMC files under `--root` (relative paths) and the built-ins.
pub async fn corpus(State(st): State<Arc<AppState>>) -> Json<Value> {
    // Motion files under `--root`, at most 6 folders deep and 5000 files.
    let files = st.config.root.as_deref().map_or_else(Vec::new, |root| {
        list_under_root(root, 5000, |rel| matches!(extension_of(rel).as_str(), "bvh" | "amc"), |_, _| Folder::Descend)
    });
    Json(json!({
        "root": st.config.root.as_ref().map(|p| p.display().to_string()),
        "files": files,
        "builtin": BUILTIN.iter().map(|b| b.0).collect::<Vec<_>>(),
    }))
}

#[derive(Deserialize)]
pub struct OpenRequest {
    /// `builtin:walk`, or a path relative to `--root`.
    pub path: String,
}

/// `POST /api/mocap/open`: a built-in take or a file under `--root`.
pub async fn open_path(State(st): State<Arc<AppState>>, Json(req): Json<OpenRequest>) -> Result<Json<Value>> {
    let source = match BUILTIN.iter().find(|b| b.0 == req.path) {
        Some(&(name, frames)) => Source::Builtin(name.to_string(), frames),
        None => Source::File(resolve_under_root(st.config.root.as_deref(), &req.path)?, req.path.clone()),
    };
    let state = st.clone();
    let id = st.jobs.spawn("open", move |job| {
        job.progress("reading the take", 0.1);
        let (name, motion) = match source {
            Source::Builtin(name, frames) => (name, gait(&GaitParams { frames, ..GaitParams::walk() })),
            Source::File(path, shown) => (shown, inbetween_io::load_motion(&path).map_err(|e| named(e, &path))?),
        };
        opened(&state, job, name, motion)
    });
    Ok(Json(answer(&st.jobs, id).await))
}

enum Source {
    Builtin(String, usize),
    File(std::path::PathBuf, String),
}

/// An I/O error's message with the absolute path shortened to its file name (the page shows it).
fn named(e: inbetween_io::IoError, path: &Path) -> StudioError {
    let full = path.display().to_string();
    let name = path.file_name().map(|n| n.to_string_lossy().to_string()).unwrap_or_default();
    StudioError::Engine(e.to_string().replace(&full, &name))
}

/// `POST /api/mocap/upload?name=…`: the file's bytes as the body. A `.bvh` opens at once; an
/// `.asf` waits for the `.amc` uploaded next.
pub async fn upload(State(st): State<Arc<AppState>>, q: Query<UploadQuery>, body: Bytes) -> Result<Json<Value>> {
    let name = q.name();
    let ext = Path::new(&name).extension().and_then(|x| x.to_str()).map(|x| x.to_ascii_lowercase());
    match ext.as_deref() {
        Some("asf") => {
            let t = utf8(&name, &body);
            let t = match t {
                Ok(t) => t,
                Err(e) => return Ok(Json(failed_now(&st.jobs, e))),
            };
            *st.mocap.pending_asf.lock().unwrap_or_else(|p| p.into_inner()) = Some((name.clone(), t));
            Ok(Json(json!({"pending": name, "need": "the .amc file of this skeleton"})))
        }
        Some("bvh") | Some("amc") => {
            let state = st.clone();
            let asf = if ext.as_deref() == Some("amc") {
                let a = st.mocap.pending_asf.lock().unwrap_or_else(|p| p.into_inner()).take();
                match a {
                    Some(a) => Some(a),
                    None => {
                        return Ok(Json(failed_now(
                            &st.jobs,
                            StudioError::BadRequest(format!(
                                "{name}: an .amc file needs its .asf skeleton: pick both files together"
                            )),
                        )))
                    }
                }
            } else {
                None
            };
            let id = st.jobs.spawn("open", move |job| {
                job.progress("parsing", 0.1);
                let body_text = utf8(&name, &body)?;
                let motion = match &asf {
                    Some((asf_name, asf_text)) => inbetween_io::parse_asf_amc(asf_text, &body_text, asf_name, &name)?,
                    None => inbetween_io::parse_bvh(&body_text, &name)?,
                };
                opened(&state, job, name.clone(), motion)
            });
            Ok(Json(answer(&st.jobs, id).await))
        }
        _ => Ok(Json(failed_now(
            &st.jobs,
            StudioError::BadRequest(format!("{name}: expected a .bvh file, or an .asf and .amc pair")),
        ))),
    }
}

fn opened(st: &AppState, job: &Job, name: String, motion: Motion) -> Result<Value> {
    if motion.num_frames() < 2 {
        return Err(StudioError::Engine(format!("{name}: {} frame(s); a take needs at least 2", motion.num_frames())));
    }
    job.progress("converting to glTF for the viewer", 0.6);
    let unit = UnitChoice::resolve(None, &motion.skeleton);
    let v = st.mocap.next_version();
    let glb = st.put_file("mocap/original.glb", "model/gltf-binary", motion_glb(&motion, "original", 1.0), v);
    let copy = motion.clone();
    let bvh = st.put_lazy(
        "mocap/original.bvh",
        "text/plain; charset=utf-8",
        move || inbetween_io::to_bvh_string(&copy).into_bytes(),
        v,
    );
    let msg = format!(
        "opened {name}: {} frames at {:.1} fps, {} joints; {unit}",
        motion.num_frames(),
        motion.fps(),
        motion.skeleton.len()
    );
    let out = json!({
        "ok": true,
        "message": msg,
        "name": name,
        "frames": motion.num_frames(),
        "fps": motion.fps(),
        "joints": motion.skeleton.len(),
        "unit": unit.unit.describe(),
        "unit_reason": unit.reason,
        "cm_per_unit": unit.cm_per_unit(),
        "files": {"original": bvh, "original_glb": glb},
    });
    job.progress("preparing the key selectors", 0.8);
    let take = Take { name, clip: PreparedClip::new(motion, unit)? };
    *st.mocap.take.lock().unwrap_or_else(|p| p.into_inner()) = Some(Arc::new(take));
    Ok(out)
}

fn current(st: &AppState) -> Result<Arc<Take>> {
    st.mocap.take.lock().unwrap_or_else(|p| p.into_inner()).clone().ok_or_else(|| {
        StudioError::BadRequest("open a take first (file picker, drag and drop, or the corpus list)".into())
    })
}

#[derive(Deserialize)]
pub struct KeysRequest {
    /// uniform, greedy, sidql, optimal, or bound (the fewest keys under `bound_cm`).
    pub method: String,
    /// Keys, counting the first and last frames.
    pub k: Option<usize>,
    /// Error bound in cm (method `bound`).
    pub bound_cm: Option<f64>,
}

/// `POST /api/mocap/keys`: keys by the chosen method, the reconstruction from them (quaternion
/// Hermite rotations, the engine's BVH output), its per-frame error in cm.
pub async fn keys(State(st): State<Arc<AppState>>, Json(req): Json<KeysRequest>) -> Result<Json<Value>> {
    let take = current(&st)?;
    let state = st.clone();
    let id = st.jobs.spawn("keys", move |job| keys_job(&state, job, &take, &req));
    Ok(Json(answer(&st.jobs, id).await))
}

fn keys_job(st: &AppState, job: &Job, take: &Take, req: &KeysRequest) -> Result<Value> {
    let sj =
        SelectJob { method: Selector::parse(&req.method)?, k: req.k, bound_cm: req.bound_cm, ..SelectJob::default() };
    sj.validate(take.clip.num_frames())?;
    // The selection fills 0.1–0.6 of the bar, the reconstruction 0.6–0.9.
    let progress = st.jobs.engine_progress(job.id, |stage, f| match stage {
        "reconstructing" => 0.6 + 0.3 * f,
        _ => 0.1 + 0.5 * f,
    });
    let report = sj.run(&take.clip, job.token(), &progress)?;
    if job.is_cancelled() {
        return Err(StudioError::Engine("cancelled".into()));
    }
    job.progress("converting to glTF for the viewer", 0.9);
    let m = &take.clip.motion;
    let (skeleton, frame_time) = (m.skeleton.clone(), m.frame_time);
    let glb = poses_glb(&skeleton, frame_time, &report.reconstruction.poses, "reconstructed", 1.0);
    let v = st.mocap.next_version();
    // The viewer loads the glTF (a binary buffer the page reads at once); the BVH is made when
    // downloaded.
    let glb = st.put_file("mocap/reconstructed.glb", "model/gltf-binary", glb, v);
    let poses = report.reconstruction.poses.clone();
    let url = st.put_lazy(
        "mocap/reconstructed.bvh",
        "text/plain; charset=utf-8",
        move || match Motion::from_poses(skeleton, frame_time, &poses) {
            Ok(rec) => inbetween_io::to_bvh_string(&rec).into_bytes(),
            Err(e) => format!("error: {e}\n").into_bytes(),
        },
        v,
    );
    let ms = job.elapsed_ms();
    let (e, planned) = (&report.reconstruction.error, &report.planned);
    let (label, select_ms) = (report.label(), report.select_ms);
    Ok(json!({
        "ok": true,
        "message": format!("{label}: {ms:.2} ms (selection {select_ms:.2} ms), {e}"),
        "method": req.method,
        "k": report.keys().len(),
        "keys": report.keys().frames(),
        "select_ms": select_ms,
        "error_cm": e.mean_cm,
        "max_cm": e.max_cm,
        "per_frame_cm": e.per_frame_cm,
        "spherical_mean_cm": planned.mean_cm,
        "spherical_max_cm": planned.max_cm,
        "mean_angle_deg": planned.mean_angle.to_degrees(),
        "files": {"reconstructed": url, "reconstructed_glb": glb},
    }))
}

#[derive(Deserialize)]
pub struct CompressRequest {
    /// Largest error of the decoded file, cm.
    pub bound_cm: f64,
}

/// `POST /api/mocap/compress`: the `.ibk` file the CLI's `mocap compress --max-error` writes
/// (the engine's `CompressJob`: version 4, every frame, the bound on the decoded file), its ratio
/// to the raw float channels and the decoded file's error.
pub async fn compress(State(st): State<Arc<AppState>>, Json(req): Json<CompressRequest>) -> Result<Json<Value>> {
    let take = current(&st)?;
    if !(req.bound_cm.is_finite() && req.bound_cm > 0.0) {
        return Err(StudioError::BadRequest(format!(
            "error bound {} cm: expected a positive number of cm",
            req.bound_cm
        )));
    }
    let state = st.clone();
    let id = st.jobs.spawn("compress", move |job| {
        let m = &take.clip.motion;
        job.progress("compressing", 0.05);
        let cj = CompressJob {
            budget: Budget::MaxErrorCm(req.bound_cm),
            version: None,
            segment_len: None,
            max_gap: m.num_frames().saturating_sub(1).max(1),
            unit: take.clip.unit.clone(),
        };
        let report = cj.run(m)?;
        let CompressReport::Sampled { compressed: c, version, raw_bytes: raw, .. } = report else {
            return Err(StudioError::Engine("an error bound writes a sampled file (version 3 or 4)".into()));
        };
        if job.is_cancelled() {
            return Err(StudioError::Engine("cancelled".into()));
        }
        job.progress("decoding", 0.7);
        let decoded = DecompressJob.run(&c.bytes, job.token(), &Progress::hidden())?.motion;
        let ratio = raw as f64 / c.bytes.len() as f64;
        let v = state.mocap.next_version();
        let stem = take
            .name
            .rsplit(['/', ':'])
            .next()
            .unwrap_or("take")
            .trim_end_matches(".bvh")
            .trim_end_matches(".amc")
            .to_string();
        let bytes = c.bytes.len();
        let ibk = state.put_file(&format!("mocap/{stem}.ibk"), "application/octet-stream", c.bytes, v);
        let dec = state.put_lazy(
            &format!("mocap/{stem}-decoded.bvh"),
            "text/plain; charset=utf-8",
            move || inbetween_io::to_bvh_string(&decoded).into_bytes(),
            v,
        );
        let ms = job.elapsed_ms();
        Ok(json!({
            "ok": true,
            "message": format!(
                "compress ≤ {} cm: {ms:.1} ms, .ibk version {version}, {bytes} bytes, ratio {ratio:.1}:1, decoded max {:.3} cm (p99 {:.3} cm)",
                req.bound_cm, c.max_error_cm, c.p99_error_cm
            ),
            "bytes": bytes,
            "raw_bytes": raw,
            "ratio": ratio,
            "error_cm": c.max_error_cm,
            "p99_cm": c.p99_error_cm,
            "unit": take.clip.unit.unit.describe(),
            "files": {"ibk": ibk, "decoded": dec},
        }))
    });
    Ok(Json(answer(&st.jobs, id).await))
}

/// The panel's routes, nested under `/api/mocap` by the server.
pub fn router(shared: Arc<Shared>) -> Router {
    Router::new()
        .route("/corpus", get(corpus))
        .route("/open", post(open_path))
        .route("/upload", post(upload))
        .route("/keys", post(keys))
        .route("/compress", post(compress))
        .with_state(AppState::new(shared))
}
