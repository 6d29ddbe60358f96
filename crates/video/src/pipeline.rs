//! The whole resequencing of a clip: grey frames → optical flows, tendencies, LMS (§5.2.1) →
//! RSFNet trained on the clip (or read from its cache) → complete graph (Eq. 7) → scene cuts →
//! SDPF walks (Algorithm 1) with PMSM motion distances (Eq. 13–15) → new orders, with each stage's
//! wall time.

use std::path::PathBuf;
use std::time::Instant;

use inbetween_io::Progress;
use rayon::prelude::*;

use crate::frames::Clip;
use crate::metric::{embeddings_cached, graph_from_embeddings, pixel_graph, Embedder, Graph, RsfConfig, TrainOptions};
use crate::motion::{analyse_clip, pseudo_images, rotate_flow, ClipMotion, Flow, FlowParams, MU0};
use crate::sdpf::{detect_shots, several, MotionDistance, MotionInfo, SdpfParams, SdpfPath};
use crate::VideoError;

/// Which frame metric builds the graph (Table 3's ablations).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MetricChoice {
    /// RSFNet trained on the clip with the distance loss (the paper).
    RsfNet,
    /// Euclidean distance of downscaled pixels ("w/o RSFNet").
    Pixels,
}

/// Settings of a resequencing.
#[derive(Clone, Debug)]
pub struct ResequenceConfig {
    /// Longer side of the grey frames the flows run on, pixels.
    pub flow_side: u32,
    pub flow: FlowParams,
    pub rsf: RsfConfig,
    pub train: TrainOptions,
    pub metric: MetricChoice,
    /// Where trained networks and embeddings are cached per clip.
    pub cache_dir: PathBuf,
    /// Detect scene cuts (off: the whole clip is one shot).
    pub detect_cuts: bool,
}

impl Default for ResequenceConfig {
    fn default() -> Self {
        ResequenceConfig {
            flow_side: 160,
            flow: FlowParams::default(),
            rsf: RsfConfig::default(),
            train: TrainOptions::default(),
            metric: MetricChoice::RsfNet,
            cache_dir: default_cache_dir(),
            detect_cuts: true,
        }
    }
}

/// `$XDG_CACHE_HOME/inbetween/video`, else `~/.cache/inbetween/video`, else a folder in the temp dir.
pub fn default_cache_dir() -> PathBuf {
    let base = std::env::var_os("XDG_CACHE_HOME")
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cache")))
        .unwrap_or_else(std::env::temp_dir);
    base.join("inbetween").join("video")
}

/// Everything the walks need, computed once per clip.
#[derive(Clone)]
pub struct Analysis {
    pub motion: ClipMotion,
    pub info: MotionInfo,
    pub graph: Graph,
    /// The network that embeds frames and pseudo-images (trained, or untrained for "w/o L_d").
    pub embedder: Embedder,
    /// (stage, seconds) in order.
    pub stages: Vec<(String, f64)>,
    /// What happened to the metric (trained, from cache, …).
    pub metric_note: String,
}

/// Flows, metric, graph and shots of `clip`.
pub fn analyse(clip: &Clip, cfg: &ResequenceConfig, progress: &Progress) -> Result<Analysis, VideoError> {
    if clip.len() < 2 {
        return Err(VideoError::Invalid(format!(
            "{}: a clip needs at least 2 frames to resequence, it has {}",
            clip.source,
            clip.len()
        )));
    }
    let mut stages = Vec::new();
    let t = Instant::now();
    let gray = clip.gray_downscaled(cfg.flow_side);
    let motion = analyse_clip(&gray, &cfg.flow);
    stages.push(("optical flow, tendency, LMS (Eq. 9-11)".to_string(), t.elapsed().as_secs_f64()));

    let t = Instant::now();
    let metric = embeddings_cached(&cfg.cache_dir, &clip.frames, &cfg.rsf, &cfg.train, progress)?;
    let metric_note = if metric.from_cache {
        format!("RSFNet read from the cache {}", metric.path.display())
    } else if metric.summary.trained {
        format!(
            "RSFNet trained on the clip: {} steps in {:.1} s (kept epoch {} of {}, early stopping), held-out triplet agreement {:.3} -> {:.3}",
            metric.summary.steps,
            metric.summary.seconds,
            metric.summary.best_epoch + 1,
            metric.summary.loss_history.len(),
            metric.summary.agreement_before,
            metric.summary.agreement_after
        )
    } else {
        "RSFNet untrained (no distance loss)".to_string()
    };
    stages.push(("RSFNet training or cache, embeddings (Eq. 4-7)".to_string(), t.elapsed().as_secs_f64()));

    let t = Instant::now();
    let graph = match cfg.metric {
        MetricChoice::RsfNet => graph_from_embeddings(&metric.embeddings),
        MetricChoice::Pixels => pixel_graph(&clip.frames, 32),
    };
    let shot = if cfg.detect_cuts { detect_shots(&clip.frames) } else { vec![0; clip.len()] };
    stages.push(("complete graph, scene cuts".to_string(), t.elapsed().as_secs_f64()));
    let info = MotionInfo { tendency: motion.tendency.clone(), lms: motion.lms.clone(), shot };
    Ok(Analysis { motion, info, graph, embedder: metric.embedder, stages, metric_note })
}

/// PMSM (Eq. 13–15): the motion distance of c → k is the latent distance of their pseudo-images.
pub struct Pmsm<'a> {
    pub backward: &'a [Flow],
    pub embedder: &'a Embedder,
}

impl Pmsm<'_> {
    /// N_e's floor (§5.2.2: "224 is the height and width of frames"): the flow's longer side.
    fn min_count(&self, c: usize) -> usize {
        self.backward[c].width.max(self.backward[c].height)
    }

    fn pair_distances(&self, fc: &Flow, fks: &[&Flow], min_count: usize) -> Vec<f32> {
        let imgs: Vec<Vec<f32>> = fks
            .par_iter()
            .flat_map_iter(|fk| {
                let (a, b) = pseudo_images(fc, fk, MU0, min_count);
                [a, b]
            })
            .collect();
        match self.embedder.embed_pseudo(&imgs, fc.width, fc.height) {
            Ok(e) => e.chunks_exact(2).map(|p| l2(&p[0], &p[1])).collect(),
            Err(_) => vec![f32::INFINITY; fks.len()],
        }
    }
}

fn l2(a: &[f32], b: &[f32]) -> f32 {
    a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum::<f32>().sqrt()
}

impl MotionDistance for Pmsm<'_> {
    fn distance(&self, c: usize, k: usize) -> f32 {
        self.distances(c, &[k])[0]
    }

    fn rotated_floor(&self, c: usize) -> f32 {
        let fc = &self.backward[c];
        let a1 = rotate_flow(fc, std::f32::consts::FRAC_PI_2);
        let a2 = rotate_flow(fc, -std::f32::consts::FRAC_PI_2);
        self.pair_distances(fc, &[&a1, &a2], self.min_count(c)).into_iter().fold(f32::INFINITY, f32::min)
    }

    fn distances(&self, c: usize, ks: &[usize]) -> Vec<f32> {
        if ks.is_empty() {
            return Vec::new();
        }
        let fks: Vec<&Flow> = ks.iter().map(|&k| &self.backward[k]).collect();
        self.pair_distances(&self.backward[c], &fks, self.min_count(c))
    }
}

/// `count` distinct new orders from `start` (SDPF on the analysed clip), and the walk's wall time.
pub fn resequence(
    analysis: &Analysis,
    start: usize,
    params: &SdpfParams,
    count: usize,
) -> Result<(Vec<SdpfPath>, f64), VideoError> {
    let t = Instant::now();
    let pmsm = Pmsm { backward: &analysis.motion.backward, embedder: &analysis.embedder };
    let paths = several(&analysis.graph, &analysis.info, &pmsm, start, params, count.max(1))?;
    Ok((paths, t.elapsed().as_secs_f64()))
}

/// A clip of `order`'s frames at the source rate.
pub fn reorder(clip: &Clip, order: &[usize]) -> Clip {
    Clip {
        frames: order.iter().map(|&f| clip.frames[f].clone()).collect(),
        fps: clip.fps,
        source: format!("{} resequenced", clip.source),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frames::{procedural_clip, ProceduralKind};
    use crate::sdpf::{overlap_delta_o, stability_md};

    fn quick_config(dir: &std::path::Path) -> ResequenceConfig {
        ResequenceConfig {
            flow_side: 48,
            rsf: RsfConfig::tiny(),
            train: TrainOptions { steps: 20, ..TrainOptions::default() },
            cache_dir: dir.to_path_buf(),
            ..ResequenceConfig::default()
        }
    }

    #[test]
    fn pipeline_resequences_a_procedural_clip_smoothly_and_reproducibly() {
        let dir = tempfile::tempdir().unwrap();
        let clip = procedural_clip(ProceduralKind::Pendulum, 24, 64, 48, 3);
        let cfg = quick_config(dir.path());
        let a = analyse(&clip, &cfg, &Progress::hidden()).unwrap();
        assert_eq!(a.graph.n, 24);
        assert_eq!(a.stages.len(), 3);
        let params = SdpfParams { seed: 5, ..SdpfParams::default() };
        let (paths, _) = resequence(&a, 4, &params, 2).unwrap();
        assert!(!paths.is_empty());
        let order = &paths[0].frames;
        assert_eq!(order[0], 4);
        assert!(order.len() >= 2, "{order:?}");
        // A new order's transitions stay far smoother than a random shuffle's.
        let source: Vec<usize> = (0..24).collect();
        let shuffled: Vec<usize> = (0..24).map(|i| (i * 7) % 24).collect();
        let md = stability_md(&clip.frames, order);
        assert!(md < stability_md(&clip.frames, &shuffled), "M_D {md}");
        assert!(stability_md(&clip.frames, &source) > 0.0);
        assert!(overlap_delta_o(order, 24) <= 1.0);
        // Second run: the metric comes from the cache and the same seed gives the same order.
        let b = analyse(&clip, &cfg, &Progress::hidden()).unwrap();
        assert!(b.metric_note.contains("cache"), "{}", b.metric_note);
        assert_eq!(resequence(&b, 4, &params, 2).unwrap().0[0].frames, *order);
        let r = reorder(&clip, order);
        assert_eq!(r.frames[1], clip.frames[order[1]]);
    }

    #[test]
    fn pipeline_refuses_a_one_frame_clip() {
        let dir = tempfile::tempdir().unwrap();
        let clip = procedural_clip(ProceduralKind::Pendulum, 1, 32, 32, 1);
        let e = analyse(&clip, &quick_config(dir.path()), &Progress::hidden()).err().expect("an error");
        assert!(e.to_string().contains("at least 2 frames"), "{e}");
    }
}
