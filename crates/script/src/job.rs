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
