//! The constructive search of [`solve`]: items placed in relation-graph order, each at the best
//! of its candidate poses, restarted with derived seeds (see the parent module).

use super::*;

/// The best layout found: items placed in relation-graph order, restarted with derived seeds
/// while items were dropped or violations remain (at most [`ATTEMPTS`] runs).
pub fn solve(problem: &LayoutProblem, seed: u64) -> LayoutOutcome {
    let order = placement_order(problem);
    let mut best: Option<(usize, usize, LayoutOutcome)> = None;
    for attempt in 0..ATTEMPTS {
        let out = Solver::new(problem, inbetween_core::seed::rng(inbetween_core::seed::derive(seed, attempt as u64)))
            .run(&order);
        let key = (out.dropped.len(), out.violations.total());
        if best.as_ref().is_none_or(|(d, v, _)| key < (*d, *v)) {
            let done = key == (0, 0);
            best = Some((key.0, key.1, out));
            if done {
                break;
            }
        }
    }
    best.map(|b| b.2).expect("at least one attempt")
}

/// Restarts of the constructive search (each with its own derived seed).
pub const ATTEMPTS: usize = 6;

/// Pinned items first, then supports before what rests on them, anchors before their actives
/// (longest anchor chain), floor objects before wall, ceiling and surface ones, bigger footprints
/// first.
fn placement_order(p: &LayoutProblem) -> Vec<usize> {
    let n = p.items.len();
    // Longest chain of `edges` (active, anchor) above each item, relaxed n times so cycles stay
    // bounded.
    let chain = |edges: &[(usize, usize)]| {
        let mut depth = vec![0usize; n];
        for _ in 0..n {
            let mut changed = false;
            for &(active, anchor) in edges {
                if active < n
                    && anchor < n
                    && active != anchor
                    && depth[active] < depth[anchor] + 1
                    && depth[anchor] < n
                {
                    depth[active] = depth[anchor] + 1;
                    changed = true;
                }
            }
            if !changed {
                break;
            }
        }
        depth
    };
    // Supports first: what stands on something ("On", or a database pose resting on another's
    // top: a lamp whose hint stands on the nightstand's) comes after it, so its pose finds its
    // support. Resting goes strictly upwards, so these chains have no cycles.
    let mut supports: Vec<(usize, usize)> =
        p.relations.iter().filter(|c| c.relation == Relation::On).map(|c| (c.active, c.anchor)).collect();
    let object = |i: usize, h: &crate::database::Placement| PlacedObject {
        label: String::new(),
        category: p.items[i].category.clone(),
        attributes: Vec::new(),
        position: h.position,
        yaw: h.yaw,
        size: h.size,
        support: None,
        origin: p.items[i].origin.clone(),
    };
    for (a, ia) in p.items.iter().enumerate() {
        let Some(ha) = ia.hint.as_ref().filter(|h| h.position[1] > EPS) else { continue };
        let oa = object(a, ha);
        for (b, ib) in p.items.iter().enumerate() {
            let Some(hb) = ib.hint.as_ref().filter(|_| a != b && ib.surface) else { continue };
            let ob = object(b, hb);
            if (oa.position[1] - ob.top()).abs() <= EPS && geom::center_inside(&oa, &ob) {
                supports.push((a, b));
            }
        }
    }
    let support_depth = chain(&supports);
    // Then anchors before their actives.
    let mut edges: Vec<(usize, usize)> = p.relations.iter().map(|c| (c.active, c.anchor)).collect();
    for pl in &p.places {
        if let RoomPlace::Between(a, b) = pl.place {
            edges.extend([(pl.item, a), (pl.item, b)]);
        }
    }
    let depth = chain(&edges);
    // A floor object the script relates to something resting on another ("an armchair facing the
    // TV" on a cabinet) waits for it: it counts one deeper in supports than its anchor (database
    // furnishing keeps its order).
    let mut support_depth = support_depth;
    for c in &p.relations {
        let script = |i: usize| matches!(p.items[i].origin, Origin::Script { .. });
        if c.active < n
            && c.anchor < n
            && script(c.active)
            && p.items[c.active].support == Support::Floor
            && support_depth[c.anchor] > 0
        {
            support_depth[c.active] = support_depth[c.active].max(support_depth[c.anchor] + 1);
        }
    }
    let rank = |s: Support| match s {
        Support::Floor => 0,
        Support::Wall => 1,
        Support::Ceiling => 2,
        Support::Surface => 3,
    };
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| {
        let (ia, ib) = (&p.items[a], &p.items[b]);
        let area = |i: &LayoutItem| i.size[0] * i.size[2];
        (ia.pinned.is_none(), support_depth[a], depth[a], rank(ia.support))
            .cmp(&(ib.pinned.is_none(), support_depth[b], depth[b], rank(ib.support)))
            .then(area(ib).total_cmp(&area(ia)))
            .then(a.cmp(&b))
    });
    order
}

/// A side of an object, in its own frame.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Side {
    Front,
    Back,
    /// Its own left (+x of its frame).
    Left,
    Right,
}

const SIDES: [Side; 4] = [Side::Front, Side::Back, Side::Left, Side::Right];

/// The gap "opposite" and "facing" aim at, metres (a desk across from a bed, an armchair facing
/// the TV).
const ACROSS_GAP: f32 = 1.5;

/// How a pose beside an object is turned.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Face {
    /// Its front to the object.
    Toward,
    /// Its back to the object.
    Away,
    /// As the object is turned.
    Same,
}

/// A candidate placement of one item: where it stands, how it is turned, what it rests on, and the
/// penalty of the candidate rule that proposed it.
#[derive(Debug, Clone, Copy)]
struct Placement {
    position: [f32; 3],
    yaw: f32,
    /// Item index it rests on.
    support: Option<usize>,
    penalty: f32,
}

/// One run of the constructive search.
struct Solver<'a, R: Rng> {
    p: &'a LayoutProblem,
    rng: R,
    /// Per item: its pose once placed (`support` there is an item index).
    poses: Vec<Option<PlacedObject>>,
    dropped: Vec<(usize, String)>,
}

/// Candidates whose walkability is tested per item (the best-scoring ones first).
const REACH_TESTS: usize = 40;
/// Door area kept clear of floor objects when possible: half width, depth (metres).
const DOOR_ZONE: [f32; 2] = [0.5, 0.9];

const QUARTER: f32 = std::f32::consts::FRAC_PI_2;
const HALF: f32 = std::f32::consts::PI;

/// Yaw in (-π, π].
fn wrap(yaw: f32) -> f32 {
    let mut y = yaw % std::f32::consts::TAU;
    if y <= -HALF {
        y += std::f32::consts::TAU;
    } else if y > HALF {
        y -= std::f32::consts::TAU;
    }
    y
}

impl<'a, R: Rng> Solver<'a, R> {
    fn new(p: &'a LayoutProblem, rng: R) -> Self {
        Solver { p, rng, poses: vec![None; p.items.len()], dropped: Vec::new() }
    }

    fn run(mut self, order: &[usize]) -> LayoutOutcome {
        for &i in order {
            self.place(i);
            self.repair(i);
        }
        self.settle_pinned_supports();
        self.finish()
    }

    /// Pinned items are placed first, not in support order, so one resting on a surface pinned
    /// after it found no support when placed: look again once everything stands (an edit's
    /// re-run must give the same supports as the first run).
    fn settle_pinned_supports(&mut self) {
        for i in 0..self.p.items.len() {
            if self.p.items[i].pinned.is_none() {
                continue;
            }
            let Some((position, yaw)) =
                self.poses[i].as_ref().filter(|o| o.support.is_none()).map(|o| (o.position, o.yaw))
            else {
                continue;
            };
            let support = self.support_at(i, position, yaw);
            if let Some(o) = self.poses[i].as_mut() {
                o.support = support;
            }
        }
    }

    /// Relations with `i` as the active end that are live and unmet.
    fn unmet_as_active(&self, i: usize) -> Vec<LayoutConstraint> {
        let Some(o) = self.poses[i].as_ref() else { return Vec::new() };
        self.live_relations(i)
            .into_iter()
            .filter(|c| c.active == i && !relation_holds(c.relation, o, self.poses[c.anchor].as_ref().expect("live")))
            .collect()
    }

    /// Local repair: when item `i` could not meet a relation to its anchor, move the anchor (if
    /// nothing else leans on it) next to `i` and place `i` again; kept only if it helps.
    fn repair(&mut self, i: usize) {
        let unmet = self.unmet_as_active(i);
        let Some(c) = unmet.first() else { return };
        let j = c.anchor;
        if self.p.items[j].pinned.is_some() {
            return;
        }
        let others_lean = self
            .poses
            .iter()
            .enumerate()
            .any(|(k, o)| k != i && k != j && o.as_ref().is_some_and(|o| o.support == Some(j)))
            || self.p.relations.iter().any(|r| {
                let other = if r.anchor == j {
                    r.active
                } else if r.active == j {
                    r.anchor
                } else {
                    return false;
                };
                other != i && self.poses[other].is_some()
            });
        if others_lean {
            return;
        }
        let (poses, dropped) = (self.poses.clone(), self.dropped.clone());
        self.poses[j] = None;
        self.place(j);
        self.poses[i] = None;
        self.place(i);
        let ok = self.poses[i].is_some() && self.poses[j].is_some() && self.unmet_as_active(i).len() < unmet.len();
        if !ok {
            self.poses = poses;
            self.dropped = dropped;
        }
    }

    fn object(&self, i: usize, pose: &Placement) -> PlacedObject {
        let it = &self.p.items[i];
        PlacedObject {
            label: it.label.clone(),
            category: it.category.clone(),
            attributes: it.attributes.clone(),
            position: pose.position,
            yaw: wrap(pose.yaw),
            size: it.size,
            support: pose.support,
            origin: it.origin.clone(),
        }
    }

    /// Relations touching item `i` whose other end is placed: (relation, active, anchor).
    fn live_relations(&self, i: usize) -> Vec<LayoutConstraint> {
        let n = self.p.items.len();
        self.p
            .relations
            .iter()
            .filter(|c| c.active < n && c.anchor < n && c.active != c.anchor)
            .filter(|c| {
                (c.active == i && self.poses[c.anchor].is_some()) || (c.anchor == i && self.poses[c.active].is_some())
            })
            .copied()
            .collect()
    }

    fn place(&mut self, i: usize) {
        let item = &self.p.items[i];
        let r = &self.p.room;
        let finite = |v: &[f32]| v.iter().all(|x| x.is_finite() && *x > 0.0);
        if !finite(&[r.width, r.depth, r.height]) {
            self.dropped.push((
                i,
                format!(
                    "cannot place '{}': the room's size {} × {} × {} m is not usable",
                    item.label, r.width, r.depth, r.height
                ),
            ));
            return;
        }
        if !finite(&item.size) {
            self.dropped.push((i, format!("cannot place '{}': its size {:?} m is not usable", item.label, item.size)));
            return;
        }
        if let Some((position, yaw)) = item.pinned {
            let support = self.support_at(i, position, yaw);
            self.poses[i] = Some(self.object(i, &Placement { position, yaw, support, penalty: 0.0 }));
            return;
        }
        let live = self.live_relations(i);
        let mut cands = self.candidates(i, &live);
        // Score: unmet relations dominate, then the candidate's own penalty.
        let mut scored: Vec<(f32, PlacedObject)> = Vec::with_capacity(cands.len());
        for pose in cands.drain(..) {
            let obj = self.object(i, &pose);
            if !inside_room(&self.p.room, &obj)
                || self.collides(i, &obj)
                || !self.rests(i, obj.position, obj.yaw, obj.support)
            {
                continue;
            }
            // The constraint's (active, anchor) objects with the candidate in its place.
            let pair = |c: &LayoutConstraint| {
                if c.active == i {
                    (&obj, self.poses[c.anchor].as_ref().expect("live"))
                } else {
                    (self.poses[c.active].as_ref().expect("live"), &obj)
                }
            };
            let unmet = live.iter().filter(|c| !relation_holds(c.relation, pair(c).0, pair(c).1)).count();
            let loose = live.iter().filter(|c| !strictly_holds(c.relation, pair(c).0, pair(c).1)).count();
            // The authored pose is kept whenever the shared definitions hold there.
            let tidy = if pose.penalty < 0.0 { 0.0 } else { 2.0 * loose as f32 };
            // "In front of X" faces X (a chair in front of a desk is turned to it).
            let turned_away = live
                .iter()
                .filter(|c| c.relation == Relation::InFrontOf && self.faces(c.active))
                .filter(|c| geom::facing_angle(pair(c).0, pair(c).1) > geom::FACING_TOLERANCE_DEG)
                .count();
            let away = self
                .p
                .places
                .iter()
                .filter(|pl| pl.item == i && !place_holds(pl.place, &obj, &self.p.room, |k| self.poses[k].as_ref()))
                .count();
            let mut score = 100.0 * (unmet + away) as f32 + tidy + pose.penalty + 10.0 * turned_away as f32;
            if grid::blocks_walking(&obj) && self.in_door_zone(&obj) {
                // Furnishing never stands in the doorway; the script's own objects only when no
                // other place meets their relations.
                if matches!(self.p.items[i].origin, Origin::Database { .. }) {
                    continue;
                }
                score += 150.0;
            }
            scored.push((score, obj));
        }
        scored.sort_by(|a, b| a.0.total_cmp(&b.0));
        let before = self.unreachable_now(None);
        for (_, obj) in scored.into_iter().take(REACH_TESTS) {
            if !grid::blocks_walking(&obj) || self.unreachable_now(Some((i, &obj))).iter().all(|k| before.contains(k)) {
                self.poses[i] = Some(obj);
                return;
            }
        }
        let r = &self.p.room;
        let space = match item.support {
            Support::Floor => "free floor space",
            Support::Surface => "free surface or floor space",
            Support::Wall => "free wall space",
            Support::Ceiling => "free ceiling space",
        };
        self.dropped
            .push((i, format!("no {space} for '{}' in the {:.1} × {:.1} m room", item.label, r.width, r.depth)));
    }

    /// Item indices (placed, plus `extra`) that cannot be walked up to.
    fn unreachable_now(&self, extra: Option<(usize, &PlacedObject)>) -> Vec<usize> {
        let mut ids = Vec::new();
        let mut objs = Vec::new();
        for (k, o) in self.poses.iter().enumerate() {
            if let Some(o) = o {
                ids.push(k);
                objs.push(o.clone());
            }
        }
        if let Some((k, o)) = extra {
            ids.push(k);
            objs.push(o.clone());
        }
        // Supports are item indices here; only their presence matters to reachability.
        let pos = |item: usize| ids.iter().position(|&k| k == item);
        let rels: Vec<(Relation, usize, usize)> =
            self.p.relations.iter().filter_map(|c| Some((c.relation, pos(c.active)?, pos(c.anchor)?))).collect();
        unreachable(&self.p.room, &objs, &rels).into_iter().map(|k| ids[k]).collect()
    }

    fn in_door_zone(&self, o: &PlacedObject) -> bool {
        let d = door(&self.p.room);
        let c = [d[0], d[1] - DOOR_ZONE[1] / 2.0];
        geom::box_penetration(geom::center(o), o.half_extents_xz(), c, [DOOR_ZONE[0], DOOR_ZONE[1] / 2.0]) > 0.0
    }

    /// Whether item `i` is a seat the script names: it turns to face what the script puts it in
    /// front of, and keeps its front free (database seats keep their authored poses and
    /// neighbours).
    fn faces(&self, i: usize) -> bool {
        let it = &self.p.items[i];
        it.seat && matches!(it.origin, Origin::Script { .. })
    }

    /// Whether `obj` (for item `i`) interpenetrates a placed item it is not stacked with, or
    /// stands in the free front of a script seat (or, as one, has something in its own).
    fn collides(&self, i: usize, obj: &PlacedObject) -> bool {
        self.poses.iter().enumerate().any(|(j, o)| {
            let Some(o) = o else { return false };
            let linked = obj.support == Some(j)
                || o.support == Some(i)
                || self.p.relations.iter().any(|c| {
                    let (me, them) = if c.active == i { (obj, o) } else { (o, obj) };
                    ((c.active, c.anchor) == (i, j) || (c.active, c.anchor) == (j, i))
                        && (stacking(c.relation) || super::tucked_pair(c.relation, me, them))
                });
            let (me, them) = (&self.p.items[i], &self.p.items[j]);
            // A seat placed in front of something is there to use it (a stool at a piano): the
            // user's knees go under it, as under a table.
            let uses = |seat: usize, other: usize| {
                self.p.relations.iter().any(|c| {
                    matches!(c.relation, Relation::InFrontOf | Relation::At | Relation::Around)
                        && (c.active, c.anchor) == (seat, other)
                })
            };
            let front = (self.faces(i) && obj.support.is_none() && blocks_seat(obj, o, them.surface || uses(i, j)))
                || (self.faces(j) && o.support.is_none() && blocks_seat(o, obj, me.surface || uses(j, i)));
            !linked && (interpenetrate(obj, o) || front)
        })
    }

    /// The placed surface item a pose at `position` rests on, if any.
    fn support_at(&self, i: usize, position: [f32; 3], yaw: f32) -> Option<usize> {
        if position[1] < 0.05 {
            return None;
        }
        let probe =
            PlacedObject { position, yaw, ..self.object(i, &Placement { position, yaw, support: None, penalty: 0.0 }) };
        self.poses
            .iter()
            .enumerate()
            .filter(|&(j, _)| j != i)
            .find(|(_, o)| o.as_ref().is_some_and(|o| rests_on(&probe, o)))
            .map(|(j, _)| j)
    }

    fn candidates(&mut self, i: usize, live: &[LayoutConstraint]) -> Vec<Placement> {
        let item = &self.p.items[i];
        let mut out = Vec::new();
        if let Some(h) = item.hint.clone() {
            // The database pose, and a few near it, where something holds them up here (a
            // keyboard at desk height is no use where this room has no desk).
            for k in 0..9 {
                let d = if k == 0 {
                    [0.0, 0.0]
                } else {
                    [self.rng.random_range(-0.4..0.4), self.rng.random_range(-0.4..0.4)]
                };
                let position = [h.position[0] + d[0], h.position[1], h.position[2] + d[1]];
                let support = self.support_at(i, position, h.yaw);
                if self.rests(i, position, h.yaw, support) {
                    let penalty = if k == 0 { -1.0 } else { 2.0 * (d[0].hypot(d[1])) };
                    out.push(Placement { position, yaw: h.yaw, support, penalty });
                    // The same place turned to whatever the item stands in front of.
                    let faces =
                        live.iter().filter(|c| c.active == i && c.relation == Relation::InFrontOf && self.faces(i));
                    for c in faces {
                        let Some(a) = &self.poses[c.anchor] else { continue };
                        let face = (a.position[0] - position[0]).atan2(a.position[2] - position[2]);
                        out.push(Placement { position, yaw: face, support, penalty: penalty + 0.5 });
                    }
                }
            }
        }
        for c in live {
            if c.active == i {
                let anchor = self.poses[c.anchor].clone().expect("live relation");
                self.relation_candidates(i, c.relation, c.anchor, &anchor, &mut out);
            } else {
                let active = self.poses[c.active].clone().expect("live relation");
                self.around(i, &active, &mut out);
            }
        }
        let places: Vec<RoomPlace> = self.p.places.iter().filter(|pl| pl.item == i).map(|pl| pl.place).collect();
        for &place in &places {
            self.place_candidates(i, place, &mut out);
        }
        let item = &self.p.items[i];
        let generic_from = out.len();
        let anchors_above_wall =
            self.p.relations.iter().any(|c| {
                c.anchor == i && c.relation == Relation::Above && self.p.items[c.active].support == Support::Wall
            });
        let free = !self.p.relations.iter().any(|c| c.active == i) && places.is_empty();
        match item.support {
            Support::Floor => {
                // Free furniture goes against walls; anchors of wall pictures "above" must.
                let wall_weight = if anchors_above_wall {
                    8.0
                } else if free {
                    0.6
                } else {
                    0.0
                };
                self.wall_candidates(i, 0.0, 10, 0.0, &mut out);
                self.interior_candidates(i, 16, wall_weight, &mut out);
            }
            Support::Surface => {
                self.surface_candidates(i, 6, &mut out);
                let mut floor = Vec::new();
                self.wall_candidates(i, 0.0, 6, 0.0, &mut floor);
                self.interior_candidates(i, 10, 0.0, &mut floor);
                out.extend(floor);
            }
            Support::Wall => {
                let h = item.size[1];
                let y = (WALL_CENTER_HEIGHT - h / 2.0).min(self.p.room.height - h).max(0.0);
                self.wall_candidates(i, y, 12, 0.0, &mut out);
            }
            Support::Ceiling => {
                for _ in 0..24 {
                    let pose = self.random_floor_pose(i);
                    let y = (self.p.room.height - item.size[1]).max(0.0);
                    out.push(Placement { position: [pose.position[0], y, pose.position[2]], ..pose });
                }
            }
        }
        // Poses made for a relation beat generic ones that meet it by chance (a chair that happens
        // to stand in front of the desk but faces away).
        if live.iter().any(|c| c.active == i) || !places.is_empty() {
            for p in &mut out[generic_from..] {
                p.penalty += 1.0;
            }
        }
        // A seat the script puts in front of something may stand anywhere it fits, turned to it.
        if let Some(a) = live.iter().find(|c| c.active == i && c.relation == Relation::InFrontOf && self.faces(i)) {
            if let Some(anchor) = &self.poses[a.anchor] {
                let turned: Vec<Placement> = out
                    .iter()
                    .map(|p| {
                        let face = (anchor.position[0] - p.position[0]).atan2(anchor.position[2] - p.position[2]);
                        Placement { yaw: face, penalty: p.penalty + 0.5, ..*p }
                    })
                    .collect();
                out.extend(turned);
            }
        }
        // Small things belong on a surface: the floor is a last resort, for database furnishing
        // even at the cost of a relation (a laptop or a pillow on the floor looks lost).
        if item.support == Support::Surface {
            let floor = if matches!(item.origin, Origin::Database { .. }) { 150.0 } else { 30.0 };
            for p in out.iter_mut().filter(|p| p.support.is_none()) {
                p.penalty += floor;
            }
        }
        // Tiny seeded jitter breaks ties differently per attempt.
        for p in &mut out {
            p.penalty += self.rng.random_range(0.0..0.01);
        }
        out
    }

    /// Whether item `i` at `position` (turned by `yaw`) is held up: by `support`, else by the
    /// floor (floor and surface items at height 0), a wall (its footprint touching one) or the
    /// ceiling (its top at it).
    fn rests(&self, i: usize, position: [f32; 3], yaw: f32, support: Option<usize>) -> bool {
        if support.is_some() {
            return true;
        }
        let it = &self.p.items[i];
        let r = &self.p.room;
        match it.support {
            Support::Floor | Support::Surface => position[1].abs() <= EPS,
            Support::Wall => {
                let probe = PlacedObject {
                    position,
                    yaw,
                    ..self.object(i, &Placement { position, yaw, support, penalty: 0.0 })
                };
                let [hx, hz] = probe.half_extents_xz();
                let [x, _, z] = position;
                position[1] > 0.0 && [x - hx, r.width - x - hx, z - hz, r.depth - z - hz].iter().any(|g| g.abs() <= EPS)
            }
            Support::Ceiling => (r.height - position[1] - it.size[1]).abs() <= EPS,
        }
    }

    /// The base height an item gets when it is not stacked: floor, wall height or under the ceiling.
    fn rest_height(&self, i: usize) -> f32 {
        let it = &self.p.items[i];
        match it.support {
            Support::Floor | Support::Surface => 0.0,
            Support::Wall => (WALL_CENTER_HEIGHT - it.size[1] / 2.0).min(self.p.room.height - it.size[1]).max(0.0),
            Support::Ceiling => (self.p.room.height - it.size[1]).max(0.0),
        }
    }

    /// Poses with the item's back against each wall, facing into the room, at base height `y`.
    fn wall_candidates(&mut self, i: usize, y: f32, per_wall: usize, penalty: f32, out: &mut Vec<Placement>) {
        let [w, _, d] = self.p.items[i].size;
        let r = &self.p.room;
        // (yaw, wall length, along → world x/z)
        let walls: [(f32, f32); 4] = [(0.0, r.width), (HALF, r.width), (QUARTER, r.depth), (-QUARTER, r.depth)];
        for (k, &(yaw, len)) in walls.iter().enumerate() {
            if len < w {
                continue;
            }
            for s in 0..per_wall {
                let t = if s == 0 {
                    w / 2.0
                } else if s == 1 {
                    len - w / 2.0
                } else {
                    self.rng.random_range(w / 2.0..=len - w / 2.0)
                };
                let (x, z) = match k {
                    0 => (t, d / 2.0),
                    1 => (t, r.depth - d / 2.0),
                    2 => (d / 2.0, t),
                    _ => (r.width - d / 2.0, t),
                };
                out.push(Placement { position: [x, y, z], yaw, support: None, penalty });
            }
        }
    }

    /// A random floor pose facing one of the four axes (turned towards the room centre).
    fn random_floor_pose(&mut self, i: usize) -> Placement {
        let r = &self.p.room;
        let [w, _, d] = self.p.items[i].size;
        let m = w.max(d) / 2.0;
        let x = if r.width > 2.0 * m { self.rng.random_range(m..r.width - m) } else { r.width / 2.0 };
        let z = if r.depth > 2.0 * m { self.rng.random_range(m..r.depth - m) } else { r.depth / 2.0 };
        let (dx, dz) = (r.width / 2.0 - x, r.depth / 2.0 - z);
        let yaw = if dx.abs() > dz.abs() {
            if dx > 0.0 {
                QUARTER
            } else {
                -QUARTER
            }
        } else if dz >= 0.0 {
            0.0
        } else {
            HALF
        };
        Placement { position: [x, 0.0, z], yaw, support: None, penalty: 0.0 }
    }

    /// Random interior poses; `wall_weight` per metre between the item's back and the nearest wall.
    fn interior_candidates(&mut self, i: usize, n: usize, wall_weight: f32, out: &mut Vec<Placement>) {
        for _ in 0..n {
            let mut p = self.random_floor_pose(i);
            p.penalty += wall_weight * self.back_gap(i, &p);
            out.push(p);
        }
    }

    /// Distance from the item's back to the wall behind it.
    fn back_gap(&self, i: usize, p: &Placement) -> f32 {
        let r = &self.p.room;
        let d = self.p.items[i].size[2] / 2.0;
        let f = geom::forward(p.yaw);
        let back = [p.position[0] - f[0] * d, p.position[2] - f[1] * d];
        let along = if f[1].abs() >= f[0].abs() {
            if f[1] > 0.0 {
                back[1]
            } else {
                r.depth - back[1]
            }
        } else if f[0] > 0.0 {
            back[0]
        } else {
            r.width - back[0]
        };
        along.max(0.0)
    }

    /// Poses on top of placed surface items, where the footprint fits.
    fn surface_candidates(&mut self, i: usize, per_surface: usize, out: &mut Vec<Placement>) {
        let [w, _, d] = self.p.items[i].size;
        let surfaces: Vec<(usize, PlacedObject)> = self
            .poses
            .iter()
            .enumerate()
            .filter(|&(j, o)| j != i && o.is_some() && self.p.items[j].surface)
            .map(|(j, o)| (j, o.clone().expect("placed")))
            .collect();
        for (j, s) in surfaces {
            for _ in 0..per_surface {
                let l = [self.random_within(s.size[0], w), self.random_within(s.size[2], d)];
                let c = geom::to_world(geom::center(&s), s.yaw, l);
                out.push(Placement { position: [c[0], s.top(), c[1]], yaw: s.yaw, support: Some(j), penalty: 0.0 });
            }
        }
    }

    /// A random offset that keeps an extent `inner` inside `outer` (0 when it cannot fit).
    fn random_within(&mut self, outer: f32, inner: f32) -> f32 {
        let room = (outer - inner) / 2.0;
        if room > 1e-3 {
            self.rng.random_range(-room..room)
        } else {
            0.0
        }
    }

    /// Poses beside `other` on all four sides at a few gaps and the four yaws (for relations whose
    /// other end is already placed, scored by the relation test).
    fn around(&mut self, i: usize, other: &PlacedObject, out: &mut Vec<Placement>) {
        let [w, _, d] = self.p.items[i].size;
        let y = self.rest_height(i);
        let (ow, od) = (other.size[0] / 2.0, other.size[2] / 2.0);
        for k in 0..4 {
            let yaw = other.yaw + k as f32 * QUARTER;
            let (s, c) = (yaw - other.yaw).sin_cos();
            let h = [w / 2.0 * c.abs() + d / 2.0 * s.abs(), w / 2.0 * s.abs() + d / 2.0 * c.abs()];
            for gap in [0.05, 0.25, 0.7] {
                for l in [
                    [0.0, od + h[1] + gap],
                    [0.0, -(od + h[1] + gap)],
                    [ow + h[0] + gap, 0.0],
                    [-(ow + h[0] + gap), 0.0],
                ] {
                    let p = geom::to_world(geom::center(other), other.yaw, l);
                    out.push(Placement { position: [p[0], y, p[1]], yaw, support: None, penalty: gap });
                }
            }
        }
    }

    /// Poses that make `rel` hold against the placed `anchor` (item `j`).
    fn relation_candidates(
        &mut self,
        i: usize,
        rel: Relation,
        j: usize,
        anchor: &PlacedObject,
        out: &mut Vec<Placement>,
    ) {
        let item = &self.p.items[i];
        let [w, h, d] = item.size;
        let (aw, ad) = (anchor.size[0] / 2.0, anchor.size[2] / 2.0);
        let ac = geom::center(anchor);
        let at = |l: [f32; 2]| geom::to_world(ac, anchor.yaw, l);
        let base = self.rest_height(i);
        let mut push = |p: [f32; 2], y: f32, yaw: f32, support: Option<usize>, penalty: f32| {
            out.push(Placement { position: [p[0], y, p[1]], yaw, support, penalty });
        };
        match rel {
            Relation::On | Relation::Under | Relation::In => {
                let y = match rel {
                    Relation::On => anchor.top(),
                    _ => anchor.position[1],
                };
                let support = (rel == Relation::On).then_some(j);
                push(at([0.0, 0.0]), y, anchor.yaw, support, 0.0);
                for _ in 0..10 {
                    let l = [self.random_within(anchor.size[0], w), self.random_within(anchor.size[2], d)];
                    push(at(l), y, anchor.yaw, support, 0.1);
                }
            }
            Relation::Near | Relation::NextTo => {
                let max_gap = if rel == Relation::Near { 0.8 } else { 0.2 };
                for k in 0..2 {
                    // Same facing as the anchor, or turned a quarter to face it (chairs round a table).
                    let (s, c) = (k as f32 * QUARTER).sin_cos();
                    let hh = [w / 2.0 * c.abs() + d / 2.0 * s.abs(), w / 2.0 * s.abs() + d / 2.0 * c.abs()];
                    for side in [-1.0f32, 1.0] {
                        let yaw = anchor.yaw - k as f32 * side * QUARTER;
                        for _ in 0..4 {
                            let g = self.rng.random_range(0.02..max_gap);
                            // Backs flush with the anchor's back, or centred, or anywhere along.
                            let lz = match self.rng.random_range(0..3) {
                                0 => -ad + hh[1],
                                1 => 0.0,
                                _ => self.random_within(2.0 * ad, 2.0 * hh[1]),
                            };
                            push(at([side * (aw + hh[0] + g), lz]), base, yaw, None, g);
                            if rel == Relation::Near {
                                let lx = self.random_within(2.0 * aw, 2.0 * hh[0]);
                                push(at([lx, side * (ad + hh[1] + g)]), base, yaw, None, g + 0.1);
                            }
                        }
                    }
                }
            }
            Relation::InFrontOf | Relation::Behind => {
                let sign = if rel == Relation::InFrontOf { 1.0 } else { -1.0 };
                // In front: facing the anchor; behind: facing the same way (a seat behind
                // something turns its back to it, so its own front stays free).
                let yaw = if rel == Relation::InFrontOf || item.seat { anchor.yaw + HALF } else { anchor.yaw };
                if rel == Relation::InFrontOf
                    && crate::catalogue::builtin::tucks_under(&item.category, &anchor.category)
                {
                    // Tucked at it: centred, its front [`super::TUCK`] in under the top.
                    push(at([0.0, ad + d / 2.0 - super::TUCK]), base, yaw, None, -2.0);
                }
                for k in 0..24 {
                    let g = if k == 0 { 0.1 } else { self.rng.random_range(0.05..FRONT_GAP - 0.1) };
                    let lx = if k < 3 { 0.0 } else { self.rng.random_range(-0.5..=0.5) * aw };
                    push(at([lx, sign * (ad + d / 2.0 + g)]), base, yaw, None, 0.3 * (g - 0.4).abs());
                }
                if rel == Relation::InFrontOf && self.faces(i) {
                    // Off to one side of the front, turned to face the anchor (when the space
                    // straight in front is taken).
                    for _ in 0..12 {
                        let g = self.rng.random_range(0.05..FRONT_GAP - 0.1);
                        let lx = self.rng.random_range(-1.0..=1.0) * (aw + 0.3);
                        let p = at([lx, ad + d / 2.0 + g]);
                        let face = (ac[0] - p[0]).atan2(ac[1] - p[1]);
                        push(p, base, face, None, 0.3 * (g - 0.4).abs() + 0.5);
                    }
                }
            }
            Relation::Against => {
                // Its sides and back first: a desk's or a sofa's front is where it is used.
                for face in [Face::Away, Face::Same] {
                    let along = [0.0, 0.5, -0.5, 1.0, -1.0];
                    self.side_poses(i, anchor, &SIDES[1..], &[0.01], &along, face, 0.0, out);
                    self.side_poses(i, anchor, &SIDES[..1], &[0.01], &along, face, 0.6, out);
                }
            }
            Relation::Opposite | Relation::Facing => {
                // Across the room rather than at arm's length: gaps near [`ACROSS_GAP`] first.
                for g in [1.0, 1.4, 0.7, 1.8, 2.4, 0.4] {
                    let penalty = 0.3 * (g - ACROSS_GAP).abs() - 0.2 * g + 0.5;
                    self.side_poses(i, anchor, &[Side::Front], &[g], &[0.0, 0.3, -0.3], Face::Toward, penalty, out);
                }
                if rel == Relation::Facing {
                    self.side_poses(i, anchor, &SIDES[1..], &[0.6, 1.2], &[0.0], Face::Toward, 1.0, out);
                }
            }
            Relation::LeftOf | Relation::RightOf | Relation::EitherSide => {
                let sides: &[Side] = match rel {
                    Relation::LeftOf => &[Side::Left],
                    Relation::RightOf => &[Side::Right],
                    _ => &[Side::Left, Side::Right],
                };
                for (face, penalty) in [(Face::Same, 0.0), (Face::Away, 0.3)] {
                    self.side_poses(i, anchor, sides, &[0.05, 0.15, 0.3], &[0.0, 1.0, -1.0], face, penalty, out);
                }
            }
            Relation::At | Relation::Around => {
                let tuck = crate::catalogue::builtin::tucks_under(&item.category, &anchor.category);
                let gaps: &[f32] = if tuck { &[-super::TUCK, 0.05] } else { &[0.05, 0.15] };
                self.side_poses(i, anchor, &SIDES[..2], gaps, &[0.0, 0.5, -0.5, 0.9, -0.9], Face::Toward, 0.0, out);
                self.side_poses(i, anchor, &SIDES[2..], gaps, &[0.0, 0.5, -0.5], Face::Toward, 0.2, out);
            }
            Relation::Above => {
                if item.support == Support::Wall {
                    // On the wall the anchor backs onto, over it.
                    let f = geom::forward(anchor.yaw);
                    let back = [ac[0] - f[0] * ad, ac[1] - f[1] * ad];
                    let y = (WALL_CENTER_HEIGHT - h / 2.0).max(anchor.top() + 0.1).min(self.p.room.height - h);
                    let r = &self.p.room;
                    let walls = [
                        (0.0, [back[0], d / 2.0]),
                        (HALF, [back[0], r.depth - d / 2.0]),
                        (QUARTER, [d / 2.0, back[1]]),
                        (-QUARTER, [r.width - d / 2.0, back[1]]),
                    ];
                    for (yaw, p) in walls {
                        push(p, y, yaw, None, 0.0);
                    }
                } else if item.support == Support::Ceiling {
                    push(ac, (self.p.room.height - h).max(anchor.top()), anchor.yaw, None, 0.0);
                } else {
                    // Nothing holds a floor or surface object in the air: it rests on the anchor.
                    push(ac, anchor.top(), anchor.yaw, Some(j), 0.0);
                }
            }
        }
    }

    /// Poses at `sides` of the placed `anchor`: `gap` metres off the side (negative: in under it,
    /// for a seat tucked at a table), shifted along it by `offsets` (fractions of the free half
    /// length), turned by `face`.
    #[allow(clippy::too_many_arguments)]
    fn side_poses(
        &mut self,
        i: usize,
        anchor: &PlacedObject,
        sides: &[Side],
        gaps: &[f32],
        offsets: &[f32],
        face: Face,
        penalty: f32,
        out: &mut Vec<Placement>,
    ) {
        let [w, _, d] = self.p.items[i].size;
        let y = self.rest_height(i);
        let (aw, ad) = (anchor.size[0] / 2.0, anchor.size[2] / 2.0);
        for &side in sides {
            // The side's outward normal and tangent in the anchor's frame, its yaw, and the
            // anchor's extents along them.
            let (n, t, turn, a_n, a_t) = match side {
                Side::Front => ([0.0, 1.0], [1.0, 0.0], 0.0, ad, aw),
                Side::Back => ([0.0, -1.0], [1.0, 0.0], HALF, ad, aw),
                Side::Left => ([1.0, 0.0], [0.0, 1.0], QUARTER, aw, ad),
                Side::Right => ([-1.0, 0.0], [0.0, 1.0], -QUARTER, aw, ad),
            };
            let normal_yaw = anchor.yaw + turn;
            let yaw = match face {
                Face::Toward => normal_yaw + HALF,
                Face::Away => normal_yaw,
                Face::Same => anchor.yaw,
            };
            let (s, c) = (yaw - normal_yaw).sin_cos();
            let h_n = w / 2.0 * s.abs() + d / 2.0 * c.abs();
            let h_t = w / 2.0 * c.abs() + d / 2.0 * s.abs();
            for &g in gaps {
                for &f in offsets {
                    let along = f * (a_t - h_t).max(0.0);
                    let out_by = a_n + h_n + g;
                    let l = [n[0] * out_by + t[0] * along, n[1] * out_by + t[1] * along];
                    let p = geom::to_world(geom::center(anchor), anchor.yaw, l);
                    out.push(Placement {
                        position: [p[0], y, p[1]],
                        yaw,
                        support: None,
                        penalty: penalty + 0.2 * g.abs() + 0.05 * f.abs(),
                    });
                }
            }
        }
    }

    /// Poses that put item `i` at `place`.
    fn place_candidates(&mut self, i: usize, place: RoomPlace, out: &mut Vec<Placement>) {
        let [w, _, d] = self.p.items[i].size;
        let y = self.rest_height(i);
        let (rw, rd) = (self.p.room.width, self.p.room.depth);
        let half = |yaw: f32| {
            let (s, c) = yaw.sin_cos();
            [w / 2.0 * c.abs() + d / 2.0 * s.abs(), w / 2.0 * s.abs() + d / 2.0 * c.abs()]
        };
        match place {
            RoomPlace::Middle => {
                for k in 0..4 {
                    let yaw = k as f32 * QUARTER;
                    out.push(Placement { position: [rw / 2.0, y, rd / 2.0], yaw, support: None, penalty: 0.0 });
                    for _ in 0..3 {
                        let j = [self.rng.random_range(-0.4..0.4), self.rng.random_range(-0.4..0.4)];
                        let position = [rw / 2.0 + j[0], y, rd / 2.0 + j[1]];
                        out.push(Placement { position, yaw, support: None, penalty: 0.3 * j[0].hypot(j[1]) });
                    }
                }
            }
            RoomPlace::Corner => {
                for (cx, cz) in [(0.0, 0.0), (rw, 0.0), (0.0, rd), (rw, rd)] {
                    let into_z = if cz == 0.0 { 0.0 } else { HALF };
                    let into_x = if cx == 0.0 { QUARTER } else { -QUARTER };
                    for yaw in [into_z, into_x] {
                        let h = half(yaw);
                        let x = if cx == 0.0 { h[0] } else { rw - h[0] };
                        let z = if cz == 0.0 { h[1] } else { rd - h[1] };
                        out.push(Placement { position: [x, y, z], yaw, support: None, penalty: 0.0 });
                    }
                }
            }
            RoomPlace::Wall => self.wall_candidates(i, y, 12, 0.0, out),
            RoomPlace::Door => {
                let door = door(&self.p.room);
                let h = half(HALF);
                for side in [-1.0f32, 1.0] {
                    for g in [0.05, 0.2, 0.4] {
                        let x = door[0] + side * (DOOR_ZONE[0] + h[0] + g);
                        out.push(Placement { position: [x, y, rd - h[1]], yaw: HALF, support: None, penalty: g });
                    }
                }
            }
            RoomPlace::Between(a, b) => {
                let (Some(pa), Some(pb)) = (self.poses[a].clone(), self.poses[b].clone()) else { return };
                let (p, q) = (geom::center(&pa), geom::center(&pb));
                let line = (q[0] - p[0]).atan2(q[1] - p[1]);
                for t in [0.5, 0.45, 0.55, 0.4, 0.6, 0.35, 0.65, 0.3, 0.7] {
                    let c = [p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])];
                    for yaw in [pa.yaw, pb.yaw, line, line + QUARTER] {
                        out.push(Placement {
                            position: [c[0], y, c[1]],
                            yaw,
                            support: None,
                            penalty: (t - 0.5f32).abs(),
                        });
                    }
                }
            }
        }
    }

    fn finish(self) -> LayoutOutcome {
        let n = self.p.items.len();
        let mut placed = vec![None; n];
        let mut objects = Vec::new();
        for (i, o) in self.poses.iter().enumerate() {
            if let Some(o) = o {
                placed[i] = Some(objects.len());
                objects.push(o.clone());
            }
        }
        for o in &mut objects {
            o.support = o.support.and_then(|s| placed[s]);
        }
        let rels: Vec<(Relation, usize, usize)> = self
            .p
            .relations
            .iter()
            .filter_map(|c| {
                Some((c.relation, placed.get(c.active).copied().flatten()?, placed.get(c.anchor).copied().flatten()?))
            })
            .collect();
        let mut violations = check(&self.p.room, &objects, &rels);
        violations.unmet_places = self
            .p
            .places
            .iter()
            .enumerate()
            .filter(|(_, pl)| {
                self.poses[pl.item]
                    .as_ref()
                    .is_some_and(|o| !place_holds(pl.place, o, &self.p.room, |k| self.poses[k].as_ref()))
            })
            .map(|(k, _)| k)
            .collect();
        let mut dropped = self.dropped;
        dropped.sort_by_key(|d| d.0);
        LayoutOutcome { objects, placed, dropped, violations }
    }
}
