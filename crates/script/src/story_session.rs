//! Incremental story editing (beyond the paper; part 1's [`crate::scene_session`] does the same for the
//! scene). It sits above both [`crate::animate`] and [`crate::optimize`], which it drives: a
//! [`StorySession`] keeps the previous run's per-character timelines and its optimised
//! scene, and a new version of the script re-solves only what the edit touches.
//!
//! - The scene: part 1's session keeps every object of an unchanged sentence in place; such an
//!   object also keeps the pose (position, height scale) the previous §4.3 optimisation gave it.
//! - A character is kept (its motion reused bit for bit, not recomputed) when its actions (verb,
//!   preposition, manner, target object by identity) are the same, every object its segments
//!   touch (and their supports) has the same pose, its start spot and the end spots of the
//!   characters before it are the same, and its walks are still as clear of the furniture as they
//!   were. Otherwise it is re-solved. A kept character whose reservation cannot be kept clear of a
//!   re-solved one by changing the re-solved one is re-solved too ([`crate::animate::crowd`]).
//! - The §4.3 optimisation runs only over the objects the re-solved characters touch (and the
//!   objects related to them, as in [`crate::optimize::movable_objects`]), leaving out any object a
//!   kept character touches or whose move would carry one; every other object keeps its exact
//!   position. Kept characters are not re-animated: a move that would bring furniture closer to
//!   a kept character's walk than it was is rejected.
//!
//! A kept character's motion is the one solved before, still valid but not necessarily what a
//! fresh run would choose (a shorter route opened elsewhere, say), as part 1 keeps objects where
//! they were.

use std::collections::HashMap;
use std::time::Instant;

use crate::animate::{
    animate_planned, characters, object_of_node, Actions, AnimateConfig, Animation, CharacterPlan, Setup, WalkCache,
};
use crate::catalogue::Catalogue;
use crate::compose::{ComposeConfig, ObjectKey};
use crate::database::SceneDatabase;
use crate::layout::{geom, grid};
use crate::motion::MotionLibrary;
use crate::optimize::{anneal, costs, movable_objects, optimize_scene_in, CostCurves, Costs, OptimizeConfig};
use crate::scene::{PlacedObject, Scene};
use crate::scene_session::{Session, Update};
use crate::ssg::Ssg;
use crate::ScriptError;
use inbetween_core::cancel::{Cancel, Cancelled};

/// An action compared across versions: verb, preposition, manner and the target's identity.
/// Verb, preposition, manner, target, and destination (preposition, object).
type ActionSignature = (String, Option<String>, Vec<String>, Option<ObjectKey>, Option<(String, Option<ObjectKey>)>);

/// One character of the previous run.
struct Kept {
    /// Lower-case name.
    key: String,
    actions: Vec<ActionSignature>,
    plan: CharacterPlan,
    /// Its walks' clearance from the furniture when solved ([`walk_clearance`]).
    clearance: f32,
}

/// The previous run.
struct Previous {
    keys: Vec<ObjectKey>,
    /// Poses as composed (before the optimisation), to tell which objects part 1 kept.
    composed: Vec<PlacedObject>,
    /// The optimised scene the characters were animated in.
    scene: Scene,
    characters: Vec<Kept>,
}

/// What one [`StorySession::update`] did.
#[derive(Debug, Clone)]
pub struct StoryUpdate {
    /// Part 1's update (composition, sentences changed, objects kept).
    pub scene: Update,
    pub animation: Animation,
    /// Costs (Eq. 1–3) of the animation before and after this update's optimisation.
    pub before: Costs,
    pub after: Costs,
    /// Cost curves when the optimisation ran.
    pub curves: Option<CostCurves>,
    /// Whether everything was solved afresh (the first version).
    pub full: bool,
    /// Characters animated anew in this update, and those whose motion was reused as it was.
    pub resolved_characters: Vec<String>,
    pub kept_characters: Vec<String>,
    /// Labels of the objects the optimisation could move in this update.
    pub resolved_objects: Vec<String>,
    /// Per character: how many times it was built in this update (0: reused; the optimisation
    /// rebuilds a re-solved character once per state it tries).
    pub character_builds: Vec<(String, usize)>,
    /// Wall-clock seconds: compose + animate + optimise.
    pub seconds: f64,
}

/// An editing session over one story (see the module comment).
pub struct StorySession {
    session: Session,
    lib: MotionLibrary,
    animate: AnimateConfig,
    optimize: Option<OptimizeConfig>,
    prev: Option<Previous>,
}

impl StorySession {
    /// A session; `optimize`: run §4.3 with these settings (None: animate only).
    pub fn new(
        catalogue: Catalogue,
        database: SceneDatabase,
        compose: ComposeConfig,
        lib: MotionLibrary,
        animate: AnimateConfig,
        optimize: Option<OptimizeConfig>,
    ) -> StorySession {
        StorySession { session: Session::new(catalogue, database, compose), lib, animate, optimize, prev: None }
    }

    /// The motion library the characters are animated from.
    pub fn library(&self) -> &MotionLibrary {
        &self.lib
    }

    /// Every character verb of `text` has motion in this session's library, or an error naming
    /// the file (`source`), line and verb of each that does not (see [`unplayable_verbs`]).
    pub fn check_verbs(&self, text: &str, source: &str) -> Result<(), ScriptError> {
        let parsed = crate::parse::parse_script(text, self.catalogue());
        let bad = unplayable_verbs(&parsed, &self.lib);
        if bad.is_empty() {
            return Ok(());
        }
        let lines: Vec<String> = bad
            .iter()
            .map(|(at, verb)| format!("{source}:{}: \"{}\": no motion for the verb \"{verb}\"", at.line, at.text))
            .collect();
        let known: Vec<&str> = crate::motion::verbs::VERBS
            .iter()
            .map(|(tag, _)| *tag)
            .filter(|tag| crate::animate::action::has_motion(tag, &self.lib))
            .collect();
        Err(ScriptError::Invalid(format!(
            "{}\nnothing was written; verbs with motion here: {} (and their synonyms; jump, kick, dance, climb, \
             bend and throw need captured clips: `shared_motions`)",
            lines.join("\n"),
            known.join(", ")
        )))
    }

    pub fn catalogue(&self) -> &Catalogue {
        self.session.catalogue()
    }

    /// Composes and animates `text`, re-solving only what changed since the previous version.
    pub fn update(&mut self, text: &str) -> StoryUpdate {
        self.update_with(text, &Cancel::new()).expect("an update without a cancel token runs to the end")
    }

    /// [`StorySession::update`] that stops early once `cancel` is cancelled (or its time limit
    /// passes): the loops over characters, crowd repairs and optimisation states check it. A
    /// stopped update returns the reason and leaves the session as it was before the call, so the
    /// next update continues from the last finished version.
    pub fn update_with(&mut self, text: &str, cancel: &Cancel) -> Result<StoryUpdate, Cancelled> {
        let start = Instant::now();
        cancel.check()?;
        let checkpoint = self.session.checkpoint();
        let up = self.session.update(text);
        let prev = self.prev.take();
        let mut out = match &prev {
            None => self.full(up, cancel),
            Some(prev) => self.incremental(up, prev, cancel),
        };
        if let Err(why) = cancel.check() {
            self.session.restore(checkpoint);
            self.prev = prev;
            return Err(why);
        }
        out.seconds = start.elapsed().as_secs_f64();
        Ok(out)
    }

    /// The first version: compose, animate, optimise everything.
    fn full(&mut self, up: Update, cancel: &Cancel) -> StoryUpdate {
        let comp = &up.composition;
        let cat = self.session.catalogue();
        let setup = Setup { cat, lib: &self.lib, cfg: &self.animate, cancel };
        let ocfg = self.optimize.clone();
        let (scene, before, after, curves, movable) = match &ocfg {
            Some(cfg) => {
                let o = optimize_scene_in(&setup, &comp.scene, &comp.query, &comp.relations, cfg);
                (o.scene, o.before, o.after, Some(o.curves), o.movable)
            }
            None => {
                let c = costs(
                    &animate_planned(&setup, &comp.scene, &comp.query, &mut WalkCache::default(), &HashMap::new())
                        .animation,
                    &OptimizeConfig::default(),
                );
                (comp.scene.clone(), c, c, None, Vec::new())
            }
        };
        // The best state again, with its plans (animation is deterministic: the same motion).
        let planned = animate_planned(&setup, &scene, &comp.query, &mut WalkCache::default(), &HashMap::new());
        let names: Vec<String> = planned.animation.characters.iter().map(|c| c.name.clone()).collect();
        let resolved_objects = movable.iter().map(|&i| scene.objects[i].label.clone()).collect();
        let builds = names.iter().map(|n| (n.clone(), 1)).collect();
        self.remember(&up, &scene, planned.plans);
        StoryUpdate {
            scene: up,
            animation: planned.animation,
            before,
            after,
            curves,
            full: true,
            resolved_characters: names,
            kept_characters: Vec::new(),
            resolved_objects,
            character_builds: builds,
            seconds: 0.0,
        }
    }

    /// A later version: keep what the edit did not touch.
    fn incremental(&mut self, up: Update, prev: &Previous, cancel: &Cancel) -> StoryUpdate {
        let comp = &up.composition;
        let cat = self.session.catalogue();
        let setup = Setup { cat, lib: &self.lib, cfg: &self.animate, cancel };
        let keys: Vec<ObjectKey> = comp.keys.iter().map(|(k, _)| k.clone()).collect();
        // Objects part 1 kept also keep their optimised pose.
        let mut scene = comp.scene.clone();
        let new_index: Vec<Option<usize>> = prev.keys.iter().map(|k| keys.iter().position(|q| q == k)).collect();
        for (j, i) in new_index.iter().enumerate() {
            if let Some(i) = *i {
                if same_pose(&prev.composed[j], &comp.scene.objects[i]) {
                    let o = &prev.scene.objects[j];
                    let n = &mut scene.objects[i];
                    (n.position, n.yaw, n.size) = (o.position, o.yaw, o.size);
                }
            }
        }
        // Characters whose inputs are unchanged are frozen.
        let mut frozen = HashMap::new();
        for (name, actions) in characters(&comp.query) {
            let key = name.to_lowercase();
            let Some(k) = prev.characters.iter().find(|k| k.key == key) else { continue };
            if k.actions != action_signature(&actions, &scene, &comp.query, &keys) {
                continue;
            }
            let Some(plan) = remap(&k.plan, &prev.scene, &scene, &new_index, &name, &actions) else { continue };
            if walk_clearance(&plan, &scene) < k.clearance.min(grid::WALKER_RADIUS) - 1e-4 {
                continue;
            }
            frozen.insert(key, plan);
        }
        let mut cache = WalkCache::default();
        let planned = animate_planned(&setup, &scene, &comp.query, &mut cache, &frozen);
        let mut builds = planned.builds.clone();
        let kept_flags: Vec<bool> = planned.resolved.iter().map(|r| !r).collect();
        let kept: HashMap<String, CharacterPlan> = planned
            .plans
            .iter()
            .zip(&kept_flags)
            .filter(|(_, k)| **k)
            .map(|(p, _)| (p.track.name.to_lowercase(), p.clone()))
            .collect();
        let kept_clearance: Vec<(CharacterPlan, f32)> =
            kept.values().map(|p| (p.clone(), walk_clearance(p, &scene))).collect();
        let ocfg = self.optimize.clone().unwrap_or_default();
        let c0 = costs(&planned.animation, &ocfg);
        let movable = match &self.optimize {
            Some(_) if kept_flags.iter().any(|k| !k) => {
                restricted_movable(&planned.animation, &kept_flags, &comp.relations, cat)
            }
            _ => Vec::new(),
        };
        let (final_scene, before, after, curves) = if movable.is_empty() {
            (scene.clone(), c0, c0, None)
        } else {
            let mut animate_state = |s: &Scene| -> Option<Animation> {
                if kept_clearance.iter().any(|(p, c)| walk_clearance(p, s) < c.min(grid::WALKER_RADIUS) - 1e-4) {
                    return None;
                }
                if cancel.is_cancelled() {
                    return None;
                }
                let pl = animate_planned(&setup, s, &comp.query, &mut cache, &kept);
                // A kept character would have to change: the state is not taken.
                if pl.resolved.iter().zip(&kept_flags).any(|(r, k)| *r && *k) {
                    return None;
                }
                for (b, x) in builds.iter_mut().zip(&pl.builds) {
                    *b += x;
                }
                Some(pl.animation)
            };
            let o = anneal(
                &scene,
                &comp.relations,
                &ocfg,
                planned.animation.clone(),
                c0,
                movable.clone(),
                &mut animate_state,
            );
            (o.scene, o.before, o.after, Some(o.curves))
        };
        let planned = if curves.is_some() {
            let p = animate_planned(&setup, &final_scene, &comp.query, &mut cache, &kept);
            for (b, x) in builds.iter_mut().zip(&p.builds) {
                *b += x;
            }
            p
        } else {
            planned
        };
        let names: Vec<String> = planned.animation.characters.iter().map(|c| c.name.clone()).collect();
        let resolved_characters = names.iter().zip(&kept_flags).filter(|(_, k)| !**k).map(|(n, _)| n.clone()).collect();
        let kept_characters = names.iter().zip(&kept_flags).filter(|(_, k)| **k).map(|(n, _)| n.clone()).collect();
        let resolved_objects = movable.iter().map(|&i| final_scene.objects[i].label.clone()).collect();
        let character_builds = names.iter().cloned().zip(builds).collect();
        self.remember(&up, &final_scene, planned.plans);
        StoryUpdate {
            scene: up,
            animation: planned.animation,
            before,
            after,
            curves,
            full: false,
            resolved_characters,
            kept_characters,
            resolved_objects,
            character_builds,
            seconds: 0.0,
        }
    }

    /// Keeps this version for the next update.
    fn remember(&mut self, up: &Update, scene: &Scene, plans: Vec<CharacterPlan>) {
        let comp = &up.composition;
        let keys: Vec<ObjectKey> = comp.keys.iter().map(|(k, _)| k.clone()).collect();
        let characters = plans
            .into_iter()
            .map(|plan| Kept {
                key: plan.track.name.to_lowercase(),
                actions: action_signature(&plan.input.actions, scene, &comp.query, &keys),
                clearance: walk_clearance(&plan, scene),
                plan,
            })
            .collect();
        self.prev = Some(Previous { keys, composed: comp.scene.objects.clone(), scene: scene.clone(), characters });
    }
}

/// Whether two placements are the same (category, position, yaw, size).
fn same_pose(a: &PlacedObject, b: &PlacedObject) -> bool {
    a.category == b.category && a.position == b.position && a.yaw == b.yaw && a.size == b.size
}

fn action_signature(actions: &Actions, scene: &Scene, query: &Ssg, keys: &[ObjectKey]) -> Vec<ActionSignature> {
    actions
        .iter()
        .map(|(_, a)| {
            (
                a.verb.clone(),
                a.preposition.clone(),
                a.manner.clone(),
                a.target.and_then(|t| object_of_node(scene, query, t)).and_then(|i| keys.get(i).cloned()),
                a.destination
                    .as_ref()
                    .map(|(p, d)| (p.clone(), object_of_node(scene, query, *d).and_then(|i| keys.get(i).cloned()))),
            )
        })
        .collect()
}

/// Objects `plan` touches (segment targets and touched objects) and their supports, transitively.
fn touched(plan: &CharacterPlan, scene: &Scene) -> Vec<usize> {
    let mut set: Vec<usize> =
        plan.track.segments.iter().flat_map(|s| s.object.into_iter().chain(s.touching.iter().copied())).collect();
    let mut k = 0;
    while k < set.len() {
        if let Some(s) = scene.objects.get(set[k]).and_then(|o| o.support) {
            if !set.contains(&s) {
                set.push(s);
            }
        }
        k += 1;
    }
    set.retain(|&i| i < scene.objects.len());
    set.sort_unstable();
    set.dedup();
    set
}

/// The previous plan in the new scene's object numbering, with the new version's actions (same
/// meaning, maybe other sentence numbers); None when an object it touches is gone or moved.
fn remap(
    plan: &CharacterPlan,
    old: &Scene,
    new: &Scene,
    new_index: &[Option<usize>],
    name: &str,
    actions: &Actions,
) -> Option<CharacterPlan> {
    for i in touched(plan, old) {
        let j = (*new_index.get(i)?)?;
        if !same_pose(&old.objects[i], new.objects.get(j)?) {
            return None;
        }
    }
    let map = |i: usize| new_index.get(i).copied().flatten();
    let mut p = plan.clone();
    for s in &mut p.track.segments {
        s.object = match s.object {
            Some(i) => Some(map(i)?),
            None => None,
        };
        s.target = s.object.map(|i| new.objects[i].label.clone());
        s.touching = s.touching.iter().map(|&i| map(i)).collect::<Option<Vec<usize>>>()?;
    }
    for c in &mut p.track.props {
        c.object = map(c.object)?;
    }
    for s in &mut p.track.slides {
        s.object = map(s.object)?;
    }
    if p.marks.len() != actions.len() {
        return None;
    }
    for (m, (sentence, _)) in p.marks.iter_mut().zip(actions) {
        m.0 = *sentence;
    }
    p.input.actions = actions.clone();
    p.input.name = name.to_string();
    p.track.name = name.to_string();
    Some(p)
}

/// The least distance (metres) from the root, over the frames of every walk, to the footprint of
/// an object in the way ([`grid::blocks_walking`]) that the walk's segment does not touch.
pub(crate) fn walk_clearance(plan: &CharacterPlan, scene: &Scene) -> f32 {
    let mut best = f32::INFINITY;
    for w in &plan.walks {
        let touching: &[usize] = plan
            .track
            .segments
            .iter()
            .find(|s| s.start <= w.walk_start && w.walk_start < s.end)
            .map(|s| s.touching.as_slice())
            .unwrap_or(&[]);
        for (i, o) in scene.objects.iter().enumerate() {
            if touching.contains(&i) || !grid::blocks_walking(o) {
                continue;
            }
            let half = [o.size[0] / 2.0, o.size[2] / 2.0];
            for r in &plan.traj[w.walk_start.min(plan.traj.len())..w.end.min(plan.traj.len())] {
                let l = geom::to_local(geom::center(o), o.yaw, *r);
                let d = (l[0].abs() - half[0]).max(0.0).hypot((l[1].abs() - half[1]).max(0.0));
                best = best.min(d);
            }
        }
    }
    best
}

/// The objects the optimisation may move when only the characters not `kept` were re-solved:
/// [`movable_objects`] of those characters, without any object a kept character touches or that
/// would carry one along.
fn restricted_movable(
    anim: &Animation,
    kept: &[bool],
    relations: &[(crate::ssg::Relation, usize, usize)],
    cat: &Catalogue,
) -> Vec<usize> {
    let mut sub = anim.clone();
    sub.characters = anim.characters.iter().zip(kept).filter(|(_, k)| !**k).map(|(c, _)| c.clone()).collect();
    let objs = &anim.scene.objects;
    let mut fixed: Vec<usize> = anim
        .characters
        .iter()
        .zip(kept)
        .filter(|(_, k)| **k)
        .flat_map(|(c, _)| c.segments.iter().flat_map(|s| s.object.into_iter().chain(s.touching.iter().copied())))
        .collect();
    // Their supports stay too (moving a support carries what rests on it).
    let mut k = 0;
    while k < fixed.len() {
        if let Some(s) = objs.get(fixed[k]).and_then(|o| o.support) {
            if !fixed.contains(&s) {
                fixed.push(s);
            }
        }
        k += 1;
    }
    movable_objects(&sub, relations, cat).into_iter().filter(|i| !fixed.contains(i)).collect()
}

/// The character actions of a parsed script whose verb has no motion in `lib` (no locomotion,
/// sitting, standing, turning or lying, and no clip): the sentence and the verb as written.
pub fn unplayable_verbs(
    parsed: &crate::parse::ParsedScript,
    lib: &MotionLibrary,
) -> Vec<(crate::error::SentenceRef, String)> {
    let mut out = Vec::new();
    for s in &parsed.sentences {
        for c in &s.ssg.characters {
            for a in &c.actions {
                let step = crate::animate::action::Step::read(a, None, lib, 0.0);
                if !crate::animate::action::plays(&step, lib) {
                    out.push((s.raw.at.clone(), a.verb.clone()));
                }
            }
        }
    }
    out
}
