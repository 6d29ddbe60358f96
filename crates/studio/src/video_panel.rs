//! The video panel (issue 24): open an MP4, a GIF or a folder of PNG/JPEG frames (uploaded, named
//! under `--root`, or a built-in procedural clip with a scene cut), analyse it once (optical flows,
//! RSFNet trained on the clip or read from its cache, graph, shots: the video engine's [`analyse`]),
//! then generate new orders from a start frame with SDPF ([`resequence`]) as often as asked: each
//! regeneration reuses the analysis (and its cache of motion distances, warmed by one walk when the
//! clip opens). The page draws frames from one JPEG sprite of the clip, so a new
//! order costs only its indices; each jump (a step that is not the next source frame) carries the
//! engine's explanation of that step. Export writes MP4 and GIF through the engine's writer.

use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use axum::body::Bytes;
use axum::extract::{Query, State};
use axum::routing::{get, post};
use axum::{Json, Router};
use image::{imageops, RgbImage};
use inbetween_io::Progress;
use inbetween_video::frames::{procedural_clip, read_clip, write_clip, Clip, ProceduralKind, ReadOptions};
use inbetween_video::job::{AnalyseJob, AnalyseReport, ResequenceJob};
use inbetween_video::pipeline::reorder;
use inbetween_video::sdpf::SdpfParams;
use inbetween_video::VideoError;
use serde::Deserialize;
use serde_json::{json, Value};

use crate::error::{Result, StudioError};
use crate::jobs::{answer, Job};
use crate::safety::{extension_of, list_under_root, resolve_under_root, Folder};
use crate::state::Shared;
use crate::upload::UploadQuery;

crate::state::panel_state!(AppState, video, VideoState);

/// The open clip and its analysis (the engine's [`AnalyseJob`] report: it keeps the clip, the
/// analysis and its caches of motion distances and of M_D's per-transition differences).
struct Opened {
    name: String,
    analysed: Arc<AnalyseReport>,
}

/// An engine error as the page shows it: a start frame past the clip is the request's fault.
fn engine(e: VideoError) -> StudioError {
    match e {
        VideoError::StartOutside { .. } => StudioError::BadRequest(e.to_string()),
        _ => StudioError::Engine(e.to_string()),
    }
}

/// The panel's clip.
#[derive(Default)]
pub struct VideoState {
    open: Mutex<Option<Arc<Opened>>>,
    version: std::sync::atomic::AtomicU64,
}

impl VideoState {
    fn next_version(&self) -> u64 {
        self.version.fetch_add(1, std::sync::atomic::Ordering::SeqCst) + 1
    }
}

/// Built-in clip: the procedural "mixed" clip (a pendulum, a linear stretch and a scene cut).
pub const BUILTIN: (&str, usize) = ("builtin:mixed", 96);

/// Width of a frame in the page's sprite, pixels.
pub const THUMB_WIDTH: u32 = 320;
/// Frames per sprite row.
pub const SPRITE_COLUMNS: u32 = 12;

/// `GET /api/video/corpus`: MP4 and GIF files and folders of PNG/JPEG frames under `--root` (below a
/// folder named `video`), and the built-in clip.
pub async fn corpus(State(st): State<Arc<AppState>>) -> Json<Value> {
    let in_video = |rel: &str| rel.split('/').any(|c| c == "video");
    let files = st.config.root.as_deref().map_or_else(Vec::new, |root| {
        let keep = |rel: &str| matches!(extension_of(rel).as_str(), "mp4" | "m4v" | "mov" | "gif") && in_video(rel);
        // A folder of PNG/JPEG frames under `video` is one clip.
        let folder = |rel: &str, dir: &Path| {
            let images = std::fs::read_dir(dir).is_ok_and(|rd| {
                rd.flatten()
                    .any(|f| matches!(extension_of(&f.file_name().to_string_lossy()).as_str(), "png" | "jpg" | "jpeg"))
            });
            if images && in_video(rel) {
                Folder::Take
            } else {
                Folder::Descend
            }
        };
        list_under_root(root, 2000, keep, folder)
    });
    Json(json!({ "files": files, "builtin": [BUILTIN.0] }))
}

#[derive(Deserialize)]
pub struct OpenRequest {
    /// `builtin:mixed`, or a file or folder relative to `--root`.
    pub path: String,
}

/// `POST /api/video/open`: the built-in clip or a file / folder under `--root`; decodes and analyses.
pub async fn open_path(State(st): State<Arc<AppState>>, Json(req): Json<OpenRequest>) -> Result<Json<Value>> {
    let file = if req.path == BUILTIN.0 {
        None
    } else {
        Some(resolve_under_root(st.config.root.as_deref(), req.path.trim_end_matches('/'))?)
    };
    let state = st.clone();
    let id = st.jobs.spawn("video-open", move |job| {
        job.progress("decoding", 0.05);
        let (name, clip) = match file {
            None => (BUILTIN.0.to_string(), procedural_clip(ProceduralKind::Mixed, BUILTIN.1, 192, 144, 7)),
            Some(path) => (req.path.clone(), decode(&path, &req.path)?),
        };
        opened(&state, job, name, clip)
    });
    Ok(Json(answer(&st.jobs, id).await))
}

fn decode(path: &Path, shown: &str) -> Result<Clip> {
    let (clip, _) = read_clip(path, &ReadOptions::default()).map_err(|e| {
        // The page shows the name the user knows, not a temporary or absolute path.
        StudioError::Engine(e.to_string().replace(&path.display().to_string(), shown))
    })?;
    Ok(clip)
}

/// `POST /api/video/upload?name=…`: an MP4 or GIF's bytes; decodes and analyses.
pub async fn upload(State(st): State<Arc<AppState>>, q: Query<UploadQuery>, body: Bytes) -> Result<Json<Value>> {
    let name = q.name();
    let state = st.clone();
    let id = st.jobs.spawn("video-open", move |job| {
        job.progress("decoding", 0.05);
        let ext = Path::new(&name).extension().and_then(|x| x.to_str()).map(|x| x.to_ascii_lowercase());
        if !matches!(ext.as_deref(), Some("mp4" | "m4v" | "mov" | "gif")) {
            return Err(StudioError::BadRequest(format!(
                "{name}: expected an .mp4 (H.264) or an animated .gif (or, from the corpus, a folder of PNG/JPEG frames)"
            )));
        }
        let dir = tempfile::tempdir().map_err(|e| StudioError::io(std::env::temp_dir(), e))?;
        let path: PathBuf = dir.path().join(format!("upload.{}", ext.unwrap_or_default()));
        std::fs::write(&path, &body).map_err(|e| StudioError::io(&path, e))?;
        let clip = decode(&path, &name)?;
        opened(&state, job, name.clone(), clip)
    });
    Ok(Json(answer(&st.jobs, id).await))
}

/// The clip's frames scaled to [`THUMB_WIDTH`] in one JPEG, [`SPRITE_COLUMNS`] per row.
fn sprite(clip: &Clip) -> Result<(Vec<u8>, u32, u32)> {
    let (w, h) = (clip.width().max(1), clip.height().max(1));
    let tw = THUMB_WIDTH.min(w);
    let th = ((u64::from(h) * u64::from(tw)) / u64::from(w)).max(1) as u32;
    let n = clip.len() as u32;
    let cols = SPRITE_COLUMNS.min(n.max(1));
    let rows = n.div_ceil(cols);
    let mut sheet = RgbImage::new(cols * tw, rows * th);
    for (i, f) in clip.frames.iter().enumerate() {
        let small = imageops::resize(f, tw, th, imageops::FilterType::Triangle);
        let (x, y) = ((i as u32 % cols) * tw, (i as u32 / cols) * th);
        imageops::replace(&mut sheet, &small, i64::from(x), i64::from(y));
    }
    let mut jpeg = Vec::new();
    image::codecs::jpeg::JpegEncoder::new_with_quality(&mut jpeg, 80)
        .encode_image(&sheet)
        .map_err(|e| StudioError::Runtime(format!("encoding the frame sprite: {e}")))?;
    Ok((jpeg, tw, th))
}

fn opened(st: &AppState, job: &Job, name: String, clip: Clip) -> Result<Value> {
    if clip.len() < 2 {
        return Err(StudioError::Engine(format!("{name}: {} frame(s); a clip needs at least 2", clip.len())));
    }
    job.progress("analysing: optical flow, RSFNet (trained on the clip, or from its cache), graph, cuts", 0.15);
    // The job's token: a cancel stops the flow, the metric's training and the graph between stages.
    let analysed = Arc::new(AnalyseJob::for_clip(clip).run(job.token(), &Progress::hidden()).map_err(engine)?);
    if job.is_cancelled() {
        return Err(StudioError::Engine("cancelled".into()));
    }
    // One walk from the first frame fills the analysis's PMSM cache (most pairs any later order
    // needs), so a Generate after opening asks the network for few new pairs.
    job.progress("warming the motion-distance cache (one walk from frame 0)", 0.75);
    ResequenceJob::on(analysed.clone()).run(job.token(), &Progress::hidden()).map_err(engine)?;
    if job.is_cancelled() {
        return Err(StudioError::Engine("cancelled".into()));
    }
    job.progress("frame sprite for the page", 0.9);
    let clip = &analysed.clip;
    let (jpeg, tw, th) = sprite(clip)?;
    let v = st.video.next_version();
    let sprite_url = st.put_file("video/frames.jpg", "image/jpeg", jpeg, v);
    let msg = format!(
        "opened {name}: {} frames {}x{} at {:.3} fps, {} shot(s); {}",
        clip.len(),
        clip.width(),
        clip.height(),
        clip.fps,
        analysed.shots,
        analysed.metric
    );
    let out = json!({
        "ok": true,
        "message": msg,
        "name": name,
        "frames": clip.len(),
        "fps": clip.fps,
        "width": clip.width(),
        "height": clip.height(),
        "shots": analysed.shot,
        "cuts": analysed.shot_starts,
        "directed": analysed.directed,
        "stages": analysed.stages.iter().map(|s| json!({"stage": s.stage, "s": s.seconds})).collect::<Vec<_>>(),
        "source_md": analysed.source_md,
        "sprite": {"url": sprite_url, "width": tw, "height": th, "columns": SPRITE_COLUMNS.min(clip.len() as u32)},
    });
    *st.video.open.lock().unwrap_or_else(|p| p.into_inner()) = Some(Arc::new(Opened { name, analysed }));
    Ok(out)
}

#[derive(Deserialize)]
pub struct GenerateRequest {
    /// Start frame (source index).
    #[serde(default)]
    pub start: usize,
    /// Frames of the new order (default: the source's length).
    pub length: Option<usize>,
    /// End on a frame that returns to the start.
    #[serde(default, rename = "loop")]
    pub loop_close: bool,
    #[serde(default)]
    pub seed: u64,
}

/// `POST /api/video/generate`: a new order from the analysed clip.
pub async fn generate(State(st): State<Arc<AppState>>, Json(req): Json<GenerateRequest>) -> Result<Json<Value>> {
    let open = st.video.open.lock().unwrap_or_else(|p| p.into_inner()).clone();
    let state = st.clone();
    let id = st.jobs.spawn("video-generate", move |job| {
        let o = open.ok_or_else(|| StudioError::BadRequest("open a clip first".into()))?;
        job.progress("SDPF walk", 0.1);
        let params =
            SdpfParams { length: req.length, loop_close: req.loop_close, seed: req.seed, ..SdpfParams::default() };
        let run = ResequenceJob { start: req.start, params, ..ResequenceJob::on(o.analysed.clone()) };
        run.validate().map_err(engine)?;
        let report = run.run(job.token(), &Progress::hidden()).map_err(engine)?;
        let seq =
            report.sequences.into_iter().next().ok_or_else(|| StudioError::Engine("no path from this start".into()))?;
        let jumps: Vec<Value> = seq
            .jumps
            .iter()
            .map(|j| json!({"position": j.position, "from": j.from, "to": j.to, "kind": j.kind.word(), "text": j.text}))
            .collect();
        let closing = seq.closing.as_ref().map(|t| json!({"from": t.from, "to": t.to, "text": t.text}));
        let v = state.video.next_version();
        let (mp4, gif) = export(&state, &o, &seq.order, v);
        let msg = format!(
            "SDPF from frame {}: {} frames ({:?}), {} jumps, M_D {:.4} (source {:.4}), walk {:.0} ms",
            req.start,
            seq.order.len(),
            seq.stop,
            jumps.len(),
            seq.md,
            o.analysed.source_md,
            report.walk_s * 1e3
        );
        Ok(json!({
            "ok": true,
            "message": msg,
            "order": seq.order,
            "jumps": jumps,
            "md": seq.md,
            "source_md": o.analysed.source_md,
            "closes_loop": seq.closes_loop,
            "closing": closing,
            "walk_ms": report.walk_s * 1e3,
            "files": {"mp4": mp4, "gif": gif},
        }))
    });
    Ok(Json(answer(&st.jobs, id).await))
}

/// MP4 and GIF of the new order, written on first download through the engine's writer.
fn export(st: &AppState, o: &Arc<Opened>, order: &[usize], v: u64) -> (String, String) {
    let stem = Path::new(&o.name).file_stem().and_then(|s| s.to_str()).unwrap_or("clip").replace(':', "-");
    let mut urls = Vec::new();
    for (ext, ctype) in [("mp4", "video/mp4"), ("gif", "image/gif")] {
        let (o, order) = (o.clone(), order.to_vec());
        urls.push(st.put_lazy(
            &format!("video/{stem}-new.{ext}"),
            ctype,
            move || {
                let Ok(dir) = tempfile::tempdir() else { return Vec::new() };
                let path = dir.path().join(format!("new.{ext}"));
                match write_clip(&path, &reorder(&o.analysed.clip, &order)) {
                    Ok(()) => std::fs::read(&path).unwrap_or_default(),
                    Err(_) => Vec::new(),
                }
            },
            v,
        ));
    }
    let gif = urls.pop().unwrap_or_default();
    (urls.pop().unwrap_or_default(), gif)
}

/// The panel's routes, nested under `/api/video` by the server.
pub fn router(shared: Arc<Shared>) -> Router {
    Router::new()
        .route("/corpus", get(corpus))
        .route("/open", post(open_path))
        .route("/upload", post(upload))
        .route("/generate", post(generate))
        .with_state(AppState::new(shared))
}
