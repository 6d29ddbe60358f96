//! The CMU clips of the shared data folder (§5.1's "CMU data"), one entry per distinct take.
//!
//! The corpus holds the same takes in three encodings: cgspeed BVH (31 joints, 120 fps, CMU length
//! units), the original ASF/AMC (120 fps, CMU units) and iClone Character Creator retargets (100 or
//! 101 joints, 60 fps, centimetres). A take present in several is read once, preferring cgspeed,
//! then ASF/AMC. Every clip records its length unit, so errors in cm mean the same on all of them.

use crate::{MocapError, Result};
use inbetween_core::procedural::CM_PER_CMU_UNIT;
use inbetween_core::Motion;
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// One take.
#[derive(Clone, Debug)]
pub struct Clip {
    /// CMU take id, `subject_trial` (`131_01`), or the file stem for a plain folder.
    pub name: String,
    /// `cgspeed`, `asf_amc`, `iclone_cc` or `bvh`.
    pub source: &'static str,
    pub motion: Motion,
    /// Centimetres per length unit of the file.
    pub cm_per_unit: f64,
}

/// Centimetres per unit of the iClone retargets (already centimetre-like, hip height ~85–105).
const CM_PER_ICLONE_UNIT: f64 = 1.0;

/// All distinct takes under `dir/mocap/cmu`, or, when `dir` has no such folder, every `.bvh` in
/// `dir` itself (read as CMU units). Sorted by name.
pub fn cmu_corpus(dir: &Path) -> Result<Vec<Clip>> {
    let cmu = dir.join("mocap/cmu");
    if !cmu.is_dir() {
        let clips = bvh_folder(dir, "bvh", CM_PER_CMU_UNIT, |stem| Some(stem.to_string()))?;
        if clips.is_empty() {
            return Err(MocapError::Invalid(format!("no .bvh clips in {}", dir.display())));
        }
        return Ok(clips);
    }
    let mut clips = bvh_folder(&cmu.join("cgspeed"), "cgspeed", CM_PER_CMU_UNIT, |s| Some(s.to_string()))?;
    let mut seen: BTreeSet<String> = clips.iter().map(|c| c.name.clone()).collect();
    for (asf, amc) in asf_amc_pairs(&cmu.join("asf_amc"))? {
        let name = stem(&amc);
        if seen.insert(name.clone()) {
            let motion = inbetween_io::read_asf_amc(&asf, &amc)?;
            clips.push(Clip { name, source: "asf_amc", motion, cm_per_unit: CM_PER_CMU_UNIT });
        }
    }
    for clip in bvh_folder(&cmu.join("iclone_cc"), "iclone_cc", CM_PER_ICLONE_UNIT, iclone_take)? {
        if seen.insert(clip.name.clone()) {
            clips.push(clip);
        }
    }
    clips.sort_by(|a, b| a.name.cmp(&b.name));
    if clips.is_empty() {
        return Err(MocapError::Invalid(format!("no clips in {}", cmu.display())));
    }
    Ok(clips)
}

/// `001_08` → `01_08` (iClone pads subjects to three digits).
fn iclone_take(stem: &str) -> Option<String> {
    let (subject, trial) = stem.split_once('_')?;
    Some(format!("{:02}_{trial}", subject.parse::<u32>().ok()?))
}

fn stem(p: &Path) -> String {
    p.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default()
}

fn sorted_files(dir: &Path, ext: &str) -> Result<Vec<PathBuf>> {
    if !dir.is_dir() {
        return Ok(Vec::new());
    }
    let entries =
        std::fs::read_dir(dir).map_err(|source| MocapError::Io { path: dir.display().to_string(), source })?;
    let mut paths: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e.eq_ignore_ascii_case(ext)))
        .collect();
    paths.sort();
    Ok(paths)
}

fn bvh_folder(
    dir: &Path,
    source: &'static str,
    cm_per_unit: f64,
    take: impl Fn(&str) -> Option<String>,
) -> Result<Vec<Clip>> {
    sorted_files(dir, "bvh")?
        .into_iter()
        .map(|p| {
            let s = stem(&p);
            let motion = inbetween_io::read_bvh(&p)?;
            Ok(Clip { name: take(&s).unwrap_or(s), source, motion, cm_per_unit })
        })
        .collect()
}

/// `NN_TT.amc` files with their subject's `NN.asf` beside them.
fn asf_amc_pairs(dir: &Path) -> Result<Vec<(PathBuf, PathBuf)>> {
    Ok(sorted_files(dir, "amc")?
        .into_iter()
        .filter_map(|amc| {
            let name = stem(&amc);
            let subject = name.split('_').next()?.to_string();
            let asf = dir.join(format!("{subject}.asf"));
            asf.is_file().then_some((asf, amc))
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use inbetween_core::procedural::{gait, GaitParams};

    #[test]
    fn iclone_names_map_to_cmu_takes() {
        assert_eq!(iclone_take("001_08").as_deref(), Some("01_08"));
        assert_eq!(iclone_take("131_01").as_deref(), Some("131_01"));
        assert_eq!(iclone_take("walk"), None);
    }

    #[test]
    fn plain_folder_reads_every_bvh_and_refuses_an_empty_one() {
        let dir = tempfile::tempdir().unwrap();
        assert!(cmu_corpus(dir.path()).unwrap_err().to_string().contains("no .bvh clips"));
        let m = gait(&GaitParams { frames: 10, fps: 30.0, ..GaitParams::walk() });
        inbetween_io::write_bvh(&dir.path().join("b.bvh"), &m).unwrap();
        inbetween_io::write_bvh(&dir.path().join("a.bvh"), &m).unwrap();
        let clips = cmu_corpus(dir.path()).unwrap();
        assert_eq!(clips.iter().map(|c| c.name.as_str()).collect::<Vec<_>>(), ["a", "b"]);
        assert_eq!(clips[0].cm_per_unit, CM_PER_CMU_UNIT);
    }

    #[test]
    fn shared_corpus_has_one_entry_per_take() {
        inbetween_io::data::with_shared_data("the CMU corpus", |dir| {
            let clips = cmu_corpus(&dir).unwrap();
            let names: BTreeSet<&str> = clips.iter().map(|c| c.name.as_str()).collect();
            assert_eq!(names.len(), clips.len(), "no take twice");
            assert!(names.contains("01_01") && names.contains("11_01") && names.contains("01_08"));
            let first = clips.iter().find(|c| c.name == "01_01").unwrap();
            assert_eq!(first.source, "cgspeed", "cgspeed preferred over ASF/AMC");
            let cc = clips.iter().find(|c| c.name == "01_08").unwrap();
            assert_eq!((cc.source, cc.cm_per_unit), ("iclone_cc", 1.0));
        });
    }
}
