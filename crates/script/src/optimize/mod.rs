//! Joint optimisation of scene layout and character motion (§4.3, Algorithm 2).
//!
//! - Collision cost C_D (Eq. 1): every object is tiled into small boxes (about
//!   [`OptimizeConfig::box_size`] on a side; a table with leg room is a thin top on four legs,
//!   [`boxes`]); the body is a set of spheres on the skeleton (at
//!   the joints and bone midpoints, radius by body part). n_c(o) counts the boxes of object `o`
//!   any sphere touches over the whole animation, leaving out objects the current segment may
//!   touch (its target, the seat sat on) and flat objects (rugs); C_D = mean over collided
//!   objects of n_c / n_a.
//! - Contact cost C_T (Eq. 2): for every joint–contact pair of the animation's segments (hips on a
//!   seat, fingers on keys, wrist on a grip, …; see [`crate::animate::ContactJoint`]), the distance
//!   from the joint's mean position over the action to the contact point; C_T = the mean.
//! - C = λ_D C_D + λ_T C_T (Eq. 3), minimised by simulated annealing over the interactive objects
//!   (segment targets with contacts) and the objects related to them: x, z and vertical scale,
//!   each move a truncated normal N(0, σ², ±3σ) (Eq. 4) on one object, objects resting on it
//!   carried along, base heights fixed (what rests on a scaled object rides on its new top).
//!   Every state is re-animated (the paper's NSMGenerate: our A* + walk + blend + IK), states that
//!   break the layout (more overlaps, unmet relations, objects outside or unreachable than at the
//!   start, [`layout::check`]) are rejected, the rest accepted by Metropolis' rule
//!   exp(−ΔC / T) with T = 1 − 0.002·iteration, in units of 1 % of the initial C by default
//!   ([`OptimizeConfig::relative_temperature`]; [`OptimizeConfig::paper`] keeps absolute units).
//!   The best state seen is returned.

pub mod boxes;

use std::path::Path;

use glam::DVec3;
use inbetween_core::fk::forward;
use inbetween_core::roles::Side;
use rand::Rng;

use crate::animate::{animate_planned, AnimateConfig, Animation, ContactJoint, Setup, WalkCache};
use crate::catalogue::{Catalogue, Support};
use crate::compose::Composition;
use crate::error::ScriptError;
use crate::layout::{self, geom, Violations};
use crate::motion::rig::Rig;
use crate::motion::MotionLibrary;
use crate::scene::{PlacedObject, Scene};
use crate::ssg::{Relation, Ssg};
use std::collections::HashMap;

/// Default fraction of the initial cost that temperature 1 stands for (see
/// [`OptimizeConfig::relative_temperature`]).
pub const RELATIVE_TEMPERATURE: f64 = 0.01;

/// Settings of [`optimize`] (defaults: the paper's values, except the temperature's unit).
#[derive(Debug, Clone, PartialEq)]
pub struct OptimizeConfig {
    pub iterations: usize,
    /// σ of the position moves (metres) and of the relative vertical-scale moves.
    pub sigma: f64,
    pub initial_temperature: f64,
    /// When set, temperatures are in units of this fraction of the initial cost C (a difference
    /// on purpose: with T in absolute cost units, as printed, our C of about 1–5 makes nearly every
    /// move acceptable and the run a random walk). `None` is the paper's schedule as printed.
    pub relative_temperature: Option<f64>,
    /// Temperature decrease per iteration.
    pub cooling: f64,
    pub lambda_d: f64,
    pub lambda_t: f64,
    /// Side of the boxes objects are tiled into, metres.
    pub box_size: f32,
    pub seed: u64,
}

impl OptimizeConfig {
    /// Algorithm 2 exactly as printed: T = 1 − 0.002·iteration in absolute cost units.
    pub fn paper() -> OptimizeConfig {
        OptimizeConfig { relative_temperature: None, ..OptimizeConfig::default() }
    }
}

impl Default for OptimizeConfig {
    fn default() -> OptimizeConfig {
        OptimizeConfig {
            iterations: 100,
            sigma: 0.02,
            initial_temperature: 1.0,
            relative_temperature: Some(RELATIVE_TEMPERATURE),
            cooling: 0.002,
            lambda_d: 1.0,
            lambda_t: 10.0,
            box_size: 0.25,
            seed: 1,
        }
    }
}

/// The costs of one animated scene.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Costs {
    /// C_D (Eq. 1).
    pub collision: f64,
    /// C_T (Eq. 2), metres: also the mean contact distance.
    pub contact: f64,
    /// C (Eq. 3).
    pub total: f64,
    /// Boxes touched by the body (Σ n_c over objects).
    pub collided_boxes: usize,
    /// Objects with at least one touched box.
    pub collided_objects: usize,
    /// Joint–contact pairs measured.
    pub contact_pairs: usize,
}

/// Per-iteration costs of the current state (index 0: the initial state), and whether the
/// iteration's move was accepted (index 0: true).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct CostCurves {
    pub collision: Vec<f64>,
    pub contact: Vec<f64>,
    pub total: Vec<f64>,
    /// Lowest C so far (the state [`optimize`] returns at the end).
    pub best: Vec<f64>,
    pub accepted: Vec<bool>,
}

/// What [`optimize`] returns.
#[derive(Debug, Clone)]
pub struct Optimized {
    /// The best scene found and its animation.
    pub scene: Scene,
    pub animation: Animation,
    pub before: Costs,
    pub after: Costs,
    pub curves: CostCurves,
    /// Indices of the objects the annealing could move.
    pub movable: Vec<usize>,
    /// Moves rejected for breaking the layout (or refused by the incremental editor).
    pub rejected_layout: usize,
}

/// Body spheres' radius for a joint by name (metres).
fn radius(name: &str) -> f64 {
    let n = name.to_ascii_lowercase();
    if n.contains("head") {
        0.1
    } else if n.contains("hand") || n.contains("finger") || n.contains("thumb") || n.contains("index") {
        0.04
    } else if n.contains("forearm") || n.contains("foot") || n.contains("toe") {
        0.045
    } else if n.contains("arm") || n.contains("neck") || n.contains("shoulder") || n.contains("clavicle") {
        0.055
    } else if n.contains("upleg") || n.contains("hipjoint") {
        0.08
    } else if n.contains("leg") {
        0.06
    } else {
        0.12
    }
}

/// The body of a pose as spheres (centre, radius): every joint and every bone's midpoint;
/// `radii[j]` is [`radius`] of joint `j`'s name.
fn body_spheres(rig: &Rig, radii: &[f64], g: &inbetween_core::fk::GlobalPose, out: &mut Vec<(DVec3, f64)>) {
    out.clear();
    for (j, &r) in radii.iter().enumerate() {
        out.push((g.positions[j], r));
        if let Some(p) = rig.skeleton.parent(j) {
            if (g.positions[j] - g.positions[p]).length() > 2.0 * r {
                out.push(((g.positions[j] + g.positions[p]) * 0.5, r));
            }
        }
    }
}

/// C_D (Eq. 1) and the number of touched boxes and objects over the whole animation. Objects are
/// approximated by the small boxes of [`boxes::object_boxes`] (tables keep leg room).
pub fn collision_cost(anim: &Animation, box_size: f32) -> (f64, usize, usize) {
    let objs = &anim.scene.objects;
    let model: Vec<Vec<boxes::LocalBox>> = objs.iter().map(|o| boxes::object_boxes(o, box_size)).collect();
    let mut hit: Vec<Vec<bool>> = model.iter().map(|b| vec![false; b.len()]).collect();
    // A prop in someone's hand has left its place: from then on nothing collides with it there.
    let carried: Vec<usize> =
        (0..objs.len()).map(|i| crate::animate::carried_from(anim, i).unwrap_or(usize::MAX)).collect();
    let mut spheres = Vec::new();
    for c in &anim.characters {
        let Ok(rig) = Rig::try_of(c.clip.skeleton().clone()) else { continue };
        let radii: Vec<f64> = rig.skeleton.joints().iter().map(|j| radius(&j.name)).collect();
        let (mut pose, mut g) = (inbetween_core::Pose::rest(&rig.skeleton), forward(&rig.skeleton, &rig.standing()));
        let mut seg = 0;
        for f in 0..c.clip.num_frames() {
            while seg + 1 < c.segments.len() && f >= c.segments[seg].end {
                seg += 1;
            }
            let touching: &[usize] = c.segments.get(seg).map(|s| s.touching.as_slice()).unwrap_or(&[]);
            c.clip.pose_into(f, &mut pose);
            inbetween_core::fk::forward_into(&rig.skeleton, &pose, &mut g);
            body_spheres(&rig, &radii, &g, &mut spheres);
            for (i, o) in objs.iter().enumerate() {
                // Flat objects (rugs) are walked on, not into.
                if touching.contains(&i) || o.top() < crate::layout::grid::FLAT || f >= carried[i] {
                    continue;
                }
                let half = [o.size[0] / 2.0, o.size[2] / 2.0];
                for &(p, r) in &spheres {
                    let r = r as f32;
                    let l = geom::to_local(geom::center(o), o.yaw, [p.x as f32, p.z as f32]);
                    // Box frame: x from the left face, y from the base, z from the back face.
                    let q = [l[0] + half[0], p.y as f32 - o.position[1], l[1] + half[1]];
                    if (0..3).any(|k| q[k] < -r || q[k] > o.size[k] + r) {
                        continue;
                    }
                    for (b, flag) in model[i].iter().zip(hit[i].iter_mut()) {
                        if !*flag && boxes::distance2(q, b) < r * r {
                            *flag = true;
                        }
                    }
                }
            }
        }
    }
    let mut sum = 0.0;
    let (mut boxes, mut collided) = (0usize, 0usize);
    for h in &hit {
        let nc = h.iter().filter(|&&x| x).count();
        if nc > 0 {
            collided += 1;
            boxes += nc;
            sum += nc as f64 / h.len() as f64;
        }
    }
    (if collided > 0 { sum / collided as f64 } else { 0.0 }, boxes, collided)
}

/// C_T (Eq. 2): mean distance (metres) from each contact joint's mean position over its window
/// to its contact point, over all pairs of the animation; and the number of pairs. A character not
/// on the common rig has no contact joints and is left out, as in [`collision_cost`].
pub fn contact_cost(anim: &Animation) -> (f64, usize) {
    let (mut sum, mut count) = (0.0, 0usize);
    for c in &anim.characters {
        let Ok(rig) = Rig::try_of(c.clip.skeleton().clone()) else { continue };
        let sk = &rig.skeleton;
        let (lh, rh) = (rig.arms[0][3], rig.arms[1][3]);
        let (lf, rf) = (rig.fingertip(Side::Left), rig.fingertip(Side::Right));
        for s in &c.segments {
            for jc in &s.contacts {
                let (a, b) = (jc.start.min(c.clip.num_frames()), jc.end.min(c.clip.num_frames()));
                if a >= b {
                    continue;
                }
                let mut mean = DVec3::ZERO;
                for f in a..b {
                    let g = forward(sk, &c.clip.pose(f));
                    mean += match jc.joint {
                        ContactJoint::Hips => (g.positions[rig.legs[0][0]] + g.positions[rig.legs[1][0]]) * 0.5,
                        ContactJoint::LeftWrist => g.positions[lh],
                        ContactJoint::RightWrist => g.positions[rh],
                        ContactJoint::LeftFinger => g.positions[lf],
                        ContactJoint::RightFinger => g.positions[rf],
                    };
                }
                mean /= (b - a) as f64;
                let p = DVec3::new(jc.point[0] as f64, jc.point[1] as f64, jc.point[2] as f64);
                sum += (mean - p).length();
                count += 1;
            }
        }
    }
    (if count > 0 { sum / count as f64 } else { 0.0 }, count)
}

/// All costs of an animation (Eq. 1–3).
pub fn costs(anim: &Animation, cfg: &OptimizeConfig) -> Costs {
    let (cd, boxes, objects) = collision_cost(anim, cfg.box_size);
    let (ct, pairs) = contact_cost(anim);
    Costs {
        collision: cd,
        contact: ct,
        total: cfg.lambda_d * cd + cfg.lambda_t * ct,
        collided_boxes: boxes,
        collided_objects: objects,
        contact_pairs: pairs,
    }
}

/// The objects the annealing moves: targets of segments with contacts, the objects related to
/// them (layout relations, support either way); wall- and ceiling-hung objects stay.
pub fn movable_objects(anim: &Animation, relations: &[(Relation, usize, usize)], cat: &Catalogue) -> Vec<usize> {
    let objs = &anim.scene.objects;
    let mut interactive: Vec<usize> = anim
        .characters
        .iter()
        .flat_map(|c| c.segments.iter())
        .filter(|s| !s.contacts.is_empty())
        .filter_map(|s| s.object)
        .collect();
    interactive.sort_unstable();
    interactive.dedup();
    let mut set = interactive.clone();
    for &i in &interactive {
        for &(_, a, b) in relations {
            if a == i {
                set.push(b);
            } else if b == i {
                set.push(a);
            }
        }
        set.extend(objs[i].support);
        set.extend((0..objs.len()).filter(|&j| objs[j].support == Some(i)));
    }
    set.sort_unstable();
    set.dedup();
    set.retain(|&i| {
        i < objs.len()
            && !matches!(cat.get(&objs[i].category).map(|c| c.support), Some(Support::Wall | Support::Ceiling))
    });
    set
}

/// A draw from N(0, σ²) truncated to ±3σ.
fn truncated_normal(rng: &mut impl Rng, sigma: f64) -> f64 {
    loop {
        let x = inbetween_core::seed::normal(rng);
        if x.abs() <= 3.0 {
            return x * sigma;
        }
    }
}

/// Moves object `k` by (dx, dz), scales its height by `s`; whatever rests on it (transitively)
/// moves along and sits on its support's (new) top, or on the same shelf of it.
fn disturb(objects: &mut [PlacedObject], k: usize, dx: f32, dz: f32, s: f32) {
    let n = objects.len();
    let mut carried = vec![false; n];
    carried[k] = true;
    for _ in 0..n {
        let mut changed = false;
        for i in 0..n {
            if !carried[i] && objects[i].support.is_some_and(|p| p < n && carried[p]) {
                carried[i] = true;
                changed = true;
            }
        }
        if !changed {
            break;
        }
    }
    for (i, o) in objects.iter_mut().enumerate() {
        if carried[i] {
            o.position[0] += dx;
            o.position[2] += dz;
        }
    }
    // Where each carried object rests on its support, as a fraction of the support's height (1 on
    // its top, less on a shelf inside it), kept as the support is scaled.
    let level: Vec<f32> = (0..n)
        .map(|i| match objects[i].support.filter(|&p| p < n && carried[p]) {
            Some(p) if objects[p].size[1] > 1e-6 => {
                (objects[i].position[1] - objects[p].position[1]) / objects[p].size[1]
            }
            _ => 1.0,
        })
        .collect();
    objects[k].size[1] *= s;
    for _ in 0..n {
        let mut changed = false;
        for i in 0..n {
            if let Some(p) = objects[i].support.filter(|&p| p < n && carried[p]) {
                let y = if (level[i] - 1.0).abs() < 1e-6 {
                    objects[p].top()
                } else {
                    objects[p].position[1] + level[i] * objects[p].size[1]
                };
                if (objects[i].position[1] - y).abs() > 1e-6 {
                    objects[i].position[1] = y;
                    changed = true;
                }
            }
        }
        if !changed {
            break;
        }
    }
}

/// Whether `v` is no worse than `base` in every kind of violation.
fn no_worse(v: &Violations, base: &Violations) -> bool {
    v.overlaps.len() <= base.overlaps.len()
        && v.unmet.len() <= base.unmet.len()
        && v.outside.len() <= base.outside.len()
        && v.unreachable.len() <= base.unreachable.len()
}

/// Algorithm 2 on a composition (see the module comment).
pub fn optimize(
    comp: &Composition,
    cat: &Catalogue,
    lib: &MotionLibrary,
    acfg: &AnimateConfig,
    cfg: &OptimizeConfig,
) -> Optimized {
    optimize_scene(&comp.scene, &comp.query, &comp.relations, cat, lib, acfg, cfg)
}

/// [`optimize`] on a scene, its query graph and its layout relations (object indices).
pub fn optimize_scene(
    scene: &Scene,
    query: &Ssg,
    relations: &[(Relation, usize, usize)],
    cat: &Catalogue,
    lib: &MotionLibrary,
    acfg: &AnimateConfig,
    cfg: &OptimizeConfig,
) -> Optimized {
    let cancel = inbetween_core::cancel::Cancel::new();
    optimize_scene_in(&Setup { cat, lib, cfg: acfg, cancel: &cancel }, scene, query, relations, cfg)
}

/// [`optimize_scene`] with `setup`'s cancel token: once it is cancelled every further state is
/// refused at once (the annealing runs out its remaining iterations without animating; the
/// caller discards the result).
pub(crate) fn optimize_scene_in(
    setup: &Setup,
    scene: &Scene,
    query: &Ssg,
    relations: &[(Relation, usize, usize)],
    cfg: &OptimizeConfig,
) -> Optimized {
    let mut cache = WalkCache::default();
    let none = HashMap::new();
    let anim0 = animate_planned(setup, scene, query, &mut cache, &none).animation;
    let before = costs(&anim0, cfg);
    let movable = movable_objects(&anim0, relations, setup.cat);
    anneal(scene, relations, cfg, anim0, before, movable, &mut |s: &Scene| {
        (!setup.cancel.is_cancelled()).then(|| animate_planned(setup, s, query, &mut cache, &none).animation)
    })
}

/// The annealing of Algorithm 2 from `scene` (animated as `anim0`, with costs `before`), moving
/// only the objects in `movable`; `animate` animates a disturbed scene, or refuses it (None: the
/// move is rejected like one that breaks the layout). The incremental editor
/// ([`crate::story_session`]) restricts `movable` to the objects of the characters it
/// re-solves.
#[allow(clippy::too_many_arguments)]
pub(crate) fn anneal(
    scene: &Scene,
    relations: &[(Relation, usize, usize)],
    cfg: &OptimizeConfig,
    anim0: Animation,
    before: Costs,
    movable: Vec<usize>,
    animate: &mut dyn FnMut(&Scene) -> Option<Animation>,
) -> Optimized {
    let base_violations = layout::check(&scene.room, &scene.objects, relations);
    let mut rng = inbetween_core::seed::rng(cfg.seed);
    let mut cur = (scene.clone(), before);
    let mut best = (anim0, before);
    let mut curves = CostCurves {
        collision: vec![before.collision],
        contact: vec![before.contact],
        total: vec![before.total],
        best: vec![before.total],
        accepted: vec![true],
    };
    let mut rejected_layout = 0;
    for it in 0..cfg.iterations {
        let unit = cfg.relative_temperature.map_or(1.0, |f| f * before.total.max(1e-9));
        let t = ((cfg.initial_temperature - cfg.cooling * it as f64) * unit).max(1e-12);
        let mut accepted = false;
        if !movable.is_empty() {
            let k = movable[rng.random_range(0..movable.len())];
            let dx = truncated_normal(&mut rng, cfg.sigma) as f32;
            let dz = truncated_normal(&mut rng, cfg.sigma) as f32;
            let s = (1.0 + truncated_normal(&mut rng, cfg.sigma)) as f32;
            let u: f64 = rng.random_range(0.0..1.0);
            let mut cand = cur.0.clone();
            disturb(&mut cand.objects, k, dx, dz, s);
            let v = layout::check(&cand.room, &cand.objects, relations);
            match no_worse(&v, &base_violations).then(|| animate(&cand)).flatten() {
                Some(anim) => {
                    let c = costs(&anim, cfg);
                    let delta = c.total - cur.1.total;
                    if delta <= 0.0 || u < (-delta / t).exp() {
                        accepted = true;
                        if c.total < best.1.total {
                            best = (anim, c);
                        }
                        cur = (cand, c);
                    }
                }
                None => rejected_layout += 1,
            }
        }
        curves.collision.push(cur.1.collision);
        curves.contact.push(cur.1.contact);
        curves.total.push(cur.1.total);
        curves.best.push(best.1.total);
        curves.accepted.push(accepted);
    }
    let (animation, after) = best;
    Optimized { scene: animation.scene.clone(), animation, before, after, curves, movable, rejected_layout }
}

/// The cost curves as a Fig. 12-style line chart (C_D, C_T, C of the current state and the best
/// C so far, per iteration), PNG.
pub fn plot_costs(path: &Path, curves: &CostCurves) -> Result<(), ScriptError> {
    use inbetween_render::plot::{line_plot, Series};
    let s = |name: &str, v: &[f64]| Series::new(name, v.iter().enumerate().map(|(i, &y)| (i as f64, y)).collect());
    let series = [
        s("C_D (collision)", &curves.collision),
        s("C_T (contact, m)", &curves.contact),
        s("C = C_D + 10 C_T", &curves.total),
        s("best C", &curves.best),
    ];
    line_plot(path, "Scene layout and motion optimisation", "iteration", "cost", &series)
        .map_err(|e| ScriptError::Asset { path: path.to_path_buf(), message: e.to_string() })
}
