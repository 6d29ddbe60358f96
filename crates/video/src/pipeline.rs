//! The whole resequencing of a clip: grey frames → optical flows, tendencies, LMS (§5.2.1) →
//! RSFNet trained on the clip (or read from its cache) → complete graph (Eq. 7) → scene cuts →
//! SDPF walks (Algorithm 1) with PMSM motion distances (Eq. 13–15) → new orders, with each stage's
//! wall time.

use std::path::PathBuf;
use std::time::Instant;

use inbetween_core::cancel::Cancel;
use inbetween_io::{LimitExceeded, Progress};
use rayon::prelude::*;

use crate::frames::Clip;
use crate::metric::{
    embeddings_cached_with, graph_from_embeddings, pixel_graph, Embedder, Graph, RsfConfig, TrainOptions,
};
use crate::motion::{analyse_clip, pseudo_images, rotate_flow, ClipMotion, Flow, FlowParams, MU0};
use crate::sdpf::{detect_shots, judge_directed, several_with, MotionDistance, MotionInfo, SdpfParams, SdpfPath};
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
    /// What a clip and a request may ask for, checked before the heavy work.
    pub limits: VideoLimits,
    /// Checked between the stages, before every RSFNet training step and before every step of a
    /// walk; a time limit (`--time-limit`) is a token with a deadline. The [`Analysis`] keeps a
    /// clone, so that the walks on it obey the same token.
    pub cancel: Cancel,
}

/// The limits of a resequencing, checked before the heavy work (flows, training, walks) so that no
/// input occupies the machine for long or fills its memory. Each error names the field it broke
/// ([`VideoError::Limit`]).
///
/// Cost grows with them: flows and embeddings with frames × pixels (the flows run on frames
/// downscaled to 160 px, but decoding and the cut detector see every pixel); the graph with
/// frames²; a walk with its length × the candidates per step (about half the clip, each needing
/// two network passes for C_t).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct VideoLimits {
    /// Most frames a clip may have.
    pub max_frames: usize,
    /// Most pixels per frame (width × height).
    pub max_pixels: u64,
    /// Longest new order, frames.
    pub max_length: usize,
    /// Most distinct sequences asked for at once.
    pub max_count: usize,
}

impl Default for VideoLimits {
    /// 3 000 frames (2 minutes at 25 fps), 3840×2160 pixels (UHD), orders of 10 000 frames, 16
    /// sequences per call.
    fn default() -> Self {
        let (width, height) = VideoLimits::DEFAULT_RESOLUTION;
        VideoLimits { max_frames: 3000, max_pixels: width * height, max_length: 10_000, max_count: 16 }
    }
}

impl VideoLimits {
    /// The default frame size limit, width × height in pixels (UHD), as front ends write it.
    pub const DEFAULT_RESOLUTION: (u64, u64) = (3840, 2160);

    /// A frame-size limit written `WIDTHxHEIGHT` (`3840x2160`, `x` or `X`), as the pixel count
    /// [`VideoLimits::max_pixels`] holds; an error says what was expected.
    pub fn parse_pixels(s: &str) -> Result<u64, String> {
        let (w, h) =
            s.split_once(['x', 'X']).ok_or_else(|| format!("expected WIDTHxHEIGHT such as 3840x2160, got {s:?}"))?;
        let w: u64 = w.trim().parse().map_err(|_| format!("width {w:?} is not a whole number (in {s:?})"))?;
        let h: u64 = h.trim().parse().map_err(|_| format!("height {h:?} is not a whole number (in {s:?})"))?;
        if w == 0 || h == 0 {
            return Err(format!("a resolution limit of {s} allows no frame"));
        }
        Ok(w * h)
    }

    /// The clip's frame count and frame size.
    pub fn check_clip(&self, clip: &Clip) -> Result<(), VideoError> {
        LimitExceeded::check_count(clip.source.clone(), clip.len(), self.max_frames, "frames", "max_frames")
            .map_err(VideoError::Limit)?;
        let pixels = clip.frames.iter().map(|f| u64::from(f.width()) * u64::from(f.height())).max().unwrap_or(0);
        if pixels > self.max_pixels {
            let subject = format!("{} ({}x{})", clip.source, clip.width(), clip.height());
            let over = LimitExceeded::check_count(
                subject,
                pixels as usize,
                self.max_pixels as usize,
                "pixels per frame",
                "max_pixels",
            );
            return over.map_err(VideoError::Limit);
        }
        Ok(())
    }

    /// A request: the target length (`None`: the source's `frames`) and the number of sequences.
    /// Zero of either is refused: it asks for nothing.
    pub fn check_request(&self, length: Option<usize>, frames: usize, count: usize) -> Result<(), VideoError> {
        if length == Some(0) {
            return Err(VideoError::Invalid(
                "a length of 0 frames asks for nothing: give at least 1 (the start frame), or none for the source's length".into(),
            ));
        }
        if count == 0 {
            return Err(VideoError::Invalid("a count of 0 sequences asks for nothing: give at least 1".into()));
        }
        let length = length.unwrap_or(frames);
        LimitExceeded::check_count("the requested length", length, self.max_length, "frames", "max_length")
            .map_err(VideoError::Limit)?;
        LimitExceeded::check_count("the requested count", count, self.max_count, "sequences", "max_count")
            .map_err(VideoError::Limit)
    }
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
            limits: VideoLimits::default(),
            cancel: Cancel::new(),
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
    /// Per shot: whether its motion is judged directed, and its share of LMS frames
    /// ([`judge_directed`]).
    pub direction: Vec<(bool, f32)>,
    /// (stage, seconds) in order.
    pub stages: Vec<(String, f64)>,
    /// What happened to the metric (trained, from cache, …).
    pub metric_note: String,
    /// The token of the [`ResequenceConfig`] that made this analysis; [`resequence`] checks it.
    pub cancel: Cancel,
    /// PMSM distances already computed on this clip, shared by every later [`resequence`] on this
    /// analysis: a regeneration with another start, seed or length asks the network only for pairs
    /// no earlier walk needed. The distance of a pair is a pure function of the flows and the
    /// embedder, so the cache never changes a result. A clone starts with an empty cache (a clone
    /// may be given another embedder, as the bench's "w/o L_d" ablation does).
    pub pmsm_memo: PmsmMemo,
}

/// The cache of [`Analysis::pmsm_memo`]: motion distances per `(from, to)` pair and the rotated floor
/// per frame. Cloning gives an empty cache.
#[derive(Default, Debug)]
pub struct PmsmMemo {
    pairs: std::sync::Mutex<std::collections::HashMap<(usize, usize), f32>>,
    floors: std::sync::Mutex<std::collections::HashMap<usize, f32>>,
}

impl Clone for PmsmMemo {
    fn clone(&self) -> Self {
        PmsmMemo::default()
    }
}

impl PmsmMemo {
    /// Pairs cached so far.
    pub fn len(&self) -> usize {
        self.pairs.lock().unwrap_or_else(|p| p.into_inner()).len()
    }

    /// Whether nothing is cached yet.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// Flows, metric, graph and shots of `clip`, after checking it against `cfg.limits`.
pub fn analyse(clip: &Clip, cfg: &ResequenceConfig, progress: &Progress) -> Result<Analysis, VideoError> {
    cfg.limits.check_clip(clip)?;
    if clip.len() < 2 {
        return Err(VideoError::Invalid(format!(
            "{}: a clip needs at least 2 frames to resequence, it has {}",
            clip.source,
            clip.len()
        )));
    }
    let mut stages = Vec::new();
    let cancel = &cfg.cancel;
    cancel.check()?;
    let t = Instant::now();
    let gray = clip.gray_downscaled(cfg.flow_side);
    let motion = analyse_clip(&gray, &cfg.flow);
    cancel.check()?;
    stages.push(("optical flow, tendency, LMS (Eq. 9-11)".to_string(), t.elapsed().as_secs_f64()));

    let t = Instant::now();
    let metric = embeddings_cached_with(&cfg.cache_dir, &clip.frames, &cfg.rsf, &cfg.train, progress, cancel)?;
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
    let direction = judge_directed(&motion.lms, &shot);
    let directed = direction.iter().map(|d| d.0).collect();
    // Appearance distances for matched transitions and the step cap (issue 41): Euclidean distance
    // of 32-pixel thumbnails, proportional to their RMS difference (M_D's D, Eq. 21).
    let appearance = pixel_graph(&clip.frames, 32).dist;
    let info = MotionInfo {
        tendency: motion.tendency.clone(),
        lms: motion.lms.clone(),
        shot,
        directed,
        appearance,
        fps: clip.fps as f32,
    };
    cancel.check()?;
    Ok(Analysis {
        motion,
        info,
        graph,
        embedder: metric.embedder,
        direction,
        stages,
        metric_note,
        cancel: cancel.clone(),
        pmsm_memo: Default::default(),
    })
}

/// PMSM (Eq. 13–15): the motion distance of c → k is the latent distance of their pseudo-images.
pub struct Pmsm<'a> {
    pub backward: &'a [Flow],
    pub embedder: &'a Embedder,
    /// Distances computed before (by this or an earlier walk on the same analysis).
    pub memo: Option<&'a PmsmMemo>,
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
        if let Some(v) = self.memo.and_then(|m| m.floors.lock().unwrap_or_else(|p| p.into_inner()).get(&c).copied()) {
            return v;
        }
        let fc = &self.backward[c];
        let a1 = rotate_flow(fc, std::f32::consts::FRAC_PI_2);
        let a2 = rotate_flow(fc, -std::f32::consts::FRAC_PI_2);
        let v = self.pair_distances(fc, &[&a1, &a2], self.min_count(c)).into_iter().fold(f32::INFINITY, f32::min);
        if let Some(m) = self.memo {
            m.floors.lock().unwrap_or_else(|p| p.into_inner()).insert(c, v);
        }
        v
    }

    fn distances(&self, c: usize, ks: &[usize]) -> Vec<f32> {
        if ks.is_empty() {
            return Vec::new();
        }
        let Some(memo) = self.memo else {
            let fks: Vec<&Flow> = ks.iter().map(|&k| &self.backward[k]).collect();
            return self.pair_distances(&self.backward[c], &fks, self.min_count(c));
        };
        let mut out: Vec<Option<f32>> = {
            let pairs = memo.pairs.lock().unwrap_or_else(|p| p.into_inner());
            ks.iter().map(|&k| pairs.get(&(c, k)).copied()).collect()
        };
        let missing: Vec<usize> = ks.iter().zip(&out).filter(|(_, v)| v.is_none()).map(|(&k, _)| k).collect();
        if !missing.is_empty() {
            let fks: Vec<&Flow> = missing.iter().map(|&k| &self.backward[k]).collect();
            let d = self.pair_distances(&self.backward[c], &fks, self.min_count(c));
            let mut pairs = memo.pairs.lock().unwrap_or_else(|p| p.into_inner());
            for (&k, &v) in missing.iter().zip(&d) {
                pairs.insert((c, k), v);
            }
            let mut fresh = d.into_iter();
            for v in out.iter_mut().filter(|v| v.is_none()) {
                *v = fresh.next();
            }
        }
        out.into_iter().map(|v| v.unwrap_or(f32::NAN)).collect()
    }
}

/// `count` distinct new orders from `start` (SDPF on the analysed clip), and the walk's wall time.
/// The request is checked against `limits` first (a zero length or count is refused).
pub fn resequence(
    analysis: &Analysis,
    start: usize,
    params: &SdpfParams,
    count: usize,
    limits: &VideoLimits,
) -> Result<(Vec<SdpfPath>, f64), VideoError> {
    resequence_with(analysis, start, params, count, limits, &analysis.cancel)
}

/// [`resequence`] under another token than the analysis's (a later request on an analysis kept
/// open, as the studio's and [`ResequenceJob`](crate::job::ResequenceJob)'s are).
pub fn resequence_with(
    analysis: &Analysis,
    start: usize,
    params: &SdpfParams,
    count: usize,
    limits: &VideoLimits,
    cancel: &Cancel,
) -> Result<(Vec<SdpfPath>, f64), VideoError> {
    limits.check_request(params.length, analysis.graph.n, count)?;
    let t = Instant::now();
    let pmsm =
        Pmsm { backward: &analysis.motion.backward, embedder: &analysis.embedder, memo: Some(&analysis.pmsm_memo) };
    let paths = several_with(&analysis.graph, &analysis.info, &pmsm, start, params, count, cancel)?;
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
pub(crate) mod tests {
    use super::*;
    use crate::frames::{procedural_clip, ProceduralKind};
    use crate::sdpf::{overlap_delta_o, stability_md};
    use crate::VideoError;

    /// A small, quick analysis for tests (here and the jobs'), its metric cached in `dir`.
    pub(crate) fn quick_config(dir: &std::path::Path) -> ResequenceConfig {
        ResequenceConfig {
            flow_side: 48,
            rsf: RsfConfig::tiny(),
            train: TrainOptions { steps: 20, ..TrainOptions::default() },
            cache_dir: dir.to_path_buf(),
            ..ResequenceConfig::default()
        }
    }

    #[test]
    fn a_resolution_limit_reads_as_pixels_and_says_what_is_wrong() {
        assert_eq!(VideoLimits::parse_pixels("1280x720"), Ok(921_600));
        assert_eq!(VideoLimits::parse_pixels(" 2 X 3 "), Ok(6));
        assert!(VideoLimits::parse_pixels("1280").unwrap_err().contains("expected WIDTHxHEIGHT"));
        assert!(VideoLimits::parse_pixels("ax720").unwrap_err().contains("width \"a\""));
        assert!(VideoLimits::parse_pixels("0x720").unwrap_err().contains("allows no frame"));
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
        let (paths, _) = resequence(&a, 4, &params, 2, &VideoLimits::default()).unwrap();
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
        assert_eq!(resequence(&b, 4, &params, 2, &VideoLimits::default()).unwrap().0[0].frames, *order);
        let r = reorder(&clip, order);
        assert_eq!(r.frames[1], clip.frames[order[1]]);
    }

    #[test]
    fn the_pmsm_cache_makes_later_walks_ask_less_and_changes_no_order() {
        let dir = tempfile::tempdir().unwrap();
        let clip = procedural_clip(ProceduralKind::Pendulum, 24, 64, 48, 3);
        let cfg = quick_config(dir.path());
        let limits = VideoLimits::default();
        let walk = |a: &Analysis, start, seed| {
            resequence(a, start, &SdpfParams { seed, ..SdpfParams::default() }, 1, &limits).unwrap().0[0].frames.clone()
        };
        // Each order from a fresh analysis (empty cache) …
        let fresh: Vec<Vec<usize>> = [(4, 5), (9, 1), (0, 8)]
            .iter()
            .map(|&(start, seed)| walk(&analyse(&clip, &cfg, &Progress::hidden()).unwrap(), start, seed))
            .collect();
        // … equals the same order from one analysis whose cache earlier walks filled.
        let shared = analyse(&clip, &cfg, &Progress::hidden()).unwrap();
        assert!(shared.pmsm_memo.is_empty());
        let first = walk(&shared, 4, 5);
        let cached = shared.pmsm_memo.len();
        assert!(cached > 0);
        assert_eq!(first, fresh[0]);
        assert_eq!(walk(&shared, 9, 1), fresh[1]);
        assert_eq!(walk(&shared, 0, 8), fresh[2]);
        assert_eq!(walk(&shared, 4, 5), fresh[0], "a repeat needs no new pair");
        assert!(shared.pmsm_memo.len() >= cached);
        // A clone starts empty: it may get another embedder.
        assert!(shared.clone().pmsm_memo.is_empty());
    }

    /// Every step of `order` but loop backs and cuts (the jumps an editor makes at a dead end, marked
    /// as such; on this tiny clip the cut detector can split the drift into shots), as (from, to).
    fn steps_but_loops(path: &SdpfPath) -> Vec<(usize, usize)> {
        let jumps = [path.loop_positions(), path.cut_positions(), path.transition_positions()].concat();
        // After a loop back the loop repeats: its steps and its seam (the loop back) are already counted.
        let fresh = path.transitions.len().min(path.len() - 1);
        (1..=fresh).filter(|i| !jumps.contains(i)).map(|i| (path.frames[i - 1], path.frames[i])).collect()
    }

    #[test]
    fn a_block_moving_right_has_no_backward_step() {
        // The block moves right at constant speed: frame k shows it left of frame c exactly when k < c.
        let dir = tempfile::tempdir().unwrap();
        let clip = procedural_clip(ProceduralKind::Drift, 24, 64, 48, 3);
        let a = analyse(&clip, &quick_config(dir.path()), &Progress::hidden()).unwrap();
        assert_eq!(a.direction.len(), 1);
        assert!(a.direction[0].0, "a steady drift is directed motion: {:?}", a.direction);
        let limits = VideoLimits::default();
        let mut left_without_cr = 0;
        for start in [0, 5, 11] {
            for seed in 0..3 {
                let p = SdpfParams { seed, ..SdpfParams::default() };
                let path = &resequence(&a, start, &p, 1, &limits).unwrap().0[0];
                assert_eq!(path.len(), 24, "the source's length: {:?}", path.frames);
                // No step goes left but the marked loop backs and cuts.
                let left: Vec<(usize, usize)> = steps_but_loops(path).into_iter().filter(|(c, k)| k < c).collect();
                assert!(left.is_empty(), "start {start}, seed {seed}: steps left {left:?} in {:?}", path.frames);
                assert_eq!(crate::sdpf::backward_steps(&path.frames, 3), 0);
                let off = SdpfParams { use_cr: false, ..p };
                let path = &resequence(&a, start, &off, 1, &limits).unwrap().0[0];
                left_without_cr += steps_but_loops(path).iter().filter(|(c, k)| k < c).count();
            }
        }
        assert!(left_without_cr > 0, "without C_r some steps go left (what the test guards against)");
    }

    #[test]
    fn a_pendulum_loops_long_through_matching_earlier_frames_never_backwards() {
        // Four swings of a pendulum (period 22–34 frames): an order twice the source's length must go
        // back, and does so by matched transitions into earlier swings, opening loops of at least a
        // second (25 frames), never stepping to one of the 3 previous frames.
        use crate::sdpf::{distinct_fraction, short_cycle_repeats, StepKind};
        let dir = tempfile::tempdir().unwrap();
        let clip = procedural_clip(ProceduralKind::Pendulum, 100, 96, 64, 3);
        let a = analyse(&clip, &quick_config(dir.path()), &Progress::hidden()).unwrap();
        for (start, seed) in [(0, 1), (37, 2), (90, 3)] {
            let p = SdpfParams { seed, length: Some(200), ..SdpfParams::default() };
            let path = &resequence(&a, start, &p, 1, &VideoLimits::default()).unwrap().0[0];
            let o = &path.frames;
            assert_eq!(o.len(), 200);
            assert_eq!(crate::sdpf::backward_steps(o, 3), 0, "{o:?}");
            assert!(short_cycle_repeats(o, 25) <= 2, "a loop under a second repeats: {o:?}");
            assert!(distinct_fraction(o, 100) >= 0.6, "{o:?}");
            let back: Vec<(usize, usize, f32, usize)> = path
                .transitions
                .iter()
                .filter_map(|t| match (t.chosen, t.kind) {
                    (Some(k), StepKind::Transition { cost, loop_frames }) if k < t.from => {
                        Some((t.from, k, cost, loop_frames))
                    }
                    _ => None,
                })
                .collect();
            assert!(!back.is_empty(), "start {start}: no transition back in {o:?}");
            for &(from, to, cost, loop_frames) in &back {
                assert!(from - to > 3 && loop_frames == from - to + 1);
                assert!(cost <= p.match_threshold * p.match_relax, "{from} -> {to}: cost {cost}");
            }
            // A matched transition plays about like a source step: at most twice the source's
            // largest step.
            let rms = |x: usize, y: usize| crate::sdpf::frame_rms(&clip.frames[x], &clip.frames[y], x, y).unwrap();
            let largest = (1..100).map(|i| rms(i - 1, i)).fold(0.0, f64::max);
            for &(from, to, cost, _) in back.iter().filter(|b| b.2 <= p.match_threshold) {
                assert!(rms(from, to) <= 2.0 * largest, "{from} -> {to} (cost {cost}): {} vs {largest}", rms(from, to));
            }
            assert!(
                back.iter().any(|b| b.3 >= 25),
                "start {start}: no loop of a second or more through a matched transition: {back:?}"
            );
        }
    }

    #[test]
    fn three_shots_cut_no_more_than_the_source_plus_dead_ends() {
        use crate::frames::multi_shot_clip;
        use crate::sdpf::{distinct_fraction, shot_changes};
        let dir = tempfile::tempdir().unwrap();
        let kinds = [ProceduralKind::Pendulum, ProceduralKind::Walker, ProceduralKind::Drift];
        let clip = multi_shot_clip(&kinds, 30, 96, 64, 5);
        let a = analyse(&clip, &quick_config(dir.path()), &Progress::hidden()).unwrap();
        let shots: Vec<usize> = (0..90).map(|i| a.info.shot_of(i)).collect();
        assert_eq!(a.info.shots(), 3, "{shots:?}");
        for (start, seed) in [(0, 1), (40, 2), (75, 3)] {
            let p = SdpfParams { seed, ..SdpfParams::default() };
            let path = &resequence(&a, start, &p, 1, &VideoLimits::default()).unwrap().0[0];
            let o = &path.frames;
            // A cut only where the walk could reach no unshown frame of its shot: a dead end.
            let changes = shot_changes(o, &shots);
            assert_eq!(changes, path.cut_positions().len(), "every change of shot is a marked cut: {o:?}");
            assert!(changes <= 2 + 1, "start {start}: {changes} cuts for 2 shot changes: {o:?}");
            assert!(distinct_fraction(o, 90) >= 0.6, "{o:?}");
            assert_eq!(crate::sdpf::backward_steps(o, 3), 0, "{o:?}");
        }
    }

    #[test]
    fn a_run_of_the_source_length_crosses_the_cut() {
        // Two shots of the drifting block, on two different backgrounds: a hard cut at frame 12.
        let dir = tempfile::tempdir().unwrap();
        let (one, two) = (
            procedural_clip(ProceduralKind::Drift, 12, 64, 48, 3),
            procedural_clip(ProceduralKind::Drift, 12, 64, 48, 9),
        );
        let clip = Clip { frames: [one.frames, two.frames].concat(), fps: one.fps, source: "two shots".into() };
        let a = analyse(&clip, &quick_config(dir.path()), &Progress::hidden()).unwrap();
        assert_eq!(a.info.shot_of(11), 0);
        assert_eq!(a.info.shot_of(12), 1, "the cut is detected");
        for seed in 0..3 {
            let path = &resequence(&a, 2, &SdpfParams { seed, ..SdpfParams::default() }, 1, &VideoLimits::default())
                .unwrap()
                .0[0];
            assert_eq!(path.len(), 24, "{:?}", path.frames);
            assert!(path.frames.iter().any(|&f| f >= 12), "never left the first shot: {:?}", path.frames);
            let cuts = path.cut_positions();
            assert!(!cuts.is_empty(), "{:?}", path.frames);
            assert!(cuts.iter().all(|&c| a.info.shot_of(path.frames[c]) != a.info.shot_of(path.frames[c - 1])));
        }
        // The paper's early stop stays in the first shot.
        let early = SdpfParams { stop_early: true, ..SdpfParams::default() };
        let path = &resequence(&a, 2, &early, 1, &VideoLimits::default()).unwrap().0[0];
        assert!(path.frames.iter().all(|&f| f < 12), "{:?}", path.frames);
    }

    #[test]
    fn limits_are_checked_before_the_work_and_name_their_field() {
        let dir = tempfile::tempdir().unwrap();
        let clip = procedural_clip(ProceduralKind::Drift, 12, 64, 48, 3);
        let mut cfg = quick_config(dir.path());
        cfg.limits.max_frames = 10;
        let e = analyse(&clip, &cfg, &Progress::hidden()).err().unwrap_or_else(|| panic!("too many frames"));
        assert!(matches!(&e, VideoError::Limit(l) if l.field == "max_frames"), "{e}");
        assert!(e.to_string().contains("12 frames, more than the limit of 10 frames (max_frames)"), "{e}");
        cfg.limits = VideoLimits { max_pixels: 64 * 47, ..VideoLimits::default() };
        let e = analyse(&clip, &cfg, &Progress::hidden()).err().unwrap_or_else(|| panic!("too many pixels"));
        assert!(e.to_string().contains("64x48") && e.to_string().contains("max_pixels"), "{e}");
        let l = VideoLimits { max_length: 100, max_count: 3, ..VideoLimits::default() };
        assert!(l.check_request(Some(0), 12, 1).unwrap_err().to_string().contains("0 frames"));
        assert!(l.check_request(None, 12, 0).unwrap_err().to_string().contains("0 sequences"));
        assert!(l.check_request(Some(101), 12, 1).unwrap_err().to_string().contains("max_length"));
        assert!(l.check_request(None, 101, 1).unwrap_err().to_string().contains("101 frames"));
        assert!(l.check_request(None, 12, 4).unwrap_err().to_string().contains("max_count"));
        assert!(l.check_request(Some(100), 12, 3).is_ok());
    }

    #[test]
    fn a_cancelled_token_stops_the_analysis_and_the_walks() {
        let dir = tempfile::tempdir().unwrap();
        let clip = procedural_clip(ProceduralKind::Drift, 12, 64, 48, 3);
        let mut cfg = quick_config(dir.path());
        cfg.cancel = Cancel::new();
        cfg.cancel.cancel();
        let e = analyse(&clip, &cfg, &Progress::hidden()).err().unwrap_or_else(|| panic!("cancelled"));
        assert!(matches!(e, VideoError::Cancelled(_)), "{e}");
        // A deadline already past: the same, reported as the time limit.
        cfg.cancel = Cancel::with_time_limit(std::time::Duration::ZERO);
        let e = analyse(&clip, &cfg, &Progress::hidden()).err().unwrap_or_else(|| panic!("time limit"));
        assert!(e.to_string().contains("time limit"), "{e}");
        // Cancelled after the analysis: the walk stops before its first step.
        cfg.cancel = Cancel::new();
        let a = analyse(&clip, &cfg, &Progress::hidden()).unwrap();
        cfg.cancel.cancel();
        let e = resequence(&a, 0, &SdpfParams::default(), 1, &VideoLimits::default())
            .err()
            .unwrap_or_else(|| panic!("cancelled walk"));
        assert!(matches!(e, VideoError::Cancelled(_)), "{e}");
    }

    #[test]
    fn pipeline_refuses_a_one_frame_clip() {
        let dir = tempfile::tempdir().unwrap();
        let clip = procedural_clip(ProceduralKind::Pendulum, 1, 32, 32, 1);
        let e =
            analyse(&clip, &quick_config(dir.path()), &Progress::hidden()).err().unwrap_or_else(|| panic!("an error"));
        assert!(e.to_string().contains("at least 2 frames"), "{e}");
    }
}
