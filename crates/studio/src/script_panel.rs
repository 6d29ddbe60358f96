//! The script panel (the paper's Fig. 1: a text box, an execution button, a live 3D view). A run
//! goes through the script engine's [`StorySession`]: the first version is solved in full, a
//! later one re-solves only the characters and objects its edit touches, so unchanged objects keep
//! their places. The page gets the animated scene as a GLB (the engine's own story writer: boxes
//! or Kenney meshes, a joint hierarchy per character, the shot camera, one "story" animation),
//! each character's BVH, the scene JSON, and a JSON summary (objects, action segments, camera per
//! frame, parse diagnostics).

use std::path::PathBuf;
use std::sync::{Arc, Mutex};

use axum::extract::State;
use axum::routing::{get, post};
use axum::{Json, Router};
use inbetween_script::animate::{camera_track, Animation};
use inbetween_script::compose::ComposeConfig;
use inbetween_script::jobs::{story_session, RunJob, SceneJob};
use inbetween_script::limits::ScriptLimits;
use inbetween_script::output;
use inbetween_script::output::skinned::SkinnedBody;
use inbetween_script::story_session::StorySession;
use serde::Deserialize;
use serde_json::{json, Value};

use crate::error::{Result, StudioError};
use crate::jobs::{answer, Job};
use crate::state::Shared;

crate::state::panel_state!(AppState, script, ScriptState);

/// The options a session was made with; a run with other options starts a new session.
#[derive(Debug, Clone, PartialEq)]
struct Options {
    seed: u64,
    optimize: bool,
    models: Option<PathBuf>,
}

struct Live {
    options: Options,
    session: StorySession,
    version: u64,
    /// The characters' skinned bodies, bound to these skeletons (reused while the cast's
    /// skeletons stay the same: reading and binding the Kenney models is the slow part).
    bodies: Option<(Vec<inbetween_core::Skeleton>, Vec<SkinnedBody>, Vec<String>)>,
}

/// The panel's editing session (one per studio: it is a local, single-user tool).
#[derive(Default)]
pub struct ScriptState {
    live: Mutex<Option<Live>>,
}

/// `GET /api/script/stories`: the built-in texts by name.
pub async fn stories() -> Json<Value> {
    let list: Vec<Value> = inbetween_script::builtin_scripts::all()
        .into_iter()
        .map(|(name, text)| json!({"name": name, "text": text}))
        .collect();
    Json(json!({"stories": list, "default": "demo"}))
}

/// `POST /api/script/run` body.
#[derive(Deserialize)]
pub struct RunRequest {
    pub text: String,
    /// Run the joint scene/motion optimisation (§4.3, Algorithm 2): slower, seconds per edit.
    #[serde(default)]
    pub optimize: bool,
    #[serde(default = "default_seed")]
    pub seed: u64,
}

fn default_seed() -> u64 {
    ComposeConfig::default().seed
}

/// The Kenney furniture folder of the shared data, when present.
fn kenney_furniture() -> Option<PathBuf> {
    let dir = inbetween_io::shared_data_dir().ok()?.join("assets/kenney_furniture");
    dir.is_dir().then_some(dir)
}

/// `POST /api/script/run`: starts a story job.
pub async fn run(State(st): State<Arc<AppState>>, Json(req): Json<RunRequest>) -> Result<Json<Value>> {
    if inbetween_script::sentences::split(&req.text).is_empty() {
        return Err(StudioError::BadRequest(
            "the script is empty: write sentences such as \"In the room, a desk is near a bed$\"".into(),
        ));
    }
    let state = st.clone();
    let id = st.jobs.spawn("script", move |job| run_job(&state, job, req));
    Ok(Json(answer(&st.jobs, id).await))
}

fn run_job(st: &AppState, job: &Job, req: RunRequest) -> Result<Value> {
    let options = Options { seed: req.seed, optimize: req.optimize, models: kenney_furniture() };
    let mut live = st.script.live.lock().unwrap_or_else(|p| p.into_inner());
    let mut notes = Vec::new();
    if live.as_ref().is_none_or(|l| l.options != options) {
        job.progress("loading the catalogue and scene database", 0.05);
        let run = RunJob {
            scene: SceneJob {
                limits: ScriptLimits::default(),
                out_dir: PathBuf::new(),
                seed: options.seed,
                view: None,
                models: options.models.clone(),
                config: ComposeConfig { seed: options.seed, ..ComposeConfig::default() },
                semantic: None,
            },
            optimize: options.optimize,
            shared_motions: false,
            gif_width: 0,
            cancel: Default::default(),
            progress: inbetween_io::Progress::hidden(),
        };
        let (session, n) = story_session(&req.text, &run)?;
        notes = n;
        *live = Some(Live { options, session, version: 0, bodies: None });
    }
    let live = live.as_mut().expect("a session was just made");
    job.progress("composing the scene and animating the characters", 0.15);
    live.session.check_verbs(&req.text, "script").map_err(|e| StudioError::Engine(e.to_string()))?;
    // A cancelled update stops early and leaves the session at the last finished version.
    let up = live.session.update_with(&req.text, job.token()).map_err(|e| StudioError::Engine(e.to_string()))?;
    live.version += 1;
    job.progress("writing the animated glTF and the BVH files", 0.8);
    let anim = &up.animation;
    let cat = live.session.catalogue();
    let v = live.version;
    // The shot camera per frame, computed once (the glTF and the page both use it).
    let t_camera = std::time::Instant::now();
    let track = camera_track(anim);
    let camera_ms = t_camera.elapsed().as_secs_f64() * 1000.0;
    let cam = |f: usize| track.pose(f);
    let t_gltf = std::time::Instant::now();
    // One document, sent as GLB to the viewer and offered as .gltf for download: every character
    // a skinned Kenney blocky character when those models are in the shared data, the engine's
    // joint hierarchy with bone boxes otherwise.
    let skeletons: Vec<inbetween_core::Skeleton> = anim.characters.iter().map(|c| c.clip.skeleton().clone()).collect();
    if live.bodies.as_ref().is_none_or(|(s, _, _)| *s != skeletons) {
        live.bodies = output::skinned::skinned_bodies(anim, None).ok().map(|(b, n)| (skeletons, b, n));
    }
    let bodies = live.bodies.as_ref().map(|(_, b, n)| (b, n));
    let (doc, bin) = match bodies {
        Some((bodies, _)) => output::skinned::skinned_story_document(anim, cat, bodies, &cam)?,
        None => output::story_gltf_document(anim, cat, &cam)?,
    };
    let glb = st.put_file("script/story.glb", "model/gltf-binary", output::glb_bytes(&doc, &bin), v);
    let gltf = st.put_lazy("script/story.gltf", "model/gltf+json", move || output::gltf_text_bytes(doc, &bin), v);
    let gltf_ms = t_gltf.elapsed().as_secs_f64() * 1000.0;
    let t_rest = std::time::Instant::now();
    let scene = anim.scene.clone();
    let mounts = inbetween_script::invariants::mounts(&scene, cat);
    let scene_url = st.put_lazy(
        "script/scene.json",
        "application/json",
        move || {
            output::scene_json_bytes(&scene, &mounts).unwrap_or_else(|e| format!("{{\"error\": \"{e}\"}}").into_bytes())
        },
        v,
    );
    let mut characters = Vec::new();
    for c in &anim.characters {
        let safe: String = c.name.chars().map(|ch| if ch.is_alphanumeric() { ch } else { '_' }).collect();
        let clip = c.clip.clone();
        // Euler channels only when the file is asked for.
        let bvh = move || match clip.to_motion() {
            Ok(motion) => inbetween_io::to_bvh_string(&motion).into_bytes(),
            Err(e) => format!("error: {e}").into_bytes(),
        };
        let url = st.put_lazy(&format!("script/{safe}.bvh"), "text/plain; charset=utf-8", bvh, v);
        characters.push(json!({
            "name": c.name,
            "joints": c.clip.skeleton().len(),
            "frames": c.clip.num_frames(),
            "bvh": url,
            "segments": c.segments.iter().map(|s| json!({
                "verb": s.verb, "start": s.start, "end": s.end, "target": s.target,
            })).collect::<Vec<_>>(),
        }));
    }
    let comp = &up.scene.composition;
    let diagnostics: Vec<Value> = notes
        .iter()
        .chain(comp.diagnostics.iter())
        .map(|d| {
            json!({
                "line": d.at.line, "sentence": d.at.sentence, "text": d.at.text, "word": d.word,
                "message": d.message, "suggestions": d.suggestions, "display": d.to_string(),
            })
        })
        .collect();
    let frames = anim.frames();
    let camera: Vec<[f32; 7]> = (0..frames)
        .map(|f| {
            let c = cam(f);
            [c.eye.x, c.eye.y, c.eye.z, c.target.x, c.target.y, c.target.z, c.fovy_deg]
        })
        .collect();
    let summary = format!(
        "{}; engine {:.1} ms, contact distance {:.3} m, collision cost {:.3}",
        summary_line(anim, &up.resolved_characters, up.scene.kept, up.full),
        up.seconds * 1000.0,
        up.after.contact,
        up.after.collision
    );
    Ok(json!({
        "ok": true,
        "message": summary,
        "fps": anim.fps,
        "frames": frames,
        "objects": objects(anim),
        "characters": characters,
        "camera": camera,
        "shots": anim.camera.iter().map(|s| json!({"view": s.view, "start": s.start, "end": s.end})).collect::<Vec<_>>(),
        "diagnostics": diagnostics,
        "notes": anim.notes,
        "full": up.full,
        "kept_objects": up.scene.kept,
        "placed_objects": up.scene.placed,
        "changed_sentences": up.scene.changed_sentences,
        "resolved_characters": up.resolved_characters,
        "kept_characters": up.kept_characters,
        "engine_ms": up.seconds * 1000.0,
        "gltf_ms": gltf_ms,
        "files_ms": t_rest.elapsed().as_secs_f64() * 1000.0,
        "camera_ms": camera_ms,
        "cost_before": up.before.total,
        "cost_after": up.after.total,
        "skinned": bodies.is_some(),
        "bodies": bodies.map(|b| b.1.clone()).unwrap_or_default(),
        "files": {"glb": glb, "gltf": gltf, "scene": scene_url},
    }))
}

/// Objects as the page's `state()` reports them: metres, Y up, yaw in radians.
fn objects(anim: &Animation) -> Vec<Value> {
    anim.scene
        .objects
        .iter()
        .map(
            |o| json!({"label": o.label, "category": o.category, "position": o.position, "size": o.size, "yaw": o.yaw}),
        )
        .collect()
}

fn summary_line(anim: &Animation, resolved: &[String], kept_objects: usize, full: bool) -> String {
    let secs = anim.frames() as f64 / anim.fps;
    let what = if full {
        "solved in full".to_string()
    } else if resolved.is_empty() {
        format!("{kept_objects} objects kept, no character re-solved")
    } else {
        format!("{kept_objects} objects kept, re-solved {}", resolved.join(", "))
    };
    format!(
        "story: {} objects, {} characters, {} frames ({secs:.1} s at {} fps); {what}",
        anim.scene.objects.len(),
        anim.characters.len(),
        anim.frames(),
        anim.fps
    )
}

/// The panel's routes, nested under `/api/script` by the server.
pub fn router(shared: Arc<Shared>) -> Router {
    Router::new().route("/stories", get(stories)).route("/run", post(run)).with_state(AppState::new(shared))
}
