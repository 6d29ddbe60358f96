//! Algorithm 1 as a walk, plus what the paper lacks: a target length, loop closure back to the
//! start frame, several distinct paths from one graph.

use inbetween_core::cancel::Cancel;
use inbetween_core::seed::{derive, rng};

use super::distill::{draw, Ctx, MIN_LOOP};
use super::types::{MotionDistance, MotionInfo, SdpfParams, SdpfPath, StepKind, StopReason};
use crate::metric::Graph;
use crate::VideoError;

/// Single-source Distillation Path-Finding (Algorithm 1) from `start`.
///
/// Each step builds S1 (Eq. 8, η = mean off-diagonal edge weight; frames of another shot left
/// out unless `allow_cuts`), distils it with C_d (Eq. 12) and C_t (Eq. 16–17) into S2 (Eq. 18–19)
/// and draws the next frame with the softmax of Eq. 20 from a seeded stream; C_r (beyond the paper)
/// first removes the steps that would play the motion backwards. No frame is visited twice before
/// a loop back. The walk ends at the target length (default: the source's frame count). Where S2
/// is empty it ends only with `stop_early` (the paper's early stop); otherwise it cuts to the shot
/// that best matches, or loops back (see [`SdpfParams::stop_early`]).
///
/// Goals beyond the paper are met by seeded retries: attempt 0 uses `seed` itself, attempt `a`
/// uses `derive(seed, a)`, up to `attempts` walks, stopping at the first that meets the goal.
/// - Target length without loop closure: the goal is `length` frames; failing that, the longest
///   walk (the earliest among equals) is kept.
/// - Loop closure: after each walk, its prefixes are scanned from the longest (at most `length`
///   frames) down to 3 frames; the first whose last frame has the start frame in its S2 — the
///   same constraints, with the start treated as unvisited and every other frame of the prefix
///   visited — is kept, and that closing step is recorded in [`SdpfPath::closing`]. The goal is a
///   closed loop (of exactly `length` frames when a target is set). Closed walks beat open ones,
///   then longer beats shorter. When no attempt closes, the best open walk is returned with
///   `closes_loop: false`.
///
/// Errors: an empty graph, a distance matrix of the wrong size, a start out of range, motion
/// vectors of the wrong length, or invalid parameters.
pub fn sdpf(
    graph: &Graph,
    motion: &MotionInfo,
    md: &dyn MotionDistance,
    start: usize,
    p: &SdpfParams,
) -> Result<SdpfPath, VideoError> {
    validate(graph, motion, start, p)?;
    best_walk(&Ctx::new(graph, motion, md, p), start, p.seed)
}

/// Several distinct paths from `start` (beyond the paper): path `i` is [`sdpf`] with a seed derived
/// from `p.seed` and `i` (path 0 uses `p.seed`, so it equals `sdpf(…, p)`); a path with the same
/// frames as one already kept is skipped. At most `4 · count + 8` seeds are tried, so a graph with
/// fewer distinct paths returns fewer than `count` (never none: `count = 0` is read as 1).
pub fn several(
    graph: &Graph,
    motion: &MotionInfo,
    md: &dyn MotionDistance,
    start: usize,
    p: &SdpfParams,
    count: usize,
) -> Result<Vec<SdpfPath>, VideoError> {
    several_with(graph, motion, md, start, p, count, &Cancel::new())
}

/// [`several`], stopping with [`VideoError::Cancelled`] once `cancel` is cancelled (checked before
/// every step of every walk).
pub fn several_with(
    graph: &Graph,
    motion: &MotionInfo,
    md: &dyn MotionDistance,
    start: usize,
    p: &SdpfParams,
    count: usize,
    cancel: &Cancel,
) -> Result<Vec<SdpfPath>, VideoError> {
    validate(graph, motion, start, p)?;
    let mut ctx = Ctx::new(graph, motion, md, p);
    ctx.cancel = cancel.clone();
    let count = count.max(1);
    let mut kept: Vec<SdpfPath> = Vec::new();
    for i in 0..(4 * count + 8) {
        if kept.len() == count {
            break;
        }
        let seed = if i == 0 { p.seed } else { derive(derive(p.seed, u64::MAX), i as u64) };
        let path = best_walk(&ctx, start, seed)?;
        if kept.iter().all(|k| k.frames != path.frames) {
            kept.push(path);
        }
    }
    Ok(kept)
}

fn validate(graph: &Graph, motion: &MotionInfo, start: usize, p: &SdpfParams) -> Result<(), VideoError> {
    if graph.n == 0 {
        return Err(VideoError::Invalid("SDPF: the graph has no frames".into()));
    }
    if graph.dist.len() != graph.n * graph.n {
        return Err(VideoError::Invalid(format!(
            "SDPF: the distance matrix has {} entries, expected {}×{}",
            graph.dist.len(),
            graph.n,
            graph.n
        )));
    }
    if start >= graph.n {
        return Err(VideoError::Invalid(format!(
            "SDPF: start frame {start} is out of range (the clip has {} frames, 0..{})",
            graph.n,
            graph.n - 1
        )));
    }
    motion.validate(graph.n)?;
    p.validate()
}

/// The seeded attempts of [`sdpf`], keeping the first that meets the goal, else the best.
fn best_walk(ctx: &Ctx, start: usize, seed: u64) -> Result<SdpfPath, VideoError> {
    let p = ctx.p;
    let mut best: Option<SdpfPath> = None;
    for attempt in 0..p.attempts.max(1) {
        let s = if attempt == 0 { seed } else { derive(seed, attempt as u64) };
        let mut path = walk(ctx, start, s, attempt)?;
        if p.loop_close {
            close_loop(ctx, &mut path);
        }
        let done = goal_met(p, ctx.graph.n, &path);
        if best.as_ref().is_none_or(|b| rank(&path) > rank(b)) {
            best = Some(path);
        }
        if done {
            break;
        }
    }
    match best {
        Some(b) => Ok(b),
        None => walk(ctx, start, seed, 0),
    }
}

/// One seeded walk of Algorithm 1 (lines 3–24, repeated until a stop). When S2 is empty the walk
/// stops only with `stop_early` (the paper); otherwise it cuts to the shot that best matches the
/// current frame ([`Ctx::cut`]) or, with no other shot left, loops back ([`Ctx::loop_back`]) and
/// repeats the loop up to the target length.
fn walk(ctx: &Ctx, start: usize, seed: u64, attempt: usize) -> Result<SdpfPath, VideoError> {
    if ctx.texture.is_some() {
        return texture_walk(ctx, start, seed, attempt);
    }
    let n = ctx.graph.n;
    let target = ctx.p.target_length(n);
    let mut rng = rng(seed);
    let mut visited = vec![false; n];
    visited[start] = true;
    let (mut frames, mut transitions) = (vec![start], Vec::new());
    let mut current = start;
    let stop = loop {
        if frames.len() >= target {
            break StopReason::TargetLength;
        }
        if ctx.p.stop_early && frames.len() == n {
            break StopReason::AllVisited;
        }
        ctx.cancel.check()?;
        let mut t = ctx.step(current, &visited);
        t.chosen = draw(&t.probs, &mut rng);
        if t.chosen.is_none() && !ctx.p.stop_early {
            if let Some((k, edge)) = ctx.cut(current, &visited) {
                t.chosen = Some(k);
                t.kind = StepKind::Cut { edge };
            } else if let Some((to, edge)) = ctx.loop_back(&frames) {
                t.chosen = Some(frames[to]);
                t.kind = StepKind::LoopBack { to, edge };
                transitions.push(t);
                let body = frames[to..].to_vec();
                while frames.len() < target {
                    let take = (target - frames.len()).min(body.len());
                    frames.extend_from_slice(&body[..take]);
                }
                break StopReason::TargetLength;
            }
        }
        let chosen = t.chosen;
        transitions.push(t);
        let Some(next) = chosen else {
            break if ctx.p.stop_early {
                StopReason::EarlyStop
            } else if frames.len() == n {
                StopReason::AllVisited
            } else {
                StopReason::DeadEnd
            };
        };
        visited[next] = true;
        frames.push(next);
        current = next;
    };
    Ok(SdpfPath { frames, transitions, stop, closes_loop: false, closing: None, eta: ctx.eta, seed, attempt })
}

/// The walk with matched transitions (issue 41; [`SdpfParams::transitions`], the default). Each
/// step draws from S2 under the step cap (Eq. 20, as [`walk`]); where nothing is left to draw:
/// 1. the shortest way within the shot to a frame not yet shown, by next source frames and matched
///    transitions ([`Transitions::route`](super::texture::Transitions::route)), followed step by
///    step unless a later draw finds a new frame first;
/// 2. else, with a stretch of at least [`MIN_LOOP`] + 1 frames of the shot still unshown, a jump cut
///    inside the shot ([`Transitions::jump_in_shot`](super::texture::Transitions::jump_in_shot)),
///    marked as a cut, to the first frame of such a stretch where it can;
/// 3. else a cut to the shot that best matches, into such a stretch ([`Ctx::cut_into_stretch`]);
/// 4. else on round the longest loop ([`Transitions::loop_step`](super::texture::Transitions::loop_step));
/// 5. else (no transition at all) a jump cut or a cut to any frame not yet shown.
fn texture_walk(ctx: &Ctx, start: usize, seed: u64, attempt: usize) -> Result<SdpfPath, VideoError> {
    let n = ctx.graph.n;
    let Some(tex) = &ctx.texture else { return Err(VideoError::Invalid("SDPF: no transitions".into())) };
    let target = ctx.p.target_length(n);
    let mut rng = rng(seed);
    let mut visited = vec![false; n];
    visited[start] = true;
    let (mut frames, mut transitions) = (vec![start], Vec::new());
    let mut current = start;
    // The rest of a route to unshown frames, next step last.
    let mut plan: Vec<(usize, StepKind)> = Vec::new();
    // How many frames were shown when a route last found nothing: until another is shown, none will.
    let mut shown = 1usize;
    let mut no_route_at: Option<usize> = None;
    let stop = loop {
        if frames.len() >= target {
            break StopReason::TargetLength;
        }
        ctx.cancel.check()?;
        let mut t = ctx.step(current, &visited);
        ctx.cap(&mut t);
        t.chosen = draw(&t.probs, &mut rng);
        if t.chosen.is_some() {
            plan.clear();
        } else {
            if plan.is_empty() && no_route_at != Some(shown) {
                match tex.route(current, &visited, ctx.motion) {
                    Some(mut steps) => {
                        steps.reverse();
                        plan = steps;
                    }
                    None => no_route_at = Some(shown),
                }
            }
            let look = |a: usize, b: usize| ctx.look(a, b);
            let jump_cut = |run: usize| {
                tex.jump_in_shot(current, &visited, ctx.motion, ctx.p.reverse_window, run, look)
                    .map(|(k, cost)| (k, StepKind::JumpCut { cost }))
            };
            let cut =
                |run: usize| ctx.cut_into_stretch(current, &visited, run).map(|(k, edge)| (k, StepKind::Cut { edge }));
            let way = plan
                .pop()
                .or_else(|| jump_cut(MIN_LOOP))
                .or_else(|| cut(MIN_LOOP))
                .or_else(|| tex.loop_step(current, ctx.motion))
                .or_else(|| jump_cut(0))
                .or_else(|| cut(0));
            if let Some((k, kind)) = way {
                t.chosen = Some(k);
                t.kind = kind;
            }
        }
        let chosen = t.chosen;
        transitions.push(t);
        let Some(next) = chosen else {
            break StopReason::DeadEnd;
        };
        shown += usize::from(!std::mem::replace(&mut visited[next], true));
        frames.push(next);
        current = next;
    };
    Ok(SdpfPath { frames, transitions, stop, closes_loop: false, closing: None, eta: ctx.eta, seed, attempt })
}

/// Cuts `path` at its longest prefix (≥ 3 frames, at most `length`) whose last frame can step
/// back to the start under the same constraints, recording that step.
fn close_loop(ctx: &Ctx, path: &mut SdpfPath) {
    let start = path.frames[0];
    // Only the part before any loop back, where no frame repeats.
    let mut seen = vec![false; ctx.graph.n];
    let fresh = path.frames.iter().take_while(|&&f| !std::mem::replace(&mut seen[f], true)).count();
    let longest = fresh.min(ctx.p.target_length(ctx.graph.n));
    let mut visited = vec![false; ctx.graph.n];
    path.frames[1..longest].iter().for_each(|&f| visited[f] = true);
    for last in (2..longest).rev() {
        let from = path.frames[last];
        if ctx.passes_cheap_checks(from, start, &visited) {
            let mut t = ctx.step(from, &visited);
            if t.probs.iter().any(|&(f, _)| f == start) {
                t.chosen = Some(start);
                path.frames.truncate(last + 1);
                path.transitions.truncate(last);
                path.stop = StopReason::LoopClosed;
                path.closes_loop = true;
                path.closing = Some(t);
                return;
            }
        }
        visited[from] = false;
    }
}

fn goal_met(p: &SdpfParams, n: usize, path: &SdpfPath) -> bool {
    let long_enough = match p.length {
        Some(l) => path.len() >= l,
        // The paper's walk ends where it ends; a loop is as long as it closes; otherwise the
        // source's length (missed only at a dead end).
        None => p.stop_early || p.loop_close || path.len() >= n,
    };
    if p.loop_close {
        path.closes_loop && long_enough
    } else {
        long_enough
    }
}

/// Closed loops first, then longer paths; a strict `>` keeps the earliest among equals.
fn rank(path: &SdpfPath) -> (bool, usize) {
    (path.closes_loop, path.len())
}
