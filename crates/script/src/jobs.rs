//! `inbetween script scene`: a script file in, the furnished scene out (JSON, glTF, SSG JSON, a
//! top-down and a perspective PNG). The CLI parses arguments and calls [`run_scene`].

use std::path::{Path, PathBuf};

use crate::catalogue::{builtin::builtin, kenney, Catalogue};
use crate::compose::{ComposeConfig, Composition};
use crate::database::SceneDatabase;
use crate::error::Diagnostic;
use crate::limits::ScriptLimits;
use crate::output;
use crate::scene::Scene;
use crate::scene_session::Session;
use crate::ssg::Ssg;
use crate::story_session::StorySession;
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
    /// What the script may ask for, checked before any work ([`ScriptLimits::check_text`]).
    pub limits: ScriptLimits,
}

impl Default for SceneJob {
    /// What `inbetween script scene` does without flags: seed 1, relation-first matching, a
    /// furnished room of boxes, the default limits, written into `out/script`.
    fn default() -> SceneJob {
        SceneJob {
            out_dir: PathBuf::from("out/script"),
            seed: 1,
            view: None,
            models: None,
            config: ComposeConfig::default(),
            semantic: None,
            limits: ScriptLimits::default(),
        }
    }
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

impl SceneReport {
    /// What a front end prints for the scene: one line of objects, room, match score, violations
    /// and time, then `  wrote <file>` per file written.
    pub fn summary(&self, source: &Path) -> String {
        let scene = &self.composition.scene;
        let line = format!(
            "{}: {} objects in a {:.1} m × {:.1} m {} (match score {:.2}, {} violations) in {:.1} ms",
            source.display(),
            scene.objects.len(),
            scene.room.width,
            scene.room.depth,
            scene.room.name,
            self.composition.match_score,
            self.composition.violations.total(),
            self.seconds * 1e3
        );
        std::iter::once(line).chain(wrote(&self.files)).collect::<Vec<_>>().join("\n")
    }
}

/// `  wrote <file>` per file: how a report lists what it wrote.
fn wrote(files: &[PathBuf]) -> impl Iterator<Item = String> + '_ {
    files.iter().map(|f| format!("  wrote {}", f.display()))
}

/// The catalogue, with Kenney models when a folder is given.
pub fn catalogue(models: Option<&Path>) -> Result<Catalogue, ScriptError> {
    let cat = builtin();
    match models {
        Some(dir) => kenney::with_models(cat, dir),
        None => Ok(cat),
    }
}

/// A script named on a command line: `builtin:NAME` for a built-in one ([`crate::builtin_scripts::all`]),
/// else a file ([`read_script`]); with the name messages use for it.
pub fn load_script(script: &str) -> Result<(String, PathBuf), ScriptError> {
    if let Some(name) = script.strip_prefix("builtin:") {
        let all = crate::builtin_scripts::all();
        let Some((_, text)) = all.iter().find(|(n, _)| *n == name) else {
            let names: Vec<&str> = all.iter().map(|(n, _)| *n).collect();
            return Err(ScriptError::Invalid(format!("no built-in script '{name}'; there are: {}", names.join(", "))));
        };
        return Ok((text.to_string(), PathBuf::from(script)));
    }
    let path = Path::new(script);
    Ok((read_script(path)?, path.to_path_buf()))
}

/// Reads a script file: UTF-8 text with at least one sentence.
pub fn read_script(path: &Path) -> Result<String, ScriptError> {
    let bytes = std::fs::read(path).map_err(|e| ScriptError::io(path, e))?;
    let text = inbetween_io::text::utf8(bytes).map_err(|e| {
        ScriptError::Invalid(format!(
            "{}: not UTF-8 text (byte {} is invalid); save the script as plain UTF-8",
            path.display(),
            e.offset
        ))
    })?;
    if crate::sentences::split(&text).is_empty() {
        return Err(ScriptError::Empty { path: path.to_path_buf() });
    }
    Ok(text)
}

/// The catalogue for one script: with Kenney models when asked, and taught the script's unknown
/// words through sentence embeddings with `--semantic` (the replacements come back as notes).
fn script_catalogue(text: &str, job: &SceneJob) -> Result<(Catalogue, Vec<Diagnostic>), ScriptError> {
    let cat = catalogue(job.models.as_deref())?;
    match &job.semantic {
        Some(dir) => crate::semantic::teach_unknown_words(text, &cat, dir.as_deref()),
        None => Ok((cat, Vec::new())),
    }
}

/// Writes the scene outputs (scene.json, ssg.json, scene.gltf, previews) of `scene` composed
/// from `query` (a story passes its optimised scene, so every output shows one layout).
fn write_scene(scene: &Scene, query: &Ssg, cat: &Catalogue, job: &SceneJob) -> Result<Vec<PathBuf>, ScriptError> {
    let dir = &job.out_dir;
    std::fs::create_dir_all(dir).map_err(|e| ScriptError::io(dir, e))?;
    let mut files = Vec::new();
    let json = dir.join("scene.json");
    output::write_json(&json, scene, cat)?;
    files.push(json);
    let ssg = dir.join("ssg.json");
    let ssg_text = serde_json::to_vec_pretty(query).map_err(|e| ScriptError::Invalid(e.to_string()))?;
    inbetween_io::write_atomic(&ssg, &ssg_text).map_err(|e| ScriptError::io(&ssg, e))?;
    files.push(ssg);
    let gltf = dir.join("scene.gltf");
    output::write_gltf(&gltf, scene, cat)?;
    files.push(gltf);
    let view = job.view.clone().or_else(|| scene.camera.last().cloned()).unwrap_or_else(|| "front".to_string());
    files.extend(output::write_previews(dir, scene, cat, &view)?);
    Ok(files)
}

/// Composes `text` (read from `source`, named in messages) and writes every output into the job's
/// folder.
pub fn run_scene(text: &str, source: &Path, job: &SceneJob) -> Result<SceneReport, ScriptError> {
    if crate::sentences::split(text).is_empty() {
        return Err(ScriptError::Empty { path: source.to_path_buf() });
    }
    let (cat, notes) = script_catalogue(text, job)?;
    job.limits.check_text(text, &source.display().to_string(), &cat)?;
    let db = SceneDatabase::builtin(&cat, DEFAULT_VARIATIONS, job.seed);
    let mut session = Session::new(cat, db, ComposeConfig { seed: job.seed, ..job.config.clone() });
    let update = session.update(text);
    let composition = update.composition;
    let files = write_scene(&composition.scene, &composition.query, session.catalogue(), job)?;
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
    /// Checked in the long loops and before each output file (a cancel button, a time limit):
    /// a cancelled run returns [`ScriptError::Cancelled`]. `Cancel::new()` never stops.
    pub cancel: inbetween_core::cancel::Cancel,
    /// Stages of the run as they start (solving the story, then each output); the CLI draws it,
    /// `Progress::hidden()` counts silently.
    pub progress: inbetween_io::Progress,
}

impl Default for RunJob {
    /// What `inbetween script run` does without flags: optimised, the procedural motion library,
    /// a 480-pixel preview GIF, no time limit, no progress drawn.
    fn default() -> RunJob {
        RunJob {
            scene: SceneJob::default(),
            optimize: true,
            shared_motions: false,
            gif_width: 480,
            cancel: inbetween_core::cancel::Cancel::new(),
            progress: inbetween_io::Progress::hidden(),
        }
    }
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
    /// Whether this run solved everything afresh (`run`, and the first run of `watch`); later
    /// runs of `watch` re-solve only what the edit touched.
    pub full: bool,
    /// Characters animated anew in this run, and those whose motion the edit left as it was.
    pub resolved_characters: Vec<String>,
    pub kept_characters: Vec<String>,
    /// Objects the optimisation could move in this run (the others kept their places).
    pub resolved_objects: Vec<String>,
}

impl RunReport {
    /// The lines a front end prints for the run: objects, characters, frames, time and the
    /// optimisation's costs before and after; after an edit (`watch`), what was solved again;
    /// then `  wrote <file>` per file written.
    pub fn summary(&self, source: &Path) -> Vec<String> {
        let (a, frames) = (&self.animation, self.animation.frames());
        let mut lines = vec![format!(
            "{}: {} objects, {} characters, {frames} frames ({:.1} s at {:.0} fps) in {:.2} s; collided boxes {} -> {}, mean contact distance {:.3} m -> {:.3} m",
            source.display(),
            a.scene.objects.len(),
            a.characters.len(),
            frames as f64 / a.fps,
            a.fps,
            self.seconds,
            self.before.collided_boxes,
            self.after.collided_boxes,
            self.before.contact,
            self.after.contact
        )];
        if !self.full {
            let list = |v: &[String]| if v.is_empty() { "none".to_string() } else { v.join(", ") };
            lines.push(format!(
                "  edit re-solved characters: {} (kept as they were: {}); objects re-optimised: {}",
                list(&self.resolved_characters),
                list(&self.kept_characters),
                list(&self.resolved_objects)
            ));
        }
        lines.extend(wrote(&self.files));
        lines
    }
}

/// A story session for a job (see [`StorySession`]): its catalogue, the scene database, the
/// motion library and the settings of animation and optimisation. `notes`: the catalogue's
/// notes (words read through embeddings).
pub fn story_session(text: &str, job: &RunJob) -> Result<(StorySession, Vec<Diagnostic>), ScriptError> {
    use crate::animate::AnimateConfig;
    use crate::motion::library::MotionLibrary;
    use crate::optimize::OptimizeConfig;
    let (cat, notes) = script_catalogue(text, &job.scene)?;
    let db = SceneDatabase::builtin(&cat, DEFAULT_VARIATIONS, job.scene.seed);
    let lib =
        if job.shared_motions { MotionLibrary::from_shared(64) } else { MotionLibrary::procedural(job.scene.seed) };
    let ocfg = job.optimize.then(|| OptimizeConfig { seed: job.scene.seed, ..OptimizeConfig::default() });
    let compose = ComposeConfig { seed: job.scene.seed, ..job.scene.config.clone() };
    Ok((StorySession::new(cat, db, compose, lib, AnimateConfig::default(), ocfg), notes))
}

/// Composes the scene, animates every character, optimises scene and motion together, and writes
/// the animated glTF, a BVH per character, the preview GIF from the script's camera, the
/// top-down routes and the cost curves (Fig. 12).
pub fn run_story(text: &str, source: &Path, job: &RunJob) -> Result<RunReport, ScriptError> {
    if crate::sentences::split(text).is_empty() {
        return Err(ScriptError::Empty { path: source.to_path_buf() });
    }
    let (mut session, notes) = story_session(text, job)?;
    run_story_in(&mut session, notes, text, source, job)
}

/// [`run_story`] with its outputs whole or not at all: written into a staging folder that is moved
/// into `job.scene.out_dir` (merged into it when it exists) only when the run finishes, so a failed,
/// cancelled or timed-out run leaves no partial set. The report's paths are where the files end up.
pub fn run_story_whole(text: &str, source: &Path, job: &RunJob) -> Result<RunReport, ScriptError> {
    let out = &job.scene.out_dir;
    let mut set = inbetween_io::OutputSet::new();
    let staging = set.dir(out).map_err(|e| ScriptError::io(out, e))?;
    let staged = RunJob { scene: SceneJob { out_dir: staging.clone(), ..job.scene.clone() }, ..job.clone() };
    let mut report = run_story(text, source, &staged)?;
    set.commit().map_err(|e| ScriptError::io(out, e))?;
    for p in report.files.iter_mut().chain(report.scene.files.iter_mut()) {
        *p = moved(&staging, out, p);
    }
    Ok(report)
}

/// The skinned outputs of a finished story ([`output::skinned::write_skinned_story`], the
/// characters from `models` or the shared data) into `out` beside the story's, whole or not at all
/// (a missing asset folder writes none of them); the paths are where the files end up.
pub fn write_skinned_whole(
    out: &Path,
    report: &RunReport,
    models: Option<&Path>,
) -> Result<output::skinned::SkinnedStory, ScriptError> {
    let cat = catalogue(models)?;
    let mut set = inbetween_io::OutputSet::new();
    let staging = set.dir(out).map_err(|e| ScriptError::io(out, e))?;
    let mut story = output::skinned::write_skinned_story(&staging, &report.animation, &cat, models)?;
    set.commit().map_err(|e| ScriptError::io(out, e))?;
    for p in story.files.iter_mut() {
        *p = moved(&staging, out, p);
    }
    Ok(story)
}

/// A path written under `staging`, shown under `out` where the output set moved it.
fn moved(staging: &Path, out: &Path, p: &Path) -> PathBuf {
    p.strip_prefix(staging).map_or_else(|_| p.to_path_buf(), |rest| out.join(rest))
}

/// [`run_story`] in a session: only the first version of a story is solved in full; a later one
/// re-solves only the characters and objects its edit touches.
pub fn run_story_in(
    session: &mut StorySession,
    notes: Vec<Diagnostic>,
    text: &str,
    source: &Path,
    job: &RunJob,
) -> Result<RunReport, ScriptError> {
    use crate::animate::camera_track;
    use crate::optimize::plot_costs;
    let start = std::time::Instant::now();
    if crate::sentences::split(text).is_empty() {
        return Err(ScriptError::Empty { path: source.to_path_buf() });
    }
    let name = source.display().to_string();
    job.scene.limits.check_text(text, &name, session.catalogue())?;
    session.check_verbs(text, &name)?;
    let cancel = &job.cancel;
    let progress = &job.progress;
    // Stages: the solve, the scene files, story.gltf, the BVH files, the GIF, the routes.
    progress.phase(6, "script run");
    progress.set_message("composing, animating and optimising");
    progress.tick_every(std::time::Duration::from_millis(250));
    let u = session.update_with(text, cancel)?;
    progress.inc(1);
    progress.set_message("writing the scene files");
    let cat = session.catalogue();
    job.scene.limits.check_animation(&name, u.animation.frames(), u.animation.fps)?;
    // One layout per run: the scene files show the optimised scene the story plays in.
    cancel.check()?;
    let scene_files = write_scene(&u.animation.scene, &u.scene.composition.query, cat, &job.scene)?;
    progress.inc(1);
    progress.set_message("writing story.gltf");
    let mut files = scene_files.clone();
    let dir = &job.scene.out_dir;
    if let Some(curves) = &u.curves {
        let plot = dir.join("costs.png");
        plot_costs(&plot, curves)?;
        files.push(plot);
    }
    let animation = u.animation;
    let chars: Vec<(&str, &inbetween_core::clip::Clip)> =
        animation.characters.iter().map(|c| (c.name.as_str(), &c.clip)).collect();
    let track = camera_track(&animation);
    let cam = |f: usize| track.pose(f);
    let gltf = dir.join("story.gltf");
    cancel.check()?;
    output::write_story_gltf(&gltf, &animation, cat, &cam)?;
    files.push(gltf);
    progress.inc(1);
    progress.set_message("writing the BVH files");
    for c in &animation.characters {
        let safe: String = c.name.chars().map(|ch| if ch.is_alphanumeric() { ch } else { '_' }).collect();
        let bvh = dir.join(format!("{safe}.bvh"));
        output::write_character_bvh(&bvh, &c.clip)?;
        files.push(bvh);
    }
    progress.inc(1);
    progress.set_message("drawing story.gif");
    let gif = dir.join("story.gif");
    cancel.check()?;
    let moving = (0..animation.scene.objects.len())
        .filter(|&i| crate::animate::moves(&animation, i))
        .map(|i| {
            let poses = (0..animation.frames())
                .map(|f| {
                    let (p, q) = crate::animate::object_pose(&animation, i, f);
                    ([p.x as f32, p.y as f32, p.z as f32], crate::motion::rig::heading_of(q) as f32)
                })
                .collect();
            (i, poses)
        })
        .collect();
    let opts = output::AnimPreviewOptions { width: job.gif_width, moving, ..output::AnimPreviewOptions::default() };
    output::render_preview_gif(&gif, &animation.scene, cat, &chars, &cam, animation.fps, &opts)?;
    files.push(gif);
    progress.inc(1);
    progress.set_message("drawing routes.png");
    let routes = dir.join("routes.png");
    cancel.check()?;
    output::render_top_down_trails(&routes, &animation.scene, cat, &chars)?;
    files.push(routes);
    progress.inc(1);
    progress.finish();
    let composition = u.scene.composition;
    let diagnostics = notes.into_iter().chain(composition.diagnostics.iter().cloned()).collect();
    let scene = SceneReport { files: scene_files, composition, diagnostics, seconds: u.scene.seconds };
    Ok(RunReport {
        scene,
        animation,
        before: u.before,
        after: u.after,
        files,
        seconds: start.elapsed().as_secs_f64(),
        full: u.full,
        resolved_characters: u.resolved_characters,
        kept_characters: u.kept_characters,
        resolved_objects: u.resolved_objects,
    })
}

/// `inbetween script watch`: re-runs `run` every time the script file changes (the paper's
/// editing loop), until `max_runs` runs (None: forever). One [`StorySession`] lives across the
/// runs, so a later version re-solves only the characters and objects its edit touches (with
/// `--semantic` the catalogue depends on the text, and every run starts afresh). `on_run` sees
/// each outcome; an error in one version (an empty file while saving) is reported and the loop
/// goes on.
pub fn watch(
    path: &Path,
    job: &RunJob,
    max_runs: Option<usize>,
    mut on_run: impl FnMut(Result<RunReport, ScriptError>),
) -> Result<(), ScriptError> {
    let mut last: Option<(std::time::SystemTime, u64)> = None;
    let mut runs = 0;
    let mut session: Option<StorySession> = None;
    loop {
        let meta = std::fs::metadata(path).map_err(|e| ScriptError::io(path, e))?;
        let stamp = (meta.modified().map_err(|e| ScriptError::io(path, e))?, meta.len());
        if last != Some(stamp) {
            last = Some(stamp);
            let outcome = read_script(path).and_then(|text| {
                let notes = match (&mut session, &job.scene.semantic) {
                    (Some(_), None) => Vec::new(),
                    _ => {
                        let (s, notes) = story_session(&text, job)?;
                        session = Some(s);
                        notes
                    }
                };
                let s = session.as_mut().expect("a session was just made");
                run_story_in(s, notes, &text, path, job)
            });
            on_run(outcome);
            runs += 1;
            if max_runs.is_some_and(|m| runs >= m) {
                return Ok(());
            }
        }
        std::thread::sleep(std::time::Duration::from_millis(250));
    }
}

#[cfg(test)]
mod whole_tests {
    use super::*;

    #[test]
    fn a_whole_run_lands_in_its_folder_and_a_failed_one_leaves_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("out");
        let job = RunJob {
            scene: SceneJob { out_dir: out.clone(), ..SceneJob::default() },
            optimize: false,
            gif_width: 120,
            ..RunJob::default()
        };
        let e = run_story_whole("", Path::new("empty.txt"), &job).unwrap_err();
        assert!(matches!(e, ScriptError::Empty { .. }), "{e}");
        assert!(!out.exists(), "a failed run writes nothing");
        let r =
            run_story_whole("A chair is near a desk$.\nEve walks to the desk.\n", Path::new("s.txt"), &job).unwrap();
        assert!(!r.files.is_empty());
        for f in r.files.iter().chain(&r.scene.files) {
            assert!(f.starts_with(&out) && f.is_file(), "{}", f.display());
        }
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1, "no staging folder left");
    }
}
