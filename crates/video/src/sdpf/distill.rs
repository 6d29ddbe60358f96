//! One step of Algorithm 1: the content-aware layer (Eq. 8), the motion-aware layer (C_d Eq. 12,
//! C_t Eq. 15–17, S2 Eq. 18–19) and the softmax choice (Eq. 20).

use std::cell::RefCell;
use std::collections::HashMap;

use inbetween_core::cancel::Cancel;
use rand::Rng;

use super::texture::{stretch_head, Transitions};
use super::types::{Candidate, CdState, CrState, MotionDistance, MotionInfo, Omega, SdpfParams, StepKind, Transition};
use crate::metric::Graph;
use crate::motion::angle_between;

/// η of Eq. 8: the mean edge weight of the graph. The paper writes `Σ e_ij / N` and calls it "the
/// mean of the weights"; we average over the `N(N − 1)` off-diagonal edges (the diagonal is the
/// zero self-distance, not an edge), skipping non-finite weights. NaN when there is no such edge
/// (then no edge is below it and the walk stops at once).
pub fn eta(graph: &Graph) -> f32 {
    let n = graph.n;
    let (mut sum, mut count) = (0.0f64, 0usize);
    for i in 0..n {
        for j in (0..n).filter(|&j| j != i) {
            let e = graph.dist[i * n + j];
            if e.is_finite() {
                sum += e as f64;
                count += 1;
            }
        }
    }
    if count == 0 {
        f32::NAN
    } else {
        (sum / count as f64) as f32
    }
}

/// What one step needs, fixed for a whole SDPF call (and shared by its attempts). Motion distances
/// are memoised per pair: retries and loop-closure checks ask for the same pairs again, and each
/// may cost a network call (PMSM embeds pseudo-images).
pub(crate) struct Ctx<'a> {
    pub graph: &'a Graph,
    pub motion: &'a MotionInfo,
    pub md: &'a dyn MotionDistance,
    pub p: &'a SdpfParams,
    pub eta: f32,
    /// Checked before every step of a walk.
    pub cancel: Cancel,
    memo: RefCell<HashMap<(usize, usize), f32>>,
    floors: RefCell<HashMap<usize, f32>>,
    /// Matched transitions (issue 41), with [`SdpfParams::transitions`] and without the early stop.
    pub texture: Option<Transitions>,
}

impl<'a> Ctx<'a> {
    pub fn new(graph: &'a Graph, motion: &'a MotionInfo, md: &'a dyn MotionDistance, p: &'a SdpfParams) -> Self {
        Ctx {
            graph,
            motion,
            md,
            p,
            eta: eta(graph),
            cancel: Cancel::new(),
            memo: RefCell::default(),
            floors: RefCell::default(),
            texture: (p.transitions && !p.stop_early).then(|| {
                let dist = if motion.appearance.len() == graph.n * graph.n { &motion.appearance } else { &graph.dist };
                Transitions::new(dist, graph.n, motion, p)
            }),
        }
    }

    /// The appearance distance of frames `a` and `b` ([`MotionInfo::appearance`], else the edge weight).
    pub fn look(&self, a: usize, b: usize) -> f32 {
        let n = self.graph.n;
        if self.motion.appearance.len() == n * n {
            self.motion.appearance[a * n + b]
        } else {
            self.edge(a, b)
        }
    }

    /// The step cap ([`SdpfParams::step_cap`], with matched transitions on): removes from S2 the
    /// frames farther in appearance from `t.from` than κ times the shot's median source step, or
    /// κ times the current frame's own step to its successor when that is larger, and renormalises
    /// the probabilities of Eq. 20 over the rest.
    pub fn cap(&self, t: &mut Transition) {
        let Some(tex) = &self.texture else { return };
        let c = t.from;
        let shot = self.motion.shot_of(c);
        let own = if c + 1 < self.graph.n && self.motion.shot_of(c + 1) == shot { self.look(c, c + 1) } else { 0.0 };
        let limit = self.p.step_cap * tex.step.get(shot).copied().unwrap_or(f32::INFINITY).max(own);
        type Probs = Vec<(usize, f32)>;
        let (kept, removed): (Probs, Probs) = t.probs.iter().copied().partition(|&(k, _)| self.look(c, k) <= limit);
        if removed.is_empty() {
            return;
        }
        t.removed_cap = removed.into_iter().map(|(k, _)| k).collect();
        let total: f32 = kept.iter().map(|&(_, p)| p).sum();
        t.probs = if total > 0.0 {
            kept.into_iter().map(|(k, p)| (k, p / total)).collect()
        } else {
            let u = 1.0 / kept.len().max(1) as f32;
            kept.into_iter().map(|(k, _)| (k, u)).collect()
        };
    }

    /// Lines 7–21 of Algorithm 1 from frame `from`; `chosen` is left `None` for the caller's draw.
    ///
    /// Order of the layers: S1 (Eq. 8, minus other shots), then C_r (beyond the paper) and C_d
    /// (Eq. 12), which need no motion distance, then C_t (Eq. 16–17) on what those two left. So
    /// PMSM (two network passes per candidate) runs only for frames that can still be chosen, and
    /// ω is their mean motion distance (the paper's Eq. 17 averages over all of S1). The candidates
    /// C_r or C_d removed keep a NaN motion distance.
    pub fn step(&self, from: usize, visited: &[bool]) -> Transition {
        let (s1, removed_cut) = self.content(from, visited);
        let (cr, removed_cr) = self.reverse(from, &s1);
        let (cd, removed_cd) = self.directional(from, &s1);
        let live: Vec<usize> =
            s1.iter().copied().filter(|k| !removed_cr.contains(k) && !removed_cd.contains(k)).collect();
        let live_motion = self.motion_distances(from, &live);
        let candidates: Vec<Candidate> = s1
            .iter()
            .map(|&k| Candidate {
                frame: k,
                edge: self.edge(from, k),
                motion: live.iter().position(|&l| l == k).map_or(f32::NAN, |i| live_motion[i]),
                tendency: self.motion.tendency_of(k),
                lms: self.motion.is_lms(k),
            })
            .collect();
        let judged: Vec<Candidate> = candidates.iter().copied().filter(|c| live.contains(&c.frame)).collect();
        let (omega, removed_ct) = self.coherent(from, &judged);
        let s2: Vec<&Candidate> = judged.iter().filter(|c| !removed_ct.contains(&c.frame)).collect();
        let scale = self.softmax_scale(&judged);
        let edge_scale = finite_mean(judged.iter().map(|c| c.edge));
        let dists: Vec<f32> = s2
            .iter()
            .map(|c| {
                let content = if self.p.content_weight > 0.0 && edge_scale > 0.0 {
                    self.p.content_weight * c.edge / edge_scale
                } else {
                    0.0
                };
                c.motion / scale + content
            })
            .collect();
        let probs = s2.iter().map(|c| c.frame).zip(softmax(&dists, self.p.temperature)).collect();
        Transition {
            from,
            chosen: None,
            s1,
            candidates,
            removed_cut,
            cr,
            removed_cr,
            cd,
            removed_cd,
            omega,
            removed_ct,
            removed_cap: Vec::new(),
            probs,
            kind: StepKind::Distilled,
        }
    }

    /// C_r (beyond the paper): the S1 frames a step to which plays the motion backwards. C_d
    /// (Eq. 12) compares the tendency of frame k's *own* motion with T_c, so it cannot see the
    /// direction of the step c → k: the source's previous frame c − 1 moves just like c and
    /// passes, and its motion (C_t) and content distances are as small as those of c + 1. Measured
    /// on `bigbuckbunny.mp4` from frame 100, Eq. 20 gave 99 and 101 probabilities 0.49 and 0.39,
    /// and 53 of 69 steps went to one of the three previous frames (36 to c − 1). A step c → k plays backwards
    /// when ([`Ctx::plays_backwards`]):
    /// - it replays the source's previous frames: k = c − j with 1 ≤ j ≤ `reverse_window`; or
    /// - k lies in c's shot and is closer in content (edge weight) to c's past, c − 1, than to
    ///   its future, c + 1: whatever k shows, it shows what came before c; or
    /// - c is its shot's last frame and k an earlier frame of the shot (all of them its past).
    ///
    /// Skipped in shots judged undirected when `allow_reverse` is on.
    fn reverse(&self, from: usize, s1: &[usize]) -> (CrState, Vec<usize>) {
        if !self.p.use_cr {
            return (CrState::Disabled, Vec::new());
        }
        if self.p.allow_reverse && !self.motion.directed_at(from) {
            return (CrState::AllowedUndirected, Vec::new());
        }
        (CrState::Active, s1.iter().copied().filter(|&k| self.plays_backwards(from, k)).collect())
    }

    /// The test of [`Ctx::reverse`] for one step `c → k` (regardless of `use_cr`).
    pub fn plays_backwards(&self, c: usize, k: usize) -> bool {
        if k < c && c - k <= self.p.reverse_window {
            return true;
        }
        let shot = self.motion.shot_of(c);
        let n = self.graph.n;
        let in_shot = |f: usize| self.motion.shot_of(f) == shot;
        if !in_shot(k) {
            return false;
        }
        // At the shot's last frame every other frame of the shot is its past: a step back into
        // it replays the motion from there, which the walk makes only as a marked loop back.
        if c + 1 >= n || !in_shot(c + 1) {
            return k < c;
        }
        if c == 0 || !in_shot(c - 1) {
            return false;
        }
        self.edge(k, c - 1) < self.edge(k, c + 1)
    }

    /// Whether C_r (as configured) forbids the step `c → k`.
    pub fn forbids(&self, c: usize, k: usize) -> bool {
        self.p.use_cr && (!self.p.allow_reverse || self.motion.directed_at(c)) && self.plays_backwards(c, k)
    }

    /// S2 was empty: the cut an editor would make, to the unvisited frame of another shot closest
    /// in content to `from` (C_r's replay test still applies), preferring a frame the walk can go
    /// on from: one followed by [`MIN_LOOP`] unvisited frames of its shot, else by one; a cut into
    /// a shot's last frames has no way forward and cuts straight back (issue 26's ping-pong).
    /// `None` when no other shot has unvisited frames.
    pub fn cut(&self, from: usize, visited: &[bool]) -> Option<(usize, f32)> {
        let shot = self.motion.shot_of(from);
        let n = self.graph.n;
        let candidates: Vec<(usize, f32)> = (0..n)
            .filter(|&k| !visited[k] && self.motion.shot_of(k) != shot && !self.forbids(from, k))
            .map(|k| (k, self.edge(from, k)))
            .filter(|(_, e)| !e.is_nan())
            .collect();
        // Unvisited frames after `k` in its shot, up to MIN_LOOP.
        let run = |k: usize| {
            (k + 1..n.min(k + 1 + MIN_LOOP))
                .take_while(|&j| !visited[j] && self.motion.shot_of(j) == self.motion.shot_of(k))
                .count()
        };
        let closest = |min_run: usize, heads: bool| {
            candidates
                .iter()
                .copied()
                .filter(|&(k, _)| run(k) >= min_run && (!heads || stretch_head(k, visited, self.motion)))
                .min_by(|a, b| a.1.total_cmp(&b.1))
        };
        closest(MIN_LOOP, false).or_else(|| closest(1, false)).or_else(|| closest(0, false))
    }

    /// The cut of the walk with matched transitions (issue 41): to the frame of another shot closest
    /// in content among those followed by at least `min_run` unvisited frames of their shot, the
    /// first frame of a stretch not yet shown ([`stretch_head`]) first, so that the stretch plays
    /// whole. The walk asks with `min_run` = [`MIN_LOOP`] first: a cut into a hole of a frame or
    /// two that a draw of Eq. 20 skipped flashes the other shot and cuts straight back; with 0 only
    /// when nothing else is left (see [`Transitions::jump_in_shot`]).
    pub fn cut_into_stretch(&self, from: usize, visited: &[bool], min_run: usize) -> Option<(usize, f32)> {
        let shot = self.motion.shot_of(from);
        let n = self.graph.n;
        let run = |k: usize| {
            (k + 1..n.min(k + 1 + min_run))
                .take_while(|&j| !visited[j] && self.motion.shot_of(j) == self.motion.shot_of(k))
                .count()
        };
        let candidates: Vec<(usize, f32, bool)> = (0..n)
            .filter(|&k| !visited[k] && self.motion.shot_of(k) != shot && !self.forbids(from, k) && run(k) >= min_run)
            .map(|k| (k, self.edge(from, k), stretch_head(k, visited, self.motion)))
            .filter(|(_, e, _)| !e.is_nan())
            .collect();
        let closest = |heads: bool| {
            candidates.iter().filter(|c| c.2 || !heads).min_by(|a, b| a.1.total_cmp(&b.1)).map(|&(k, e, _)| (k, e))
        };
        closest(true).or_else(|| closest(false))
    }

    /// S2 was empty and no cut is left: the position in `path` to loop back to, the one whose
    /// frame is closest in content to `from` among those C_r's replay test allows, leaving a loop
    /// of at least [`MIN_LOOP`] frames.
    pub fn loop_back(&self, path: &[usize]) -> Option<(usize, f32)> {
        let from = *path.last()?;
        let last = path.len().checked_sub(MIN_LOOP)?;
        (0..=last)
            .filter(|&j| {
                let k = path[j];
                k != from && !(self.p.use_cr && k < from && from - k <= self.p.reverse_window)
            })
            .map(|j| (j, self.edge(from, path[j])))
            .filter(|(_, e)| !e.is_nan())
            .min_by(|a, b| a.1.total_cmp(&b.1))
    }

    /// What the motion distances are divided by before Eq. 20: their mean over S1 with
    /// `relative_temperature` (1 when that mean is not a positive number), else 1.
    fn softmax_scale(&self, cands: &[Candidate]) -> f32 {
        let scale = if self.p.relative_temperature { finite_mean(cands.iter().map(|c| c.motion)) } else { 1.0 };
        if scale.is_finite() && scale > 0.0 {
            scale
        } else {
            1.0
        }
    }

    /// Whether `to` survives Eq. 8, the shot rule and C_d from `from` — the checks that need no
    /// motion distance, so that hopeless loop closures cost nothing.
    pub fn passes_cheap_checks(&self, from: usize, to: usize, visited: &[bool]) -> bool {
        let (s1, _) = self.content(from, visited);
        s1.contains(&to) && !self.reverse(from, &s1).1.contains(&to) && !self.directional(from, &s1).1.contains(&to)
    }

    fn edge(&self, c: usize, k: usize) -> f32 {
        self.graph.dist[c * self.graph.n + k]
    }

    /// Eq. 8 (lines 7–11): unvisited frames with `e_ck < η`, strictly, as the paper writes. Those
    /// in another shot are split off unless `allow_cuts` (beyond the paper).
    fn content(&self, from: usize, visited: &[bool]) -> (Vec<usize>, Vec<usize>) {
        let under: Vec<usize> =
            (0..self.graph.n).filter(|&k| k != from && !visited[k] && self.edge(from, k) < self.eta).collect();
        if self.p.allow_cuts {
            return (under, Vec::new());
        }
        under.into_iter().partition(|&k| self.motion.shot_of(k) == self.motion.shot_of(from))
    }

    /// C_d of Eq. 12. It acts only when the current frame is an LMS frame with a known tendency and
    /// S1 holds an LMS frame; then it keeps the LMS candidates whose tendency lies within ξ of T_c
    /// (angles wrapped) and removes the rest, non-LMS candidates included: Fig. 13 reads "if S1
    /// has LMS-frames, they will be considered", and the non-LMS frames 152 and 135 "may cause
    /// artifacts". An LMS candidate with an unknown (or NaN) tendency cannot be checked and is removed.
    fn directional(&self, from: usize, s1: &[usize]) -> (CdState, Vec<usize>) {
        if !self.p.use_cd {
            return (CdState::Disabled, Vec::new());
        }
        let Some(tc) = self.motion.tendency_of(from).filter(|_| self.motion.is_lms(from)) else {
            return (CdState::NotLms, Vec::new());
        };
        if !s1.iter().any(|&k| self.motion.is_lms(k)) {
            return (CdState::NoLmsCandidate, Vec::new());
        }
        let keeps = |k: usize| {
            self.motion.is_lms(k) && self.motion.tendency_of(k).is_some_and(|tk| angle_between(tc, tk) <= self.p.xi)
        };
        (CdState::Active { tendency: tc, xi: self.p.xi }, s1.iter().copied().filter(|&k| !keeps(k)).collect())
    }

    /// C_t of Eq. 16–17, read with distances. The paper writes `δ ≤ ω` with `δ = −distance`
    /// (Eq. 15) and ω the mean δ over S1; taken literally that keeps the candidates whose motion
    /// changes *more* than average, against the text ("a smaller PMSM reveals a smooth
    /// transition"; C_t is "to control the motion in adjacent frames not to change frequently or
    /// drastically") and against Eq. 20, which favours large δ. We keep the smoother ones:
    /// `distance ≤ mean distance over S1` when n1 ≥ 2, else `distance ≤ rotated_floor(c)` (FC's
    /// distance to its ±π/2 rotations). The threshold is taken over all of S1, independent of C_d
    /// (Eq. 17 names S1 and n1). A candidate with a non-finite distance cannot be checked and is
    /// removed; non-finite distances are left out of the mean.
    fn coherent(&self, from: usize, cands: &[Candidate]) -> (Omega, Vec<usize>) {
        if !self.p.use_ct || cands.is_empty() {
            return (Omega::Off, Vec::new());
        }
        let (omega, w) = if cands.len() >= 2 {
            let w = finite_mean(cands.iter().map(|c| c.motion));
            (Omega::Mean(w), w)
        } else {
            let w = self.floor(from);
            (Omega::Rotated(w), w)
        };
        let removed = cands.iter().filter(|c| !(c.motion.is_finite() && c.motion <= w)).map(|c| c.frame).collect();
        (omega, removed)
    }

    /// Motion distances `from → k` for every `k` of `ks`, asking the [`MotionDistance`] (in one
    /// batch) only for the pairs not seen before.
    fn motion_distances(&self, from: usize, ks: &[usize]) -> Vec<f32> {
        let missing: Vec<usize> =
            ks.iter().copied().filter(|&k| !self.memo.borrow().contains_key(&(from, k))).collect();
        if !missing.is_empty() {
            let got = self.md.distances(from, &missing);
            let mut memo = self.memo.borrow_mut();
            for (i, &k) in missing.iter().enumerate() {
                memo.insert((from, k), got.get(i).copied().unwrap_or(f32::NAN));
            }
        }
        let memo = self.memo.borrow();
        ks.iter().map(|&k| memo[&(from, k)]).collect()
    }

    fn floor(&self, from: usize) -> f32 {
        *self.floors.borrow_mut().entry(from).or_insert_with(|| self.md.rotated_floor(from))
    }
}

/// The shortest loop [`Ctx::loop_back`] makes, in frames (a shorter one flickers).
pub const MIN_LOOP: usize = 4;

/// Mean of the finite values (NaN when there is none).
fn finite_mean(values: impl Iterator<Item = f32>) -> f32 {
    let (sum, count) = values.filter(|v| v.is_finite()).fold((0.0f64, 0usize), |(s, c), v| (s + v as f64, c + 1));
    if count == 0 {
        f32::NAN
    } else {
        (sum / count as f64) as f32
    }
}

/// Eq. 20 with δ_j = −distance_j: `Ω_j = exp(δ_j/τ) / Σ_i exp(δ_i/τ)`, computed with the largest δ
/// subtracted so that large distances cannot underflow every term. Non-finite distances get
/// probability 0 unless all are non-finite, in which case the choice is uniform.
pub fn softmax(distances: &[f32], temperature: f32) -> Vec<f32> {
    let best = distances.iter().copied().filter(|d| d.is_finite()).fold(f32::INFINITY, f32::min);
    if !best.is_finite() {
        return vec![1.0 / distances.len().max(1) as f32; distances.len()];
    }
    let w: Vec<f64> = distances
        .iter()
        .map(|&d| if d.is_finite() { (-((d - best) / temperature) as f64).exp() } else { 0.0 })
        .collect();
    let total: f64 = w.iter().sum();
    w.iter().map(|x| (x / total) as f32).collect()
}

/// Line 22 of Algorithm 1: one frame drawn from S2 with the probabilities of Eq. 20.
pub fn draw(probs: &[(usize, f32)], rng: &mut impl Rng) -> Option<usize> {
    let u: f32 = rng.random();
    let mut acc = 0.0;
    for &(frame, p) in probs {
        acc += p;
        if u < acc {
            return Some(frame);
        }
    }
    // Rounding left u above the total: the last frame with a non-zero probability.
    probs.iter().rev().find(|&&(_, p)| p > 0.0).or(probs.last()).map(|&(f, _)| f)
}
