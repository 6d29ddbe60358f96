//! The template-action library (§3.2 "template action dataset", §4.2 retrieval of action motion
//! files): clips on the common skeleton indexed by action tags, retrieved by verb lemma.

use super::cmu::{load_bvh, read_index, CmuTrial};
use super::kenney;
use super::procedural;
use super::rig::Rig;
use super::verbs::canonical;
use crate::ScriptError;
use inbetween_core::clip::Clip;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Where a clip comes from.
#[derive(Clone, Debug, PartialEq)]
pub enum ClipSource {
    /// Built in ([`MotionLibrary::procedural`]).
    Procedural,
    /// A CMU trial's BVH, retargeted.
    Cmu { clip_id: String, description: String, path: PathBuf },
    /// A named animation of a Kenney blocky character (glTF), retargeted.
    Kenney { animation: String, path: PathBuf },
}

/// One template action: a clip on the common metre skeleton (30 fps, starting at the origin
/// facing +Z, feet on y = 0) with its tags; the first tag is the primary action.
#[derive(Clone, Debug, PartialEq)]
pub struct LibraryClip {
    pub name: String,
    pub tags: Vec<String>,
    pub clip: Clip,
    pub source: ClipSource,
}

impl LibraryClip {
    pub fn has_tag(&self, tag: &str) -> bool {
        self.tags.iter().any(|t| t == tag)
    }

    /// True for motion capture (CMU).
    pub fn is_captured(&self) -> bool {
        matches!(self.source, ClipSource::Cmu { .. })
    }

    /// Retrieval preference among clips of the same action: mocap, then procedural, then the
    /// Kenney game animations (one segment per limb, so stiffer than the procedural clips).
    pub fn source_rank(&self) -> u8 {
        match self.source {
            ClipSource::Cmu { .. } => 0,
            ClipSource::Procedural => 1,
            ClipSource::Kenney { .. } => 2,
        }
    }
}

/// Clips indexed by tags, plus what loading the CMU corpus found.
#[derive(Clone, Debug, Default)]
pub struct MotionLibrary {
    pub clips: Vec<LibraryClip>,
    /// Every trial of the CMU index with its tags (empty without the corpus).
    pub trials: Vec<CmuTrial>,
    /// Trials with a file in the corpus that were not loaded, and why.
    pub skipped: Vec<(String, String)>,
    /// Seconds spent reading and retargeting BVH files.
    pub load_seconds: f64,
}

impl MotionLibrary {
    /// The built-in procedural library: walk and run cycles, idle, sit down / sit / stand up,
    /// reach, wave, punch, type (play), call (talk), drink, look, think, write, hammer. Needs no
    /// files; `seed` varies amplitudes by a few percent.
    pub fn procedural(seed: u64) -> MotionLibrary {
        let clips = procedural::clips(seed)
            .into_iter()
            .map(|(name, tags, clip)| LibraryClip { name, tags, clip, source: ClipSource::Procedural })
            .collect();
        MotionLibrary { clips, ..Default::default() }
    }

    /// The procedural library plus the CMU corpus at `dir` (the folder holding `index.tsv`): every
    /// trial is tagged from its description; up to `max_clips` trials with a BVH in the corpus
    /// (the cgspeed conversion, else the iClone/Character Creator one) are loaded up front and
    /// retargeted (in index order; the time goes to [`MotionLibrary::load_seconds`]). Trials whose
    /// only files are ASF/AMC or another rig (Daz) are listed in [`MotionLibrary::skipped`].
    pub fn with_cmu(dir: &Path, max_clips: usize) -> Result<MotionLibrary, ScriptError> {
        let mut lib = MotionLibrary::procedural(0);
        lib.trials = read_index(&dir.join("index.tsv"))?;
        let rig = Rig::standard();
        let t0 = Instant::now();
        let mut loaded = 0;
        for trial in &lib.trials {
            if trial.files.is_empty() {
                continue;
            }
            let Some(file) = trial.bvh() else {
                lib.skipped.push((trial.clip_id.clone(), format!("no loadable BVH ({})", trial.files.join(", "))));
                continue;
            };
            let path = dir.join(file);
            if loaded >= max_clips {
                lib.skipped.push((trial.clip_id.clone(), format!("over max_clips = {max_clips}")));
                continue;
            }
            if !path.is_file() {
                lib.skipped.push((trial.clip_id.clone(), format!("{} is missing", path.display())));
                continue;
            }
            match load_bvh(&path, &rig) {
                Ok(clip) => {
                    let mut tags = trial.tags.clone();
                    tags.push("cmu".into());
                    lib.clips.push(LibraryClip {
                        name: format!("cmu {} {}", trial.clip_id, trial.description),
                        tags,
                        clip,
                        source: ClipSource::Cmu {
                            clip_id: trial.clip_id.clone(),
                            description: trial.description.clone(),
                            path,
                        },
                    });
                    loaded += 1;
                }
                Err(e) => lib.skipped.push((trial.clip_id.clone(), e.to_string())),
            }
        }
        lib.add_captured_cycles(&rig);
        lib.load_seconds = t0.elapsed().as_secs_f64();
        Ok(lib)
    }

    /// For walk and run: the best-looping gait cycle cut from the loaded CMU clips of that action
    /// ([`super::cycle::extract_cycle`]), added as a `cycle` clip so locomotion loops captured
    /// steps (mocap ranks before the procedural cycle). Returns the cycles added.
    pub fn add_captured_cycles(&mut self, rig: &Rig) -> usize {
        let mut added = 0;
        for verb in ["walk", "run"] {
            let best = self
                .clips
                .iter()
                .filter(|c| c.is_captured() && c.tags.first().is_some_and(|t| t == verb))
                .filter_map(|c| super::cycle::extract_cycle(&c.clip, rig).map(|(m, cut)| (c, m, cut)))
                .min_by(|a, b| a.2.seam.total_cmp(&b.2.seam));
            let Some((from, clip, cut)) = best else { continue };
            let name = format!("{} {verb} cycle (frames {}–{})", from.name, cut.start, cut.start + cut.period);
            let source = from.source.clone();
            let tags = [verb, "cycle", "loop", "locomotion", "cmu"].map(String::from).to_vec();
            self.clips.push(LibraryClip { name, tags, clip, source });
            added += 1;
        }
        added
    }

    /// Adds the named animations of the Kenney blocky characters in `dir` (every `.glb`, sorted;
    /// an animation name already loaded from an earlier file is skipped; animations whose name is
    /// no known action are left out). Returns how many clips were added.
    pub fn add_kenney(&mut self, dir: &Path) -> Result<usize, ScriptError> {
        let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
            .map_err(|e| ScriptError::io(dir, e))?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|x| x.eq_ignore_ascii_case("glb")))
            .collect();
        files.sort();
        let t0 = Instant::now();
        let mut added = 0;
        for path in files {
            for (animation, clip) in kenney::read_animations(&path)? {
                let tags = kenney::tags_of_name(&animation);
                let seen = self
                    .clips
                    .iter()
                    .any(|c| matches!(&c.source, ClipSource::Kenney { animation: a, .. } if *a == animation));
                if tags.is_empty() || seen {
                    continue;
                }
                let stem = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
                let mut tags = tags;
                tags.push("kenney".into());
                self.clips.push(LibraryClip {
                    name: format!("kenney {stem} {animation}"),
                    tags,
                    clip,
                    source: ClipSource::Kenney { animation, path: path.clone() },
                });
                added += 1;
            }
        }
        self.load_seconds += t0.elapsed().as_secs_f64();
        Ok(added)
    }

    /// Everything available: the procedural library, plus the CMU corpus (`mocap/cmu`, up to
    /// `max_cmu` clips) and the Kenney characters (`assets/kenney_blocky_characters`) under the
    /// shared data folder when present. Problems become [`MotionLibrary::skipped`] entries.
    pub fn from_shared(max_cmu: usize) -> MotionLibrary {
        let Ok(data) = inbetween_io::shared_data_dir() else {
            return MotionLibrary::procedural(0);
        };
        let cmu = data.join("mocap/cmu");
        let mut lib = if cmu.join("index.tsv").is_file() {
            MotionLibrary::with_cmu(&cmu, max_cmu).unwrap_or_else(|e| {
                let mut l = MotionLibrary::procedural(0);
                l.skipped.push(("cmu".into(), e.to_string()));
                l
            })
        } else {
            MotionLibrary::procedural(0)
        };
        let kenney = data.join("assets/kenney_blocky_characters");
        if kenney.is_dir() {
            if let Err(e) = lib.add_kenney(&kenney) {
                lib.skipped.push(("kenney".into(), e.to_string()));
            }
        }
        lib
    }

    /// The clip for a verb lemma: the lemma is mapped to its canonical action through the synonym
    /// table ([`super::verbs::VERBS`]); among clips with that tag, clips whose primary tag it is come
    /// first, then by [`LibraryClip::source_rank`] (mocap first), then by name. None for a verb
    /// no clip covers.
    pub fn retrieve(&self, verb_lemma: &str) -> Option<&LibraryClip> {
        let tag = canonical(verb_lemma)?;
        self.candidates(tag).into_iter().next()
    }

    /// All clips tagged `tag`, best first (the order [`MotionLibrary::retrieve`] uses).
    pub fn candidates(&self, tag: &str) -> Vec<&LibraryClip> {
        let mut c: Vec<&LibraryClip> = self.clips.iter().filter(|c| c.has_tag(tag)).collect();
        c.sort_by(|a, b| {
            let key = |c: &LibraryClip| (c.tags.first().is_none_or(|t| t != tag), c.source_rank());
            key(a).cmp(&key(b)).then_with(|| a.name.cmp(&b.name))
        });
        c
    }

    /// The locomotion cycle for a verb (walk, run): a clip tagged `cycle` with that action.
    pub fn cycle(&self, verb_lemma: &str) -> Option<&LibraryClip> {
        let tag = canonical(verb_lemma)?;
        self.candidates(tag).into_iter().find(|c| c.has_tag("cycle"))
    }

    /// The clip with this exact name.
    pub fn get(&self, name: &str) -> Option<&LibraryClip> {
        self.clips.iter().find(|c| c.name == name)
    }

    /// Number of clips per tag, sorted by tag.
    pub fn tag_counts(&self) -> Vec<(String, usize)> {
        let mut m = std::collections::BTreeMap::new();
        for c in &self.clips {
            for t in &c.tags {
                *m.entry(t.clone()).or_insert(0) += 1;
            }
        }
        m.into_iter().collect()
    }
}
