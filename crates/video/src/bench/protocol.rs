//! The bench's protocol: its clips (procedural and the corpus), the configurations (the full
//! method, the paper's ablations of Table 3, ours, the baselines) and how each one's analysis and
//! walk parameters are made.

use std::path::{Path, PathBuf};
use std::time::Instant;

use inbetween_io::Progress;

use crate::frames::{multi_shot_clip, procedural_clip, read_clip, Clip, ProceduralKind, ReadOptions};
use crate::metric::{embeddings_cached, graph_from_embeddings, pixel_graph, RsfConfig, TrainOptions};
use crate::pipeline::Analysis;
use crate::sdpf::SdpfParams;
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
    /// Parts of files cut together, each resized to `width`×`height`: a clip of several real shots
    /// (issue 41's "clips you make with several shots").
    Montage {
        name: String,
        parts: Vec<(PathBuf, std::ops::Range<usize>)>,
        width: u32,
        height: u32,
    },
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
            let (bunny, car, distorted) =
                (dir.join("bigbuckbunny.mp4"), dir.join("carphone_pristine.mp4"), dir.join("carphone_distorted.mp4"));
            if bunny.exists() && car.exists() && distorted.exists() {
                clips.push(BenchClip::Montage {
                    name: "four shots (bbb 70-131, carphone 0-59, bbb 0-59, carphone_distorted 60-119)".into(),
                    parts: vec![(bunny.clone(), 70..132), (car, 0..60), (bunny, 0..60), (distorted, 60..120)],
                    width: 256,
                    height: 144,
                });
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
/// units), the baselines (the shortest-path walk of Fig. 3(a) on our graph and on plain
/// pixel distances), and the full method's orders written with a cross-fade (issue 41).
pub(super) const CONFIGS: [&str; 14] = [
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
    "full, cross-fade 2 frames (--blend 2)",
    "full, cross-fade 4 frames (--blend 4)",
];
/// The paper's Table 3 (M_D, Δ_o), same order, and its ground truth.
pub(super) const PAPER_TABLE3: [Option<(f64, f64)>; 14] = [
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
    None,
    None,
];

/// The frames of the cross-fade of a configuration (issue 41's `--blend N`; the full method's
/// orders, rendered with [`Blend`](crate::render::Blend)); 0: none.
pub(super) fn blend_frames(which: &str) -> usize {
    match which {
        "full, cross-fade 2 frames (--blend 2)" => 2,
        "full, cross-fade 4 frames (--blend 4)" => 4,
        _ => 0,
    }
}
pub(super) const PAPER_GT_MD: f64 = 0.0535;

pub(super) fn load(clip: &BenchClip) -> Result<(Clip, String, f64), VideoError> {
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
        BenchClip::Montage { name, parts, width, height } => {
            let mut frames = Vec::new();
            let mut fps = crate::frames::DEFAULT_FPS;
            for (path, range) in parts {
                let (c, _) = read_clip(path, &ReadOptions { max_frames: Some(range.end), ..ReadOptions::default() })?;
                let Some(part) = c.frames.get(range.clone()) else {
                    return Err(VideoError::Invalid(format!(
                        "{}: frames {}..{} asked for, the clip has {}",
                        path.display(),
                        range.start,
                        range.end,
                        c.len()
                    )));
                };
                fps = c.fps;
                frames.extend(
                    part.iter()
                        .map(|f| image::imageops::resize(f, *width, *height, image::imageops::FilterType::Triangle)),
                );
            }
            Ok((Clip { frames, fps, source: name.clone() }, name.clone(), t.elapsed().as_secs_f64()))
        }
    }
}

/// The analysis of an ablation, reusing the full one's flows.
pub(super) fn ablated(
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

pub(super) fn params_for(which: &str, length: Option<usize>, seed: u64) -> SdpfParams {
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
