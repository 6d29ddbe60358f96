//! Matched transitions (issue 41, beyond the paper), after Schödl et al. 2000, "Video Textures"
//! (§3.1–3.2): a jump `c → j` plays well when the frames around `j − 1` look like those around `c`,
//! for then `j` follows `c` as `c + 1` would. Comparing a short window of frames in order, not one
//! pair, "preserves the dynamics": a pendulum passing the same place swinging the other way
//! matches in one frame but not over the window, so the match holds content *and* motion direction.
//!
//! - **Cost.** `D'(c, j) = Σ_{k=−m}^{m} w_k D(c + k, j − 1 + k) / Σ w_k` over the `k` where both
//!   frames lie in the shot (binomial weights, `m` = [`SdpfParams::match_window`] = 2: five frame
//!   pairs), with `D` the appearance distance ([`MotionInfo::appearance`], 32-pixel thumbnails),
//!   divided by the shot's median source step `σ` (the distance between adjacent frames of the
//!   shot). So a cost of 1 is as far as one source step; the next frame `c + 1` costs 0.
//! - **Accepted** when the cost is at most θ = [`SdpfParams::match_threshold`] (1.0); where no
//!   such way leads to an unvisited frame, up to [`SdpfParams::match_relax`] × θ.
//! - **C_r keeps its meaning.** `j` is never one of the `reverse_window` frames before `c` (nor `c`
//!   itself): that would replay the source backwards. A jump further back is a transition, not a
//!   reverse: from `j` the source plays forwards again, as the window match says it should. With
//!   C_d on, when `c` and `j − 1` are both LMS frames (Eq. 11) their tendencies (Eq. 10) must lie
//!   within ξ of each other too.
//! - **Long loops** (Schödl's §3.4 picks sets of transitions that maximise loop length at an
//!   acceptable cost): once every frame the walk can reach is shown, it plays on to the shot's last
//!   frame and jumps back by the accepted transition that opens the longest loop; a loop shorter than
//!   [`SdpfParams::min_loop_s`] is taken only when the shot is shorter.

use std::collections::VecDeque;

use super::types::{MotionInfo, SdpfParams, StepKind};
use crate::motion::angle_between;

/// Binomial weights `C(2m, m + k)` for `k = −m..=m`.
fn weights(m: usize) -> Vec<f64> {
    let mut w = vec![1.0f64];
    for _ in 0..2 * m {
        let mut next = vec![1.0; w.len() + 1];
        for i in 1..w.len() {
            next[i] = w[i - 1] + w[i];
        }
        w = next;
    }
    w
}

/// Median of the finite values (NaN when none).
fn median(mut v: Vec<f32>) -> f32 {
    v.retain(|x| x.is_finite());
    if v.is_empty() {
        return f32::NAN;
    }
    v.sort_by(f32::total_cmp);
    v[v.len() / 2]
}

/// Every matched transition of a clip, with the shots' source steps.
#[derive(Debug, Clone)]
pub struct Transitions {
    pub n: usize,
    /// `cost[c · n + j]`: the cost of `c → j` in units of the shot's source step; +∞ where `c → j`
    /// is no transition (another shot, `c + 1` itself, a replay backwards, a direction that differs).
    cost: Vec<f32>,
    /// Per shot: its median source step `σ` in appearance distance.
    pub step: Vec<f32>,
    /// Per frame: the transitions with a cost up to `relax × θ`, cheapest first.
    near: Vec<Vec<(usize, f32)>>,
    /// θ and `relax × θ`.
    threshold: f32,
    relaxed: f32,
    min_loop: usize,
}

impl Transitions {
    /// The transitions of a clip of `n` frames whose appearance distances are `dist` (`n × n`).
    pub fn new(dist: &[f32], n: usize, info: &MotionInfo, p: &SdpfParams) -> Transitions {
        let shot = |f: usize| info.shot_of(f);
        let d = |a: usize, b: usize| dist.get(a * n + b).copied().unwrap_or(f32::NAN);
        let all_steps: Vec<f32> = (1..n).filter(|&i| shot(i) == shot(i - 1)).map(|i| d(i - 1, i)).collect();
        let fallback = median(all_steps).max(f32::MIN_POSITIVE);
        let step: Vec<f32> = (0..info.shots())
            .map(|s| {
                let v: Vec<f32> = (1..n).filter(|&i| shot(i) == s && shot(i - 1) == s).map(|i| d(i - 1, i)).collect();
                let m = median(v);
                if m.is_finite() && m > 0.0 {
                    m
                } else if fallback.is_finite() {
                    fallback
                } else {
                    1.0
                }
            })
            .collect();
        let m = p.match_window as isize;
        let w = weights(p.match_window);
        let mut cost = vec![f32::INFINITY; n * n];
        for c in 0..n {
            let s = shot(c);
            let in_shot = |f: isize| f >= 0 && (f as usize) < n && shot(f as usize) == s;
            for j in 1..n {
                if shot(j) != s || shot(j - 1) != s || j == c + 1 || j == c {
                    continue;
                }
                if j < c && c - j <= p.reverse_window {
                    continue;
                }
                if p.use_cd && info.is_lms(c) && info.is_lms(j - 1) {
                    let (Some(tc), Some(tj)) = (info.tendency_of(c), info.tendency_of(j - 1)) else { continue };
                    if angle_between(tc, tj) > p.xi {
                        continue;
                    }
                }
                let (mut sum, mut wsum, mut pairs) = (0.0f64, 0.0f64, 0usize);
                for k in -m..=m {
                    let (a, b) = (c as isize + k, j as isize - 1 + k);
                    if in_shot(a) && in_shot(b) {
                        let v = d(a as usize, b as usize);
                        if v.is_finite() {
                            sum += w[(k + m) as usize] * v as f64;
                            wsum += w[(k + m) as usize];
                            pairs += 1;
                        }
                    }
                }
                // The frame pair itself and at least one neighbour: one pair says nothing of direction.
                if pairs >= 2.min(2 * p.match_window + 1) && wsum > 0.0 {
                    cost[c * n + j] = (sum / wsum) as f32 / step[s];
                }
            }
        }
        let threshold = p.match_threshold;
        let relaxed = p.match_threshold * p.match_relax.max(1.0);
        let near = (0..n)
            .map(|c| {
                let mut v: Vec<(usize, f32)> =
                    (0..n).map(|j| (j, cost[c * n + j])).filter(|&(_, x)| x <= relaxed).collect();
                v.sort_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)));
                v
            })
            .collect();
        Transitions { n, cost, step, near, threshold, relaxed, min_loop: info.min_loop_frames(p.min_loop_s) }
    }

    /// The cost of `c → j` (θ's unit), +∞ where it is no transition.
    pub fn cost(&self, c: usize, j: usize) -> f32 {
        self.cost.get(c * self.n + j).copied().unwrap_or(f32::INFINITY)
    }

    /// The accepted transitions from `c` (cost ≤ θ), cheapest first.
    pub fn accepted(&self, c: usize) -> impl Iterator<Item = (usize, f32)> + '_ {
        self.near[c].iter().copied().filter(move |&(_, x)| x <= self.threshold)
    }

    /// The shortest way from `c` to a frame not yet shown, by next source frames and transitions
    /// of cost ≤ θ (else ≤ `relax × θ`): its steps in order, each a [`StepKind::Replay`] or a
    /// [`StepKind::Transition`]. Breadth first, next frames before transitions and cheaper
    /// transitions first, so among equally short ways the smoothest is kept. `None`: every frame of
    /// the shot that such steps reach is shown.
    pub fn route(&self, c: usize, visited: &[bool], info: &MotionInfo) -> Option<Vec<(usize, StepKind)>> {
        self.route_under(c, visited, info, self.threshold).or_else(|| self.route_under(c, visited, info, self.relaxed))
    }

    fn route_under(&self, c: usize, visited: &[bool], info: &MotionInfo, limit: f32) -> Option<Vec<(usize, StepKind)>> {
        let n = self.n;
        let mut parent: Vec<Option<(usize, StepKind)>> = vec![None; n];
        let mut seen = vec![false; n];
        seen[c] = true;
        let mut queue = VecDeque::from([c]);
        while let Some(f) = queue.pop_front() {
            let next = (f + 1 < n && info.shot_of(f + 1) == info.shot_of(f)).then_some((f + 1, StepKind::Replay));
            let jumps = self.near[f]
                .iter()
                .filter(|&&(_, x)| x <= limit)
                .map(|&(j, x)| (j, StepKind::Transition { cost: x, loop_frames: if j <= f { f - j + 1 } else { 0 } }));
            for (g, kind) in next.into_iter().chain(jumps) {
                if seen[g] {
                    continue;
                }
                seen[g] = true;
                parent[g] = Some((f, kind));
                if !visited[g] {
                    let mut steps = vec![(g, kind)];
                    let mut at = f;
                    while at != c {
                        let (p, k) = parent[at]?;
                        steps.push((at, k));
                        at = p;
                    }
                    steps.reverse();
                    return Some(steps);
                }
                queue.push_back(g);
            }
        }
        None
    }

    /// A dead end with frames of the shot still unshown but no way to them under `relax × θ`: the
    /// jump an editor would make inside the shot (a jump cut, marked as a cut), to the unshown frame
    /// `k` that best follows `c` (the transition cost where it is one, else the appearance distance
    /// `look(c, k)` in source steps), never to one of the `reverse_window` frames before `c`.
    /// Only a frame followed by at least `run` unshown frames is a target: the walk asks with
    /// `run` = 4 first, since a jump cut costs several source steps (3–5 on the corpus), too much
    /// for a hole of a frame or two that a draw of Eq. 20 skipped (the walk then plays on, cuts to
    /// another shot or loops), and with 0 only when nothing else is left. The first frame of a
    /// stretch of unshown frames ([`stretch_head`]) comes first.
    ///
    /// Entering a stretch at its first frame plays it whole: entered in the middle, its first part
    /// is left for another jump cut later, and the walk goes back through the shot in short blocks
    /// (measured on `bbb_png_seq` from frame 18: 23 → 13, 17 → 8, 12 → 0, three jump cuts and
    /// M_D 1.26× the source's, where 23 → 0 plays 0–17 whole; on a held-out clip of four shots,
    /// up to 20 jump cuts in 5-frame blocks going backwards).
    pub fn jump_in_shot(
        &self,
        c: usize,
        visited: &[bool],
        info: &MotionInfo,
        reverse_window: usize,
        run: usize,
        look: impl Fn(usize, usize) -> f32,
    ) -> Option<(usize, f32)> {
        let shot = info.shot_of(c);
        let sigma = self.step.get(shot).copied().unwrap_or(1.0);
        let fresh_after =
            |k: usize| (k + 1..self.n.min(k + 1 + run)).take_while(|&j| !visited[j] && info.shot_of(j) == shot).count();
        let cands: Vec<(usize, f32, usize, bool)> = (0..self.n)
            .filter(|&k| !visited[k] && k != c && info.shot_of(k) == shot && !(k < c && c - k <= reverse_window))
            .map(|k| {
                let x = self.cost(c, k);
                (k, if x.is_finite() { x } else { look(c, k) / sigma }, fresh_after(k), stretch_head(k, visited, info))
            })
            .filter(|t| t.1.is_finite())
            .collect();
        let best = |min_run: usize, heads: bool| {
            cands
                .iter()
                .filter(|t| t.2 >= min_run && (t.3 || !heads))
                .min_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)))
                .copied()
        };
        best(run, true).or_else(|| best(run, false)).map(|(k, x, ..)| (k, x))
    }

    /// Once every frame the walk can reach is shown: the next source frame while there is one in the
    /// shot; at the shot's last frame, the transition back that opens the longest loop among those
    /// of cost ≤ θ and at least [`SdpfParams::min_loop_s`] long (its length discounted by up to half
    /// for its cost: `L · (1 − cost / 2θ)`); else the cheapest loop at least that
    /// long; else (a shot shorter than that) the cheapest transition. `None`: no transition at all.
    pub fn loop_step(&self, c: usize, info: &MotionInfo) -> Option<(usize, StepKind)> {
        if c + 1 < self.n && info.shot_of(c + 1) == info.shot_of(c) {
            return Some((c + 1, StepKind::Replay));
        }
        let all: Vec<(usize, f32, usize)> = (0..self.n)
            .map(|j| (j, self.cost(c, j)))
            .filter(|&(j, x)| x.is_finite() && j <= c)
            .map(|(j, x)| (j, x, c - j + 1))
            .collect();
        // A shot shorter than the shortest loop can loop over all of itself at most.
        let shot_len = (0..self.n).filter(|&f| info.shot_of(f) == info.shot_of(c)).count();
        let min_loop = self.min_loop.min(shot_len.saturating_sub(1)).max(2);
        let long = |&&(_, _, l): &&(usize, f32, usize)| l >= min_loop;
        // Length discounted by cost: a loop at θ counts half its length, so a perfect match a
        // frame shorter beats a loop one source step off.
        let score = |t: &(usize, f32, usize)| t.2 as f32 * (1.0 - 0.5 * t.1 / self.threshold.max(f32::MIN_POSITIVE));
        let longest_accepted = all
            .iter()
            .filter(|t| t.1 <= self.threshold)
            .filter(long)
            .max_by(|a, b| score(a).total_cmp(&score(b)).then(b.0.cmp(&a.0)));
        let cheapest = |pick: &dyn Fn(&&(usize, f32, usize)) -> bool| {
            all.iter().filter(pick).min_by(|a, b| a.1.total_cmp(&b.1).then(b.2.cmp(&a.2))).copied()
        };
        let (j, x, l) = longest_accepted.copied().or_else(|| cheapest(&long)).or_else(|| cheapest(&|_| true))?;
        Some((j, StepKind::Transition { cost: x, loop_frames: l }))
    }
}

/// Whether `k` is the first frame of a stretch of unshown frames of its shot: `k` is unshown and
/// the frame before it is shown, in another shot, or absent.
pub fn stretch_head(k: usize, visited: &[bool], info: &MotionInfo) -> bool {
    !visited[k] && (k == 0 || visited[k - 1] || info.shot_of(k - 1) != info.shot_of(k))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn binomial_weights() {
        assert_eq!(weights(0), vec![1.0]);
        assert_eq!(weights(2), vec![1.0, 4.0, 6.0, 4.0, 1.0]);
    }

    /// A clip of `n` frames whose appearance repeats with `period` frames: frame f looks like
    /// phase f mod period (distance = circular phase difference).
    fn periodic(n: usize, period: usize) -> Vec<f32> {
        let mut d = vec![0.0; n * n];
        for a in 0..n {
            for b in 0..n {
                let x = (a % period).abs_diff(b % period);
                d[a * n + b] = x.min(period - x) as f32;
            }
        }
        d
    }

    #[test]
    fn a_periodic_clip_has_transitions_back_one_period_and_none_backwards() {
        let (n, period) = (40, 8);
        let t = Transitions::new(&periodic(n, period), n, &MotionInfo::none(), &SdpfParams::default());
        assert_eq!(t.step, vec![1.0]);
        // From 30, frame 23 follows as 31 would (23 − 1 = 22 ≡ 30 mod 8): cost 0.
        assert_eq!(t.cost(30, 23), 0.0);
        assert_eq!(t.cost(30, 15), 0.0);
        // Never one of the three frames before, nor the next frame, nor itself.
        for j in [27, 28, 29, 30, 31] {
            assert!(t.cost(30, j).is_infinite(), "30 → {j}");
        }
        // A frame one step off in phase costs one source step.
        assert_eq!(t.cost(30, 24), 1.0);
        // Once all is shown, at the last frame the longest accepted loop opens: back to frame 8,
        // whose predecessor 7 ≡ 39 mod 8 (32 frames, more than a second at 25 fps).
        let (j, kind) = t.loop_step(n - 1, &MotionInfo::none()).unwrap();
        assert_eq!(j, 8, "{kind:?}");
        assert!(matches!(kind, StepKind::Transition { loop_frames: 32, .. }), "{kind:?}");
        // Before the last frame it plays on.
        assert_eq!(t.loop_step(20, &MotionInfo::none()), Some((21, StepKind::Replay)));
    }

    /// A clip on a line: D(a, b) = |a − b| (a drift: no earlier frame matches a later one).
    fn line(n: usize) -> Vec<f32> {
        (0..n * n).map(|i| (i / n).abs_diff(i % n) as f32).collect()
    }

    #[test]
    fn a_jump_cut_enters_an_unshown_stretch_at_its_first_frame_and_skips_small_holes() {
        let n = 24;
        let t = Transitions::new(&line(n), n, &MotionInfo::none(), &SdpfParams::default());
        let look = |a: usize, b: usize| a.abs_diff(b) as f32;
        // 12..=23 shown, from 23: frame 19 of the stretch 0..=11 would be cheaper than 0, but entered
        // there the walk must come back for 0..=6 by a second jump cut; 0 plays it whole.
        let visited: Vec<bool> = (0..n).map(|f| f >= 12).collect();
        assert_eq!(t.jump_in_shot(23, &visited, &MotionInfo::none(), 3, 4, look).map(|j| j.0), Some(0));
        // Only a hole of two frames (3, 4) left: no jump cut for it, unless nothing else is left.
        let visited: Vec<bool> = (0..n).map(|f| !(3..5).contains(&f)).collect();
        assert_eq!(t.jump_in_shot(23, &visited, &MotionInfo::none(), 3, 4, look), None);
        assert_eq!(t.jump_in_shot(23, &visited, &MotionInfo::none(), 3, 0, look).map(|j| j.0), Some(3));
        assert!(stretch_head(3, &visited, &MotionInfo::none()) && !stretch_head(4, &visited, &MotionInfo::none()));
    }

    #[test]
    fn the_route_to_unshown_frames_replays_forwards_or_jumps_by_a_match() {
        let (n, period) = (24, 8);
        let t = Transitions::new(&periodic(n, period), n, &MotionInfo::none(), &SdpfParams::default());
        // Shown: 10..=23; from 23 the nearest unshown frame is reached by a matched jump back.
        let visited: Vec<bool> = (0..n).map(|f| f >= 10).collect();
        let steps = t.route(23, &visited, &MotionInfo::none()).unwrap();
        assert_eq!(steps.len(), 1, "{steps:?}");
        let (j, kind) = steps[0];
        assert!(j < 10 && (j + 8 * 3 - 1) % 8 == 23 % 8, "{j}");
        assert!(matches!(kind, StepKind::Transition { .. }));
        // Everything shown: no route.
        assert!(t.route(23, &[true; 24], &MotionInfo::none()).is_none());
    }
}
