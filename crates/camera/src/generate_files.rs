//! `inbetween camera generate`'s outputs: one track per requested style through the same keys
//! ([`crate::weights::CameraWeights::requested_styles`]), each written as JSON, glTF and (when
//! asked) a top-down preview GIF; all of them appear together when every track is done, or none.

use std::path::{Path, PathBuf};

use inbetween_io::fsutil::with_stem_suffix;
use inbetween_io::OutputSet;

use crate::dataset::{Behaviour, Scene};
use crate::infer::{FastModel, GenerateJob, GenerateOptions, Keys, Style};
use crate::CameraError;

/// Where the tracks go.
#[derive(Clone, Debug)]
pub struct TrackFiles {
    /// The track's JSON; a behaviour's track has its name inserted (`out-orbit.json`).
    pub out: PathBuf,
    /// The glTF camera animation (None: `out` with `.gltf`).
    pub gltf: Option<PathBuf>,
    /// A top-down preview GIF with a picture-in-picture camera view.
    pub gif: Option<PathBuf>,
    /// One track per style: the given glTF and GIF names get the style's name inserted too.
    pub per_style: bool,
}

/// Generates a track per `(style, behaviour)` over `scene` through `keys` (named `origin` in
/// errors) and writes each (see [`TrackFiles`]) as one whole set. Returns the lines to show: the
/// previews written and, per track, its frames, file and keyframe misses before and after the
/// correction.
pub fn write_tracks(
    model: &FastModel,
    scene: &Scene,
    keys: &Keys,
    origin: &Path,
    styles: Vec<(Style, Option<Behaviour>)>,
    options: GenerateOptions,
    files: &TrackFiles,
) -> Result<Vec<String>, CameraError> {
    let mut set = OutputSet::new();
    let mut lines = Vec::new();
    let staged =
        |set: &mut OutputSet, p: &Path| set.file(p).map_err(|source| CameraError::Io { path: p.into(), source });
    for (style, behaviour) in styles {
        let name = style.name.clone();
        let out = behaviour.map_or_else(|| files.out.clone(), |b| with_stem_suffix(&files.out, b.name()));
        let track = GenerateJob { model, scene, keys, style: &style, options, origin }.run()?;
        crate::write_json(&staged(&mut set, &out)?, &track)?;
        let gltf = match &files.gltf {
            Some(g) if files.per_style => with_stem_suffix(g, &name),
            Some(g) => g.clone(),
            None => out.with_extension("gltf"),
        };
        crate::gltf::write_gltf(&staged(&mut set, &gltf)?, &track, scene)?;
        if let Some(g) = &files.gif {
            let g = if files.per_style { with_stem_suffix(g, &name) } else { g.clone() };
            crate::preview::write_preview(&staged(&mut set, &g)?, &track, scene, 3)?;
            lines.push(format!("  preview {}", g.display()));
        }
        if let Some(cancel) = options.cancel {
            cancel.check()?;
        }
        lines.push(format!(
            "{name}: {} frames -> {} (network keyframe miss max {:.4}, after correction {:.1e})",
            track.frames.len(),
            out.display(),
            track.worst_key_miss(),
            track.max_corrected_residual
        ));
    }
    set.commit().map_err(|source| CameraError::Io { path: files.out.clone(), source })?;
    Ok(lines)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The demo's example scene and keys with the committed weights: a track per behaviour, each
    /// with its JSON, glTF and GIF named after it, and nothing when a track cannot be made.
    #[test]
    fn one_track_per_style_is_written_under_its_name() {
        let dir = tempfile::tempdir().unwrap();
        let w = crate::weights::committed().unwrap();
        let (scene, keys) = crate::demo::scaled_example(1);
        let styles = w.requested_styles(true, None, None, &scene).unwrap();
        let n = styles.len();
        let files = TrackFiles {
            out: dir.path().join("cam.json"),
            gltf: Some(dir.path().join("cam.gltf")),
            gif: Some(dir.path().join("cam.gif")),
            per_style: true,
        };
        let lines =
            write_tracks(&w.model, &scene, &keys, Path::new("keys"), styles, GenerateOptions::default(), &files)
                .unwrap();
        assert_eq!(lines.len(), 2 * n, "{lines:?}");
        for b in ["direct", "orbit"] {
            for ext in ["json", "gltf", "gif"] {
                assert!(dir.path().join(format!("cam-{b}.{ext}")).is_file(), "cam-{b}.{ext}");
            }
        }
        let mut far = keys.clone();
        far.keys[0].frame = scene.num_frames() + 10;
        let other = TrackFiles { out: dir.path().join("none.json"), gltf: None, gif: None, per_style: false };
        let style = w.requested_styles(false, None, Some("orbit"), &scene).unwrap();
        assert!(
            write_tracks(&w.model, &scene, &far, Path::new("k"), style, GenerateOptions::default(), &other).is_err()
        );
        assert!(!dir.path().join("none.json").exists() && !dir.path().join("none.gltf").exists());
    }
}
