//! One character's timeline: what it is built from ([`CharacterInput`]), each action read once
//! ([`Step::read`]) and played by its module of [`super::action`] ([`build_character`]), and the
//! [`CharacterPlan`] that keeps what it was built from, so the crowd repair and the story session can
//! rebuild it from a checkpoint ([`rebuild`]) or keep it.

use super::action::Step;
use super::builder::{Builder, State};
use super::context::Ctx;
use super::routes::{WalkCache, WalkChoice, WalkInfo};
use super::{object_of_node, CharacterTrack};
use crate::layout::grid::Grid;

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
    /// Per walk: how long to wait first and which route to take ([`super::crowd::separate`]).
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
    st: State,
    frames: usize,
    segments: usize,
    walks: usize,
    seats: usize,
    props: usize,
    slides: usize,
    notes: usize,
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
    use crate::animate::context::Setup;
    use crate::animate::plan::animate_planned;
    use crate::animate::AnimateConfig;
    use crate::catalogue::builtin::builtin;
    use crate::compose::{compose, ComposeConfig, ComposeInput};
    use crate::database::SceneDatabase;
    use crate::motion::rig::Rig;
    use crate::motion::MotionLibrary;
    use crate::parse::parse_script;
    use inbetween_core::cancel::Cancel;
    use std::collections::HashMap;

    /// A resumed rebuild equals a full build with the same choices, whichever walk changes.
    #[test]
    fn rebuild_from_the_changed_walk_equals_a_full_build() {
        let cat = builtin();
        let db = SceneDatabase::builtin(&cat, 2, 7);
        let text = format!(
            "{}Eve walks to the sofa.\nTom walks to the desk.\nEve walks to the bookshelf.\n",
            crate::builtin_scripts::DEMO
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
