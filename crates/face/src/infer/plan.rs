//! The policy of an edit that the front ends used to carry each on their own (issues 40 and 43): the
//! `auto` method rule, what the method loads ([`EditResources`]), the guidance read from what the
//! user gave ([`GuideSource`]), viseme runs from phoneme timings, spans given in seconds or frames,
//! the groups each guidance acts on, and where the shared captures are. `face edit`, the studio's
//! face panel, the Python package, the batch runner and the tests build their [`super::EditJob`] with
//! these, so the rules live in one place.

use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, OnceLock};

use crate::data::{read_clip_limited, BlendshapeClip, FaceError, MODEL_FPS};
use crate::edit::mask::{parse_span_spec, SpanSpec};
use crate::edit::{ConstraintKind, MotionLibrary, RetrievalOptions};
use crate::infer::{read_keys, Guide, Inpainter, KeyPose, Method, DEFAULT_LIBRARY_S, DEFAULT_LIBRARY_SEED};
use crate::visemes::{phoneme_viseme, read_viseme_source, text_to_phonemes, validate_spans, PhonemeSpan, Viseme};
use crate::weights::Network;

pub use crate::edit::constraints::guided_channels;
pub use crate::edit::groups::SPEECH_GROUPS;

/// How an edit is asked to fill, before [`MethodChoice::resolve`] applies the `auto` rule.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MethodChoice {
    /// The best measured method for the guidance (`face bench`, see [`MethodChoice::resolve`]).
    Auto,
    /// The trained network for the guidance.
    Network,
    /// Segments of recorded motion ([`crate::edit::retrieve`]).
    Retrieval,
    /// Linear interpolation.
    Linear,
    /// Cubic Hermite interpolation.
    Cubic,
}

impl MethodChoice {
    /// Every choice, in the order of [`MethodChoice::name`]'s list.
    pub const ALL: [MethodChoice; 5] =
        [MethodChoice::Auto, MethodChoice::Network, MethodChoice::Retrieval, MethodChoice::Linear, MethodChoice::Cubic];

    /// The name on the command line and in the studio.
    pub fn name(self) -> &'static str {
        match self {
            MethodChoice::Auto => "auto",
            MethodChoice::Network => "network",
            MethodChoice::Retrieval => "retrieval",
            MethodChoice::Linear => "linear",
            MethodChoice::Cubic => "cubic",
        }
    }

    /// The choice named `name`, or an error listing the names.
    pub fn parse(name: &str) -> Result<MethodChoice, FaceError> {
        MethodChoice::ALL.into_iter().find(|m| m.name() == name).ok_or_else(|| {
            FaceError::Invalid(format!(
                "method '{name}': expected {}",
                MethodChoice::ALL.map(MethodChoice::name).join(", ")
            ))
        })
    }

    /// The `auto` rule, from the face bench's tables (README): retrieval when unguided or guided by a
    /// noisy take (the only fills that pass the plausibility test, and the noisy guide's best
    /// error), the network for keys (lowest error) and visemes (retrieval cannot follow them), and the
    /// network whenever the user gave weights. Other choices are returned as they are.
    pub fn resolve(self, kind: ConstraintKind, weights_given: bool) -> MethodChoice {
        match self {
            MethodChoice::Auto if weights_given => MethodChoice::Network,
            MethodChoice::Auto => match kind {
                ConstraintKind::None | ConstraintKind::Noisy => MethodChoice::Retrieval,
                ConstraintKind::Keyframes | ConstraintKind::Visemes => MethodChoice::Network,
            },
            m => m,
        }
    }
}

/// The procedural retrieval library ([`DEFAULT_LIBRARY_S`] seconds, seed [`DEFAULT_LIBRARY_SEED`]):
/// made once per process; every call hands out a clone sharing its frames.
pub fn default_library() -> MotionLibrary {
    static LIBRARY: OnceLock<MotionLibrary> = OnceLock::new();
    LIBRARY.get_or_init(|| MotionLibrary::procedural(DEFAULT_LIBRARY_S, DEFAULT_LIBRARY_SEED)).clone()
}

/// The committed network for guidance `kind` ([`crate::weights::committed`]), loaded once per
/// process and shared by every edit after (the studio's, Python's and the batch runner's many edits).
pub fn committed_network(kind: ConstraintKind) -> Result<Arc<Network>, FaceError> {
    static NETWORKS: Mutex<Vec<(ConstraintKind, Arc<Network>)>> = Mutex::new(Vec::new());
    let mut nets = NETWORKS.lock().unwrap_or_else(|p| p.into_inner());
    if let Some((_, n)) = nets.iter().find(|(k, _)| *k == kind) {
        return Ok(n.clone());
    }
    let n = Arc::new(crate::weights::committed(kind)?);
    nets.push((kind, n.clone()));
    Ok(n)
}

/// The library retrieval draws from: the clips in `files` at the model rate (each at most `max_rows`
/// rows), or the procedural library ([`default_library`]) when none is given.
pub fn retrieval_library(files: &[PathBuf], max_rows: usize) -> Result<MotionLibrary, FaceError> {
    if files.is_empty() {
        return Ok(default_library());
    }
    let clips = files.iter().map(|f| read_clip_limited(f, max_rows)).collect::<Result<Vec<_>, _>>()?;
    library_of_clips(&clips, |i| files[i].display().to_string())
}

/// A retrieval library of `clips` (at any frame rate, resampled to the model rate); a clip that
/// cannot be resampled is an error naming it by `name(index)`.
pub fn library_of_clips(clips: &[BlendshapeClip], name: impl Fn(usize) -> String) -> Result<MotionLibrary, FaceError> {
    let mut lib = MotionLibrary::default();
    for (i, c) in clips.iter().enumerate() {
        let at_model_rate =
            c.resample(MODEL_FPS).map_err(|e| FaceError::File { file: name(i), message: e.to_string() })?;
        lib.push(at_model_rate.arkit_frames());
    }
    Ok(lib)
}

/// A step of setting up an edit that failed, said the way the front ends say it ("loading face
/// weights w.bpk"), with the engine's error as its cause.
#[derive(Debug, thiserror::Error)]
#[error("{what}")]
pub struct SetupError {
    /// What was being done.
    pub what: String,
    /// Why it failed.
    #[source]
    pub source: FaceError,
}

/// What an edit's method needs loaded: the network (for [`MethodChoice::Network`]) and the retrieval
/// library (for [`MethodChoice::Retrieval`], and for the groups viseme guidance leaves unguided).
/// The one setup of every front end (`face edit`, the studio's face panel, `inbetween.face.edit`,
/// the batch runner's `face-edit`), so all build the same [`Method`] and [`super::EditJob::library`]. The
/// committed networks and the default library are loaded once per process ([`committed_network`],
/// [`default_library`]).
pub struct EditResources {
    /// The method, `auto` resolved ([`MethodChoice::resolve`]).
    pub chosen: MethodChoice,
    /// The guidance the edit follows.
    pub kind: ConstraintKind,
    /// The loaded network, when the method is the network.
    pub network: Option<Arc<Network>>,
    /// The retrieval library, when the method or the unguided groups draw from it.
    pub library: Option<MotionLibrary>,
}

impl EditResources {
    /// Resolves `choice` for guidance `kind` and loads the network it needs: `weights` when given,
    /// else the committed network for `kind`. The library is loaded by [`EditResources::load_library`].
    pub fn load_network(
        choice: MethodChoice,
        kind: ConstraintKind,
        weights: Option<&Path>,
    ) -> Result<EditResources, SetupError> {
        let chosen = choice.resolve(kind, weights.is_some());
        let network = match (chosen, weights) {
            (MethodChoice::Network, Some(w)) => Some(Arc::new(
                crate::weights::load(w)
                    .map_err(|source| SetupError { what: format!("loading face weights {}", w.display()), source })?,
            )),
            (MethodChoice::Network, None) => Some(committed_network(kind).map_err(|source| SetupError {
                what: format!("loading the committed {} network", kind.name()),
                source,
            })?),
            _ => None,
        };
        Ok(EditResources { chosen, kind, network, library: None })
    }

    /// Refuses a retrieval library given for an edit whose method is not retrieval (it would be
    /// ignored). The message names the options in backticks (`library`, `method`) for a front end
    /// to write as its own.
    pub fn check_library_given(&self, given: bool) -> Result<(), FaceError> {
        if given && self.chosen != MethodChoice::Retrieval {
            return Err(FaceError::Invalid(format!(
                "`library` is read only by `method` retrieval (the method resolved to {} for {} guidance; auto \
                 picks the network for keys and visemes)",
                self.chosen.name(),
                self.kind.name()
            )));
        }
        Ok(())
    }

    /// Loads the retrieval library ([`retrieval_library`] of `files`, each at most `max_rows` rows)
    /// when the method is retrieval, or the default one when the guidance is visemes and
    /// `groups_given` is false (the groups the visemes leave unguided are drawn from it).
    pub fn load_library(&mut self, files: &[PathBuf], groups_given: bool, max_rows: usize) -> Result<(), FaceError> {
        self.set_library(groups_given, || retrieval_library(files, max_rows))
    }

    /// [`EditResources::load_library`] from clips in memory ([`library_of_clips`], named
    /// `name(index)` in errors; the default library when `clips` is empty).
    pub fn load_library_clips(
        &mut self,
        clips: &[BlendshapeClip],
        groups_given: bool,
        name: impl Fn(usize) -> String,
    ) -> Result<(), FaceError> {
        self.set_library(groups_given, || match clips {
            [] => Ok(default_library()),
            _ => library_of_clips(clips, name),
        })
    }

    fn set_library(
        &mut self,
        groups_given: bool,
        chosen_library: impl FnOnce() -> Result<MotionLibrary, FaceError>,
    ) -> Result<(), FaceError> {
        let unguided_rest = !groups_given && self.kind == ConstraintKind::Visemes;
        self.library = match self.chosen {
            MethodChoice::Retrieval => Some(chosen_library()?),
            _ if unguided_rest => Some(default_library()),
            _ => None,
        };
        Ok(())
    }

    /// The job's [`Method`]; retrieval draws `variants` distinct fills
    /// ([`RetrievalOptions::for_variants`]). An error when the network or the library the method
    /// needs was not loaded.
    pub fn method(&self, variants: usize) -> Result<Method<'_>, FaceError> {
        let missing = |what: &str| FaceError::Invalid(format!("method {}: no {what} loaded", self.chosen.name()));
        Ok(match self.chosen {
            MethodChoice::Linear => Method::Linear,
            MethodChoice::Cubic => Method::Cubic,
            MethodChoice::Retrieval => Method::Retrieval(
                self.library.as_ref().ok_or_else(|| missing("library"))?,
                RetrievalOptions::for_variants(self.kind, variants),
            ),
            MethodChoice::Network => {
                Method::Network(self.network.as_deref().ok_or_else(|| missing("network"))? as &dyn Inpainter)
            }
            MethodChoice::Auto => return Err(missing("resolved method")),
        })
    }
}

/// Where an edit's guidance comes from, as the front ends receive it. [`GuideSource::load`] turns
/// it into the job's [`Guide`] the same way for all of them: keys read, a noisy take read (at most
/// the edit's `max_rows` rows), phoneme timings checked, text pronounced (CMUdict, then the
/// letter-to-sound rules), phonemes made viseme runs ([`viseme_runs`]).
pub enum GuideSource<'a> {
    /// Unguided.
    None,
    /// A keys file ([`crate::infer::read_keys`]).
    KeysFile(&'a Path),
    /// Keys already parsed.
    Keys(Vec<KeyPose>),
    /// A noisy take of the same performance, as a clip file.
    TakeFile(&'a Path),
    /// A noisy take in memory.
    Take(BlendshapeClip),
    /// A TextGrid (with the tier to read, default the phones tier) or a phoneme CSV / JSON file.
    VisemesFile(&'a Path, Option<&'a str>),
    /// Timed phonemes (ARPAbet or MFA labels), checked like a file's ([`validate_spans`]).
    Phonemes(Vec<PhonemeSpan>),
    /// English words spoken over `span` (seconds from the clip's first frame).
    Text(&'a str, (f64, f64)),
}

/// A loaded guidance: the job's [`Guide`], the file it came from (for [`super::EditJob::guide_file`]) and
/// the words of a text that CMUdict does not list (pronounced by the letter-to-sound rules; the
/// front ends say so).
pub struct LoadedGuide {
    pub guide: Guide,
    pub file: Option<String>,
    pub guessed_words: Vec<String>,
}

impl LoadedGuide {
    /// The note on the words of a text that CMUdict lacks (None when every word was found).
    pub fn guessed_note(&self) -> Option<String> {
        let words = self.guessed_words.join(", ");
        (!words.is_empty()).then(|| format!("not in CMUdict, pronounced by our letter-to-sound rules: {words}"))
    }
}

impl GuideSource<'_> {
    /// The guidance, read and checked (see [`GuideSource`]); `max_rows` bounds a noisy take's rows.
    pub fn load(self, max_rows: usize) -> Result<LoadedGuide, FaceError> {
        let shown = |p: &Path| Some(p.display().to_string());
        let (guide, file, guessed_words) = match self {
            GuideSource::None => (Guide::None, None, Vec::new()),
            GuideSource::KeysFile(p) => (Guide::Keys(read_keys(p)?), shown(p), Vec::new()),
            GuideSource::Keys(keys) => (Guide::Keys(keys), None, Vec::new()),
            GuideSource::TakeFile(p) => (Guide::Noisy(read_clip_limited(p, max_rows)?), shown(p), Vec::new()),
            GuideSource::Take(clip) => (Guide::Noisy(clip), None, Vec::new()),
            GuideSource::VisemesFile(p, tier) => {
                (Guide::Visemes(viseme_runs(&read_viseme_source(p, tier)?)?), shown(p), Vec::new())
            }
            GuideSource::Phonemes(spans) => {
                validate_spans(&spans)?;
                (Guide::Visemes(viseme_runs(&spans)?), None, Vec::new())
            }
            GuideSource::Text(text, (start_s, end_s)) => {
                let ph = text_to_phonemes(text, start_s, end_s)?;
                (Guide::Visemes(viseme_runs(&ph.spans)?), None, ph.guessed_words)
            }
        };
        Ok(LoadedGuide { guide, file, guessed_words })
    }
}

/// Whether an edit of `input` written to `out` keeps the Live Link Face layout: a Live Link CSV in,
/// and not a `.json` curve file out.
pub fn keeps_live_link(input: &Path, out: &Path) -> bool {
    let ext = |p: &Path, e: &str| p.extension().is_some_and(|x| x.eq_ignore_ascii_case(e));
    ext(input, "csv") && !ext(out, "json") && crate::data::is_live_link(input)
}

/// The note an edit guided by visemes gives about the groups: which ones the visemes guide, and
/// that the others are filled unguided. `groups`: the groups the user gave, if any; `with_value`
/// and `alone`: how the front end writes that option before a value (`--groups`, `groups`) and on
/// its own (`--groups`, `groups=`).
pub fn visemes_groups_note(groups: Option<&str>, with_value: &str, alone: &str) -> String {
    let speech = SPEECH_GROUPS.map(|g| g.name()).join(", ");
    match groups {
        Some(g) => format!("{with_value} {g}: the visemes guide these groups (default: {speech}; the rest unguided)"),
        None => format!("the visemes guide {speech}; eyes and brows are filled unguided ({alone} overrides)"),
    }
}

/// Phoneme spans as viseme runs `(start_s, end_s, viseme)`; a phoneme with no viseme class is an
/// error naming it and its time.
pub fn viseme_runs(spans: &[PhonemeSpan]) -> Result<Vec<(f64, f64, Viseme)>, FaceError> {
    spans
        .iter()
        .map(|s| {
            phoneme_viseme(&s.phoneme).map(|v| (s.start_s, s.end_s, v)).ok_or_else(|| {
                FaceError::Invalid(format!("phoneme '{}' at {:.3} s has no viseme class", s.phoneme, s.start_s))
            })
        })
        .collect()
}

/// Seconds from the clip's first frame of a span written `4.0s..6.5s` (seconds) or `240f..390f`
/// (frames of the clip itself); a span outside the clip is an error naming it.
pub fn span_seconds(text: &str, clip: &BlendshapeClip) -> Result<(f64, f64), FaceError> {
    let t0 = clip.times()[0];
    let duration = clip.duration();
    let (a, b) = match parse_span_spec(text).map_err(FaceError::Invalid)? {
        SpanSpec::Seconds(a, b) => (a, b),
        SpanSpec::Frames(a, b) => {
            let n = clip.num_frames();
            if a >= n {
                return Err(FaceError::Invalid(format!(
                    "mask '{text}' starts past the clip's last frame ({n} frames)"
                )));
            }
            let end = clip.times().get(b).map_or(duration + 1.0 / clip.fps(), |t| t - t0);
            (clip.times()[a] - t0, end)
        }
    };
    if a >= duration {
        return Err(FaceError::Invalid(format!("mask '{text}' lies outside the clip ({duration:.2} s long)")));
    }
    // A span in frames may end one frame past the last frame's time (it covers the last frame).
    if b > duration + 1.0 / clip.fps() + 1e-9 {
        return Err(FaceError::Invalid(format!(
            "mask '{text}' runs past the clip's end ({duration:.2} s long); end it at {duration:.2}s at the latest"
        )));
    }
    Ok((a, b))
}

/// The folder of the shared face captures (`face/neurosync` under `../shared/data` or
/// `$INBETWEEN_DATA`), or `given` when the user named one.
pub fn captures_dir(given: Option<&Path>) -> Result<PathBuf, FaceError> {
    if let Some(p) = given {
        return Ok(p.to_path_buf());
    }
    let root = inbetween_io::data::shared_data_dir().unwrap_or_else(|missing| missing);
    let dir = root.join("face/neurosync");
    if !dir.is_dir() {
        return Err(FaceError::Invalid(format!(
            "no face captures at {} (set INBETWEEN_DATA or pass --captures)",
            dir.display()
        )));
    }
    Ok(dir)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::{arkit_index, NUM_ARKIT};

    #[test]
    fn auto_picks_per_guidance_and_weights_mean_the_network() {
        use ConstraintKind::*;
        let auto = MethodChoice::Auto;
        assert_eq!(auto.resolve(None, false), MethodChoice::Retrieval);
        assert_eq!(auto.resolve(Noisy, false), MethodChoice::Retrieval);
        assert_eq!(auto.resolve(Keyframes, false), MethodChoice::Network);
        assert_eq!(auto.resolve(Visemes, false), MethodChoice::Network);
        assert_eq!(auto.resolve(None, true), MethodChoice::Network);
        assert_eq!(MethodChoice::Cubic.resolve(Visemes, true), MethodChoice::Cubic);
        assert_eq!(MethodChoice::parse("linear").unwrap(), MethodChoice::Linear);
        let e = MethodChoice::parse("bezier").unwrap_err().to_string();
        assert!(e.contains("'bezier'") && e.contains("auto, network, retrieval, linear, cubic"), "{e}");
    }

    #[test]
    fn resources_hold_what_the_method_needs_and_failures_say_what_was_loading() {
        let r = EditResources::load_network(MethodChoice::Auto, ConstraintKind::Keyframes, None).unwrap();
        assert_eq!(r.chosen, MethodChoice::Network);
        assert!(r.network.is_some() && matches!(r.method(1), Ok(Method::Network(_))));
        let mut r = EditResources::load_network(MethodChoice::Auto, ConstraintKind::None, None).unwrap();
        assert_eq!(r.chosen, MethodChoice::Retrieval);
        assert!(r.network.is_none());
        let e = r.method(1).err().unwrap().to_string();
        assert!(e.contains("method retrieval: no library loaded"), "{e}");
        r.load_library(&[], false, 100_000).unwrap();
        assert!(matches!(r.method(2), Ok(Method::Retrieval(..))));
        // Visemes leave the groups they do not guide to the library, unless the edit names groups.
        let mut v = EditResources::load_network(MethodChoice::Linear, ConstraintKind::Visemes, None).unwrap();
        v.load_library(&[], false, 100_000).unwrap();
        assert!(v.library.is_some() && matches!(v.method(1), Ok(Method::Linear)));
        v.load_library(&[], true, 100_000).unwrap();
        assert!(v.library.is_none());
        let missing = Path::new("/nonexistent/w.bpk");
        let e = EditResources::load_network(MethodChoice::Auto, ConstraintKind::None, Some(missing)).err().unwrap();
        assert_eq!(e.to_string(), "loading face weights /nonexistent/w.bpk");
        assert!(std::error::Error::source(&e).unwrap().to_string().contains("/nonexistent/w.bpk"), "{e:?}");
    }

    #[test]
    fn visemes_guide_the_speech_groups_and_other_guidance_the_whole_face() {
        let v = guided_channels(ConstraintKind::Visemes);
        for name in ["JawOpen", "MouthClose", "CheekPuff", "NoseSneerLeft", "TongueOut"] {
            assert!(v[arkit_index(name).unwrap()], "{name}");
        }
        for name in ["EyeBlinkLeft", "EyeLookDownRight", "BrowInnerUp"] {
            assert!(!v[arkit_index(name).unwrap()], "{name}");
        }
        assert_eq!(guided_channels(ConstraintKind::Noisy), [true; NUM_ARKIT]);
        let text = GuideSource::Text("hello zorblax", (0.0, 1.0)).load(100).unwrap();
        assert_eq!(text.guessed_note().unwrap(), "not in CMUdict, pronounced by our letter-to-sound rules: zorblax");
        assert_eq!(GuideSource::None.load(100).unwrap().guessed_note(), None);
        assert_eq!(
            visemes_groups_note(None, "--groups", "--groups"),
            "the visemes guide jaw, mouth, cheeks, tongue; eyes and brows are filled unguided (--groups overrides)"
        );
        assert_eq!(
            visemes_groups_note(Some("jaw"), "groups", "groups="),
            "groups jaw: the visemes guide these groups (default: jaw, mouth, cheeks, tongue; the rest unguided)"
        );
    }

    #[test]
    fn spans_in_seconds_or_frames_and_bad_ones_named() {
        let times: Vec<f64> = (0..600).map(|i| 10.0 + i as f64 / 60.0).collect();
        let clip = BlendshapeClip::new(60.0, times, false, vec![], vec![0.0; 600 * NUM_ARKIT]).unwrap();
        assert_eq!(span_seconds("1s..2s", &clip).unwrap(), (1.0, 2.0));
        let (a, b) = span_seconds("60f..120f", &clip).unwrap();
        assert!((a - 1.0).abs() < 1e-9 && (b - 2.0).abs() < 1e-9);
        assert!(span_seconds("20s..21s", &clip).unwrap_err().to_string().contains("outside the clip"));
        assert!(span_seconds("5s..30s", &clip).unwrap_err().to_string().contains("runs past the clip's end"));
        assert!(span_seconds("700f..710f", &clip).unwrap_err().to_string().contains("past the clip's last frame"));
        let e = viseme_runs(&[PhonemeSpan { start_s: 0.5, end_s: 0.6, phoneme: "QQ".into() }]).unwrap_err();
        assert!(e.to_string().contains("phoneme 'QQ' at 0.500 s has no viseme class"), "{e}");
    }
}
