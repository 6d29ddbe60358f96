//! The script part of `inbetween demo`: the built-in story composed into a furnished scene, then
//! one sentence edited to show that the rest of the scene stays in place.

use std::path::{Path, PathBuf};

use crate::builtin_scripts;
use crate::compose::ComposeConfig;
use crate::jobs::{run_scene, SceneJob};
use crate::ScriptError;

/// Runs the demo into `<dir>/script`; returns the lines the CLI prints.
pub fn run(dir: &Path, seed: u64) -> Result<Vec<String>, ScriptError> {
    let out = dir.join("script");
    let job = SceneJob {
        limits: crate::limits::ScriptLimits::default(),
        out_dir: out.clone(),
        seed,
        view: None,
        models: None,
        config: ComposeConfig { seed, ..ComposeConfig::default() },
        semantic: None,
    };
    let report = run_scene(builtin_scripts::DEMO, &PathBuf::from("builtin:demo"), &job)?;
    let c = &report.composition;
    let mut lines = vec![format!(
        "script: the built-in story → {} objects in a {:.1} m × {:.1} m {}, {} relations, {} layout violations, {:.1} ms -> {}",
        c.scene.objects.len(),
        c.scene.room.width,
        c.scene.room.depth,
        c.scene.room.name,
        c.relations.len(),
        c.violations.total(),
        report.seconds * 1e3,
        out.display()
    )];
    for d in &report.diagnostics {
        lines.push(format!("script: note: {d}"));
    }
    // Part 2: the characters act in the scene, after the joint optimisation (§4.3).
    let run = crate::jobs::RunJob {
        scene: SceneJob { out_dir: out.join("story"), ..job.clone() },
        optimize: true,
        shared_motions: false,
        gif_width: 320,
        cancel: Default::default(),
        progress: inbetween_io::Progress::hidden(),
    };
    let story = crate::jobs::run_story(builtin_scripts::DEMO, &PathBuf::from("builtin:demo"), &run)?;
    lines.push(format!(
        "script: {} characters animated, {} frames ({:.1} s); joint optimisation C {:.3} -> {:.3}, mean contact distance {:.3} m -> {:.3} m -> {}",
        story.animation.characters.len(),
        story.animation.frames(),
        story.animation.frames() as f64 / story.animation.fps,
        story.before.total,
        story.after.total,
        story.before.contact,
        story.after.contact,
        out.join("story").display()
    ));
    // The editing loop: one sentence changed, everything else stays.
    let cat = crate::jobs::catalogue(None)?;
    let db = crate::database::SceneDatabase::builtin(&cat, crate::jobs::DEFAULT_VARIATIONS, seed);
    let mut session = crate::scene_session::Session::new(cat, db, ComposeConfig { seed, ..ComposeConfig::default() });
    session.update(builtin_scripts::DEMO);
    let edit = session.update(&builtin_scripts::edit_one_sentence(builtin_scripts::DEMO));
    lines.push(format!(
        "script: after editing one sentence, {} objects kept their places and {} were placed anew in {:.1} ms",
        edit.kept,
        edit.placed,
        edit.seconds * 1e3
    ));
    Ok(lines)
}
