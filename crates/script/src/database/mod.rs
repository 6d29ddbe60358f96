//! The scene database (§3.2): scenes saved as SSGs with object categories, sizes and placements.
//! Hand-authored rooms (office, bedroom, living room, gallery, music room, meeting room, workshop,
//! boxing gym) plus seeded variations of them. The paper indexes 133 scenes of SceneNN,
//! SceneSynth and 3D-FRONT; we author the rooms its figures show and vary them.
//!
//! Relation nodes are derived from the placements ([`derive_relations`]), so every scene's graph
//! agrees with its geometry by construction, variations included.

pub mod geometry;
mod scenes;

use rand::Rng;
use serde::{Deserialize, Serialize};

pub use geometry::{derive_relations, holds};

use crate::catalogue::{Catalogue, Support};
use crate::scene::Room;
use crate::ssg::{NodeId, ObjectNode, Relation, Ssg};

/// Where a database object stands: footprint centre at its base (x, y, z) and yaw, metres/radians,
/// in its room's frame. Indexed like the scene's SSG object nodes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Placement {
    pub position: [f32; 3],
    pub yaw: f32,
    /// Size in metres (width, height, depth): the category's default unless the scene scales it.
    pub size: [f32; 3],
}

/// One database scene.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DbScene {
    pub name: String,
    pub room: Room,
    /// Its SSG: one object node per object (count 1), relation nodes between them.
    pub ssg: Ssg,
    /// `placements[i]` places `ssg.objects[i]`.
    pub placements: Vec<Placement>,
}

impl DbScene {
    /// Whether `rel` holds between two of its objects, by geometry (a relation node implies it;
    /// geometry also answers the weaker relations a more specific node hides, e.g. Near under NextTo).
    pub fn relation_holds(&self, rel: Relation, active: NodeId, anchor: NodeId) -> bool {
        active != anchor && holds(rel, &self.placements[active], &self.placements[anchor])
    }

    /// What is wrong with the scene, empty when nothing: objects outside the room, pairs that
    /// interpenetrate (an `In` pair may: containers are hollow), relation nodes that do not hold.
    pub fn problems(&self) -> Vec<String> {
        let mut out = Vec::new();
        let label = |i: usize| format!("{} #{i}", self.ssg.objects[i].category);
        for (i, p) in self.placements.iter().enumerate() {
            if !geometry::inside_room(p, &self.room) {
                out.push(format!("{}: {} outside the room", self.name, label(i)));
            }
            for (j, q) in self.placements.iter().enumerate().skip(i + 1) {
                if geometry::overlaps(p, q) && !holds(Relation::In, p, q) && !holds(Relation::In, q, p) {
                    out.push(format!("{}: {} overlaps {}", self.name, label(i), label(j)));
                }
            }
        }
        for r in &self.ssg.relations {
            if !self.relation_holds(r.relation, r.active, r.anchor) {
                out.push(format!(
                    "{}: {} {} {} does not hold",
                    self.name,
                    label(r.active),
                    r.relation.phrase(),
                    label(r.anchor)
                ));
            }
        }
        out
    }
}

/// All database scenes.
#[derive(Debug, Clone, Default)]
pub struct SceneDatabase {
    pub scenes: Vec<DbScene>,
}

impl SceneDatabase {
    /// The eight authored rooms, each followed by `variations_per_room` seeded variations
    /// ([`vary`]). Same seed, same database.
    ///
    /// Placements use the built-in box sizes whatever `cat` says (its Kenney-measured sizes
    /// included), so the database, its relations and its soundness do not depend on which models
    /// are installed; layout re-sizes what it places.
    pub fn builtin(cat: &Catalogue, variations_per_room: usize, seed: u64) -> SceneDatabase {
        let boxes = crate::catalogue::builtin::builtin();
        let cat = if cat.categories().iter().all(|c| boxes.get(&c.name).is_some_and(|b| b.size == c.size)) {
            cat
        } else {
            &boxes
        };
        let mut scenes = Vec::new();
        for (r, a) in scenes::authored(cat).into_iter().enumerate() {
            let base = to_scene(a.name.to_string(), a.room, &a.items);
            scenes.push(base.clone());
            for v in 1..=variations_per_room {
                let s = inbetween_core::seed::derive(seed, (r * 10_000 + v) as u64);
                let mut varied = vary(&base, cat, s);
                varied.name = format!("{}-v{v}", base.name);
                scenes.push(varied);
            }
        }
        SceneDatabase { scenes }
    }

    /// A scene by name.
    pub fn find(&self, name: &str) -> Option<&DbScene> {
        self.scenes.iter().find(|s| s.name == name)
    }
}

/// The authored relations of the hand-made rooms: (scene name, active, relation, anchor). The
/// tests check that each holds and appears among the derived relation nodes' implications.
pub fn authored_relations(cat: &Catalogue) -> Vec<(String, NodeId, Relation, NodeId)> {
    scenes::authored(cat)
        .into_iter()
        .flat_map(|a| a.intended.into_iter().map(move |(x, r, y)| (a.name.to_string(), x, r, y)))
        .collect()
}

/// An object while a scene is authored or varied: its parent is what it rests on or sits in, so
/// moving or resizing the parent carries it along.
#[derive(Debug, Clone)]
pub(crate) struct Item {
    pub category: String,
    pub attributes: Vec<String>,
    pub position: [f32; 3],
    pub yaw: f32,
    pub size: [f32; 3],
    pub parent: Option<usize>,
}

impl Item {
    fn placement(&self) -> Placement {
        Placement { position: self.position, yaw: self.yaw, size: self.size }
    }
}

fn to_scene(name: String, room: Room, items: &[Item]) -> DbScene {
    let placements: Vec<Placement> = items.iter().map(Item::placement).collect();
    let objects = items
        .iter()
        .map(|it| ObjectNode {
            category: it.category.clone(),
            attributes: it.attributes.clone(),
            count: 1,
            word: it.category.clone(),
            sentence: 0,
        })
        .collect();
    let relations = derive_relations(&placements);
    let ssg = Ssg { room: Some(room.name.clone()), objects, relations, ..Ssg::default() };
    DbScene { name, room, ssg, placements }
}

/// Recovers parents from geometry: the object something rests on (the highest), else sits in.
fn items_of(scene: &DbScene) -> Vec<Item> {
    let p = &scene.placements;
    (0..p.len())
        .map(|i| {
            let on = (0..p.len())
                .filter(|&j| j != i && holds(Relation::On, &p[i], &p[j]))
                .max_by(|&a, &b| (p[a].position[1] + p[a].size[1]).total_cmp(&(p[b].position[1] + p[b].size[1])));
            let parent = on.or_else(|| (0..p.len()).find(|&j| j != i && holds(Relation::In, &p[i], &p[j])));
            let o = &scene.ssg.objects[i];
            Item {
                category: o.category.clone(),
                attributes: o.attributes.clone(),
                position: p[i].position,
                yaw: p[i].yaw,
                size: p[i].size,
                parent,
            }
        })
        .collect()
}

/// Children follow their parents' moves (dx, dz) recursively.
fn move_tree(items: &mut [Item], root: usize, dx: f32, dz: f32) {
    items[root].position[0] += dx;
    items[root].position[2] += dz;
    for c in 0..items.len() {
        if items[c].parent == Some(root) && c != root {
            move_tree(items, c, dx, dz);
        }
    }
}

/// Puts every object resting on something back on its parent's top (after a resize).
fn settle(items: &mut [Item], old: &[Item]) {
    for _ in 0..4 {
        for i in 0..items.len() {
            if let Some(p) = items[i].parent {
                let was_on = (old[i].position[1] - (old[p].position[1] + old[p].size[1])).abs() <= geometry::EPS;
                if was_on {
                    items[i].position[1] = items[p].position[1] + items[p].size[1];
                }
            }
        }
    }
}

fn valid(items: &[Item], room: &Room) -> bool {
    let ps: Vec<Placement> = items.iter().map(Item::placement).collect();
    for (i, it) in items.iter().enumerate() {
        if !geometry::inside_room(&ps[i], room) {
            return false;
        }
        if let Some(p) = it.parent {
            if !holds(Relation::On, &ps[i], &ps[p]) && !holds(Relation::In, &ps[i], &ps[p]) {
                return false;
            }
        }
        for j in i + 1..items.len() {
            if geometry::overlaps(&ps[i], &ps[j])
                && !holds(Relation::In, &ps[i], &ps[j])
                && !holds(Relation::In, &ps[j], &ps[i])
            {
                return false;
            }
        }
    }
    true
}

/// Removes item `i` and everything resting on or in it, renumbering parents.
fn remove_tree(items: &mut Vec<Item>, i: usize) {
    let mut gone = vec![false; items.len()];
    gone[i] = true;
    for _ in 0..4 {
        for c in 0..items.len() {
            if let Some(p) = items[c].parent {
                if gone[p] {
                    gone[c] = true;
                }
            }
        }
    }
    let mut new_index = vec![usize::MAX; items.len()];
    let mut n = 0;
    for (k, g) in gone.iter().enumerate() {
        if !g {
            new_index[k] = n;
            n += 1;
        }
    }
    let mut k = 0;
    items.retain(|_| {
        k += 1;
        !gone[k - 1]
    });
    for it in items.iter_mut() {
        it.parent = it.parent.map(|p| new_index[p]);
    }
}

/// Small things that variations add on surfaces, and floor things they add in free space.
const SURFACE_ADDS: [&str; 7] = ["cup", "book", "vase", "bottle", "phone", "lamp", "laptop"];
const FLOOR_ADDS: [&str; 5] = ["plant", "trashcan", "floorlamp", "stool", "box"];

/// A seeded variation of a scene: maybe mirrored, categories swapped within their class (a desk
/// for a table, an armchair for a chair), floor groups jittered, objects dropped and added. Each
/// change is kept only if the scene stays valid (inside the room, no interpenetration, children
/// still on their parents); relation nodes are then derived again from the new placements.
pub fn vary(base: &DbScene, cat: &Catalogue, seed: u64) -> DbScene {
    let mut rng = inbetween_core::seed::rng(seed);
    let room = &base.room;
    let mut items = items_of(base);
    let try_change = |items: &mut Vec<Item>, next: Vec<Item>| {
        if valid(&next, room) {
            *items = next;
        }
    };
    if rng.random_bool(0.5) {
        let next = items
            .iter()
            .map(|it| {
                let mut it = it.clone();
                it.position[0] = room.width - it.position[0];
                it.yaw = -it.yaw;
                it
            })
            .collect();
        try_change(&mut items, next);
    }
    for i in 0..items.len() {
        if !rng.random_bool(0.3) {
            continue;
        }
        let class = cat.class_of(&items[i].category).to_string();
        let support = cat.get(&items[i].category).map(|c| c.support);
        let mates: Vec<_> = cat
            .categories()
            .iter()
            .filter(|c| c.name != items[i].category && cat.class_of(&c.name) == class && Some(c.support) == support)
            .collect();
        if mates.is_empty() {
            continue;
        }
        let mate = mates[rng.random_range(0..mates.len())];
        let mut next = items.clone();
        next[i].category = mate.name.clone();
        next[i].size = mate.size;
        if mate.support == Support::Wall {
            // Keep the wall side: a thinner or thicker board stays against the wall.
            let h = geometry::half_xz(&next[i].placement());
            let old = geometry::half_xz(&items[i].placement());
            let (s, c) = next[i].yaw.sin_cos();
            if s.abs() > 0.5 {
                next[i].position[0] += (h[0] - old[0]) * s.signum();
            }
            if c.abs() > 0.5 {
                next[i].position[2] += (h[1] - old[1]) * c.signum();
            }
        }
        settle(&mut next, &items);
        try_change(&mut items, next);
    }
    for i in 0..items.len() {
        let floor =
            items[i].parent.is_none() && cat.get(&items[i].category).is_some_and(|c| c.support == Support::Floor);
        if !floor {
            continue;
        }
        let dx = (inbetween_core::seed::normal(&mut rng) * 0.12).clamp(-0.3, 0.3) as f32;
        let dz = (inbetween_core::seed::normal(&mut rng) * 0.12).clamp(-0.3, 0.3) as f32;
        let mut next = items.clone();
        move_tree(&mut next, i, dx, dz);
        try_change(&mut items, next);
    }
    let mut i = 0;
    while i < items.len() {
        if items.len() > 6 && rng.random_bool(0.12) {
            remove_tree(&mut items, i);
        } else {
            i += 1;
        }
    }
    let adds = rng.random_range(1..=2);
    for _ in 0..adds {
        for _attempt in 0..10 {
            let mut next = items.clone();
            let surfaces: Vec<usize> = (0..items.len())
                .filter(|&k| cat.get(&items[k].category).is_some_and(|c| c.surface) && items[k].parent.is_none())
                .collect();
            if !surfaces.is_empty() && rng.random_bool(0.6) {
                let p = surfaces[rng.random_range(0..surfaces.len())];
                let name = SURFACE_ADDS[rng.random_range(0..SURFACE_ADDS.len())];
                let Some(c) = cat.get(name) else { continue };
                let h = geometry::half_xz(&items[p].placement());
                let x = items[p].position[0] + rng.random_range(-0.8..0.8) * h[0];
                let z = items[p].position[2] + rng.random_range(-0.8..0.8) * h[1];
                let y = items[p].position[1] + items[p].size[1];
                next.push(Item {
                    category: name.into(),
                    attributes: vec![],
                    position: [x, y, z],
                    yaw: 0.0,
                    size: c.size,
                    parent: Some(p),
                });
            } else {
                let name = FLOOR_ADDS[rng.random_range(0..FLOOR_ADDS.len())];
                let Some(c) = cat.get(name) else { continue };
                let x = rng.random_range(0.3..room.width - 0.3);
                let z = rng.random_range(0.3..room.depth - 0.3);
                next.push(Item {
                    category: name.into(),
                    attributes: vec![],
                    position: [x, 0.0, z],
                    yaw: 0.0,
                    size: c.size,
                    parent: None,
                });
            }
            if valid(&next, room) {
                items = next;
                break;
            }
        }
    }
    to_scene(base.name.clone(), room.clone(), &items)
}
