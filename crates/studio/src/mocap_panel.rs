//! The mocap panel: open a take (BVH, or an ASF + AMC pair; uploaded, or named under `--root`, or
//! the built-in procedural walk), choose keys with one of the mocap engine's selectors (uniform,
//! greedy, SIDQL, optimal, or the fewest keys under an error bound), see the reconstruction and
//! its per-frame error, and compress to `.ibk`. Uploads go through the same parsers as the CLI
//! (`inbetween_io::parse_bvh`, `parse_asf_amc`), so a bad file's message names file and line.

use std::path::Path;
use std::sync::{Arc, Mutex};
use std::time::Instant;

use axum::body::Bytes;
use axum::extract::{Query, State};
use axum::Json;
use glam::DVec3;
use inbetween_core::procedural::{gait, GaitParams};
use inbetween_core::units::UnitChoice;
use inbetween_core::{forward, positions_clip, KeyframeSet, Motion, Pose, Skeleton};
use inbetween_io::motion_gltf::{motion_glb, poses_glb};
use inbetween_mocap::codec::job::{CompressJob, CompressReport};
use inbetween_mocap::codec::{self, Budget};
use inbetween_mocap::metrics::SegmentModel;
use inbetween_mocap::rotations::reconstruct_poses;
use inbetween_mocap::select::OptimalMemo;
use inbetween_mocap::select::{self, sidql::SidqlPolicy};
use inbetween_mocap::{ErrorMeasure, RotationMotion, SegmentTable, SphericalMotion};
use serde::Deserialize;
use serde_json::{json, Value};

use crate::error::{Result, StudioError};
use crate::jobs::{answer, Job};
use crate::safety::{extension_of, list_under_root, resolve_under_root, Folder};
use crate::server::AppState;

/// The open take, with what every keys job needs computed once when it opens (so a K change
/// pays only for its selection and reconstruction).
struct Take {
    name: String,
    motion: Motion,
    unit: UnitChoice,
    /// The spherical representation the selectors work on (§3.1), lengths in cm.
    rep: SphericalMotion,
    /// Local rotations per frame, the key poses of a reconstruction.
    rotations: RotationMotion,
    /// World joint positions per frame (file units), the reference of the per-frame error.
    positions: Vec<Vec<DVec3>>,
    /// Greedy's insertion order on this take, made at the first greedy request and grown as larger
    /// K are asked: a K change is then a prefix of it.
    greedy: Mutex<Option<select::GreedyOrder<'static>>>,
    /// The segment costs optimal searches on this take learnt (20·n² bytes), kept for the next K on
    /// takes up to [`OPTIMAL_MEMO_FRAMES`]: the first optimal K costs seconds on 1000 frames, the
    /// next ones tens of milliseconds.
    optimal: Mutex<Option<OptimalMemo>>,
    /// SIDQL's windows of this take and their keyings so far.
    sidql: Mutex<Option<select::sidql::SidqlLong<'static>>>,
}

/// The committed SIDQL policy (weights compiled into the binary), loaded once.
fn committed_policy() -> Result<&'static SidqlPolicy> {
    static POLICY: std::sync::OnceLock<SidqlPolicy> = std::sync::OnceLock::new();
    if let Some(p) = POLICY.get() {
        return Ok(p);
    }
    let p = SidqlPolicy::committed()?;
    Ok(POLICY.get_or_init(|| p))
}

/// The longest take whose optimal-keys memo the studio keeps (80 MB at 2000 frames).
const OPTIMAL_MEMO_FRAMES: usize = 2000;

impl Take {
    fn new(name: String, motion: Motion, unit: UnitChoice) -> Result<Take> {
        let cm = unit.cm_per_unit();
        let mut rep = SphericalMotion::from_motion(&motion)?;
        rep.cm_per_unit = cm;
        let rotations = RotationMotion::from_motion_in(&motion, cm)?;
        let positions = positions_clip(&motion);
        Ok(Take {
            name,
            motion,
            unit,
            rep,
            rotations,
            positions,
            greedy: Mutex::new(None),
            optimal: Mutex::new(None),
            sidql: Mutex::new(None),
        })
    }
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

#[derive(Deserialize)]
pub struct UploadQuery {
    /// The file's name as the user picked it (its extension picks the parser).
    pub name: String,
}

/// `POST /api/mocap/upload?name=…`: the file's bytes as the body. A `.bvh` opens at once; an
/// `.asf` waits for the `.amc` uploaded next.
pub async fn upload(State(st): State<Arc<AppState>>, q: Query<UploadQuery>, body: Bytes) -> Result<Json<Value>> {
    let name: String = q.name.chars().filter(|c| !c.is_control() && *c != '/' && *c != '\\').take(200).collect();
    let ext = Path::new(&name).extension().and_then(|x| x.to_str()).map(|x| x.to_ascii_lowercase());
    match ext.as_deref() {
        Some("asf") => {
            let t = utf8(&name, &body);
            let t = match t {
                Ok(t) => t,
                Err(e) => return Ok(Json(failed_now(&st, e))),
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
                            &st,
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
            &st,
            StudioError::BadRequest(format!("{name}: expected a .bvh file, or an .asf and .amc pair")),
        ))),
    }
}

/// The upload as text, or an error naming the file, the line and the first byte that is not UTF-8.
pub(crate) fn utf8(name: &str, bytes: &[u8]) -> Result<String> {
    String::from_utf8(bytes.to_vec()).map_err(|e| {
        let at = e.utf8_error().valid_up_to();
        StudioError::Engine(format!(
            "{name}:{}: expected UTF-8 text, found byte 0x{:02x}",
            1 + bytes[..at].iter().filter(|&&b| b == b'\n').count(),
            bytes[at]
        ))
    })
}

/// A job that fails at once (so the page's `ready()` sees the error like any other job's).
pub(crate) fn failed_now(st: &AppState, e: StudioError) -> Value {
    let id = st.jobs.spawn("open", move |_| Err(e));
    json!({"job": id})
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
    let take = Take::new(name, motion, unit)?;
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
    let m = &take.motion;
    let n = m.num_frames();
    let cm = take.unit.cm_per_unit();
    let rep = &take.rep;
    let need_k = || -> Result<usize> {
        let k = req.k.ok_or_else(|| StudioError::BadRequest(format!("method '{}' needs K", req.method)))?;
        select::check_k(n, k)?;
        Ok(k)
    };
    job.progress("choosing keys", 0.1);
    let t = Instant::now();
    let (keys, label) = match req.method.as_str() {
        "uniform" => {
            let k = need_k()?;
            (select::uniform(n, k)?, format!("uniform K={k}"))
        }
        "greedy" => {
            let k = need_k()?;
            let mut order = take.greedy.lock().unwrap_or_else(|p| p.into_inner());
            let keys = order.get_or_insert_with(|| select::GreedyOrder::angle(rep)).keys(k, job.token())?;
            (keys, format!("greedy K={k}"))
        }
        "optimal" => {
            let k = need_k()?;
            let (keys, _) = if n <= OPTIMAL_MEMO_FRAMES {
                let mut memo = take.optimal.lock().unwrap_or_else(|p| p.into_inner());
                let memo = memo.get_or_insert_with(|| OptimalMemo::new(n, ErrorMeasure::Angle));
                let mut progress = |f: f64| job.progress("choosing keys (exact optimum)", 0.1 + 0.5 * f);
                select::optimal_spherical_memo(rep, k, ErrorMeasure::Angle, job.token(), memo, &mut progress)?
            } else {
                select::optimal_spherical_cancellable(rep, k, ErrorMeasure::Angle, job.token())?
            };
            (keys, format!("optimal K={k}"))
        }
        "sidql" => {
            let k = need_k()?;
            // Windows of at most 64 frames on a longer take (the policy's range), each window's
            // keyings kept with the take for the next K.
            let mut sidql = take.sidql.lock().unwrap_or_else(|p| p.into_inner());
            if sidql.is_none() {
                *sidql = Some(select::sidql::SidqlLong::new(committed_policy()?, m, cm)?);
            }
            (sidql.as_mut().expect("made just above").keys(k)?, format!("SIDQL K={k}"))
        }
        "bound" => {
            let b = req
                .bound_cm
                .ok_or_else(|| StudioError::BadRequest("method 'bound' needs an error bound in cm".into()))?;
            if !(b.is_finite() && b > 0.0) {
                return Err(StudioError::BadRequest(format!("error bound {b} cm: expected a positive number of cm")));
            }
            // The CLI's default longest gap between keys (`--max-gap-s 0.5`).
            let max_gap = ((0.5 / m.frame_time).round() as usize).clamp(1, n - 1);
            let table = SegmentTable::bounded(rep, max_gap, b);
            let keys = select::error_bounded(&table, b, ErrorMeasure::Angle)?;
            let k = keys.frames().len();
            (keys, format!("fewest keys under {b} cm: K={k}"))
        }
        other => {
            return Err(StudioError::BadRequest(format!(
                "method '{other}': expected uniform, greedy, sidql, optimal or bound"
            )))
        }
    };
    let select_ms = t.elapsed().as_secs_f64() * 1000.0;
    if job.is_cancelled() {
        return Err(StudioError::Engine("cancelled".into()));
    }
    job.progress("reconstructing", 0.6);
    // The planned error beside the reconstruction, its error curve beside its glTF (rayon's pool).
    // Both from the rebuilt local poses: the clip's Euler channels are made for the BVH download.
    let skeleton = &take.motion.skeleton;
    let frame_time = take.motion.frame_time;
    let (planned, built) = rayon::join(
        || rep.error(&keys),
        || -> Result<_> {
            let poses = reconstruct(take, &keys)?;
            let ((per_frame, mean, max), glb) = rayon::join(
                || per_frame_error(&take.positions, skeleton, &poses, cm),
                || poses_glb(skeleton, frame_time, &poses, "reconstructed", 1.0),
            );
            Ok((poses, per_frame, mean, max, glb))
        },
    );
    let (poses, per_frame, mean, max, glb) = built?;
    let skeleton = skeleton.clone();
    let v = st.mocap.next_version();
    // The viewer loads the glTF (a binary buffer the page reads at once); the BVH is made when
    // downloaded.
    let glb = st.put_file("mocap/reconstructed.glb", "model/gltf-binary", glb, v);
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
    Ok(json!({
        "ok": true,
        "message": format!("{label}: {ms:.2} ms (selection {select_ms:.2} ms), mean {mean:.2} cm, max {max:.2} cm"),
        "method": req.method,
        "k": keys.frames().len(),
        "keys": keys.frames(),
        "select_ms": select_ms,
        "error_cm": mean,
        "max_cm": max,
        "per_frame_cm": per_frame,
        "spherical_mean_cm": planned.mean_cm,
        "spherical_max_cm": planned.max_cm,
        "mean_angle_deg": planned.mean_angle.to_degrees(),
        "files": {"reconstructed": url, "reconstructed_glb": glb},
    }))
}

/// The local poses rebuilt from the key poses (the engine's rotation reconstruction).
fn reconstruct(take: &Take, keys: &KeyframeSet) -> Result<Vec<Pose>> {
    let frames = keys.frames();
    let poses: Vec<_> = frames.iter().map(|&f| take.rotations.frames[f].clone()).collect();
    Ok(reconstruct_poses(&take.motion.skeleton, take.motion.frame_time, frames, &poses)?)
}

/// Per frame, the mean distance (cm) between original and rebuilt joints; the mean over frames
/// and the largest joint distance.
fn per_frame_error(original: &[Vec<DVec3>], skeleton: &Skeleton, poses: &[Pose], cm: f64) -> (Vec<f64>, f64, f64) {
    use rayon::prelude::*;
    let pb: Vec<Vec<DVec3>> = poses.par_iter().map(|p| forward(skeleton, p).positions).collect();
    let mut max = 0.0f64;
    let per: Vec<f64> = original
        .iter()
        .zip(&pb)
        .map(|(fa, fb)| {
            let mut sum = 0.0;
            for (x, y) in fa.iter().zip(fb) {
                let d = x.distance(*y) * cm;
                max = max.max(d);
                sum += d;
            }
            sum / fa.len().max(1) as f64
        })
        .collect();
    let mean = per.iter().sum::<f64>() / per.len().max(1) as f64;
    (per, mean, max)
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
        let m = &take.motion;
        job.progress("compressing", 0.05);
        let cj = CompressJob {
            budget: Budget::MaxErrorCm(req.bound_cm),
            version: None,
            segment_len: None,
            max_gap: m.num_frames().saturating_sub(1).max(1),
            unit: take.unit.clone(),
        };
        let report = cj.run(m)?;
        let CompressReport::Sampled { compressed: c, version, .. } = report else {
            return Err(StudioError::Engine("an error bound writes a sampled file (version 3 or 4)".into()));
        };
        if job.is_cancelled() {
            return Err(StudioError::Engine("cancelled".into()));
        }
        job.progress("decoding", 0.7);
        let decoded = codec::read(&c.bytes)?.motion()?;
        let raw = codec::raw_bytes(m);
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
            "unit": take.unit.unit.describe(),
            "files": {"ibk": ibk, "decoded": dec},
        }))
    });
    Ok(Json(answer(&st.jobs, id).await))
}
