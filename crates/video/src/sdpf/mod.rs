//! Single-source Distillation Path-Finding (§5, Algorithm 1): from a start frame the user picks,
//! walk the complete graph of frame distances (Eq. 7), at each step keeping the unvisited frames
//! close in content (S1, Eq. 8), then those whose motion continues the current one (C_d, Eq. 12;
//! C_t, Eq. 15–17), and draw the next frame from a softmax of their motion distances (Eq. 20);
//! stop early when nothing is left (S2 empty).
//!
//! Readings of the paper (where its text is ambiguous):
//! - η (Eq. 8) is the mean of the N(N−1) off-diagonal edge weights.
//! - Eq. 16 reads "δ ≤ ω" with δ = −distance (Eq. 15), which would keep the candidates whose motion
//!   differs *more* than average; the text ("to control the motion in adjacent frames not to change
//!   frequently or drastically") and Eq. 20 (which favours large δ, i.e. small distances) say the
//!   opposite, so C_t keeps the candidates whose motion distance is at most the mean over S1
//!   (n1 ≥ 2), or at most the distance between the current flow and its ±90° rotations (n1 < 2).
//! - S2 = the candidates passing both C_d and C_t (Eq. 18–19, "+" read as "and").
//!
//! Beyond the paper: shots (no jump across a scene cut unless asked), a target length, loop closure
//! back to the start frame, several distinct sequences from one graph, and a record of every
//! transition for `--explain`.

mod metrics;

pub use metrics::{detect_shots, overlap_delta_o, stability_md};

use std::fmt::Write as _;

use inbetween_core::seed::{derive, rng};
use rand::Rng;

use crate::metric::Graph;
use crate::motion::angle_between;
use crate::VideoError;

/// The motion distance of a transition, Eq. 15 without its sign: ‖R(X_c^p) − R(X_k^p)‖.
pub trait MotionDistance {
    /// Motion distance of the transition c → k (small: k's motion continues c's).
    fn distance(&self, c: usize, k: usize) -> f32;
    /// The floor of Eq. 17 when S1 holds fewer than two frames: the smaller distance between c's
    /// flow and its ±90° rotations.
    fn rotated_floor(&self, c: usize) -> f32;
    /// Distances of c → each of `ks` (override to batch the work).
    fn distances(&self, c: usize, ks: &[usize]) -> Vec<f32> {
        ks.iter().map(|&k| self.distance(c, k)).collect()
    }
}

/// What the walk needs to know about each frame's motion and shot.
#[derive(Clone, Debug, Default)]
pub struct MotionInfo {
    /// Motion tendency (Eq. 10), radians; `None` where nothing moves enough.
    pub tendency: Vec<Option<f32>>,
    /// Whether the frame belongs to a linear motion segment (Eq. 11).
    pub lms: Vec<bool>,
    /// Shot index of each frame (scene cuts split shots; all zero when there is none).
    pub shot: Vec<usize>,
}

/// Settings of a walk.
#[derive(Clone, Debug)]
pub struct SdpfParams {
    /// ξ of Eq. 12 (paper: π/3).
    pub xi: f32,
    /// Directional distillation C_d (off: the "w/o C_d" ablation).
    pub use_cd: bool,
    /// Coherent distillation C_t (off: the "w/o C_t" ablation).
    pub use_ct: bool,
    /// Stop after this many frames (start included); `None`: until S2 is empty.
    pub length: Option<usize>,
    /// Require the last frame to be able to transition back to the start.
    pub loop_close: bool,
    /// Allow transitions between shots.
    pub allow_cuts: bool,
    /// Seeds the softmax draws.
    pub seed: u64,
    /// Walks tried (with derived seeds) to satisfy the loop closure or to find distinct sequences.
    pub attempts: usize,
}

impl Default for SdpfParams {
    fn default() -> Self {
        SdpfParams {
            xi: std::f32::consts::FRAC_PI_3,
            use_cd: true,
            use_ct: true,
            length: None,
            loop_close: false,
            allow_cuts: false,
            seed: 1,
            attempts: 32,
        }
    }
}

/// One step of the walk, as `--explain` prints it.
#[derive(Clone, Debug, PartialEq)]
pub struct Transition {
    pub from: usize,
    /// Content-aware candidates (Eq. 8).
    pub s1: Vec<usize>,
    /// Removed by the directional distillation (Eq. 12).
    pub removed_cd: Vec<usize>,
    /// Removed by the coherent distillation (Eq. 16), with the threshold ω used.
    pub removed_ct: Vec<usize>,
    pub omega: Option<f32>,
    /// The remaining candidates S2: (frame, motion distance, probability of Eq. 20).
    pub choices: Vec<(usize, f32, f32)>,
    /// The frame drawn; `None` when S2 was empty (early stop).
    pub chosen: Option<usize>,
}

/// Why a walk ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StopReason {
    /// The target length was reached.
    Length,
    /// No candidate survived the distillation (the paper's early stop).
    NoCandidate,
}

/// A new frame order.
#[derive(Clone, Debug, PartialEq)]
pub struct SdpfPath {
    /// Source frame indices, the start first.
    pub frames: Vec<usize>,
    pub transitions: Vec<Transition>,
    pub stop: StopReason,
    /// Whether the last frame can transition back to the start (checked when asked for).
    pub closes_loop: bool,
    /// The seed of the walk that produced it.
    pub seed: u64,
}

/// η of Eq. 8: the mean off-diagonal edge weight.
pub fn eta(graph: &Graph) -> f32 {
    let n = graph.n;
    if n < 2 {
        return 0.0;
    }
    let sum: f64 = (0..n).flat_map(|i| (0..n).filter(move |&j| j != i).map(move |j| (i, j))).map(|(i, j)| f64::from(graph.get(i, j))).sum();
    (sum / (n * (n - 1)) as f64) as f32
}

fn check_inputs(graph: &Graph, motion: &MotionInfo, start: usize) -> Result<(), VideoError> {
    let n = graph.n;
    if n == 0 {
        return Err(VideoError::Invalid("the clip has no frames".into()));
    }
    if start >= n {
        return Err(VideoError::Invalid(format!("start frame {start} is outside the clip (frames 0..{})", n - 1)));
    }
    if motion.tendency.len() != n || motion.lms.len() != n || motion.shot.len() != n {
        return Err(VideoError::Invalid(format!(
            "motion information covers {}/{}/{} frames, the graph {n}",
            motion.tendency.len(),
            motion.lms.len(),
            motion.shot.len()
        )));
    }
    Ok(())
}

/// S1 (Eq. 8): frames not yet visited, in the current shot unless cuts are allowed, with e_ck < η.
fn content_candidates(graph: &Graph, motion: &MotionInfo, visited: &[bool], c: usize, eta: f32, allow_cuts: bool) -> Vec<usize> {
    (0..graph.n)
        .filter(|&k| !visited[k] && k != c)
        .filter(|&k| allow_cuts || motion.shot[k] == motion.shot[c])
        .filter(|&k| graph.get(c, k) < eta)
        .collect()
}

/// C_d (Eq. 12): when c and some candidates are LMS frames, keep the LMS candidates whose tendency is
/// within ξ of c's; otherwise keep everything. Returns (kept, removed).
fn directional(motion: &MotionInfo, c: usize, s1: &[usize], xi: f32) -> (Vec<usize>, Vec<usize>) {
    let applies = motion.lms[c] && s1.iter().any(|&k| motion.lms[k]);
    if !applies {
        return (s1.to_vec(), Vec::new());
    }
    s1.iter().partition(|&&k| {
        motion.lms[k]
            && match (motion.tendency[c], motion.tendency[k]) {
                (Some(a), Some(b)) => angle_between(a, b) <= xi,
                _ => false,
            }
    })
}

/// C_t (Eq. 16–17): keep candidates whose motion distance is at most ω. Returns (kept with
/// distances, removed, ω).
fn coherent(md: &dyn MotionDistance, c: usize, cands: &[usize], n1: usize) -> (Vec<(usize, f32)>, Vec<usize>, f32) {
    let d = md.distances(c, cands);
    let omega = if n1 >= 2 && !d.is_empty() { d.iter().sum::<f32>() / d.len() as f32 } else { md.rotated_floor(c) };
    let mut kept = Vec::new();
    let mut removed = Vec::new();
    for (&k, &dk) in cands.iter().zip(&d) {
        if dk <= omega {
            kept.push((k, dk));
        } else {
            removed.push(k);
        }
    }
    (kept, removed, omega)
}

/// Eq. 20: softmax of δ = −distance (shifted by the largest δ for stability).
fn softmax_of_distances(d: &[f32]) -> Vec<f32> {
    let best = d.iter().copied().fold(f32::INFINITY, f32::min);
    let e: Vec<f32> = d.iter().map(|x| (-(x - best)).exp()).collect();
    let s: f32 = e.iter().sum();
    e.iter().map(|x| x / s).collect()
}

fn draw(probs: &[f32], u: f32) -> usize {
    let mut acc = 0.0;
    for (i, p) in probs.iter().enumerate() {
        acc += p;
        if u < acc {
            return i;
        }
    }
    probs.len() - 1
}

/// What every step of a walk reads.
struct Walk<'a> {
    graph: &'a Graph,
    motion: &'a MotionInfo,
    md: &'a dyn MotionDistance,
    eta: f32,
    p: &'a SdpfParams,
}

/// One transition from `c` (Algorithm 1, lines 7–22), drawing with the uniform number `u`.
fn step(w: &Walk, visited: &[bool], c: usize, u: f32) -> Transition {
    let Walk { graph, motion, md, eta, p } = *w;
    let s1 = content_candidates(graph, motion, visited, c, eta, p.allow_cuts);
    let (after_cd, removed_cd) = if p.use_cd { directional(motion, c, &s1, p.xi) } else { (s1.clone(), Vec::new()) };
    let (kept, removed_ct, omega) = if p.use_ct && !after_cd.is_empty() {
        let (k, r, o) = coherent(md, c, &after_cd, s1.len());
        (k, r, Some(o))
    } else {
        let d = md.distances(c, &after_cd);
        (after_cd.iter().copied().zip(d).collect(), Vec::new(), None)
    };
    let dists: Vec<f32> = kept.iter().map(|(_, d)| *d).collect();
    let probs = softmax_of_distances(&dists);
    let chosen = (!kept.is_empty()).then(|| kept[draw(&probs, u)].0);
    let choices = kept.iter().zip(&probs).map(|((k, d), p)| (*k, *d, *p)).collect();
    Transition { from: c, s1, removed_cd, removed_ct, omega, choices, chosen }
}

/// Whether the walk can close: a step from `last` with only the start unvisited would keep it.
fn can_close(w: &Walk, last: usize, start: usize) -> bool {
    if last == start {
        return true;
    }
    let mut visited = vec![true; w.graph.n];
    visited[start] = false;
    let t = step(w, &visited, last, 0.0);
    t.chosen == Some(start)
}

/// One walk of Algorithm 1 from `start` with the seed `seed`.
fn walk(graph: &Graph, motion: &MotionInfo, md: &dyn MotionDistance, start: usize, p: &SdpfParams, seed: u64) -> SdpfPath {
    let w = Walk { graph, motion, md, eta: eta(graph), p };
    let mut r = rng(seed);
    let mut visited = vec![false; graph.n];
    visited[start] = true;
    let mut frames = vec![start];
    let mut transitions = Vec::new();
    let target = p.length.unwrap_or(usize::MAX).max(1);
    let mut stop = StopReason::Length;
    let mut c = start;
    while frames.len() < target {
        let t = step(&w, &visited, c, r.random::<f32>());
        let next = t.chosen;
        transitions.push(t);
        match next {
            Some(k) => {
                visited[k] = true;
                frames.push(k);
                c = k;
            }
            None => {
                stop = StopReason::NoCandidate;
                break;
            }
        }
    }
    let closes_loop = p.loop_close && can_close(&w, c, start);
    SdpfPath { frames, transitions, stop, closes_loop, seed }
}

/// SDPF from `start` (Algorithm 1). With `loop_close`, up to `attempts` seeded walks are tried and
/// the first whose last frame can return to the start is kept (a walk ending early is cut back to
/// its latest frame that can, when that leaves at least two frames); otherwise the first walk.
pub fn sdpf(graph: &Graph, motion: &MotionInfo, md: &dyn MotionDistance, start: usize, p: &SdpfParams) -> Result<SdpfPath, VideoError> {
    check_inputs(graph, motion, start)?;
    let first = walk(graph, motion, md, start, p, p.seed);
    if !p.loop_close || first.closes_loop {
        return Ok(first);
    }
    let ctx = Walk { graph, motion, md, eta: eta(graph), p };
    for a in 0..p.attempts.max(1) as u64 {
        let w = if a == 0 { first.clone() } else { walk(graph, motion, md, start, p, derive(p.seed, a)) };
        if w.closes_loop {
            return Ok(w);
        }
        if let Some(cut) = (1..w.frames.len()).rev().find(|&i| can_close(&ctx, w.frames[i], start)) {
            let mut w = w;
            w.frames.truncate(cut + 1);
            w.transitions.truncate(cut);
            w.closes_loop = true;
            return Ok(w);
        }
    }
    Ok(first)
}

/// Up to `count` distinct sequences from `start` (walks with derived seeds; duplicates are dropped).
pub fn several(graph: &Graph, motion: &MotionInfo, md: &dyn MotionDistance, start: usize, p: &SdpfParams, count: usize) -> Result<Vec<SdpfPath>, VideoError> {
    check_inputs(graph, motion, start)?;
    let mut out: Vec<SdpfPath> = Vec::new();
    let tries = (count * 8).max(p.attempts);
    for a in 0..tries as u64 {
        if out.len() >= count {
            break;
        }
        let q = SdpfParams { seed: if a == 0 { p.seed } else { derive(p.seed, 1000 + a) }, ..p.clone() };
        let path = sdpf(graph, motion, md, start, &q)?;
        if !out.iter().any(|o| o.frames == path.frames) {
            out.push(path);
        }
    }
    Ok(out)
}

/// A readable account of each transition (`--explain`).
pub fn explain(path: &SdpfPath) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "sequence of {} frames from frame {} (seed {}): {:?}", path.frames.len(), path.frames[0], path.seed, path.frames);
    for (i, t) in path.transitions.iter().enumerate() {
        let _ = writeln!(s, "step {}: from frame {}", i + 1, t.from);
        let _ = writeln!(s, "  S1 (content, Eq. 8): {:?}", t.s1);
        if !t.removed_cd.is_empty() {
            let _ = writeln!(s, "  removed by C_d (direction, Eq. 12): {:?}", t.removed_cd);
        }
        if let Some(o) = t.omega {
            let _ = writeln!(s, "  removed by C_t (motion distance > ω = {o:.4}, Eq. 16-17): {:?}", t.removed_ct);
        }
        let c: Vec<String> = t.choices.iter().map(|(k, d, p)| format!("{k} (d {d:.4}, p {p:.3})")).collect();
        let _ = writeln!(s, "  S2 with softmax probabilities (Eq. 20): {}", c.join(", "));
        match t.chosen {
            Some(k) => {
                let _ = writeln!(s, "  chose frame {k}");
            }
            None => {
                let _ = writeln!(s, "  no candidate left: early stop");
            }
        }
    }
    if path.closes_loop {
        let _ = writeln!(s, "the last frame can transition back to the start (loop closes)");
    }
    s
}

#[cfg(test)]
mod tests;
