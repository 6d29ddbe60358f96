//! `inbetween video bench`: the paper's measures (§6.3: M_D of Eq. 21, Δ_o of Eq. 23) on procedural
//! and real clips, with the length each run reached and its share of backward steps (steps to one
//! of the three previous source frames), per clip and start; the ablations of Table 3 (w/o C_t,
//! w/o C_d, w/o RSFNet, w/o L_d) plus ours (w/o C_r, the paper's walk with its early stop); contact
//! sheets that mark cuts and backward steps; and the wall time of each stage of the pipeline.
//!
//! Beyond the paper, a perceptual proxy that needs no download: SSIM (Wang et al. 2004, see
//! [`crate::sdpf::ssim`]) of every transition of the new orders against that of the source's own
//! adjacent pairs, on luma downscaled to at most [`SSIM_SIDE`] pixels on the longer side.
//!
//! - [`protocol`]: clips, configurations and their parameters;
//! - [`tables`]: the tables of the report;
//! - [`report`]: contact sheets and the SSIM plot.

mod protocol;
mod report;
mod tables;

pub use protocol::{BenchClip, VideoBenchConfig};

use inbetween_io::report::{BenchOptions, Report};
use inbetween_io::Progress;
use std::path::{Path, PathBuf};

use crate::job::BACKWARD_WINDOW;
use crate::pipeline::{analyse, resequence, ResequenceConfig, VideoLimits};
use crate::render::{render, Blend};
use crate::sdpf::{
    backward_steps, direction_flips, distinct_fraction, longest_repeated_cycle, overlap_delta_o, short_cycle_repeats,
    shot_changes, ssim_planes, stability_md, transition_ssims, Cycle, SdpfParams, SSIM_SIDE,
};
use crate::VideoError;
use protocol::{ablated, blend_frames, load, params_for, CONFIGS};
use report::{sheet_png, slug, ssim_png};
use tables::{mean, quantile, runs_table, ssim_table, stage_table, table2, table3};

/// One new order: where it started, how long it got, its steps backwards, cuts and loops.
#[derive(Clone, Debug)]
struct Run {
    start: usize,
    length: usize,
    steps: usize,
    backward: usize,
    /// Steps between LMS frames whose tendencies differ by more than ξ (what C_d prevents).
    flips: usize,
    cuts: usize,
    loops: usize,
    md: f64,
    delta_o: f64,
    /// Share of the source's frames shown at least once.
    distinct: f64,
    /// The repeated cycle covering the most frames, if any.
    cycle: Option<Cycle>,
    /// Most plays in a row of a block shorter than a second.
    short_repeats: usize,
    /// Steps between shots, and the run's frames; the source's own shot changes.
    shot_changes: usize,
    source_changes: usize,
}

struct ClipResult {
    name: String,
    frames: usize,
    size: (u32, u32),
    decode_s: f64,
    stages: Vec<(String, f64)>,
    walk_s: f64,
    metric_note: String,
    md_source: f64,
    /// Per configuration: (mean M_D, mean Δ_o, mean length).
    configs: Vec<(f64, f64, f64)>,
    /// Per configuration, per start: one run.
    runs: Vec<Vec<Run>>,
    /// The target length of every run.
    target: usize,
    /// Per shot: directed, share of LMS frames.
    direction: Vec<(bool, f32)>,
    /// Contact sheets (file name, PNG bytes) of the first start: full method and w/o C_r.
    sheets: Vec<(String, Vec<u8>)>,
    /// SSIM of the source's adjacent pairs `f → f + 1`.
    ssim_source: Vec<f64>,
    /// Per configuration: SSIM of every transition of its new orders (all starts pooled).
    ssim_configs: Vec<Vec<f64>>,
}

impl ClipResult {
    /// (mean SSIM, mean over the source's, 10th percentile) of configuration `i`.
    fn ssim(&self, i: usize) -> (f64, f64, f64) {
        let ours = mean(&self.ssim_configs[i]);
        (ours, ours / mean(&self.ssim_source), quantile(&self.ssim_configs[i], 0.1))
    }
}

fn bench_clip(spec: &BenchClip, cfg: &VideoBenchConfig, progress: &Progress) -> Result<ClipResult, VideoError> {
    let (clip, name, decode_s) = load(spec)?;
    let rcfg = ResequenceConfig {
        flow_side: cfg.flow_side,
        rsf: cfg.rsf.clone(),
        train: cfg.train.clone(),
        cache_dir: cfg.cache_dir.clone(),
        ..ResequenceConfig::default()
    };
    let full = analyse(&clip, &rcfg, progress)?;
    let n = clip.len();
    let k = cfg.starts.max(1);
    let starts: Vec<usize> = (0..k).map(|i| ((i * n) / k).min(n - 1)).collect();
    let target = cfg.length.unwrap_or(n);
    let planes = ssim_planes(&clip.frames, SSIM_SIDE);
    let source_order: Vec<usize> = (0..n).collect();
    let (mut configs, mut ssim_configs, mut runs, mut sheets) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let mut walk_s = 0.0;
    let mut walks = 0usize;
    // The full method's orders per start, which the cross-fade rows render again.
    let mut full_orders: Vec<(Vec<usize>, Vec<usize>, Vec<usize>)> = Vec::new();
    for which in CONFIGS {
        let a = if matches!(which, "w/o RSFNet" | "w/o L_d" | "SSPF on pixel distance") {
            ablated(&full, &clip, cfg, which, progress)?
        } else {
            full.clone()
        };
        let shots: Vec<usize> = (0..n).map(|i| a.info.shot_of(i)).collect();
        let mut ssims = Vec::new();
        let mut these = Vec::new();
        for (i, &s) in starts.iter().enumerate() {
            let blend = blend_frames(which);
            let (order, cuts, loops) = if which.starts_with("SSPF") {
                (crate::sdpf::sspf(&a.graph, s, target, Some(&shots)), Vec::new(), Vec::new())
            } else if blend > 0 {
                full_orders[i].clone()
            } else {
                let params = params_for(which, cfg.length, inbetween_core::seed::derive(cfg.seed, i as u64));
                let (paths, secs) = resequence(&a, s, &params, 1, &VideoLimits::default())?;
                if which == "full" {
                    walk_s += secs;
                    walks += 1;
                }
                let p = &paths[0];
                let cuts = [p.cut_positions(), p.jump_cut_positions()].concat();
                let run = (p.frames.clone(), cuts, [p.loop_positions(), p.transition_positions()].concat());
                if which == "full" {
                    full_orders.push(run.clone());
                }
                run
            };
            // With a cross-fade, M_D and SSIM are measured on the frames written.
            let (md, ssim) = if blend > 0 {
                let written = render(&order, &Blend::new(&clip, &shots, blend));
                let all: Vec<usize> = (0..written.len()).collect();
                let planes = ssim_planes(&written.frames, SSIM_SIDE);
                (stability_md(&written.frames, &all), transition_ssims(&planes, &all)?)
            } else {
                (stability_md(&clip.frames, &order), transition_ssims(&planes, &order)?)
            };
            if i == 0 && (which == "full" || which == "w/o C_r" || which.starts_with("round 2")) {
                let title = format!(
                    "{name}, {which}, from frame {s}: {} frames (red BACK: backward step, blue CUT, purple LOOP: a jump back)",
                    order.len()
                );
                let tag = match which {
                    "full" => "full",
                    "w/o C_r" => "no-cr",
                    _ => "round2",
                };
                let file = format!("sheet-{}-{tag}.png", slug(&name));
                sheets.push((file, sheet_png(&clip, &order, cuts.clone(), loops.clone(), title)?));
            }
            these.push(Run {
                start: s,
                length: order.len(),
                steps: order.len().saturating_sub(1),
                backward: backward_steps(&order, BACKWARD_WINDOW),
                flips: direction_flips(&order, &full.info, SdpfParams::default().xi),
                cuts: cuts.len(),
                loops: loops.len(),
                md,
                delta_o: overlap_delta_o(&order, n),
                distinct: distinct_fraction(&order, n),
                cycle: longest_repeated_cycle(&order),
                short_repeats: short_cycle_repeats(&order, full.info.min_loop_frames(1.0)),
                shot_changes: shot_changes(&order, &shots),
                source_changes: shot_changes(&source_order, &shots),
            });
            ssims.extend(ssim);
        }
        ssim_configs.push(ssims);
        let kf = these.len() as f64;
        configs.push((
            these.iter().map(|r| r.md).sum::<f64>() / kf,
            these.iter().map(|r| r.delta_o).sum::<f64>() / kf,
            these.iter().map(|r| r.length as f64).sum::<f64>() / kf,
        ));
        runs.push(these);
    }
    let source: Vec<usize> = (0..n).collect();
    let ssim_source = transition_ssims(&planes, &source)?;
    let metric_note = format!("{name}: {}", full.metric_note);
    Ok(ClipResult {
        name,
        frames: n,
        size: (clip.width(), clip.height()),
        decode_s,
        stages: full.stages.clone(),
        walk_s: walk_s / walks.max(1) as f64,
        metric_note,
        md_source: stability_md(&clip.frames, &source),
        configs,
        runs,
        target,
        direction: full.direction.clone(),
        sheets,
        ssim_source,
        ssim_configs,
    })
}

/// The video bench's own options (beside [`BenchOptions`], whose `data` is the folder of real clips).
#[derive(Clone, Debug, Default)]
pub struct VideoBench {
    /// Start frames per clip (None: the configuration's, 4 or 2 when quick).
    pub starts: Option<usize>,
}

/// The real clips a full run reads, `data` or `video` under the shared data folder, when that
/// folder exists; and the line that says which (or that they are skipped).
pub fn real_clips(data: Option<&Path>) -> (Option<PathBuf>, String) {
    let dir = data.map_or_else(|| inbetween_io::shared_data_dir().unwrap_or_else(|m| m).join("video"), PathBuf::from);
    match dir.exists() {
        true => (Some(dir.clone()), format!("real clips from {}", dir.display())),
        false => (None, format!("skipped real clips: no data at {}", dir.display())),
    }
}

/// `inbetween video bench`: [`VideoBenchConfig::quick`] (procedural only) or
/// [`VideoBenchConfig::full`] on the [`real_clips`], with a fresh metric cache (removed afterwards) so
/// the stage times include training, then [`measure`].
pub fn run(opts: &BenchOptions<VideoBench>) -> Result<Report, VideoError> {
    if opts.engine.starts == Some(0) {
        return Err(VideoError::Invalid("`starts` 0 runs nothing: give at least 1".into()));
    }
    let cache = tempfile::Builder::new()
        .prefix("inbetween-video-bench-")
        .tempdir()
        .map_err(|source| VideoError::Io { path: std::env::temp_dir(), source })?;
    let cfg = match opts.quick {
        true => VideoBenchConfig::quick(cache.path().to_path_buf()),
        false => VideoBenchConfig::full(real_clips(opts.data.as_deref()).0.as_deref(), cache.path().to_path_buf()),
    };
    let starts = opts.engine.starts.unwrap_or(cfg.starts);
    measure(&VideoBenchConfig { starts, seed: opts.seed.unwrap_or(cfg.seed), ..cfg }, &opts.progress)
}

/// Runs the bench and returns its report (tables as text, Markdown and CSV).
pub fn measure(cfg: &VideoBenchConfig, progress: &Progress) -> Result<Report, VideoError> {
    let results: Vec<ClipResult> = cfg.clips.iter().map(|c| bench_clip(c, cfg, progress)).collect::<Result<_, _>>()?;
    let mut report = Report::new("video-bench", "Video engine benchmark (resequencing with SDPF, Le et al.)");
    report.table(table2(&results, cfg));
    report.table(table3(&results));
    report.table(runs_table(&results));
    report.table(ssim_table(&results));
    report.table(stage_table(&results));
    report.file("ssim.png", ssim_png(&results)?);
    for r in &results {
        for (file, bytes) in &r.sheets {
            report.file(file, bytes.clone());
        }
    }
    Ok(report)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantiles_interpolate_between_order_statistics() {
        let v = [4.0, 1.0, 3.0, 2.0, 5.0, 6.0, 7.0, 8.0, 9.0, 10.0, 11.0];
        assert_eq!(quantile(&v, 0.1), 2.0);
        assert_eq!(quantile(&v, 0.0), 1.0);
        assert_eq!(quantile(&v, 1.0), 11.0);
        assert!((quantile(&[0.0, 1.0], 0.1) - 0.1).abs() < 1e-12);
        assert!(quantile(&[], 0.1).is_nan());
        assert!(mean(&[]).is_nan());
    }

    #[test]
    fn quick_bench_fills_every_table() {
        let dir = tempfile::tempdir().unwrap();
        let report = run(&BenchOptions { quick: true, ..BenchOptions::new(VideoBench::default()) }).unwrap();
        let text = report.to_text();
        for needle in [
            "Table 2 analogue",
            "Table 3 analogue",
            "w/o C_t",
            "w/o L_d",
            "ground truth",
            "SDPF walk",
            "ssim_ratio",
            "source (adjacent pairs)",
        ] {
            assert!(text.contains(needle), "{needle} missing:\n{text}");
        }
        assert_eq!(report.tables().count(), 5);
        let ssim = report.tables().find(|t| t.name == "ssim").unwrap().to_csv();
        // Header, the source's own pairs, then one row per configuration.
        assert_eq!(ssim.lines().count(), 2 + CONFIGS.len(), "{ssim}");
        assert!(text.contains("SSPF (shortest path)") && text.contains("SSPF on pixel distance"));
        let written = report.write(&dir.path().join("out")).unwrap();
        assert!(written.iter().any(|p| p.ends_with("ssim.png")));
        let none = BenchOptions { quick: true, ..BenchOptions::new(VideoBench { starts: Some(0) }) };
        assert!(run(&none).unwrap_err().to_string().contains("`starts` 0 runs nothing"));
        let (clips, line) = real_clips(Some(&dir.path().join("missing")));
        assert!(clips.is_none() && line.starts_with("skipped real clips: no data at "), "{line}");
        assert_eq!(real_clips(Some(dir.path())).1, format!("real clips from {}", dir.path().display()));
    }
}
