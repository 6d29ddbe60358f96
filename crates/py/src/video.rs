//! video `resequence`: the video engine's `ResequenceJob` (`inbetween video resequence`): a clip
//! analysed once (RSFNet trained on it or read from its cache), `count` new frame orders walked from
//! a start frame, each measured and explained step by step, and written as MP4/GIF with a contact
//! sheet when asked.

use crate::errors::{ctx, invalid, JobError};
use crate::runner::run_job;
use inbetween_core::cancel::Cancel;
use inbetween_io::Progress;
use inbetween_video::frames::{Decoder, ReadOptions};
use inbetween_video::job::{AnalyseJob, ResequenceJob, ResequenceReport, ResequenceSource, VideoInput};
use inbetween_video::pipeline::{MetricChoice, ResequenceConfig};
use inbetween_video::sdpf::SdpfParams;
use numpy::PyArray1;
use pyo3::prelude::*;
use std::path::PathBuf;

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(video_resequence, m)?)?;
    Ok(())
}

/// Everything `video.resequence` was given (the CLI's flags, by field), so the same request runs
/// from Python and from the bench.
#[derive(Clone, Debug, Default)]
pub struct ResequenceRequest {
    pub path: PathBuf,
    pub start: usize,
    pub length: Option<usize>,
    pub seed: Option<u64>,
    pub loop_close: bool,
    pub count: usize,
    pub out: Option<PathBuf>,
    pub sheet: Option<PathBuf>,
    pub blend: usize,
    pub explain: bool,
    pub stop_early: bool,
    pub transitions: bool,
    pub allow_reverse: bool,
    pub allow_cuts: bool,
    pub metric: String,
    pub steps: Option<usize>,
    pub cache_dir: Option<PathBuf>,
    pub max_frames: Option<usize>,
}

impl ResequenceRequest {
    /// The job, with the engine's defaults wherever the request leaves a field open.
    pub fn job(&self) -> Result<ResequenceJob, JobError> {
        let mut config = ResequenceConfig {
            metric: match self.metric.as_str() {
                "rsfnet" => MetricChoice::RsfNet,
                "pixels" => MetricChoice::Pixels,
                other => {
                    return Err(JobError::Failed(format!(
                        "metric '{other}': expected rsfnet (RSFNet trained on the clip, the paper) or pixels (ablation)"
                    )))
                }
            },
            ..ResequenceConfig::default()
        };
        if let Some(s) = self.steps {
            config.train.steps = s;
        }
        if let Some(d) = &self.cache_dir {
            config.cache_dir = d.clone();
        }
        let defaults = SdpfParams::default();
        let params = SdpfParams {
            allow_reverse: self.allow_reverse,
            stop_early: self.stop_early,
            length: self.length,
            loop_close: self.loop_close,
            allow_cuts: self.allow_cuts,
            seed: self.seed.unwrap_or(defaults.seed),
            transitions: self.transitions,
            ..defaults
        };
        Ok(ResequenceJob {
            source: ResequenceSource::Analyse(Box::new(AnalyseJob {
                input: VideoInput::File(self.path.clone()),
                read: ReadOptions { decoder: Decoder::Auto, max_frames: self.max_frames },
                config,
            })),
            start: self.start,
            params,
            count: self.count,
            out: self.out.clone(),
            sheet: self.sheet.clone(),
            blend: self.blend,
            explain: self.explain,
        })
    }
}

/// Runs the job of `r` (validated first).
pub fn resequence(r: &ResequenceRequest, cancel: &Cancel, progress: &Progress) -> Result<ResequenceReport, JobError> {
    let job = r.job()?;
    job.validate().map_err(ctx(""))?;
    job.run(cancel, progress).map_err(ctx(format!("resequencing {}", r.path.display())))
}

/// One int64 array of source frames per new order.
type Orders<'py> = Vec<Bound<'py, PyArray1<i64>>>;

/// Runs `video resequence` on `path` (see `inbetween.video.resequence`). Returns (report JSON,
/// report text, one int64 order array per sequence).
#[pyfunction]
#[pyo3(signature = (path, start=0, length=None, seed=None, loop_close=false, count=1, out=None, sheet=None, blend=0, explain=false, stop_early=false, transitions=true, allow_reverse=false, allow_cuts=false, metric="rsfnet".to_string(), steps=None, cache_dir=None, max_frames=None, progress=None))]
#[allow(clippy::too_many_arguments)]
fn video_resequence<'py>(
    py: Python<'py>,
    path: PathBuf,
    start: usize,
    length: Option<usize>,
    seed: Option<u64>,
    loop_close: bool,
    count: usize,
    out: Option<PathBuf>,
    sheet: Option<PathBuf>,
    blend: usize,
    explain: bool,
    stop_early: bool,
    transitions: bool,
    allow_reverse: bool,
    allow_cuts: bool,
    metric: String,
    steps: Option<usize>,
    cache_dir: Option<PathBuf>,
    max_frames: Option<usize>,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<(String, String, Orders<'py>)> {
    let request = ResequenceRequest {
        path,
        start,
        length,
        seed,
        loop_close,
        count,
        out,
        sheet,
        blend,
        explain,
        stop_early,
        transitions,
        allow_reverse,
        allow_cuts,
        metric,
        steps,
        cache_dir,
        max_frames,
    };
    let report = run_job(py, progress.as_ref(), |cancel, bar| resequence(&request, cancel, bar))?;
    let json = serde_json::to_string(&report).map_err(|e| invalid(e.to_string()))?;
    let orders =
        report.sequences.iter().map(|s| PyArray1::from_vec(py, s.order.iter().map(|&f| f as i64).collect())).collect();
    Ok((json, report.to_string(), orders))
}
