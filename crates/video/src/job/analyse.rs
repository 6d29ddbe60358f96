//! [`AnalyseJob`]: read a clip and analyse it once (flows, metric, graph, shots).

use std::collections::HashMap;
use std::fmt;
use std::path::PathBuf;
use std::sync::{Arc, Mutex};

use inbetween_core::cancel::Cancel;
use inbetween_io::{LimitExceeded, Progress};
use serde::Serialize;

use crate::frames::{read_clip, Clip, ReadOptions};
use crate::pipeline::{analyse, Analysis, ResequenceConfig, VideoLimits};
use crate::sdpf::frame_rms;
use crate::VideoError;

/// Where a job's frames come from.
#[derive(Clone)]
pub enum VideoInput {
    /// An `.mp4` / `.gif` file or a folder of PNG/JPEG frames, read with [`AnalyseJob::read`].
    File(PathBuf),
    /// Frames already in memory (a procedural clip, an upload decoded by the caller).
    Clip(Arc<Clip>),
}

impl fmt::Debug for VideoInput {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            VideoInput::File(p) => write!(f, "File({})", p.display()),
            VideoInput::Clip(c) => write!(f, "Clip({}, {} frames)", c.source, c.len()),
        }
    }
}

/// Analyse one clip: what every new order of it needs, computed once.
#[derive(Clone, Debug)]
pub struct AnalyseJob {
    pub input: VideoInput,
    /// Decoder and frame count to read (a file input only). Decoding stops one frame past
    /// `config.limits.max_frames`, so a clip over the limit is refused without reading all of it.
    pub read: ReadOptions,
    /// Flow size, RSFNet and its training, metric, cache folder, cut detection and limits (the
    /// engine's defaults). Its `cancel` is replaced by the token given to [`AnalyseJob::run`].
    pub config: ResequenceConfig,
}

impl Default for AnalyseJob {
    /// No input yet (`validate` says so); the engine's configuration.
    fn default() -> Self {
        AnalyseJob {
            input: VideoInput::File(PathBuf::new()),
            read: ReadOptions::default(),
            config: ResequenceConfig::default(),
        }
    }
}

impl AnalyseJob {
    /// The job for a file or folder, with the engine's defaults.
    pub fn for_file(path: impl Into<PathBuf>) -> AnalyseJob {
        AnalyseJob { input: VideoInput::File(path.into()), ..AnalyseJob::default() }
    }

    /// The job for frames in memory, with the engine's defaults.
    pub fn for_clip(clip: Clip) -> AnalyseJob {
        AnalyseJob { input: VideoInput::Clip(Arc::new(clip)), ..AnalyseJob::default() }
    }

    /// Checks the inputs before any work: an input is given, and frames in memory are within the
    /// limits (a file's are checked while it is read).
    pub fn validate(&self) -> Result<(), VideoError> {
        match &self.input {
            VideoInput::File(p) if p.as_os_str().is_empty() => {
                Err(VideoError::Invalid("no input: give a clip (.mp4, .gif or a folder of PNG/JPEG frames)".into()))
            }
            VideoInput::File(_) => Ok(()),
            VideoInput::Clip(c) => self.config.limits.check_clip(c),
        }
    }

    /// Reads the clip (a file: at most one frame past the frame limit) and refuses one over it.
    fn clip(&self) -> Result<(Arc<Clip>, Option<crate::frames::DecodeReport>), VideoError> {
        match &self.input {
            VideoInput::Clip(c) => Ok((c.clone(), None)),
            VideoInput::File(path) => {
                let limit = self.config.limits.max_frames;
                let past_limit = limit.saturating_add(1);
                let max_frames = Some(self.read.max_frames.map_or(past_limit, |m| m.min(past_limit)));
                let (clip, report) = read_clip(path, &ReadOptions { max_frames, ..self.read.clone() })?;
                if clip.len() > limit {
                    // Decoding stopped one frame past the limit: the file holds at least that many.
                    let found = format!("{} frames or more", clip.len());
                    let (subject, limit) = (path.display().to_string(), format!("{limit} frames"));
                    return Err(VideoError::TooManyFrames(LimitExceeded {
                        subject,
                        found,
                        limit,
                        field: "max_frames",
                    }));
                }
                Ok((Arc::new(clip), Some(report)))
            }
        }
    }

    /// Reads and analyses the clip ([`analyse`]); `progress` follows RSFNet's training steps.
    pub fn run(&self, cancel: &Cancel, progress: &Progress) -> Result<AnalyseReport, VideoError> {
        self.run_checked(cancel, progress, &|_| Ok(()))
    }

    /// [`AnalyseJob::run`], calling `check` with the clip's frame count once it is read and before
    /// the analysis (a request on the clip, such as a start frame, is refused before the work).
    pub(crate) fn run_checked(
        &self,
        cancel: &Cancel,
        progress: &Progress,
        check: &dyn Fn(usize) -> Result<(), VideoError>,
    ) -> Result<AnalyseReport, VideoError> {
        self.validate()?;
        cancel.check()?;
        let (clip, decoded) = self.clip()?;
        check(clip.len())?;
        let config = ResequenceConfig { cancel: cancel.clone(), ..self.config.clone() };
        let analysis = analyse(&clip, &config, progress)?;
        let shot = analysis.info.shot.clone();
        let shot_starts = (1..shot.len()).filter(|&i| shot[i] != shot[i - 1]).collect();
        let source_order: Vec<usize> = (0..clip.len()).collect();
        let memo = Arc::new(Mutex::new(HashMap::new()));
        let mut report = AnalyseReport {
            source: clip.source.clone(),
            frames: clip.len(),
            width: clip.width(),
            height: clip.height(),
            fps: clip.fps,
            decoder: decoded.as_ref().map(|d| d.decoder.clone()),
            notes: decoded.map(|d| d.notes).unwrap_or_default(),
            shots: analysis.info.shots(),
            shot,
            shot_starts,
            directed: analysis.direction.iter().map(|d| d.0).collect(),
            lms_share: analysis.direction.iter().map(|d| d.1).collect(),
            metric: analysis.metric_note.clone(),
            stages: analysis
                .stages
                .iter()
                .map(|(stage, seconds)| StageTime { stage: stage.clone(), seconds: *seconds })
                .collect(),
            source_md: 0.0,
            limits: config.limits.clone(),
            clip,
            analysis: Arc::new(analysis),
            rms: memo,
        };
        report.source_md = report.md(&source_order);
        Ok(report)
    }
}

/// The wall time of one stage of the analysis.
#[derive(Clone, Debug, Serialize)]
pub struct StageTime {
    pub stage: String,
    pub seconds: f64,
}

/// An analysed clip: what it is, its shots and how its metric was made; it keeps the clip and the
/// analysis (not serialised) for the orders a [`ResequenceJob`](super::ResequenceJob) draws from it.
#[derive(Clone, Serialize)]
pub struct AnalyseReport {
    /// The file the frames came from (or the in-memory clip's name).
    pub source: String,
    pub frames: usize,
    /// Frame size, pixels.
    pub width: u32,
    pub height: u32,
    /// Frames per second.
    pub fps: f64,
    /// The decoder that read a file (`None`: frames given in memory).
    pub decoder: Option<String>,
    /// What the decoder had to say (fallbacks taken, an assumed frame rate).
    pub notes: Vec<String>,
    /// Shots found (scene cuts + 1), the shot of every frame and the frames that start a shot.
    pub shots: usize,
    pub shot: Vec<usize>,
    pub shot_starts: Vec<usize>,
    /// Per shot: whether its motion is judged directed, and its share of LMS frames (Eq. 11).
    pub directed: Vec<bool>,
    pub lms_share: Vec<f32>,
    /// What happened to the metric (trained on the clip, or read from its cache).
    pub metric: String,
    pub stages: Vec<StageTime>,
    /// M_D (Eq. 21) of the source order, the ground truth new orders are compared with.
    pub source_md: f64,
    #[serde(skip)]
    pub limits: VideoLimits,
    #[serde(skip)]
    pub clip: Arc<Clip>,
    #[serde(skip)]
    pub analysis: Arc<Analysis>,
    /// `D` of Eq. 21 per transition already measured: most steps of every order are the next
    /// source frame, so later orders reuse nearly all of them.
    #[serde(skip)]
    rms: Arc<Mutex<HashMap<(usize, usize), f64>>>,
}

impl AnalyseReport {
    /// M_D (Eq. 21) of `order` on this clip's frames: the mean RMS difference of its transitions,
    /// each measured once per analysis (the same value as [`stability_md`](crate::sdpf::stability_md),
    /// NaN for an index out of range).
    pub fn md(&self, order: &[usize]) -> f64 {
        if order.iter().any(|&f| f >= self.clip.len()) {
            return f64::NAN;
        }
        if order.len() < 2 {
            return 0.0;
        }
        let mut rms = self.rms.lock().unwrap_or_else(|p| p.into_inner());
        let frames = &self.clip.frames;
        let sum: f64 = order
            .windows(2)
            .map(|w| {
                *rms.entry((w[0], w[1]))
                    .or_insert_with(|| frame_rms(&frames[w[0]], &frames[w[1]], w[0], w[1]).unwrap_or(f64::NAN))
            })
            .sum();
        sum / (order.len() - 1) as f64
    }
}

impl fmt::Debug for AnalyseReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("AnalyseReport")
            .field("source", &self.source)
            .field("frames", &self.frames)
            .field("shots", &self.shots)
            .field("metric", &self.metric)
            .finish_non_exhaustive()
    }
}

impl fmt::Display for AnalyseReport {
    /// The clip, how it was read, and what happened to the metric.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let how = self.decoder.as_ref().map_or_else(|| "given in memory".to_string(), |d| format!("decoded by {d}"));
        writeln!(
            f,
            "{}: {} frames {}x{} at {:.3} fps, {how}",
            self.source, self.frames, self.width, self.height, self.fps
        )?;
        for n in &self.notes {
            writeln!(f, "  {n}")?;
        }
        writeln!(f, "{}", self.metric)
    }
}
