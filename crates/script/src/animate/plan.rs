//! Planning every character of a scene: their actions grouped by name ([`characters`]), where
//! each starts ([`start_spot`]), each built on its own timeline ([`build_character`]; later
//! characters' grids block where earlier ones end up), then the crowd repair
//! ([`crowd::separate`]) and the camera shots. [`CharacterPlan`] keeps what a character was built
//! from, so the crowd repair and the story session can rebuild or keep it.

use std::collections::HashMap;

use super::action::walk::WalkCache;
use super::action::Step;
use super::builder::Builder;
use super::spots::dist2;
use super::{
    camera_shots, crowd, object_of_node, AnimateConfig, Animation, CharacterTrack, WalkChoice, WalkInfo,
    PASSING_DISTANCE,
};
use crate::catalogue::Catalogue;
use crate::layout::{self, grid, grid::Grid};
use crate::motion::rig::{Rig, FPS};
use crate::motion::MotionLibrary;
use crate::scene::Scene;
use crate::ssg::Ssg;
use inbetween_core::cancel::Cancel;

/// A character's actions with their sentence, grouped by name in order of appearance.
pub(crate) fn characters(query: &Ssg) -> Vec<(String, Actions)> {
    let mut out: Vec<(String, Vec<(usize, crate::ssg::Action)>)> = Vec::new();
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

/// The scene, query and settings one character is built in.
pub(crate) struct Ctx<'a> {
    pub scene: &'a Scene,
    pub query: &'a Ssg,
    pub cat: &'a Catalogue,
    pub lib: &'a MotionLibrary,
    pub cfg: &'a AnimateConfig,
    pub rig: Rig,
    /// Checked between characters and between crowd repairs; once cancelled they stop early (the
    /// caller discards what was built).
    pub cancel: &'a Cancel,
}

/// What every animation of a session is made with: the catalogue, the motion library, the
/// settings, and the cancel token the long loops check.
#[derive(Clone, Copy)]
pub(crate) struct Setup<'a> {
    pub cat: &'a Catalogue,
    pub lib: &'a MotionLibrary,
    pub cfg: &'a AnimateConfig,
    pub cancel: &'a Cancel,
}

/// A character's actions with the sentence each comes from.
pub(crate) type Actions = Vec<(usize, crate::ssg::Action)>;

/// What one character is built from: its actions, where it starts, its grid and walk choices,
/// and the spots of earlier characters it keeps clear of.
#[derive(Debug, Clone)]
pub(crate) struct CharacterInput {
    pub name: String,
    pub actions: Actions,
    pub start: [f32; 2],
    /// Where the characters planned before end up (blocked in `grid`).
    pub blocked_by: Vec<[f32; 2]>,
    /// The character's occupancy grid (objects plus `blocked_by`).
    pub grid: Grid,
    /// The earlier characters' spots this one's stand points keep clear of.
    pub avoid: Vec<[f32; 2]>,
    /// Per walk: how long to wait first and which route to take ([`crowd::separate`]).
    pub choices: Vec<WalkChoice>,
    /// Where the characters planned before end up, for actions done to or with them ("sits next
    /// to Ben", "walks to Tom").
    pub people: Vec<Person>,
}

/// Another character as an action towards them sees it: where it ends up (root and heading at
/// its track's last frame) and the seat it sits on, if any.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Person {
    pub name: String,
    pub pos: [f32; 2],
    pub heading: f64,
    pub seated: bool,
}

/// Everything needed to rebuild one character with other walk choices, and what it built.
#[derive(Debug, Clone)]
pub(crate) struct CharacterPlan {
    pub input: CharacterInput,
    pub track: CharacterTrack,
    /// Root (x, z) per frame.
    pub traj: Vec<[f32; 2]>,
    pub walks: Vec<WalkInfo>,
    /// (sentence, first frame) of every action, for the camera cuts.
    pub marks: Vec<(usize, usize)>,
    pub notes: Vec<String>,
    /// Where it ends: the stand point, and the seat when seated (later characters keep clear).
    pub end_spots: Vec<[f32; 2]>,
    /// Every spot it stands or sits at (start, walk ends, seats): later characters' stand points
    /// keep clear of them.
    pub spots: Vec<[f32; 2]>,
    /// The seats sat on and the builder's state before each action: with `track.clip`'s frames,
    /// what [`rebuild`] resumes from.
    pub seats: Vec<[f32; 2]>,
    pub checkpoints: Vec<Checkpoint>,
}

/// The builder's state before one action (its timeline only grows, so lengths locate it).
#[derive(Debug, Clone)]
pub(crate) struct Checkpoint {
    st: super::builder::State,
    frames: usize,
    segments: usize,
    walks: usize,
    seats: usize,
    props: usize,
    slides: usize,
    notes: usize,
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

/// Builds one character's timeline from its input: each action read once ([`Step::read`]) and
/// played by its module of [`super::action`].
pub(crate) fn build_character(ctx: &Ctx, input: CharacterInput, cache: &mut WalkCache) -> CharacterPlan {
    build(ctx, input, cache, None)
}

/// `old` rebuilt with other walk choices (`input` is `old.input` with only `choices` changed, as
/// [`crowd::separate`] makes it): the actions before the one that makes the first changed walk
/// read no changed choice, so the build resumes there from `old`'s checkpoint and reuses its
/// frames, converted channels and root track; the result equals [`build_character`]'s.
pub(crate) fn rebuild(ctx: &Ctx, old: &CharacterPlan, input: CharacterInput, cache: &mut WalkCache) -> CharacterPlan {
    let n = old.input.choices.len().max(input.choices.len());
    let choice = |c: &[WalkChoice], w: usize| c.get(w).cloned().unwrap_or_default();
    let first_changed = (0..n).find(|&w| choice(&old.input.choices, w) != choice(&input.choices, w));
    let resume = first_changed.and_then(|w| old.checkpoints.iter().rposition(|cp| cp.walks <= w));
    match resume {
        Some(k) if old.checkpoints.len() == input.actions.len() => build(ctx, input, cache, Some((old, k))),
        _ => build(ctx, input, cache, None),
    }
}

fn build(
    ctx: &Ctx,
    input: CharacterInput,
    cache: &mut WalkCache,
    resume: Option<(&CharacterPlan, usize)>,
) -> CharacterPlan {
    let (scene, query, rig) = (ctx.scene, ctx.query, &ctx.rig);
    let mut b = Builder::new(ctx, &input.name, &input.grid, &input.avoid, &input.choices, input.start, cache);
    let (mut marks, mut checkpoints, first, prefix) = match resume {
        Some((old, k)) => {
            let cp = &old.checkpoints[k];
            b.st = cp.st;
            b.frames = (0..cp.frames).map(|f| old.track.clip.pose(f)).collect();
            b.segments = old.track.segments[..cp.segments].to_vec();
            b.walks = old.walks[..cp.walks].to_vec();
            b.seats = old.seats[..cp.seats].to_vec();
            b.props = old.track.props[..cp.props].to_vec();
            // A prop put down after the checkpoint is still in the hand there.
            for p in &mut b.props {
                if p.put_down.as_ref().is_some_and(|d| d.frame >= cp.frames) {
                    p.put_down = None;
                }
            }
            b.slides = old.track.slides[..cp.slides].to_vec();
            b.notes = old.notes[..cp.notes].to_vec();
            (old.marks[..k].to_vec(), old.checkpoints[..k].to_vec(), k, cp.frames)
        }
        None => (Vec::new(), Vec::new(), 0, 0),
    };
    for (sentence, a) in input.actions.iter().skip(first) {
        checkpoints.push(Checkpoint {
            st: b.st,
            frames: b.frames.len(),
            segments: b.segments.len(),
            walks: b.walks.len(),
            seats: b.seats.len(),
            props: b.props.len(),
            slides: b.slides.len(),
            notes: b.notes.len(),
        });
        marks.push((*sentence, b.frames.len()));
        let obj = a.target.and_then(|t| object_of_node(scene, query, t));
        if a.target.is_some() && obj.is_none() {
            b.notes.push(format!("{}: the target of \"{}\" is not in the scene", input.name, a.verb));
        }
        let mut step = Step::read(a, obj, ctx.lib, ctx.cfg.slow_speed);
        step.destination =
            a.destination.as_ref().and_then(|(p, n)| object_of_node(scene, query, *n).map(|o| (p.clone(), o)));
        let person = a.person.as_ref().map(|n| (n, input.people.iter().find(|p| p.name.eq_ignore_ascii_case(n))));
        match person {
            Some((_, Some(p))) => b.play_towards(&step, p),
            Some((n, None)) => {
                b.notes.push(format!(
                    "{}: \"{}\" is done towards {n}, who is not placed before {} acts (name them in an earlier sentence)",
                    input.name, a.verb, input.name
                ));
                b.play(&step);
            }
            None => b.play(&step),
        }
    }
    if b.frames.is_empty() {
        let n = b.min_action_frames();
        let idle = b.idle_clip();
        let poses = b.looped(&idle, b.st.pos, b.st.heading, n);
        b.append(poses);
    }
    let st = b.st;
    let mut end_spots = vec![st.pos];
    if let Some((_, s, _)) = st.seated {
        end_spots.push([s[0], s[2]]);
    }
    let root = |p: &inbetween_core::Pose| [p.translations[rig.hips].x as f32, p.translations[rig.hips].z as f32];
    // Root track: the resumed prefix as it was, the rest read now (per frame, so the result is
    // the same as reading everything).
    let traj = match resume {
        Some((old, _)) if prefix > 0 && prefix <= b.frames.len() => {
            let mut traj = old.traj[..prefix].to_vec();
            traj.extend(b.frames[prefix..].iter().map(root));
            traj
        }
        _ => b.frames.iter().map(root).collect(),
    };
    let clip = crate::motion::rig::clip(rig, &b.frames);
    let Builder { segments, props, slides, walks, seats, notes, .. } = b;
    let track = CharacterTrack { name: input.name.clone(), clip, segments, props, slides };
    let mut spots = vec![input.start];
    spots.extend(walks.iter().filter_map(|w| traj.get(w.end.saturating_sub(1)).copied()));
    spots.extend(seats.iter().copied());
    CharacterPlan { input, track, traj, walks, marks, notes, end_spots, spots, seats, checkpoints }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::catalogue::builtin::builtin;
    use crate::compose::{compose, ComposeConfig, ComposeInput};
    use crate::database::SceneDatabase;
    use crate::parse::parse_script;

    /// A resumed rebuild equals a full build with the same choices, whichever walk changes.
    #[test]
    fn rebuild_from_the_changed_walk_equals_a_full_build() {
        let cat = builtin();
        let db = SceneDatabase::builtin(&cat, 2, 7);
        let text = format!(
            "{}Eve walks to the sofa.\nTom walks to the desk.\nEve walks to the bookshelf.\n",
            crate::stories::DEMO
        );
        let parsed = parse_script(&text, &cat);
        let comp = compose(
            &ComposeInput { parsed: &parsed, catalogue: &cat, database: &db, pins: &HashMap::new() },
            &ComposeConfig::default(),
        );
        let lib = MotionLibrary::procedural(0);
        let cfg = AnimateConfig::default();
        let mut cache = WalkCache::default();
        let cancel = Cancel::new();
        let setup = Setup { cat: &cat, lib: &lib, cfg: &cfg, cancel: &cancel };
        let planned = animate_planned(&setup, &comp.scene, &comp.query, &mut cache, &HashMap::new());
        let ctx = Ctx {
            scene: &comp.scene,
            query: &comp.query,
            cat: &cat,
            lib: &lib,
            cfg: &cfg,
            rig: Rig::standard(),
            cancel: &cancel,
        };
        let mut checked = 0;
        for plan in &planned.plans {
            for w in 0..plan.walks.len() {
                let mut choices = plan.input.choices.clone();
                choices.resize(plan.walks.len().max(choices.len()), WalkChoice::default());
                choices[w].wait += 20;
                let input = CharacterInput { choices, ..plan.input.clone() };
                let full = build_character(&ctx, input.clone(), &mut cache);
                let resumed = rebuild(&ctx, plan, input, &mut cache);
                assert_eq!(resumed.track.clip, full.track.clip, "{} walk {w}", plan.input.name);
                assert_eq!(resumed.traj, full.traj);
                assert_eq!(resumed.walks, full.walks);
                assert_eq!(resumed.marks, full.marks);
                assert_eq!(resumed.notes, full.notes);
                assert_eq!(resumed.spots, full.spots);
                assert_eq!(resumed.end_spots, full.end_spots);
                assert_eq!(resumed.track.segments.len(), full.track.segments.len());
                checked += 1;
            }
        }
        assert!(checked >= 4, "walks rebuilt: {checked}");
    }
}
