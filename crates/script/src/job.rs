//! `inbetween script scene`: a script file in, the furnished scene out (JSON, glTF, SSG JSON, a
//! top-down and a perspective PNG). The CLI parses arguments and calls [`run_scene`].

use std::path::{Path, PathBuf};

use crate::catalogue::{builtin::builtin, kenney, Catalogue};
use crate::compose::{ComposeConfig, Composition};
use crate::database::SceneDatabase;
use crate::error::Diagnostic;
use crate::output;
use crate::session::Session;
use crate::ScriptError;

/// Variations per hand-authored room in the default database.
pub const DEFAULT_VARIATIONS: usize = 6;

/// Options of a scene job.
#[derive(Debug, Clone)]
pub struct SceneJob {
    pub out_dir: PathBuf,
    pub seed: u64,
    /// Camera of the perspective preview; `None` takes the script's last "camera …" command, else
    /// "front".
    pub view: Option<String>,
    /// Kenney furniture folder: real meshes and measured sizes instead of boxes.
    pub models: Option<PathBuf>,
    pub config: ComposeConfig,
    /// Read words outside the synonym tables through sentence embeddings (feature `embeddings`);
    /// `Some(None)` uses the default model folder.
    pub semantic: Option<Option<PathBuf>>,
}

/// What a scene job wrote and found.
#[derive(Debug)]
pub struct SceneReport {
    pub files: Vec<PathBuf>,
    pub composition: Composition,
    /// Per-sentence problems: the parser's and the layout's. The rest of the script still ran.
    pub diagnostics: Vec<Diagnostic>,
    pub seconds: f64,
}

/// The catalogue, with Kenney models when a folder is given.
pub fn catalogue(models: Option<&Path>) -> Result<Catalogue, ScriptError> {
    let cat = builtin();
    match models {
        Some(dir) => kenney::with_models(cat, dir),
        None => Ok(cat),
    }
}

/// Reads a script file: UTF-8 text with at least one sentence.
pub fn read_script(path: &Path) -> Result<String, ScriptError> {
    let bytes = std::fs::read(path).map_err(|e| ScriptError::io(path, e))?;
    let text = String::from_utf8(bytes).map_err(|e| ScriptError::Invalid(format!(
        "{}: not UTF-8 text (byte {} is invalid); save the script as plain UTF-8",
        path.display(),
        e.utf8_error().valid_up_to()
    )))?;
    if crate::script::split(&text).is_empty() {
        return Err(ScriptError::Empty { path: path.to_path_buf() });
    }
    Ok(text)
}

/// Composes `text` (read from `source`, named in messages) and writes every output into the job's
/// folder.
pub fn run_scene(text: &str, source: &Path, job: &SceneJob) -> Result<SceneReport, ScriptError> {
    if crate::script::split(text).is_empty() {
        return Err(ScriptError::Empty { path: source.to_path_buf() });
    }
    let cat = catalogue(job.models.as_deref())?;
    let (cat, notes) = match &job.semantic {
        Some(dir) => crate::semantic::teach_unknown_words(text, &cat, dir.as_deref())?,
        None => (cat, Vec::new()),
    };
    let db = SceneDatabase::builtin(&cat, DEFAULT_VARIATIONS, job.seed);
    let mut session = Session::new(cat, db, ComposeConfig { seed: job.seed, ..job.config.clone() });
    let update = session.update(text);
    let composition = update.composition;
    let dir = &job.out_dir;
    std::fs::create_dir_all(dir).map_err(|e| ScriptError::io(dir, e))?;
    let mut files = Vec::new();
    let json = dir.join("scene.json");
    output::write_json(&json, &composition.scene)?;
    files.push(json);
    let ssg = dir.join("ssg.json");
    let ssg_text = serde_json::to_vec_pretty(&composition.query).map_err(|e| ScriptError::Invalid(e.to_string()))?;
    inbetween_io::write_atomic(&ssg, &ssg_text).map_err(|e| ScriptError::io(&ssg, e))?;
    files.push(ssg);
    let gltf = dir.join("scene.gltf");
    output::write_gltf(&gltf, &composition.scene, session.catalogue())?;
    files.push(gltf);
    let view = job
        .view
        .clone()
        .or_else(|| composition.scene.camera.last().cloned())
        .unwrap_or_else(|| "front".to_string());
    files.extend(output::write_previews(dir, &composition.scene, session.catalogue(), &view)?);
    let diagnostics = notes.into_iter().chain(composition.diagnostics.iter().cloned()).collect();
    Ok(SceneReport { files, diagnostics, composition, seconds: update.seconds })
}

/// Options of a story job (`inbetween script run`): a scene job plus the characters.
#[derive(Debug, Clone)]
pub struct RunJob {
    pub scene: SceneJob,
    /// Run the joint scene/motion optimisation (§4.3, Algorithm 2).
    pub optimize: bool,
    /// Use the CMU clips and Kenney animations of `../shared/data` when present (else procedural).
    pub shared_motions: bool,
    /// Preview GIF options.
    pub gif_width: u32,
}

/// What a story job wrote and measured.
#[derive(Debug)]
pub struct RunReport {
    pub scene: SceneReport,
    pub animation: crate::animate::Animation,
    /// Costs before and after the optimisation (equal when it did not run).
    pub before: crate::optimize::Costs,
    pub after: crate::optimize::Costs,
    pub files: Vec<PathBuf>,
    pub seconds: f64,
}

/// Composes the scene, animates every character, optimises scene and motion together, and writes
/// the animated glTF, a BVH per character, the preview GIF from the script's camera, the
/// top-down routes and the cost curves (Fig. 12).
pub fn run_story(text: &str, source: &Path, job: &RunJob) -> Result<RunReport, ScriptError> {
    use crate::animate::{animate, camera_pose, AnimateConfig};
    use crate::motion::library::MotionLibrary;
    use crate::optimize::{costs, optimize, plot_costs, OptimizeConfig};
    let start = std::time::Instant::now();
    let scene = run_scene(text, source, &job.scene)?;
    let cat = catalogue(job.scene.models.as_deref())?;
    let lib = if job.shared_motions { MotionLibrary::from_shared(64) } else { MotionLibrary::procedural(job.scene.seed) };
    let acfg = AnimateConfig::default();
    let ocfg = OptimizeConfig { seed: job.scene.seed, ..OptimizeConfig::default() };
    let dir = &job.scene.out_dir;
    let mut files = scene.files.clone();
    let (animation, before, after) = if job.optimize {
        let o = optimize(&scene.composition, &cat, &lib, &acfg, &ocfg);
        let plot = dir.join("costs.png");
        plot_costs(&plot, &o.curves)?;
        files.push(plot);
        (o.animation, o.before, o.after)
    } else {
        let a = animate(&scene.composition, &cat, &lib, &acfg);
        let c = costs(&a, &ocfg);
        (a, c, c)
    };
    let chars: Vec<(&str, &inbetween_core::Motion)> = animation.characters.iter().map(|c| (c.name.as_str(), &c.motion)).collect();
    let cam = |f: usize| camera_pose(&animation, f);
    let gltf = dir.join("story.gltf");
    output::write_animated_gltf(&gltf, &animation.scene, &cat, &chars, &cam, animation.fps)?;
    files.push(gltf);
    for c in &animation.characters {
        let safe: String = c.name.chars().map(|ch| if ch.is_alphanumeric() { ch } else { '_' }).collect();
        let bvh = dir.join(format!("{safe}.bvh"));
        output::write_character_bvh(&bvh, &c.motion)?;
        files.push(bvh);
    }
    let gif = dir.join("story.gif");
    let opts = output::AnimPreviewOptions { width: job.gif_width, ..output::AnimPreviewOptions::default() };
    output::render_preview_gif(&gif, &animation.scene, &cat, &chars, &cam, animation.fps, &opts)?;
    files.push(gif);
    let routes = dir.join("routes.png");
    output::render_top_down_trails(&routes, &animation.scene, &cat, &chars)?;
    files.push(routes);
    Ok(RunReport { scene, animation, before, after, files, seconds: start.elapsed().as_secs_f64() })
}

/// `inbetween script watch`: re-runs `run` every time the script file changes (the paper's
/// editing loop), until `max_runs` runs (None: forever). `on_run` sees each outcome; an error in
/// one version (an empty file while saving) is reported and the loop goes on.
pub fn watch(path: &Path, job: &RunJob, max_runs: Option<usize>, mut on_run: impl FnMut(Result<RunReport, ScriptError>)) -> Result<(), ScriptError> {
    let mut last: Option<(std::time::SystemTime, u64)> = None;
    let mut runs = 0;
    loop {
        let meta = std::fs::metadata(path).map_err(|e| ScriptError::io(path, e))?;
        let stamp = (meta.modified().map_err(|e| ScriptError::io(path, e))?, meta.len());
        if last != Some(stamp) {
            last = Some(stamp);
            on_run(read_script(path).and_then(|text| run_story(&text, path, job)));
            runs += 1;
            if max_runs.is_some_and(|m| runs >= m) {
                return Ok(());
            }
        }
        std::thread::sleep(std::time::Duration::from_millis(250));
    }
}
