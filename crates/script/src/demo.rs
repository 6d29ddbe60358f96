//! The script part of `inbetween demo`: the built-in story composed into a furnished scene, then
//! one sentence edited to show that the rest of the scene stays in place.

use std::path::{Path, PathBuf};

use crate::bench::edit_one_sentence;
use crate::compose::ComposeConfig;
use crate::job::{run_scene, SceneJob};
use crate::stories;
use crate::ScriptError;

/// Runs the demo into `<dir>/script`; returns the lines the CLI prints.
pub fn run(dir: &Path, seed: u64) -> Result<Vec<String>, ScriptError> {
    let out = dir.join("script");
    let job = SceneJob { out_dir: out.clone(), seed, view: None, models: None, config: ComposeConfig { seed, ..ComposeConfig::default() }, semantic: None };
    let report = run_scene(stories::DEMO, &PathBuf::from("builtin:demo"), &job)?;
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
    // The editing loop: one sentence changed, everything else stays.
    let cat = crate::job::catalogue(None)?;
    let db = crate::database::SceneDatabase::builtin(&cat, crate::job::DEFAULT_VARIATIONS, seed);
    let mut session = crate::session::Session::new(cat, db, ComposeConfig { seed, ..ComposeConfig::default() });
    session.update(stories::DEMO);
    let edit = session.update(&edit_one_sentence(stories::DEMO));
    lines.push(format!(
        "script: after editing one sentence, {} objects kept their places and {} were placed anew in {:.1} ms",
        edit.kept,
        edit.placed,
        edit.seconds * 1e3
    ));
    Ok(lines)
}
