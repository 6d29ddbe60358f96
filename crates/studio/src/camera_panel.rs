//! The camera panel (issue 24; the camera paper's §6.1 and Fig. 9): a scene of two characters (two
//! mocap takes the user opens, or the built-in procedural pair), camera keys in Toric space (the page
//! edits them), and one generation that returns the trajectory of every style at once (the four
//! behaviours, and the style of a reference clip when one is open), through the camera engine's
//! [`GenerateJob`]. The page plays a chosen trajectory through the shot camera; JSON and glTF (camera
//! and both characters) are offered per style.

use std::path::Path;
use std::sync::{Arc, Mutex, OnceLock};

use axum::body::Bytes;
use axum::extract::{Query, State};
use axum::routing::post;
use axum::{Json, Router};
use glam::{DQuat, DVec3};
use inbetween_camera::dataset::{scene_from_motions, Scene, BEHAVIOURS};
use inbetween_camera::infer::{example_keys, GenerateJob, GenerateOptions, Keys, ReferenceClip, Style};
use inbetween_camera::toric::{from_pose, CameraPose, Lens};
use inbetween_camera::weights::{self, CameraWeights};
use inbetween_core::Motion;
use serde::Deserialize;
use serde_json::{json, Value};

use crate::error::{Result, StudioError};
use crate::jobs::answer;
use crate::state::Shared;
use crate::upload::{clean_name, utf8};

crate::state::panel_state!(AppState, camera, CameraState);

/// The panel's scene, the first take waiting for its partner, a reference style, the weights.
#[derive(Default)]
pub struct CameraState {
    scene: Mutex<Option<Arc<Scene>>>,
    pending: Mutex<Option<(String, Motion)>>,
    reference: Mutex<Option<Style>>,
    weights: OnceLock<std::result::Result<CameraWeights, String>>,
    version: std::sync::atomic::AtomicU64,
}

impl CameraState {
    fn weights(&self) -> Result<&CameraWeights> {
        self.weights
            .get_or_init(|| weights::committed().map_err(|e| e.to_string()))
            .as_ref()
            .map_err(|e| StudioError::Engine(format!("the committed camera weights: {e}")))
    }

    fn scene(&self) -> Result<Arc<Scene>> {
        self.scene
            .lock()
            .unwrap_or_else(|p| p.into_inner())
            .clone()
            .ok_or_else(|| StudioError::BadRequest("open a scene first (two takes, or the built-in pair)".into()))
    }
}

/// Built-in scene: the camera engine's procedural pair, 300 frames at 30 fps.
pub const BUILTIN: (&str, usize) = ("builtin:pair", 300);

#[derive(Deserialize)]
pub struct OpenRequest {
    pub path: String,
}

/// `POST /api/camera/open {path: "builtin:pair"}`.
pub async fn open(State(st): State<Arc<AppState>>, Json(req): Json<OpenRequest>) -> Result<Json<Value>> {
    if req.path != BUILTIN.0 {
        return Err(StudioError::BadRequest(format!("unknown scene '{}': expected {}", req.path, BUILTIN.0)));
    }
    let state = st.clone();
    let id = st.jobs.spawn("camera-scene", move |_| {
        let scene = Scene::procedural(11, BUILTIN.1, 30.0);
        opened(&state, BUILTIN.0.to_string(), scene, Vec::new())
    });
    Ok(Json(answer(&st.jobs, id).await))
}

#[derive(Deserialize)]
pub struct UploadQuery {
    pub name: String,
    /// 0 for the first take of the pair, 1 for the second (which builds the scene).
    #[serde(default)]
    pub slot: usize,
}

/// `POST /api/camera/upload?name=…&slot=0|1`: a BVH take; the second one makes the scene.
pub async fn upload(State(st): State<Arc<AppState>>, q: Query<UploadQuery>, body: Bytes) -> Result<Json<Value>> {
    let name = clean_name(&q.name);
    let slot = q.slot;
    let state = st.clone();
    let id = st.jobs.spawn("camera-scene", move |job| {
        if !name.to_ascii_lowercase().ends_with(".bvh") {
            return Err(StudioError::BadRequest(format!("{name}: expected a .bvh take")));
        }
        job.progress("parsing", 0.1);
        let motion = inbetween_io::parse_bvh(&utf8(&name, &body)?, &name)?;
        if slot == 0 {
            *state.camera.pending.lock().unwrap_or_else(|p| p.into_inner()) = Some((name.clone(), motion));
            return Ok(json!({"ok": true, "pending": name, "message": format!("{name}: waiting for the second take")}));
        }
        let first = state.camera.pending.lock().unwrap_or_else(|p| p.into_inner()).take().ok_or_else(|| {
            StudioError::BadRequest(format!("{name}: the scene needs two takes: pick both files together"))
        })?;
        let (scene, notes) =
            scene_from_motions(&[(&first.0, &first.1), (&name, &motion)]).map_err(StudioError::Engine)?;
        opened(&state, format!("{} + {name}", first.0), scene, notes.lines)
    });
    Ok(Json(answer(&st.jobs, id).await))
}

/// `POST /api/camera/reference?name=…`: a reference clip whose style the extractor computes; it
/// joins the generated styles. Our JSON (per-frame character features and Toric camera), or a glTF /
/// GLB camera animation over the open scene's two characters.
pub async fn reference(State(st): State<Arc<AppState>>, q: Query<UploadQuery>, body: Bytes) -> Result<Json<Value>> {
    let name = q.name.clone();
    let state = st.clone();
    let id = st.jobs.spawn("camera-reference", move |_| {
        let lower = name.to_ascii_lowercase();
        if lower.ends_with(".gltf") || lower.ends_with(".glb") {
            // A camera animation over the open scene's characters.
            let scene = state.camera.scene()?;
            let clip = inbetween_camera::infer::reference_from_gltf(&body, &name, &scene, &Lens::default())
                .map_err(StudioError::Engine)?;
            let w = state.camera.weights()?;
            let code = clip.style(&w.model, Path::new(&name)).map_err(|e| StudioError::Engine(e.to_string()))?;
            *state.camera.reference.lock().unwrap_or_else(|p| p.into_inner()) =
                Some(Style { name: format!("reference {name}"), code });
            return Ok(json!({"ok": true, "message": format!("style extracted from the camera animation in {name}: it joins the styles of the next Generate")}));
        }
        let text = utf8(&name, &body)?;
        let clip: ReferenceClip = serde_json::from_str(&text).map_err(|e| {
            StudioError::Engine(format!(
                "{name}:{}:{}: {e}; expected a reference clip: {{\"characters\": [per-frame features], \"camera\": [per-frame toric]}}",
                e.line(),
                e.column()
            ))
        })?;
        let w = state.camera.weights()?;
        let code = clip.style(&w.model, Path::new(&name)).map_err(|e| StudioError::Engine(e.to_string()))?;
        *state.camera.reference.lock().unwrap_or_else(|p| p.into_inner()) =
            Some(Style { name: format!("reference {name}"), code });
        Ok(json!({"ok": true, "message": format!("style extracted from {name}: it joins the styles of the next Generate")}))
    });
    Ok(Json(answer(&st.jobs, id).await))
}

fn v3(v: DVec3) -> [f64; 3] {
    [v.x, v.y, v.z]
}

fn opened(st: &AppState, name: String, scene: Scene, notes: Vec<String>) -> Result<Value> {
    let n = scene.num_frames();
    let frames: Vec<usize> = [0, n / 2, n - 1].into_iter().collect();
    let keys = example_keys(&scene, &frames);
    let chars: Vec<Value> = scene
        .characters
        .iter()
        .map(|c| {
            json!({
                "name": c.name,
                "root": c.root.iter().map(|v| v3(*v)).collect::<Vec<_>>(),
                "shoulder_l": c.shoulder_l.iter().map(|v| v3(*v)).collect::<Vec<_>>(),
                "shoulder_r": c.shoulder_r.iter().map(|v| v3(*v)).collect::<Vec<_>>(),
            })
        })
        .collect();
    let msg = format!("scene {name}: {} characters, {n} frames at {:.1} fps", scene.characters.len(), scene.fps);
    let out = json!({
        "ok": true,
        "message": msg,
        "name": name,
        "fps": scene.fps,
        "frames": n,
        "characters": chars,
        "keys": keys,
        "notes": notes,
        "lens": Lens::default(),
    });
    *st.camera.scene.lock().unwrap_or_else(|p| p.into_inner()) = Some(Arc::new(scene));
    *st.camera.reference.lock().unwrap_or_else(|p| p.into_inner()) = None;
    Ok(out)
}

#[derive(Deserialize)]
pub struct KeyAtRequest {
    pub frame: usize,
}

/// `POST /api/camera/key_at {frame}`: a default key at a frame (the relative behaviour's framing there).
pub async fn key_at(State(st): State<Arc<AppState>>, Json(req): Json<KeyAtRequest>) -> Result<Json<Value>> {
    let scene = st.camera.scene()?;
    if req.frame >= scene.num_frames() {
        return Err(StudioError::BadRequest(format!(
            "frame {} is past the scene's last frame {}",
            req.frame,
            scene.num_frames() - 1
        )));
    }
    let keys = example_keys(&scene, &[req.frame]);
    Ok(Json(json!({"key": keys.keys[0]})))
}

/// The framing targets of characters `targets` (default the first two) at `frame`.
fn targets_at(scene: &Scene, frame: usize, targets: Option<[usize; 2]>) -> Result<(DVec3, DVec3)> {
    let [i, j] = targets.unwrap_or([0, 1]);
    let n = scene.characters.len();
    if frame >= scene.num_frames() || i >= n || j >= n || i == j {
        return Err(StudioError::BadRequest(format!(
            "frame {frame} or targets [{i}, {j}] outside the scene ({} frames, {n} characters)",
            scene.num_frames()
        )));
    }
    Ok((scene.characters[i].frame(frame).target(), scene.characters[j].frame(frame).target()))
}

#[derive(Deserialize)]
pub struct ToricRequest {
    pub frame: usize,
    /// Camera position (metres) and rotation quaternion `[x, y, z, w]` (camera → world, looking down −Z).
    pub position: [f64; 3],
    pub rotation: [f64; 4],
    /// Target characters (indices; default the first two).
    pub targets: Option<[usize; 2]>,
}

/// `POST /api/camera/toric`: the Toric coordinates of a camera placed in the viewport.
pub async fn toric(State(st): State<Arc<AppState>>, Json(req): Json<ToricRequest>) -> Result<Json<Value>> {
    let scene = st.camera.scene()?;
    let (a, b) = targets_at(&scene, req.frame, req.targets)?;
    let q = req.rotation;
    let pose = CameraPose {
        position: DVec3::from_array(req.position),
        rotation: DQuat::from_xyzw(q[0], q[1], q[2], q[3]).normalize(),
    };
    let toric = from_pose(&pose, a, b, &Lens::default()).map_err(|e| {
        StudioError::Engine(format!("this camera cannot frame both characters at frame {}: {e}", req.frame))
    })?;
    Ok(Json(json!({"camera": toric})))
}

#[derive(Deserialize)]
pub struct PoseRequest {
    pub frame: usize,
    pub camera: inbetween_camera::toric::Toric,
    pub targets: Option<[usize; 2]>,
}

/// `POST /api/camera/pose`: the world pose of a key's Toric camera (where the viewport's gizmo
/// starts).
pub async fn pose(State(st): State<Arc<AppState>>, Json(req): Json<PoseRequest>) -> Result<Json<Value>> {
    let scene = st.camera.scene()?;
    let (a, b) = targets_at(&scene, req.frame, req.targets)?;
    let p = inbetween_camera::toric::to_pose(&req.camera, a, b, &Lens::default())
        .map_err(|e| StudioError::Engine(format!("key at frame {}: {e}", req.frame)))?;
    let q = p.rotation;
    Ok(Json(json!({"position": v3(p.position), "rotation": [q.x, q.y, q.z, q.w], "look_at": v3((a + b) * 0.5)})))
}

#[derive(Deserialize)]
pub struct GenerateRequest {
    pub keys: Keys,
    /// Styles to generate (`direct`, `relative`, `side`, `orbit`, `reference`); empty: all.
    #[serde(default)]
    pub styles: Vec<String>,
}

/// `POST /api/camera/generate`: one trajectory per style through the keys.
pub async fn generate(State(st): State<Arc<AppState>>, Json(req): Json<GenerateRequest>) -> Result<Json<Value>> {
    let state = st.clone();
    let id = st.jobs.spawn("camera-generate", move |job| {
        let scene = state.camera.scene()?;
        let w = state.camera.weights()?;
        let mut styles: Vec<Style> = Vec::new();
        for b in BEHAVIOURS {
            if req.styles.is_empty() || req.styles.iter().any(|s| s == b.name()) {
                styles.push(
                    w.style(b).ok_or_else(|| StudioError::Engine(format!("no style code for {}", b.name())))?,
                );
            }
        }
        if req.styles.is_empty() || req.styles.iter().any(|s| s == "reference") {
            if let Some(r) = state.camera.reference.lock().unwrap_or_else(|p| p.into_inner()).clone() {
                styles.push(r);
            }
        }
        if styles.is_empty() {
            return Err(StudioError::BadRequest(format!(
                "styles {:?}: expected direct, relative, side, orbit or reference",
                req.styles
            )));
        }
        let v = state.camera.version.fetch_add(1, std::sync::atomic::Ordering::SeqCst) + 1;
        let mut out = Vec::new();
        let mut worst_hit = 0.0f64;
        for (k, style) in styles.iter().enumerate() {
            job.progress(&format!("generating {}", style.name), k as f64 / styles.len() as f64);
            let t = std::time::Instant::now();
            let track = GenerateJob {
                model: &w.model,
                scene: &scene,
                keys: &req.keys,
                style,
                options: GenerateOptions::default(),
                origin: Path::new("keys"),
            }
            .run()
            .map_err(|e| StudioError::Engine(e.to_string()))?;
            let ms = t.elapsed().as_secs_f64() * 1e3;
            worst_hit = worst_hit.max(track.max_corrected_residual);
            let slug: String = style.name.chars().map(|c| if c.is_ascii_alphanumeric() { c } else { '-' }).collect();
            let json_bytes = serde_json::to_vec_pretty(&track).unwrap_or_default();
            let json_url = state.put_file(&format!("camera/{slug}.json"), "application/json", json_bytes, v);
            let (tr, sc) = (track.clone(), scene.clone());
            let gltf_url = state.put_lazy(
                &format!("camera/{slug}.gltf"),
                "model/gltf+json",
                move || serde_json::to_vec(&inbetween_camera::gltf::camera_gltf(&tr, &sc)).unwrap_or_default(),
                v,
            );
            out.push(json!({
                "style": style.name,
                "first_frame": track.frames.first().map_or(0, |f| f.frame),
                "position": track.frames.iter().map(|f| v3(f.pose.position)).collect::<Vec<_>>(),
                "rotation": track.frames.iter().map(|f| { let q = f.pose.rotation; [q.x, q.y, q.z, q.w] }).collect::<Vec<_>>(),
                "fovy_deg": track.lens.fovy.to_degrees(),
                "aspect": track.lens.aspect,
                "key_hit_error": track.max_corrected_residual,
                "network_key_miss": track.worst_key_miss(),
                "ms": ms,
                "files": {"json": json_url, "gltf": gltf_url},
            }));
        }
        let msg = format!(
            "{} trajectories through {} keys; key hit error {worst_hit:.1e} (Toric units; 0 = every key hit)",
            out.len(),
            req.keys.keys.len()
        );
        Ok(json!({"ok": true, "message": msg, "trajectories": out, "key_hit_error": worst_hit}))
    });
    Ok(Json(answer(&st.jobs, id).await))
}

/// The panel's routes, nested under `/api/camera` by the server.
pub fn router(shared: Arc<Shared>) -> Router {
    Router::new()
        .route("/open", post(open))
        .route("/upload", post(upload))
        .route("/reference", post(reference))
        .route("/key_at", post(key_at))
        .route("/toric", post(toric))
        .route("/pose", post(pose))
        .route("/generate", post(generate))
        .with_state(AppState::new(shared))
}
