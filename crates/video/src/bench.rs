//! `inbetween video bench`: the paper's measures (§6.3: M_D of Eq. 21, Δ_o of Eq. 23) on procedural
//! and real clips, with the length each run reached and its share of backward steps (steps to one
//! of the three previous source frames), per clip and start; the ablations of Table 3 (w/o C_t,
//! w/o C_d, w/o RSFNet, w/o L_d) plus ours (w/o C_r, the paper's walk with its early stop); contact
//! sheets that mark cuts and backward steps; and the wall time of each stage of the pipeline.
//!
//! Beyond the paper, a perceptual proxy that needs no download: SSIM (Wang et al. 2004, see
//! [`crate::sdpf::ssim`]) of every transition of the new orders against that of the source's own
//! adjacent pairs, on luma downscaled to at most [`SSIM_SIDE`] pixels on the longer side.

use std::path::{Path, PathBuf};
use std::time::Instant;

use inbetween_io::report::{num, Report, Table};
use inbetween_io::Progress;

use crate::frames::{multi_shot_clip, procedural_clip, read_clip, Clip, ProceduralKind, ReadOptions};
use crate::metric::{embeddings_cached, graph_from_embeddings, pixel_graph, RsfConfig, TrainOptions};
use crate::pipeline::{analyse, resequence, Analysis, ResequenceConfig, VideoLimits};
use crate::preview::{contact_sheet, SheetOptions};
use crate::sdpf::{
    backward_steps, direction_flips, distinct_fraction, longest_repeated_cycle, overlap_delta_o, per_100_frames,
    short_cycle_repeats, shot_changes, ssim_planes, stability_md, transition_ssims, Cycle, SdpfParams, SSIM_SIDE,
};
use crate::VideoError;

/// A clip of the bench.
#[derive(Clone, Debug)]
pub enum BenchClip {
    Procedural {
        kind: ProceduralKind,
        frames: usize,
        width: u32,
        height: u32,
    },
    /// Procedural shots cut together ([`multi_shot_clip`]), `frames` each.
    Shots {
        kinds: Vec<ProceduralKind>,
        frames: usize,
        width: u32,
        height: u32,
    },
    File(PathBuf),
}

/// What the bench runs.
#[derive(Clone, Debug)]
pub struct VideoBenchConfig {
    pub clips: Vec<BenchClip>,
    /// Start frames per clip (evenly spread, the first at frame 0).
    pub starts: usize,
    /// Target length of each new order; `None`: the clip's frame count (the default of `resequence`).
    pub length: Option<usize>,
    pub rsf: RsfConfig,
    pub train: TrainOptions,
    pub flow_side: u32,
    pub cache_dir: PathBuf,
    pub seed: u64,
}

impl VideoBenchConfig {
    /// A small run for tests: one short procedural clip, a tiny network.
    pub fn quick(cache_dir: PathBuf) -> VideoBenchConfig {
        VideoBenchConfig {
            clips: vec![BenchClip::Procedural { kind: ProceduralKind::Pendulum, frames: 24, width: 64, height: 48 }],
            starts: 2,
            length: None,
            rsf: RsfConfig::tiny(),
            train: TrainOptions { steps: 10, ..TrainOptions::default() },
            flow_side: 48,
            cache_dir,
            seed: 1,
        }
    }

    /// Procedural clips plus the real clips found in `video_dir` (`../shared/data/video`).
    pub fn full(video_dir: Option<&Path>, cache_dir: PathBuf) -> VideoBenchConfig {
        let mut clips = vec![
            BenchClip::Procedural { kind: ProceduralKind::Mixed, frames: 72, width: 320, height: 180 },
            BenchClip::Procedural { kind: ProceduralKind::Drift, frames: 48, width: 320, height: 180 },
            BenchClip::Shots {
                kinds: vec![
                    ProceduralKind::Pendulum,
                    ProceduralKind::Walker,
                    ProceduralKind::Drift,
                    ProceduralKind::Slider,
                    ProceduralKind::Pendulum,
                ],
                frames: 50,
                width: 320,
                height: 180,
            },
        ];
        if let Some(dir) = video_dir {
            for f in ["bigbuckbunny.mp4", "bbb_png_seq", "carphone_pristine.mp4"] {
                if dir.join(f).exists() {
                    clips.push(BenchClip::File(dir.join(f)));
                }
            }
        }
        VideoBenchConfig {
            clips,
            starts: 4,
            length: None,
            rsf: RsfConfig::default(),
            train: TrainOptions::default(),
            flow_side: 160,
            cache_dir,
            seed: 1,
        }
    }
}

/// The configurations: the full method, the ablations of Table 3, ours (w/o C_r, the paper's walk
/// with its early stop), the full method with Eq. 20 as printed (no content term, τ = 1 on latent
/// units), and the issue's baselines: the shortest-path walk of Fig. 3(a) on our graph and on plain
/// pixel distances.
const CONFIGS: [&str; 12] = [
    "full",
    "round 2 walk (no transitions, no step cap)",
    "w/o step cap",
    "w/o C_r",
    "w/o C_d",
    "w/o C_t",
    "w/o RSFNet",
    "w/o L_d",
    "paper walk (no C_r, early stop)",
    "Eq. 20 as printed",
    "SSPF (shortest path)",
    "SSPF on pixel distance",
];
/// The paper's Table 3 (M_D, Δ_o), same order, and its ground truth.
const PAPER_TABLE3: [Option<(f64, f64)>; 12] = [
    Some((0.0648, 0.706)),
    None,
    None,
    None,
    Some((0.079, 0.827)),
    Some((0.118, 0.783)),
    Some((0.082, 0.731)),
    Some((0.281, 0.816)),
    None,
    None,
    None,
    None,
];
/// Backward steps: to one of this many previous source frames (the issue's i → i−1, i−2, i−3).
const BACKWARD_WINDOW: usize = 3;
const PAPER_GT_MD: f64 = 0.0535;

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

/// The `p`-th quantile (p in [0, 1]) by linear interpolation between order statistics; NaN for no
/// value.
fn quantile(values: &[f64], p: f64) -> f64 {
    let mut v: Vec<f64> = values.iter().copied().filter(|x| x.is_finite()).collect();
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    let pos = p.clamp(0.0, 1.0) * (v.len() - 1) as f64;
    let (i, f) = (pos.floor() as usize, pos.fract());
    v[i] + (v[(i + 1).min(v.len() - 1)] - v[i]) * f
}

fn mean(values: &[f64]) -> f64 {
    if values.is_empty() {
        f64::NAN
    } else {
        values.iter().sum::<f64>() / values.len() as f64
    }
}

impl ClipResult {
    /// (mean SSIM, mean over the source's, 10th percentile) of configuration `i`.
    fn ssim(&self, i: usize) -> (f64, f64, f64) {
        let ours = mean(&self.ssim_configs[i]);
        (ours, ours / mean(&self.ssim_source), quantile(&self.ssim_configs[i], 0.1))
    }
}

fn load(clip: &BenchClip) -> Result<(Clip, String, f64), VideoError> {
    let t = Instant::now();
    match clip {
        BenchClip::Procedural { kind, frames, width, height } => {
            let c = procedural_clip(*kind, *frames, *width, *height, 1);
            Ok((c, format!("procedural {kind:?}"), t.elapsed().as_secs_f64()))
        }
        BenchClip::Shots { kinds, frames, width, height } => {
            let c = multi_shot_clip(kinds, *frames, *width, *height, 1);
            Ok((c, format!("procedural {} shots", kinds.len()), t.elapsed().as_secs_f64()))
        }
        BenchClip::File(path) => {
            let (c, _) = read_clip(path, &ReadOptions::default())?;
            let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
            Ok((c, name, t.elapsed().as_secs_f64()))
        }
    }
}

/// The analysis of an ablation, reusing the full one's flows.
fn ablated(
    full: &Analysis,
    clip: &Clip,
    cfg: &VideoBenchConfig,
    which: &str,
    progress: &Progress,
) -> Result<Analysis, VideoError> {
    let mut a = full.clone();
    match which {
        "w/o RSFNet" | "SSPF on pixel distance" => a.graph = pixel_graph(&clip.frames, 32),
        "w/o L_d" => {
            let opts = TrainOptions { use_distance_loss: false, ..cfg.train.clone() };
            let m = embeddings_cached(&cfg.cache_dir, &clip.frames, &cfg.rsf, &opts, progress)?;
            a.graph = graph_from_embeddings(&m.embeddings);
            a.embedder = m.embedder;
        }
        _ => {}
    }
    Ok(a)
}

fn params_for(which: &str, length: Option<usize>, seed: u64) -> SdpfParams {
    let base = if which.starts_with("paper walk") { SdpfParams::paper_walk() } else { SdpfParams::default() };
    let base = match which {
        "w/o step cap" => SdpfParams { step_cap: f32::MAX, ..base },
        w if w.starts_with("round 2") => SdpfParams { transitions: false, ..base },
        _ => base,
    };
    let p = SdpfParams {
        use_ct: which != "w/o C_t",
        use_cd: which != "w/o C_d",
        use_cr: base.use_cr && which != "w/o C_r",
        length,
        seed,
        ..base
    };
    if which == "Eq. 20 as printed" {
        p.paper_choice()
    } else {
        p
    }
}

/// A contact sheet as PNG bytes, small thumbnails, cuts/loops/backward steps marked.
fn sheet_png(
    clip: &Clip,
    order: &[usize],
    cuts: Vec<usize>,
    loops: Vec<usize>,
    title: String,
) -> Result<Vec<u8>, VideoError> {
    let opts = SheetOptions { columns: 16, thumb_width: 72, title, cuts, loops, backward_window: BACKWARD_WINDOW };
    let img = contact_sheet(&clip.frames, order, &opts)?;
    let mut bytes = Vec::new();
    img.write_to(&mut std::io::Cursor::new(&mut bytes), image::ImageFormat::Png)
        .map_err(|e| VideoError::Invalid(format!("contact sheet PNG: {e}")))?;
    Ok(bytes)
}

/// A file-name-safe version of a clip name.
fn slug(name: &str) -> String {
    name.chars().map(|c| if c.is_ascii_alphanumeric() { c.to_ascii_lowercase() } else { '-' }).collect()
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
            let (order, cuts, loops) = if which.starts_with("SSPF") {
                (crate::sdpf::sspf(&a.graph, s, target, Some(&shots)), Vec::new(), Vec::new())
            } else {
                let params = params_for(which, cfg.length, inbetween_core::seed::derive(cfg.seed, i as u64));
                let (paths, secs) = resequence(&a, s, &params, 1, &VideoLimits::default())?;
                if which == "full" {
                    walk_s += secs;
                    walks += 1;
                }
                let p = &paths[0];
                let cuts = [p.cut_positions(), p.jump_cut_positions()].concat();
                (p.frames.clone(), cuts, [p.loop_positions(), p.transition_positions()].concat())
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
                md: stability_md(&clip.frames, &order),
                delta_o: overlap_delta_o(&order, n),
                distinct: distinct_fraction(&order, n),
                cycle: longest_repeated_cycle(&order),
                short_repeats: short_cycle_repeats(&order, full.info.min_loop_frames(1.0)),
                shot_changes: shot_changes(&order, &shots),
                source_changes: shot_changes(&source_order, &shots),
            });
            ssims.extend(transition_ssims(&planes, &order)?);
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

/// Runs the bench and returns its report (tables as text, Markdown and CSV).
pub fn run(cfg: &VideoBenchConfig, progress: &Progress) -> Result<Report, VideoError> {
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

/// `period×repeats` of a cycle, `-` for none.
fn cycle_words(c: Option<Cycle>) -> String {
    c.map_or_else(|| "-".to_string(), |c| format!("{}x{}", c.period, c.repeats))
}

/// The repeated cycle of `runs` covering the most frames.
fn longest_cycle(runs: &[Run]) -> Option<Cycle> {
    runs.iter().filter_map(|r| r.cycle).max_by_key(|c| (c.frames(), std::cmp::Reverse(c.period)))
}

/// Mean over `runs` of the steps between shots per 100 frames, and the source's own.
fn cuts_per_100(runs: &[Run]) -> (f64, f64) {
    let ours = mean(&runs.iter().map(|r| per_100_frames(r.shot_changes, r.length)).collect::<Vec<_>>());
    let source = mean(&runs.iter().map(|r| per_100_frames(r.source_changes, r.length.max(1))).collect::<Vec<_>>());
    (ours, source)
}

/// Backward steps over all steps of `runs`, percent.
fn backward_pct(runs: &[Run]) -> f64 {
    let steps: usize = runs.iter().map(|r| r.steps).sum();
    let back: usize = runs.iter().map(|r| r.backward).sum();
    if steps == 0 {
        0.0
    } else {
        100.0 * back as f64 / steps as f64
    }
}

/// Direction flips (Eq. 12 broken) over all steps of `runs`, percent.
fn flip_pct(runs: &[Run]) -> f64 {
    let steps: usize = runs.iter().map(|r| r.steps).sum();
    if steps == 0 {
        0.0
    } else {
        100.0 * runs.iter().map(|r| r.flips).sum::<usize>() as f64 / steps as f64
    }
}

/// Mean share of the target length the runs reached.
fn reached(runs: &[Run], target: usize) -> f64 {
    mean(&runs.iter().map(|r| r.length as f64 / target.max(1) as f64).collect::<Vec<_>>())
}

/// Every run: clip, start, method, length reached, backward steps, M_D ratio, Δo, cuts, loops.
fn runs_table(results: &[ClipResult]) -> Table {
    let mut t = Table::new(
        "runs",
        "Every run: per clip, start and method",
        &[
            "clip",
            "start",
            "method",
            "length",
            "target",
            "backward_steps",
            "backward_pct",
            "flips",
            "md_ratio",
            "delta_o",
            "cuts",
            "loops",
            "distinct_frames",
            "longest_cycle",
            "short_cycle_repeats",
            "shot_changes_per_100",
            "source_shot_changes_per_100",
        ],
    );
    for r in results {
        for (i, name) in CONFIGS.iter().enumerate() {
            for run in &r.runs[i] {
                t.row([
                    r.name.clone(),
                    run.start.to_string(),
                    name.to_string(),
                    run.length.to_string(),
                    r.target.to_string(),
                    run.backward.to_string(),
                    num(backward_pct(std::slice::from_ref(run)), 1),
                    run.flips.to_string(),
                    num(run.md / r.md_source.max(1e-12), 2),
                    num(run.delta_o, 3),
                    run.cuts.to_string(),
                    run.loops.to_string(),
                    num(run.distinct, 2),
                    cycle_words(run.cycle),
                    run.short_repeats.to_string(),
                    num(per_100_frames(run.shot_changes, run.length), 1),
                    num(per_100_frames(run.source_changes, r.frames), 1),
                ]);
            }
        }
    }
    t.note("backward step: a step to one of the 3 previous source frames (i -> i-1, i-2, i-3), which plays the source backwards; backward_pct = backward steps / steps");
    t.note("flips: steps between two LMS frames whose motion tendencies differ by more than 60 degrees (what C_d, Eq. 12, prevents)");
    t.note("length: frames reached; target: the clip's frame count (the default length); cuts: steps that cut to another shot where no candidate was left, and (full method) jump cuts inside a shot where no matched way led on; loops: loop backs (round 2's walk; then the loop repeats) and matched transitions (the full method)");
    t.note(CYCLE_NOTE);
    t
}

fn table2(results: &[ClipResult], cfg: &VideoBenchConfig) -> Table {
    let mut t = Table::new(
        "table2",
        "Table 2 analogue: stability M_D (Eq. 21) and overlap Δo (Eq. 23) per clip, full method",
        &[
            "clip",
            "frames",
            "directed_shots",
            "length_reached",
            "backward_pct",
            "backward_pct_no_cr",
            "md_source",
            "md_ours",
            "md_ratio",
            "delta_o",
            "cuts",
            "loops",
            "distinct_frames",
            "distinct_min",
            "longest_cycle",
            "short_cycle_repeats",
            "shot_changes_per_100",
            "source_shot_changes_per_100",
            "ssim_source",
            "ssim_ours",
            "ssim_ratio",
            "ssim_p10",
        ],
    );
    for r in results {
        let (md, dq, _) = r.configs[0];
        let (ss, sr, sp) = r.ssim(0);
        let directed = r.direction.iter().filter(|d| d.0).count();
        t.row([
            r.name.clone(),
            r.frames.to_string(),
            format!("{directed}/{}", r.direction.len()),
            num(reached(&r.runs[0], r.target), 2),
            num(backward_pct(&r.runs[0]), 1),
            num(backward_pct(&r.runs[CONFIGS.iter().position(|c| *c == "w/o C_r").unwrap_or(0)]), 1),
            num(r.md_source, 4),
            num(md, 4),
            num(md / r.md_source.max(1e-12), 2),
            num(dq, 3),
            r.runs[0].iter().map(|x| x.cuts).sum::<usize>().to_string(),
            r.runs[0].iter().map(|x| x.loops).sum::<usize>().to_string(),
            num(mean(&r.runs[0].iter().map(|x| x.distinct).collect::<Vec<_>>()), 2),
            num(r.runs[0].iter().map(|x| x.distinct).fold(f64::INFINITY, f64::min), 2),
            cycle_words(longest_cycle(&r.runs[0])),
            r.runs[0].iter().map(|x| x.short_repeats).max().unwrap_or(0).to_string(),
            num(cuts_per_100(&r.runs[0]).0, 1),
            num(cuts_per_100(&r.runs[0]).1, 1),
            num(mean(&r.ssim_source), 3),
            num(ss, 3),
            num(sr, 3),
            num(sp, 3),
        ]);
    }
    t.note(format!(
        "{} start frames per clip (from frame 0, evenly spread), target length {}; M_D = mean RMS step of pixels in [0, 1]",
        cfg.starts,
        cfg.length.map_or_else(|| "= the clip's frame count".to_string(), |l| l.to_string())
    ));
    t.note("directed_shots: shots whose motion is judged directed (at least half LMS frames); length_reached: mean share of the target length; backward_pct: steps to one of the 3 previous source frames, over all steps of the 4 starts (full method; _no_cr: without C_r); cuts, loops: summed over the starts");
    t.note(CYCLE_NOTE);
    t.note("paper (12 clips, their own): ground truth M_D 0.050, ours 0.055 (ratio 1.10), Δo 0.73; Morace et al. 0.069, Δo 0.74");
    t.note(SSIM_NOTE);
    t
}

const CYCLE_NOTE: &str = "distinct_frames: share of the source's frames the order shows (mean over the starts; distinct_min: the lowest); longest_cycle: the block of frames played most often in a row, as frames x plays (the one covering the most frames, over the starts); short_cycle_repeats: most plays in a row of a block shorter than 1 s (issue 41's limit: 2); shot_changes_per_100: steps between shots per 100 frames of the order, beside the source's own shot changes per 100 frames";

const SSIM_NOTE: &str = "ssim (ours; the paper reports none): mean SSIM (Wang et al. 2004, 11x11 Gaussian window, sigma 1.5, on luma at most 160 px on the longer side) of the transitions i -> i+1 of the new orders; ssim_source over the clip's own adjacent pairs; ssim_ratio = ours / source (1 = transitions as similar as real ones); ssim_p10 = 10th percentile of the new transitions (the worst jumps)";

fn table3(results: &[ClipResult]) -> Table {
    let mut t = Table::new(
        "table3",
        "Table 3 analogue: ablations, mean over clips",
        &[
            "method",
            "length_reached",
            "backward_pct",
            "flip_pct",
            "md",
            "md_ratio",
            "delta_o",
            "ssim",
            "ssim_ratio",
            "ssim_p10",
            "distinct_frames",
            "short_cycle_repeats",
            "shot_changes_per_100",
            "paper_md",
            "paper_md_ratio",
            "paper_delta_o",
        ],
    );
    let k = results.len().max(1) as f64;
    let gt: f64 = results.iter().map(|r| r.md_source).sum::<f64>() / k;
    let gt_ssim = results.iter().map(|r| mean(&r.ssim_source)).sum::<f64>() / k;
    let gt_p10 = results.iter().map(|r| quantile(&r.ssim_source, 0.1)).sum::<f64>() / k;
    t.row([
        "ground truth".to_string(),
        "1.00".into(),
        "0.0".into(),
        "-".into(),
        num(gt, 4),
        "1.00".into(),
        "1".into(),
        num(gt_ssim, 3),
        "1.000".into(),
        num(gt_p10, 3),
        "1.00".into(),
        "-".into(),
        num(results.iter().map(|r| per_100_frames(r.direction.len().saturating_sub(1), r.frames)).sum::<f64>() / k, 1),
        num(PAPER_GT_MD, 4),
        "1.00".into(),
        "1".into(),
    ]);
    for (i, name) in CONFIGS.iter().enumerate() {
        let md = results.iter().map(|r| r.configs[i].0).sum::<f64>() / k;
        let ratio = results.iter().map(|r| r.configs[i].0 / r.md_source.max(1e-12)).sum::<f64>() / k;
        let dq = results.iter().map(|r| r.configs[i].1).sum::<f64>() / k;
        let paper = match PAPER_TABLE3[i] {
            Some((pm, pd)) => [num(pm, 4), num(pm / PAPER_GT_MD, 2), num(pd, 3)],
            None => ["-".to_string(), "-".to_string(), "-".to_string()],
        };
        let [pm, pr, pd] = paper;
        let ssim = |f: fn((f64, f64, f64)) -> f64| results.iter().map(|r| f(r.ssim(i))).sum::<f64>() / k;
        let (ss, sr, sp) = (ssim(|s| s.0), ssim(|s| s.1), ssim(|s| s.2));
        let len = results.iter().map(|r| reached(&r.runs[i], r.target)).sum::<f64>() / k;
        let back = results.iter().map(|r| backward_pct(&r.runs[i])).sum::<f64>() / k;
        let flips = results.iter().map(|r| flip_pct(&r.runs[i])).sum::<f64>() / k;
        let distinct =
            results.iter().map(|r| mean(&r.runs[i].iter().map(|x| x.distinct).collect::<Vec<_>>())).sum::<f64>() / k;
        let short = results.iter().flat_map(|r| r.runs[i].iter().map(|x| x.short_repeats)).max().unwrap_or(0);
        let cuts = results.iter().map(|r| cuts_per_100(&r.runs[i]).0).sum::<f64>() / k;
        t.row([
            name.to_string(),
            num(len, 2),
            num(back, 1),
            num(flips, 1),
            num(md, 4),
            num(ratio, 2),
            num(dq, 3),
            num(ss, 3),
            num(sr, 3),
            num(sp, 3),
            num(distinct, 2),
            short.to_string(),
            num(cuts, 1),
            pm,
            pr,
            pd,
        ]);
    }
    t.note("md_ratio: M_D of the new orders over the clip's own (lower is smoother); the paper's clips differ from ours, so compare ratios");
    t.note("length_reached: mean share of the clip's frame count reached; backward_pct: mean over the clips of the share of steps to one of the 3 previous source frames");
    t.note("flip_pct: mean over the clips of the share of steps between LMS frames whose tendencies differ by more than 60 degrees (Eq. 12 broken)");
    t.note("w/o C_r: without our reverse distillation; paper walk: also without C_r, and the paper's early stop where S2 is empty (no cut, no loop back)");
    t.note("w/o RSFNet: Euclidean distance of 32-pixel thumbnails; w/o L_d: the same network untrained (our backbone is not pretrained)");
    t.note("Eq. 20 as printed: the full method choosing by exp(-motion distance) in latent units, without our content term and relative temperature");
    t.note("SSPF: the baseline of Fig. 3(a), always the nearest unvisited frame (RSFNet graph); SSPF on pixel distance: the same on 32-pixel thumbnails; the paper gives no numbers for them");
    t.note("distinct_frames, shot_changes_per_100: means over the clips; short_cycle_repeats: the most over every clip and start (see Table 2's note)");
    t.note("round 2 walk: issue 26's walk, where S2 is empty a cut or one loop back to the closest frame of the path, repeated up to the length, and no step cap (the 'before' of issue 41); w/o step cap: the full method drawing from all of S2");
    t.note("ssim, ssim_ratio, ssim_p10: means over the clips of Table 2's columns (ours; the paper reports no SSIM); ground truth: the clips' own adjacent pairs");
    t
}

/// SSIM per clip and method: the source's adjacent pairs, then every configuration.
fn ssim_table(results: &[ClipResult]) -> Table {
    let mut t = Table::new(
        "ssim",
        "SSIM of transitions per clip and method (ours; not in the paper)",
        &["clip", "method", "transitions", "ssim", "ssim_ratio", "ssim_p10", "ssim_min"],
    );
    for r in results {
        let src = mean(&r.ssim_source);
        let min = |v: &[f64]| v.iter().copied().fold(f64::INFINITY, f64::min);
        t.row([
            r.name.clone(),
            "source (adjacent pairs)".into(),
            r.ssim_source.len().to_string(),
            num(src, 3),
            "1.000".into(),
            num(quantile(&r.ssim_source, 0.1), 3),
            num(min(&r.ssim_source), 3),
        ]);
        for (i, name) in CONFIGS.iter().enumerate() {
            let (ss, sr, sp) = r.ssim(i);
            let v = &r.ssim_configs[i];
            t.row([
                r.name.clone(),
                name.to_string(),
                v.len().to_string(),
                num(ss, 3),
                num(sr, 3),
                num(sp, 3),
                num(min(v), 3),
            ]);
        }
    }
    t.note(SSIM_NOTE);
    t.note("transitions: pooled over the start frames; ssim_min: the worst single transition");
    t
}

/// Box plot of the SSIM of every transition, per method, grouped by clip (`ssim.png`).
fn ssim_png(results: &[ClipResult]) -> Result<Vec<u8>, VideoError> {
    let groups: Vec<String> = results.iter().map(|r| r.name.clone()).collect();
    let mut series = vec![("source".to_string(), results.iter().map(|r| r.ssim_source.clone()).collect::<Vec<_>>())];
    for (i, name) in CONFIGS.iter().enumerate() {
        series.push((name.to_string(), results.iter().map(|r| r.ssim_configs[i].clone()).collect()));
    }
    inbetween_render::rendered_bytes("ssim.png", |p| {
        inbetween_render::plot::box_plot(
            p,
            "SSIM of transitions (source's adjacent pairs vs new orders)",
            "SSIM (luma, <= 160 px)",
            &groups,
            &series,
        )
    })
    .map_err(|e| VideoError::Invalid(format!("ssim.png: {e}")))
}

fn stage_table(results: &[ClipResult]) -> Table {
    let mut t = Table::new(
        "stages",
        "Seconds per stage (this machine, 2 cores)",
        &["clip", "size", "frames", "stage", "seconds"],
    );
    for r in results {
        let size = format!("{}x{}", r.size.0, r.size.1);
        t.row([r.name.clone(), size.clone(), r.frames.to_string(), "decode or render".into(), num(r.decode_s, 2)]);
        for (stage, s) in &r.stages {
            t.row([r.name.clone(), size.clone(), r.frames.to_string(), stage.clone(), num(*s, 2)]);
        }
        t.row([r.name.clone(), size, r.frames.to_string(), "SDPF walk (one sequence)".into(), num(r.walk_s, 2)]);
    }
    t.note("the RSFNet stage trains on the clip the first time and reads the cache afterwards (a fresh cache folder is used per bench run)");
    for r in results {
        t.note(r.metric_note.clone());
    }
    t
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
        let report = run(&VideoBenchConfig::quick(dir.path().to_path_buf()), &Progress::hidden()).unwrap();
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
    }
}
