//! `inbetween face edit`'s outputs: one edit per seed (the variants), each written as a clip, a PNG
//! of its curves and (when asked) a GIF of the schematic face; all of them appear together when
//! every variant is done, or none ([`inbetween_io::OutputSet`]).

use std::path::{Path, PathBuf};

use inbetween_io::fsutil::with_stem_suffix;
use inbetween_io::{OutputSet, Progress};

use crate::data::{write_clip, FaceError};
use crate::infer::{run_variants, EditJob, Variant};
use crate::preview::{write_outcome_gif, write_outcome_png};

/// Where an edit's outputs go.
#[derive(Clone, Debug)]
pub struct EditFiles {
    /// The file the clip was read from, named in the lines and in the PNG's title.
    pub input: PathBuf,
    /// The edited clip: Live Link CSV when `live_link`, else curve CSV/JSON by extension.
    pub out: PathBuf,
    /// Write `out` as Live Link Face CSV ([`crate::infer::plan::keeps_live_link`]).
    pub live_link: bool,
    /// The PNG of the edited curves (None: `out` with `.png`).
    pub png: Option<PathBuf>,
    /// A GIF of the schematic face, original beside edited, over the spans ±1 s.
    pub gif: Option<PathBuf>,
    /// Edits with the seeds `seed`, `seed + 1`, …; with more than one, every file's name gets
    /// `-1` … `-N` before its extension.
    pub variants: u32,
}

/// What [`write_variants`] wrote.
#[derive(Clone, Debug, Default)]
pub struct WrittenEdits {
    /// Per variant: the previews written, then the edit's line (spans, input, method, seed,
    /// milliseconds, file).
    pub lines: Vec<String>,
    /// Variants 2..N: mean |difference| from variant 1 inside the spans, in blendshape weight
    /// ([`crate::infer::EditOutcome::mean_abs_difference`]).
    pub spreads: Vec<f64>,
}

impl WrittenEdits {
    /// The spreads as one line (None with a single variant).
    pub fn spreads_line(&self) -> Option<String> {
        let list: Vec<String> = self.spreads.iter().map(|d| format!("{d:.4}")).collect();
        (!list.is_empty()).then(|| {
            format!(
                "variants 2..{}: mean |difference| from variant 1 inside the spans (blendshape weight, 0..1): {}",
                list.len() + 1,
                list.join(", ")
            )
        })
    }
}

/// Runs `job` once per variant ([`run_variants`]: its seed, then the next ones) and stages each
/// edit's clip, PNG and GIF (see [`EditFiles`]); moves them all into place once every variant is
/// done. `job.seed` is left at the last variant's seed.
pub fn write_variants(job: &mut EditJob, files: &EditFiles) -> Result<WrittenEdits, FaceError> {
    fn output<E: std::error::Error + Send + Sync + 'static>(what: String) -> impl FnOnce(E) -> FaceError {
        move |e| FaceError::Output { what, source: Box::new(e) }
    }
    let staged = |set: &mut OutputSet, p: &Path| set.file(p).map_err(output(format!("preparing {}", p.display())));
    let (mut set, mut written) = (OutputSet::new(), WrittenEdits::default());
    let made = run_variants(job, files.variants as usize, &[], &Progress::hidden())?;
    for (k, Variant { outcome: out, report }) in (1..).zip(&made) {
        let named = |p: &Path| if files.variants == 1 { p.to_path_buf() } else { with_stem_suffix(p, &k.to_string()) };
        let out_path = named(&files.out);
        write_clip(&staged(&mut set, &out_path)?, &out.clip, files.live_link)?;
        let png = named(&files.png.clone().unwrap_or_else(|| files.out.with_extension("png")));
        let title = format!("{} · {} · {}", files.input.display(), report.method, report.guidance);
        write_outcome_png(&staged(&mut set, &png)?, out, &title)
            .map_err(output(format!("writing {}", png.display())))?;
        job.cancel.check()?;
        if let Some(gif) = files.gif.as_deref().map(named) {
            let progress = Progress::new(0, "face gif");
            write_outcome_gif(&staged(&mut set, &gif)?, out, &progress)
                .map_err(output(format!("writing {}", gif.display())))?;
            progress.finish();
            job.cancel.check()?;
            written.lines.push(format!("  preview {}", gif.display()));
        }
        written.lines.push(format!("  curves {}", png.display()));
        written.lines.push(format!(
            "edited {} span(s) of {} ({} frames at {:.3} fps) with {} (seed {}) in {:.1} ms -> {}",
            job.spans.len(),
            files.input.display(),
            job.clip.num_frames(),
            job.clip.measured_fps(),
            report.method,
            report.seed,
            report.ms,
            out_path.display(),
        ));
        written.spreads.extend(report.difference_from_first);
    }
    set.commit().map_err(output("moving the edit's outputs into place".into()))?;
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::infer::linear_test_job as job;
    use crate::procedural::{generate, ProceduralConfig};

    /// Two variants of a linear fill: both clips and PNGs under numbered names, a line per file and
    /// edit, the seeds 7 and 8, and a spread of exactly 0 (the method draws nothing); a cancelled
    /// job writes nothing at all.
    #[test]
    fn variants_are_numbered_and_written_together() {
        let clip = generate(&ProceduralConfig { duration_s: 6.0, ..Default::default() }, 3).clip;
        let dir = tempfile::tempdir().unwrap();
        let files = EditFiles {
            input: dir.path().join("in.csv"),
            out: dir.path().join("edit.csv"),
            live_link: false,
            png: None,
            gif: None,
            variants: 2,
        };
        let mut j = job(&clip);
        let written = write_variants(&mut j, &files).unwrap();
        for name in ["edit-1.csv", "edit-2.csv", "edit-1.png", "edit-2.png"] {
            assert!(dir.path().join(name).is_file(), "{name} missing");
        }
        assert!(!dir.path().join("edit.csv").exists());
        assert_eq!(written.lines.len(), 4, "{:?}", written.lines);
        assert!(written.lines[1].contains("(seed 7)") && written.lines[3].contains("(seed 8)"), "{:?}", written.lines);
        assert!(written.lines[3].ends_with(&format!("-> {}", dir.path().join("edit-2.csv").display())));
        assert_eq!(written.spreads, vec![0.0]);
        assert!(written.spreads_line().unwrap().starts_with("variants 2..2: mean |difference|"));

        let other = EditFiles { out: dir.path().join("none.csv"), variants: 1, ..files };
        let mut j = job(&clip);
        j.cancel.cancel();
        assert!(write_variants(&mut j, &other).is_err());
        assert!(!dir.path().join("none.csv").exists() && !dir.path().join("none.png").exists());
    }
}
