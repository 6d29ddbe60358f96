//! Planning every character of a scene: their actions grouped by name ([`characters`]), where
//! each starts ([`start_spot`]), each built on its own timeline ([`build_character`]; later
//! characters' grids block where earlier ones end up), then the crowd repair
//! ([`crowd::separate`]) and the camera shots.

use std::collections::HashMap;

use super::character::{build_character, Actions, CharacterInput, CharacterPlan, Person};
use super::context::{Ctx, Setup};
use super::routes::WalkCache;
use super::spots::dist2;
use super::{camera_shots, crowd, AnimateConfig, Animation, PASSING_DISTANCE};
use crate::layout::{self, grid, grid::Grid};
use crate::motion::rig::{Rig, FPS};
use crate::scene::Scene;
use crate::ssg::Ssg;

/// A character's actions with their sentence, grouped by name in order of appearance.
pub(crate) fn characters(query: &Ssg) -> Vec<(String, Actions)> {
    let mut out: Vec<(String, Actions)> = Vec::new();
    let mut nodes: Vec<&crate::ssg::CharacterNode> = query.characters.iter().collect();
    nodes.sort_by_key(|c| c.sentence);
    for c in nodes {
        let key = c.name.to_lowercase();
        let acts = c.actions.iter().map(|a| (c.sentence, a.clone()));
        match out.iter_mut().find(|(n, _)| n.to_lowercase() == key) {
            Some((_, list)) => list.extend(acts),
            None => out.push((c.name.clone(), acts.collect())),
        }
    }
    out
}

/// What [`animate_planned`] returns.
pub(crate) struct Planned {
    pub animation: Animation,
    pub plans: Vec<CharacterPlan>,
    /// Per character: built (or rebuilt) in this call rather than taken from `frozen`.
    pub resolved: Vec<bool>,
    /// Character builds per character (the crowd repair rebuilds a character per change).
    pub builds: Vec<usize>,
}

/// Animates every character: each built on its own timeline (later characters' grids block
/// where earlier ones end up), then [`crowd::separate`] adds waits and detours until every pair
/// of roots keeps [`PASSING_DISTANCE`] at every frame. A character found in `frozen` (by lower-case
/// name) whose start and blocked spots are unchanged is taken as it is, and only rebuilt when a
/// conflict cannot be solved otherwise.
pub(crate) fn animate_planned(
    setup: &Setup,
    scene: &Scene,
    query: &Ssg,
    cache: &mut WalkCache,
    frozen: &HashMap<String, CharacterPlan>,
) -> Planned {
    let Setup { cat, lib, cfg, cancel } = *setup;
    let ctx = Ctx { scene, query, cat, lib, cfg, rig: Rig::standard(), cancel };
    let base_grid = Grid::from_objects(&scene.room, &scene.objects, grid::CELL, grid::WALKER_RADIUS);
    let mut plans: Vec<CharacterPlan> = Vec::new();
    let mut names = Vec::new();
    let (mut resolved, mut builds) = (Vec::new(), Vec::new());
    // Where earlier characters end up: later characters' routes keep clear of them.
    let mut occupied: Vec<[f32; 2]> = Vec::new();
    // Every spot earlier characters stand or sit at: later stand points keep clear of them.
    let mut spots: Vec<[f32; 2]> = Vec::new();
    for (ci, (name, actions)) in characters(query).into_iter().enumerate() {
        if cancel.is_cancelled() {
            break;
        }
        let mut g = base_grid.clone();
        for p in &occupied {
            g.block_rect(*p, [0.0, 0.0], 0.0, PASSING_DISTANCE + grid::CELL);
        }
        let starts: Vec<[f32; 2]> = plans.iter().map(|p| p.input.start).collect();
        let people: Vec<Person> = plans
            .iter()
            .filter_map(|p| {
                let pos = *p.traj.last()?;
                let last = p.track.clip.num_frames().checked_sub(1)?;
                let heading = crate::motion::locomotion::heading_at(&p.track.clip, last);
                Some(Person { name: p.input.name.clone(), pos, heading, seated: p.end_spots.len() > 1 })
            })
            .collect();
        let start = start_spot(scene, cfg, &base_grid, &g, &starts, ci);
        let plan = match frozen.get(&name.to_lowercase()) {
            Some(p)
                if p.input.start == start
                    && p.input.blocked_by == occupied
                    && p.input.avoid == spots
                    && p.input.actions == actions
                    && p.input.people == people =>
            {
                resolved.push(false);
                builds.push(0);
                let mut p = p.clone();
                p.input.grid = g;
                p
            }
            _ => {
                resolved.push(true);
                builds.push(1);
                let input = CharacterInput {
                    name: name.clone(),
                    actions,
                    start,
                    blocked_by: occupied.clone(),
                    grid: g,
                    avoid: spots.clone(),
                    choices: Vec::new(),
                    people,
                };
                build_character(&ctx, input, cache)
            }
        };
        occupied.extend(plan.end_spots.iter().copied());
        spots.extend(plan.spots.iter().copied());
        names.push(name);
        plans.push(plan);
    }
    let crowd_notes = crowd::separate(&ctx, &names, &mut plans, &mut resolved, &mut builds, cache);
    let mut notes: Vec<String> = plans.iter().flat_map(|p| p.notes.iter().cloned()).collect();
    notes.extend(crowd_notes);
    let marks: Vec<(usize, usize)> = plans.iter().flat_map(|p| p.marks.iter().copied()).collect();
    let tracks = plans.iter().map(|p| p.track.clone()).collect();
    let mut anim = Animation { fps: FPS, scene: scene.clone(), characters: tracks, camera: Vec::new(), notes };
    anim.camera = camera_shots(&anim, query, &marks);
    Planned { animation: anim, plans, resolved, builds }
}

/// Where character `ci` starts: along the door wall, `start_spacing` apart on alternating sides,
/// on the free cell nearest that spot that is reachable from the door and at least
/// [`PASSING_DISTANCE`] from the characters placed before (`starts`).
fn start_spot(
    scene: &Scene,
    cfg: &AnimateConfig,
    base_grid: &Grid,
    g: &Grid,
    starts: &[[f32; 2]],
    ci: usize,
) -> [f32; 2] {
    let door = layout::door(&scene.room);
    let side = if ci.is_multiple_of(2) { 1.0 } else { -1.0 };
    let want = [door[0] + side * cfg.start_spacing * ci.div_ceil(2) as f32, door[1]];
    let mut gs = g.clone();
    for p in starts {
        gs.block_rect(*p, [0.0, 0.0], 0.0, PASSING_DISTANCE);
    }
    let door_reach = g.nearest_free(door).map(|c| g.reachable_from(c));
    let mut best: Option<(f32, [f32; 2])> = None;
    for j in 0..gs.nz {
        for i in 0..gs.nx {
            let ok = !gs.is_blocked((i, j)) && door_reach.as_ref().is_none_or(|r| r[j * g.nx + i]);
            let c = gs.center((i, j));
            if ok && best.is_none_or(|(d, _)| dist2(c, want) < d) {
                best = Some((dist2(c, want), c));
            }
        }
    }
    best.map(|b| b.1)
        .or_else(|| base_grid.nearest_free(want).map(|c| g.center(c)))
        .unwrap_or([scene.room.width / 2.0, scene.room.depth / 2.0])
}
