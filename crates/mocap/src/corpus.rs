//! The CMU clips of the shared data folder (§5.1's "CMU data"), one entry per distinct take, or
//! every `.bvh` under any other folder.
//!
//! The corpus holds the same takes in three encodings: cgspeed BVH (31 joints, 120 fps, CMU length
//! units), the original ASF/AMC (120 fps, CMU units) and iClone Character Creator retargets (100 or
//! 101 joints, 60 fps, centimetres). A take present in several is read once, preferring cgspeed,
//! then ASF/AMC. Every clip records its length unit, so errors in cm mean the same on all of them:
//! the corpus folders' units are known; a clip from any other folder gets the unit inferred from
//! its skeleton ([`LengthUnit::infer`]) unless the caller gives one.

use crate::codec::RAW_BYTES_PER_BONE;
use crate::{MocapError, Result};
use inbetween_core::units::{LengthUnit, UnitChoice};
use inbetween_core::Motion;
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// One take.
#[derive(Clone, Debug)]
pub struct Clip {
    /// CMU take id, `subject_trial` (`131_01`), or the path below the folder without `.bvh`
    /// (`walk`, `sub/run`) for a plain folder.
    pub name: String,
    /// `cgspeed`, `asf_amc`, `iclone_cc` or `bvh`.
    pub source: &'static str,
    pub motion: Motion,
    /// Centimetres per length unit of the file.
    pub cm_per_unit: f64,
}

/// Clips with the unit each one was read in and why.
#[derive(Clone, Debug)]
pub struct Corpus {
    pub clips: Vec<Clip>,
    /// One per clip, same order.
    pub units: Vec<UnitChoice>,
}

impl Corpus {
    /// Report lines saying which unit the clips were read in and why; clips that share a source and
    /// a reason share a line.
    pub fn unit_notes(&self) -> Vec<String> {
        let mut groups: Vec<(&str, &UnitChoice, Vec<&str>)> = Vec::new();
        for (c, u) in self.clips.iter().zip(&self.units) {
            match groups.iter_mut().find(|(s, g, _)| *s == c.source && *g == u) {
                Some((_, _, names)) => names.push(&c.name),
                None => groups.push((c.source, u, vec![&c.name])),
            }
        }
        groups
            .into_iter()
            .map(|(source, u, names)| {
                let who =
                    if names.len() == 1 { names[0].to_string() } else { format!("{} {source} takes", names.len()) };
                format!("{who}: {u}")
            })
            .collect()
    }
}

/// Centimetres per unit of the iClone retargets (already centimetre-like, hip height ~85–105).
const ICLONE_UNIT: LengthUnit = LengthUnit::Centimetre;

/// The sub-folders that mark a CMU corpus folder (`…/mocap/cmu`).
const CORPUS_FOLDERS: [&str; 3] = ["cgspeed", "asf_amc", "iclone_cc"];

/// All distinct takes of a data folder, sorted by name, each read in its inferred unit; see [`load`].
pub fn cmu_corpus(dir: &Path) -> Result<Vec<Clip>> {
    Ok(load(dir, None)?.clips)
}

/// The clips of `dir`: the CMU corpus when `dir` is the shared data folder, its `mocap` or its
/// `mocap/cmu` folder (one entry per take, known units); otherwise every `.bvh` in `dir` and its
/// sub-folders (sorted by path; units inferred per clip). `unit` overrides every clip's unit.
pub fn load(dir: &Path, unit: Option<LengthUnit>) -> Result<Corpus> {
    if !dir.is_dir() {
        return Err(MocapError::Invalid(format!("{} is not a folder", dir.display())));
    }
    let corpus_root = [dir.join("mocap/cmu"), dir.join("cmu"), dir.to_path_buf()]
        .into_iter()
        .find(|d| CORPUS_FOLDERS.iter().any(|f| d.join(f).is_dir()));
    match corpus_root {
        Some(cmu) => cmu_folder(&cmu, unit),
        None => plain_folder(dir, unit),
    }
}

fn cmu_folder(cmu: &Path, unit: Option<LengthUnit>) -> Result<Corpus> {
    let known = |u: LengthUnit, why: &str| match unit {
        Some(g) => UnitChoice::given(g),
        None => UnitChoice { unit: u, reason: format!("known corpus folder: {why}") },
    };
    let cgspeed = known(LengthUnit::Cmu, "cgspeed conversions of CMU mocap keep CMU units");
    let asf = known(LengthUnit::Cmu, "CMU ASF/AMC files are in CMU units");
    let iclone = known(ICLONE_UNIT, "iClone Character Creator exports are in cm");
    let mut out = Corpus { clips: Vec::new(), units: Vec::new() };
    for (name, motion) in bvh_files(&cmu.join("cgspeed"), false)? {
        out.push(name, "cgspeed", motion, cgspeed.clone());
    }
    let mut seen: BTreeSet<String> = out.clips.iter().map(|c| c.name.clone()).collect();
    for (asf_path, amc) in asf_amc_pairs(&cmu.join("asf_amc"))? {
        let name = stem(&amc);
        if seen.insert(name.clone()) {
            out.push(name, "asf_amc", inbetween_io::read_asf_amc(&asf_path, &amc)?, asf.clone());
        }
    }
    for (s, motion) in bvh_files(&cmu.join("iclone_cc"), false)? {
        let name = iclone_take(&s).unwrap_or(s);
        if seen.insert(name.clone()) {
            out.push(name, "iclone_cc", motion, iclone.clone());
        }
    }
    if out.clips.is_empty() {
        return Err(MocapError::Invalid(format!("no clips in {}", cmu.display())));
    }
    out.sort();
    Ok(out)
}

fn plain_folder(dir: &Path, unit: Option<LengthUnit>) -> Result<Corpus> {
    let mut out = Corpus { clips: Vec::new(), units: Vec::new() };
    for (name, motion) in bvh_files(dir, true)? {
        let u = UnitChoice::resolve(unit, &motion.skeleton);
        out.push(name, "bvh", motion, u);
    }
    if out.clips.is_empty() {
        return Err(MocapError::Invalid(format!("no .bvh clips in {} or its sub-folders", dir.display())));
    }
    Ok(out)
}

impl Corpus {
    fn push(&mut self, name: String, source: &'static str, motion: Motion, unit: UnitChoice) {
        self.clips.push(Clip { name, source, motion, cm_per_unit: unit.cm_per_unit() });
        self.units.push(unit);
    }

    fn sort(&mut self) {
        let mut pairs: Vec<(Clip, UnitChoice)> = self.clips.drain(..).zip(self.units.drain(..)).collect();
        pairs.sort_by(|a, b| a.0.name.cmp(&b.0.name));
        (self.clips, self.units) = pairs.into_iter().unzip();
    }
}

/// `001_08` → `01_08` (iClone pads subjects to three digits).
fn iclone_take(stem: &str) -> Option<String> {
    let (subject, trial) = stem.split_once('_')?;
    Some(format!("{:02}_{trial}", subject.parse::<u32>().ok()?))
}

fn stem(p: &Path) -> String {
    p.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default()
}

fn read_dir_sorted(dir: &Path) -> Result<Vec<PathBuf>> {
    let entries =
        std::fs::read_dir(dir).map_err(|source| MocapError::Io { path: dir.display().to_string(), source })?;
    let mut paths: Vec<PathBuf> = entries.filter_map(|e| e.ok().map(|e| e.path())).collect();
    paths.sort();
    Ok(paths)
}

fn has_ext(p: &Path, ext: &str) -> bool {
    p.extension().is_some_and(|e| e.eq_ignore_ascii_case(ext))
}

/// Files with extension `ext` in `dir` (and, when `recursive`, its sub-folders; symbolic links to
/// folders are not followed), sorted by their path relative to `dir`.
pub fn find_files(dir: &Path, ext: &str, recursive: bool) -> Result<Vec<PathBuf>> {
    let mut out = Vec::new();
    if dir.is_dir() {
        collect(dir, ext, recursive, &mut out)?;
    }
    out.sort();
    Ok(out)
}

fn collect(dir: &Path, ext: &str, recursive: bool, out: &mut Vec<PathBuf>) -> Result<()> {
    for p in read_dir_sorted(dir)? {
        let is_real_dir = std::fs::symlink_metadata(&p).map(|m| m.is_dir()).unwrap_or(false);
        if is_real_dir {
            if recursive {
                collect(&p, ext, recursive, out)?;
            }
        } else if p.is_file() && has_ext(&p, ext) {
            out.push(p);
        }
    }
    Ok(())
}

/// Every `.bvh` of a folder as (name, clip); the name is the path below `dir` without the
/// extension, with `/` between folders.
fn bvh_files(dir: &Path, recursive: bool) -> Result<Vec<(String, Motion)>> {
    find_files(dir, "bvh", recursive)?
        .into_iter()
        .map(|p| {
            let rel = p.strip_prefix(dir).unwrap_or(&p).with_extension("");
            let name = rel.components().map(|c| c.as_os_str().to_string_lossy()).collect::<Vec<_>>().join("/");
            Ok((name, inbetween_io::read_bvh(&p)?))
        })
        .collect()
}

/// `NN_TT.amc` files with their subject's `NN.asf` beside them.
fn asf_amc_pairs(dir: &Path) -> Result<Vec<(PathBuf, PathBuf)>> {
    Ok(find_files(dir, "amc", false)?
        .into_iter()
        .filter_map(|amc| {
            let name = stem(&amc);
            let subject = name.split('_').next()?.to_string();
            let asf = dir.join(format!("{subject}.asf"));
            asf.is_file().then_some((asf, amc))
        })
        .collect())
}

/// One take of the corpus at a protocol's frame rate (the codec bench on ACL's protocol), with
/// its length unit and why.
pub struct Take {
    pub name: String,
    pub source: &'static str,
    pub motion: Motion,
    pub unit: UnitChoice,
}

impl Take {
    /// ACL's raw size of the take: [`RAW_BYTES_PER_BONE`] per joint and frame.
    pub fn raw_bytes(&self) -> usize {
        RAW_BYTES_PER_BONE * self.motion.skeleton.len() * self.motion.num_frames()
    }
}

/// The takes of `clips` (`units` beside them) at `fps` (the cgspeed T-pose frame dropped).
pub fn takes(clips: &[Clip], units: &[UnitChoice], fps: f64) -> Result<Vec<Take>> {
    clips
        .iter()
        .zip(units)
        .map(|(c, u)| {
            let m = if c.source == "cgspeed" && c.motion.num_frames() > 2 {
                c.motion.crop(1, c.motion.num_frames())?
            } else {
                c.motion.clone()
            };
            Ok(Take { name: c.name.clone(), source: c.source, motion: m.resample(fps)?, unit: u.clone() })
        })
        .collect()
}

/// The data folder: `data`, else the shared corpus.
pub fn data_dir(data: Option<&Path>) -> Result<PathBuf> {
    match data {
        Some(d) => Ok(d.to_path_buf()),
        None => inbetween_io::data::shared_data_dir()
            .map_err(|p| MocapError::Invalid(format!("no data at {} (give `data`)", p.display()))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use inbetween_core::procedural::{gait, GaitParams, CM_PER_CMU_UNIT};
    use inbetween_core::units::scale_motion;

    #[test]
    fn iclone_names_map_to_cmu_takes() {
        assert_eq!(iclone_take("001_08").as_deref(), Some("01_08"));
        assert_eq!(iclone_take("131_01").as_deref(), Some("131_01"));
        assert_eq!(iclone_take("walk"), None);
    }

    #[test]
    fn plain_folder_reads_every_bvh_below_it_in_its_own_unit() {
        let dir = tempfile::tempdir().unwrap();
        assert!(cmu_corpus(dir.path()).unwrap_err().to_string().contains("no .bvh clips"));
        let m = gait(&GaitParams { frames: 10, fps: 30.0, ..GaitParams::walk() });
        std::fs::create_dir_all(dir.path().join("sub/deeper")).unwrap();
        inbetween_io::write_bvh(&dir.path().join("b.bvh"), &m).unwrap();
        inbetween_io::write_bvh(&dir.path().join("a.bvh"), &m).unwrap();
        // A centimetre rig two folders down, and a file that is not a clip.
        inbetween_io::write_bvh(&dir.path().join("sub/deeper/cm.BVH"), &scale_motion(&m, CM_PER_CMU_UNIT)).unwrap();
        std::fs::write(dir.path().join("sub/notes.txt"), "x").unwrap();
        let corpus = load(dir.path(), None).unwrap();
        let names: Vec<&str> = corpus.clips.iter().map(|c| c.name.as_str()).collect();
        assert_eq!(names, ["a", "b", "sub/deeper/cm"]);
        assert_eq!(corpus.clips[0].cm_per_unit, CM_PER_CMU_UNIT);
        assert_eq!(corpus.clips[2].cm_per_unit, 1.0);
        let notes = corpus.unit_notes();
        assert!(notes.iter().any(|n| n.starts_with("sub/deeper/cm: length unit: cm (rest-pose height")), "{notes:?}");
        // --unit overrides the inference; a sub-folder alone is a plain folder too.
        let given = load(dir.path(), Some(LengthUnit::Metre)).unwrap();
        assert!(given.clips.iter().all(|c| c.cm_per_unit == 100.0));
        assert_eq!(given.unit_notes(), ["3 bvh takes: length unit: m (given with `unit`)"]);
        assert_eq!(cmu_corpus(&dir.path().join("sub")).unwrap()[0].name, "deeper/cm");
    }

    #[test]
    fn shared_corpus_has_one_entry_per_take_from_any_of_its_folders() {
        inbetween_io::data::with_shared_data("the CMU corpus", |dir| {
            let corpus = load(&dir, None).unwrap();
            let clips = &corpus.clips;
            let names: BTreeSet<&str> = clips.iter().map(|c| c.name.as_str()).collect();
            assert_eq!(names.len(), clips.len(), "no take twice");
            assert!(names.contains("01_01") && names.contains("11_01") && names.contains("01_08"));
            let first = clips.iter().find(|c| c.name == "01_01").unwrap();
            assert_eq!(first.source, "cgspeed", "cgspeed preferred over ASF/AMC");
            let cc = clips.iter().find(|c| c.name == "01_08").unwrap();
            assert_eq!((cc.source, cc.cm_per_unit), ("iclone_cc", 1.0));
            // The known units agree with what inference reads from each skeleton.
            for (c, u) in clips.iter().zip(&corpus.units) {
                assert!(u.reason.starts_with("known corpus folder"), "{}", u.reason);
                let inferred = LengthUnit::infer(&c.motion.skeleton);
                assert_eq!(inferred.cm_per_unit(), c.cm_per_unit, "{}: {}", c.name, inferred.reason);
            }
            assert_eq!(corpus.unit_notes().len(), 3, "{:?}", corpus.unit_notes());
            // `--data …/mocap/cmu` and `--data …/mocap` find the same takes.
            for sub in ["mocap", "mocap/cmu"] {
                assert_eq!(cmu_corpus(&dir.join(sub)).unwrap().len(), clips.len(), "{sub}");
            }
        });
    }
}
