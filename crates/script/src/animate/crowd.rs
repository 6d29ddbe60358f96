//! Several characters in one room (beyond the paper, which animates its characters one by one):
//! prioritised planning with a space-time reservation of every character's root.
//!
//! Every character is first built on its own timeline ([`super::character::build_character`]). Each
//! character's reservation is its root (x, z) at every frame, held at its last position after its
//! timeline ends, so standing, sitting and acting in place reserve space as much as walking.
//! [`separate`] then repairs the earliest frame where two roots come closer than
//! [`PASSING_DISTANCE`]: the later character first (then the earlier one) changes the walk whose
//! window holds that frame: it waits in place before walking (1/3 s steps, up to [`MAX_WAIT`]
//! frames), takes a detour around the others' standing spots (A* on its grid with those spots
//! blocked), or both, the earliest arrival that keeps the distance from the start of that wait
//! until its next walk starts (or, after its last walk, for good). The character is rebuilt with
//! that choice from the action that makes the changed walk on ([`super::character::rebuild`]: the
//! timeline before it is kept, so a repair costs the rest of the story, not all of it) and the next
//! conflict is repaired; each repair clears every frame up to the end of
//! its window, so the loop ends. A conflict no choice solves (a character standing where another
//! must go) stays, and a note gives the pair, the frame and the distance.

use super::character::{rebuild, CharacterInput, CharacterPlan};
use super::context::Ctx;
use super::routes::{route, WalkCache, WalkChoice};
use super::{Animation, PASSING_DISTANCE};
use crate::motion::rig::{Rig, FPS};
use crate::motion::WalkParams;

/// A route choice: None walks the A* route.
type Route = Option<Vec<[f32; 2]>>;

/// Longest wait before a walk that a repair tries, frames (6 s at 30 fps).
pub const MAX_WAIT: usize = 180;
/// Wait steps a repair tries, frames.
const WAIT_STEP: usize = 10;
/// Extra margin around another character's standing spot when searching a detour, metres (the
/// walk cuts corners of the grid route a little).
const DETOUR_MARGIN: f32 = 0.15;

/// The closest two characters' roots come over an animation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Clearance {
    /// Horizontal distance between the roots, metres.
    pub metres: f32,
    pub frame: usize,
    /// Indices into [`Animation::characters`].
    pub a: usize,
    pub b: usize,
}

/// A root trajectory at frame `f`, held at its ends.
fn at(traj: &[[f32; 2]], f: usize) -> [f32; 2] {
    traj[f.min(traj.len().saturating_sub(1))]
}

fn dist(a: [f32; 2], b: [f32; 2]) -> f32 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// Root (x, z) of every frame of a motion; an error names the joint missing when it is not on the
/// common rig.
pub fn root_track(m: &inbetween_core::clip::Clip) -> Result<Vec<[f32; 2]>, crate::ScriptError> {
    let rig = Rig::for_clip(m, "a root track")?;
    Ok(hip_track(m, rig.hips))
}

/// Joint `hips`' (x, z) at every frame of a clip.
fn hip_track(m: &inbetween_core::clip::Clip, hips: usize) -> Vec<[f32; 2]> {
    let mut p = inbetween_core::Pose::rest(m.skeleton());
    (0..m.num_frames())
        .map(|f| {
            m.pose_into(f, &mut p);
            let r = p.translations[hips];
            [r.x as f32, r.z as f32]
        })
        .collect()
}

/// The minimum distance between any two characters' roots over every frame of the animation
/// (a character holds its last position after its track ends); None with fewer than two (a
/// character not on the common rig has no root track and is left out).
pub fn min_clearance(anim: &Animation) -> Option<Clearance> {
    let trajs: Vec<Vec<[f32; 2]>> =
        anim.characters.iter().filter_map(|c| root_track(&c.clip).ok()).filter(|t| !t.is_empty()).collect();
    closest(&trajs, &[])
}

/// The closest pair over all frames, leaving out `(a, b, from, to)` frame ranges.
fn closest(trajs: &[Vec<[f32; 2]>], skip: &[(usize, usize, usize, usize)]) -> Option<Clearance> {
    let horizon = trajs.iter().map(Vec::len).max()?;
    let mut best: Option<Clearance> = None;
    for f in 0..horizon {
        for a in 0..trajs.len() {
            for b in a + 1..trajs.len() {
                if skip.iter().any(|&(x, y, s, e)| x == a && y == b && (s..e).contains(&f)) {
                    continue;
                }
                let d = dist(at(&trajs[a], f), at(&trajs[b], f));
                if best.is_none_or(|c| d < c.metres) {
                    best = Some(Clearance { metres: d, frame: f, a, b });
                }
            }
        }
    }
    best
}

/// The first frame (and pair) where two roots are closer than [`PASSING_DISTANCE`], outside the
/// `accepted` ranges.
fn first_conflict(trajs: &[&[[f32; 2]]], accepted: &[(usize, usize, usize, usize)]) -> Option<(usize, usize, usize)> {
    let horizon = trajs.iter().map(|t| t.len()).max()?;
    for f in 0..horizon {
        for a in 0..trajs.len() {
            for b in a + 1..trajs.len() {
                if dist(at(trajs[a], f), at(trajs[b], f)) < PASSING_DISTANCE
                    && !accepted.iter().any(|&(x, y, s, e)| x == a && y == b && (s..e).contains(&f))
                {
                    return Some((f, a, b));
                }
            }
        }
    }
    None
}

/// The end (exclusive) of the run of frames from `f` where `a` and `b` stay too close.
fn conflict_end(trajs: &[&[[f32; 2]]], a: usize, b: usize, f: usize) -> usize {
    let horizon = trajs.iter().map(|t| t.len()).max().unwrap_or(0);
    (f..horizon).find(|&t| dist(at(trajs[a], t), at(trajs[b], t)) >= PASSING_DISTANCE).unwrap_or(horizon.max(f + 1))
}

/// Repairs conflicts between the characters' reservations (see the module comment). `resolved`
/// marks characters built in this call; a character not resolved (kept from a previous run) is
/// changed only when the other one of a conflict cannot solve it, and is then marked resolved.
/// Returns notes on the conflicts left.
pub(crate) fn separate(
    ctx: &Ctx,
    names: &[String],
    plans: &mut [CharacterPlan],
    resolved: &mut [bool],
    builds: &mut [usize],
    cache: &mut WalkCache,
) -> Vec<String> {
    let n = plans.len();
    if n < 2 {
        return Vec::new();
    }
    let mut accepted: Vec<(usize, usize, usize, usize)> = Vec::new();
    let max_rounds = 8 * n + 4 * plans.iter().map(|p| p.walks.len()).sum::<usize>();
    let mut notes = Vec::new();
    for round in 0.. {
        let conflict = {
            let trajs: Vec<&[[f32; 2]]> = plans.iter().map(|p| p.traj.as_slice()).collect();
            first_conflict(&trajs, &accepted)
        };
        let Some((f, a, b)) = conflict else { break };
        if ctx.cancel.is_cancelled() {
            break;
        }
        if round >= max_rounds {
            notes.push(format!("characters: stopped repairing close passes after {max_rounds} changes"));
            break;
        }
        // The later character yields first; one kept from the previous run only when needed.
        let mut order = [b, a];
        order.sort_by_key(|&x| !resolved[x]);
        let fix = order.into_iter().find_map(|x| improve(ctx, plans, x, f, cache).map(|c| (x, c)));
        match fix {
            Some((x, choices)) => {
                let input = CharacterInput { name: names[x].clone(), choices, ..plans[x].input.clone() };
                // Only the walk choices change: the build resumes at the first changed walk.
                plans[x] = rebuild(ctx, &plans[x], input, cache);
                resolved[x] = true;
                builds[x] += 1;
                accepted.retain(|&(p, q, _, _)| p != x && q != x);
            }
            None => {
                let trajs: Vec<&[[f32; 2]]> = plans.iter().map(|p| p.traj.as_slice()).collect();
                accepted.push((a, b, f, conflict_end(&trajs, a, b, f)));
            }
        }
    }
    // What is left, one note per pair.
    let trajs: Vec<Vec<[f32; 2]>> = plans.iter().map(|p| p.traj.clone()).collect();
    for a in 0..n {
        for b in a + 1..n {
            let pair = [trajs[a].clone(), trajs[b].clone()];
            if let Some(c) = closest(&pair, &[]).filter(|c| c.metres < PASSING_DISTANCE) {
                notes.push(format!(
                    "{} and {} come {:.2} m close at frame {} ({:.1} s): no wait of up to {:.0} s or detour keeps them {PASSING_DISTANCE} m apart",
                    names[a],
                    names[b],
                    c.metres,
                    c.frame,
                    c.frame as f64 / FPS,
                    MAX_WAIT as f64 / FPS
                ));
            }
        }
    }
    notes
}

/// Root (x, z) per frame of a walk along `route`.
fn walk_roots(ctx: &Ctx, cache: &mut WalkCache, route: &[[f32; 2]], params: &WalkParams) -> Vec<[f32; 2]> {
    hip_track(&cache.walk(route, ctx.lib, params), ctx.rig.hips)
}

/// New walk choices for character `x` that clear its conflict at frame `f` (see the module
/// comment), or None when no wait up to [`MAX_WAIT`] and no detour does.
fn improve(ctx: &Ctx, plans: &[CharacterPlan], x: usize, f: usize, cache: &mut WalkCache) -> Option<Vec<WalkChoice>> {
    let p = &plans[x];
    // Standing where it started, before its first walk: only the other character can move.
    let w = p.walks.iter().rposition(|w| w.wait_start <= f)?;
    let info = &p.walks[w];
    let next = p.walks.get(w + 1).map(|n| n.wait_start);
    let dwell = &p.traj[info.end.min(p.traj.len())..next.unwrap_or(p.traj.len())];
    let others: Vec<&[[f32; 2]]> =
        plans.iter().enumerate().filter(|(i, _)| *i != x).map(|(_, q)| q.traj.as_slice()).collect();
    let horizon = others.iter().map(|t| t.len()).max().unwrap_or(0);
    let cur = p.input.choices.get(w).cloned().unwrap_or_default();
    let from = info.route[0];
    // The first frame from the wait on where waiting `d` frames and then walking `roots` comes
    // too close to someone, until the next walk (or for good after the last one); None: clear.
    let first_close = |d: usize, roots: &[[f32; 2]]| -> Option<usize> {
        let t0 = info.wait_start;
        let t1 = t0 + d + roots.len();
        let last = dwell.last().or(roots.last()).copied().unwrap_or(from);
        let end = if next.is_some() { t1 + dwell.len() } else { horizon.max(t1 + dwell.len()) };
        (t0..end).find(|&t| {
            let q = if t < t0 + d {
                from
            } else if t < t1 {
                roots[t - t0 - d]
            } else {
                dwell.get(t - t1).copied().unwrap_or(last)
            };
            others.iter().any(|o| dist(at(o, t), q) < PASSING_DISTANCE)
        })
    };
    // Until when the current plan stays too close to someone from `f` on: a change that only
    // clears part of its window must at least get past this.
    let run_end = (f..horizon.max(p.traj.len()))
        .find(|&t| others.iter().all(|o| dist(at(o, t), at(&p.traj, t)) >= PASSING_DISTANCE))
        .unwrap_or(usize::MAX);
    let current = walk_roots(ctx, cache, &info.route, &info.params);
    // A detour around where the others stand still while this walk could happen.
    let detour = {
        let mut g = p.input.grid.clone();
        let (t0, t1) = (info.wait_start, info.wait_start + MAX_WAIT + current.len());
        for o in &others {
            for t in (t0..t1).step_by(3) {
                let (q, q2) = (at(o, t), at(o, t + 3));
                if dist(q, q2) < 0.05 {
                    g.block_rect(q, [0.0, 0.0], 0.0, PASSING_DISTANCE + DETOUR_MARGIN);
                }
            }
        }
        let to = *info.route.last().unwrap_or(&from);
        route(&g, from, to).filter(|r| *r != info.route).map(|r| {
            let roots = walk_roots(ctx, cache, &r, &info.params);
            (r, roots)
        })
    };
    // The earliest arrival that clears the whole window; else the change whose first close
    // pass comes latest, when that is past the current one.
    let mut partial: Option<(usize, WalkChoice)> = None;
    for extra in (0..=MAX_WAIT).step_by(WAIT_STEP) {
        let d = cur.wait + extra;
        let mut options: Vec<(Route, &[[f32; 2]])> = Vec::new();
        if extra > 0 {
            options.push((cur.route.clone(), current.as_slice()));
        }
        if let Some((r, roots)) = &detour {
            options.push((Some(r.clone()), roots.as_slice()));
        }
        for (route, roots) in options {
            let choice = WalkChoice { wait: d, route };
            match first_close(d, roots) {
                None => return Some(with_choice(p, w, choice)),
                // A partial clear only when it gains at least a second and the plan stays short
                // (pushing a conflict on and on would only stretch the timeline).
                Some(t)
                    if t >= run_end.saturating_add(FPS as usize)
                        && extra <= 3 * WAIT_STEP
                        && partial.as_ref().is_none_or(|(b, _)| t > *b) =>
                {
                    partial = Some((t, choice))
                }
                Some(_) => {}
            }
        }
    }
    partial.map(|(_, c)| with_choice(p, w, c))
}

/// `p`'s walk choices with walk `w`'s replaced.
fn with_choice(p: &CharacterPlan, w: usize, c: WalkChoice) -> Vec<WalkChoice> {
    let mut all = p.input.choices.clone();
    if all.len() <= w {
        all.resize(w + 1, WalkChoice::default());
    }
    all[w] = c;
    all
}
