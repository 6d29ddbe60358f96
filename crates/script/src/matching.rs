//! SSG matching (§4.1): which database objects a query graph's objects come from.
//!
//! - [`relation_first`] is the paper's Algorithm 1: match the query's relation nodes (u, v) against
//!   the database scenes, preferring the scene that satisfies the most relations jointly (a
//!   connected subgraph from one scene), put the matched subgraph into the matching map M, repeat
//!   on what is left, and only then fall back to matching single object nodes.
//! - [`object_first`] is the LDS baseline [MPF*18] the paper compares with (Fig. 4, Fig. 8): match
//!   every object on its own first, then check relations among the top returned objects only.
//!
//! Objects match when their categories are equal (1) or classmates (0.5, [`Catalogue::similarity`]);
//! shared attributes and a matching room kind break ties. A relation matches when both ends map
//! into the same scene and the relation holds there geometrically ([`DbScene::relation_holds`]).

use rand::Rng;

use crate::catalogue::Catalogue;
use crate::database::{DbScene, SceneDatabase};
use crate::ssg::{NodeId, ObjectNode, Relation, RelationNode, Ssg};

/// One matched query object: the database scene and object node it comes from.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct MatchEntry {
    pub query_node: NodeId,
    /// Index into [`SceneDatabase::scenes`].
    pub scene: usize,
    pub db_node: NodeId,
    /// Matched as the end of a matched relation (true) or on its own (fallback, false).
    pub via_relation: bool,
}

/// The matching map M of Algorithm 1, plus the query objects nothing matched.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct MatchMap {
    /// Sorted by query node.
    pub entries: Vec<MatchEntry>,
    pub unmatched: Vec<NodeId>,
}

impl MatchMap {
    pub fn get(&self, query_node: NodeId) -> Option<&MatchEntry> {
        self.entries.iter().find(|e| e.query_node == query_node)
    }

    /// The scenes used, by how many query objects each supplies (most first).
    pub fn scenes(&self) -> Vec<(usize, usize)> {
        let mut counts: Vec<(usize, usize)> = Vec::new();
        for e in &self.entries {
            match counts.iter_mut().find(|(s, _)| *s == e.scene) {
                Some(c) => c.1 += 1,
                None => counts.push((e.scene, 1)),
            }
        }
        counts.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
        counts
    }

    fn build(n: usize, assign: &[Option<(usize, NodeId, bool)>]) -> MatchMap {
        let mut m = MatchMap::default();
        for (q, a) in assign.iter().enumerate().take(n) {
            match a {
                Some((scene, db_node, via_relation)) => m.entries.push(MatchEntry {
                    query_node: q,
                    scene: *scene,
                    db_node: *db_node,
                    via_relation: *via_relation,
                }),
                None => m.unmatched.push(q),
            }
        }
        m
    }
}

/// How well a database object fits a query object: category similarity (1 or 0.5, 0 = no match)
/// plus small tie-breakers: 0.1 × the share of the query's attributes it has, 0.05 when the scene's
/// room is the room the query names.
pub fn object_score(cat: &Catalogue, q: &Ssg, node: &ObjectNode, scene: &DbScene, db_node: NodeId) -> f64 {
    let d = &scene.ssg.objects[db_node];
    let sim = cat.similarity(&node.category, &d.category);
    if sim == 0.0 {
        return 0.0;
    }
    let attr = if node.attributes.is_empty() {
        0.0
    } else {
        node.attributes.iter().filter(|a| d.attributes.contains(a)).count() as f64 / node.attributes.len() as f64
    };
    sim + 0.1 * attr + 0.05 * f64::from(room_matches(cat, q, scene))
}

fn room_matches(cat: &Catalogue, q: &Ssg, scene: &DbScene) -> bool {
    q.room
        .as_deref()
        .is_some_and(|r| r == scene.room.name || cat.resolve_room(r).is_some_and(|k| k.name == scene.room.name))
}

/// Query relations worth matching: valid, distinct ends.
fn usable(q: &Ssg, r: &RelationNode) -> bool {
    r.active < q.objects.len() && r.anchor < q.objects.len() && r.active != r.anchor
}

/// Search budget (visited partial assignments) per scene and component, so a large query cannot
/// stall composition; the best assignment found so far is kept.
const BUDGET: usize = 20_000;

/// One end of a relation in a scene search: a query node to assign or a database node already fixed.
#[derive(Clone, Copy)]
enum End {
    Var(usize),
    Fixed(NodeId),
}

struct Search<'a> {
    scene: &'a DbScene,
    /// Candidate database nodes of each variable, best first, with their object scores.
    domains: Vec<Vec<(NodeId, f64)>>,
    rels: Vec<(Relation, End, End)>,
    /// Relations (indices into `rels`) to evaluate once variable k is decided (all their variables
    /// have index ≤ k).
    ready_at: Vec<Vec<usize>>,
    /// Each variable's best object score anywhere in the database (what the fallback would get).
    alone: Vec<f64>,
    current: Vec<Option<NodeId>>,
    steps: usize,
    /// (value, matched relations, assignment); value = matched relations + Σ over the nodes they
    /// touch of (object score here − best object score alone), the change in the matching score's
    /// numerator against matching those nodes on their own.
    best: (f64, usize, Vec<Option<NodeId>>),
}

impl Search<'_> {
    fn node(&self, e: End) -> Option<NodeId> {
        match e {
            End::Var(k) => self.current[k],
            End::Fixed(d) => Some(d),
        }
    }

    fn go(&mut self, k: usize, count: usize, decided: usize) {
        self.steps += 1;
        if ((count + self.rels.len() - decided) as f64) < self.best.0 - 1e-9 || self.steps > BUDGET {
            return;
        }
        if k == self.domains.len() {
            let mut touched = vec![false; self.domains.len()];
            for &(rel, a, b) in &self.rels {
                if let (Some(x), Some(y)) = (self.node(a), self.node(b)) {
                    if self.scene.relation_holds(rel, x, y) {
                        for e in [a, b] {
                            if let End::Var(v) = e {
                                touched[v] = true;
                            }
                        }
                    }
                }
            }
            let loss: f64 = (0..self.domains.len())
                .filter(|&v| touched[v])
                .map(|v| {
                    self.domains[v].iter().find(|c| Some(c.0) == self.current[v]).map_or(0.0, |c| c.1) - self.alone[v]
                })
                .sum();
            let value = count as f64 + loss;
            if count > 0 && (value > self.best.0 + 1e-9 || ((value - self.best.0).abs() <= 1e-9 && count > self.best.1))
            {
                self.best = (value, count, self.current.clone());
            }
            return;
        }
        let options: Vec<Option<NodeId>> =
            self.domains[k].iter().map(|c| Some(c.0)).chain(std::iter::once(None)).collect();
        for opt in options {
            if let Some(d) = opt {
                if self.current[..k].contains(&Some(d)) {
                    continue;
                }
            }
            self.current[k] = opt;
            let mut gained = 0;
            for &ri in &self.ready_at[k] {
                let (rel, a, b) = self.rels[ri];
                if let (Some(x), Some(y)) = (self.node(a), self.node(b)) {
                    if x != y && self.scene.relation_holds(rel, x, y) {
                        gained += 1;
                    }
                }
            }
            let n_ready = self.ready_at[k].len();
            self.go(k + 1, count + gained, decided + n_ready);
        }
        self.current[k] = None;
    }
}

/// Connected groups of relation indices (linked by shared query nodes).
fn components(q: &Ssg, rels: &[usize]) -> Vec<Vec<usize>> {
    let mut comp: Vec<usize> = (0..rels.len()).collect();
    fn root(c: &mut [usize], mut i: usize) -> usize {
        while c[i] != i {
            c[i] = c[c[i]];
            i = c[i];
        }
        i
    }
    for i in 0..rels.len() {
        for j in i + 1..rels.len() {
            let (a, b) = (&q.relations[rels[i]], &q.relations[rels[j]]);
            if a.active == b.active || a.active == b.anchor || a.anchor == b.active || a.anchor == b.anchor {
                let (ri, rj) = (root(&mut comp, i), root(&mut comp, j));
                comp[ri] = rj;
            }
        }
    }
    let mut groups: Vec<(usize, Vec<usize>)> = Vec::new();
    for (i, &rel) in rels.iter().enumerate() {
        let r = root(&mut comp, i);
        match groups.iter_mut().find(|g| g.0 == r) {
            Some(g) => g.1.push(rel),
            None => groups.push((r, vec![rel])),
        }
    }
    groups.into_iter().map(|g| g.1).collect()
}

/// Best joint match of one group of query relations in one scene: (value (see `Search::best`),
/// matched relations, new assignments (query node → db node) of the nodes the matched relations
/// touch, matched relation indices).
type Joint = (f64, usize, Vec<(NodeId, NodeId)>, Vec<usize>);

/// What Algorithm 1 has decided so far: M as (scene, db node, via relation) per query node, the
/// database objects taken, and each query node's best score alone.
struct State<'a> {
    assign: &'a [Option<(usize, NodeId, bool)>],
    used: &'a [(usize, NodeId)],
    alone: &'a [f64],
}

fn match_in_scene(
    cat: &Catalogue,
    q: &Ssg,
    (scene_index, scene): (usize, &DbScene),
    group: &[usize],
    state: &State,
) -> Option<Joint> {
    let State { assign, used, alone } = *state;
    // Relations usable here: each end unassigned or already assigned to this scene.
    let rels: Vec<usize> = group
        .iter()
        .copied()
        .filter(|&ri| {
            let r = &q.relations[ri];
            [r.active, r.anchor].iter().all(|&n| assign[n].is_none_or(|a| a.0 == scene_index))
        })
        .collect();
    if rels.is_empty() {
        return None;
    }
    let mut vars: Vec<NodeId> = Vec::new();
    for &ri in &rels {
        for n in [q.relations[ri].active, q.relations[ri].anchor] {
            if assign[n].is_none() && !vars.contains(&n) {
                vars.push(n);
            }
        }
    }
    let taken = |d: NodeId| used.contains(&(scene_index, d));
    let mut domains: Vec<Vec<(NodeId, f64)>> = vars
        .iter()
        .map(|&n| {
            let mut dom: Vec<(NodeId, f64)> = (0..scene.ssg.objects.len())
                .filter(|&d| !taken(d))
                .map(|d| (d, object_score(cat, q, &q.objects[n], scene, d)))
                .filter(|c| c.1 > 0.0)
                .collect();
            dom.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
            dom
        })
        .collect();
    // Most constrained variables first.
    let mut order: Vec<usize> = (0..vars.len()).collect();
    order.sort_by_key(|&k| (domains[k].len(), vars[k]));
    vars = order.iter().map(|&k| vars[k]).collect();
    domains = order.iter().map(|&k| std::mem::take(&mut domains[k])).collect();
    let end = |n: NodeId| match vars.iter().position(|&v| v == n) {
        Some(k) => End::Var(k),
        None => End::Fixed(assign[n].expect("fixed end").1),
    };
    let srels: Vec<(Relation, End, End)> = rels
        .iter()
        .map(|&ri| (q.relations[ri].relation, end(q.relations[ri].active), end(q.relations[ri].anchor)))
        .collect();
    let mut ready_at = vec![Vec::new(); vars.len().max(1)];
    let mut pre = 0;
    let mut pre_count = 0;
    for (i, &(rel, a, b)) in srels.iter().enumerate() {
        let last = [a, b].iter().filter_map(|e| if let End::Var(k) = e { Some(*k) } else { None }).max();
        match last {
            Some(k) => ready_at[k].push(i),
            None => {
                pre += 1;
                if let (End::Fixed(x), End::Fixed(y)) = (a, b) {
                    if scene.relation_holds(rel, x, y) {
                        pre_count += 1;
                    }
                }
            }
        }
    }
    let alone = vars.iter().map(|&v| alone[v]).collect();
    let mut s = Search {
        scene,
        domains,
        rels: srels.clone(),
        ready_at,
        alone,
        current: vec![None; vars.len()],
        steps: 0,
        best: (f64::NEG_INFINITY, 0, vec![None; vars.len()]),
    };
    if vars.is_empty() {
        s.best = (pre_count as f64, pre_count, Vec::new());
    } else {
        s.go(0, pre_count, pre);
    }
    let (value, count, best) = s.best;
    if count == 0 {
        return None;
    }
    let node = |e: End| match e {
        End::Var(k) => best[k],
        End::Fixed(d) => Some(d),
    };
    let mut matched = Vec::new();
    let mut new = Vec::new();
    for (i, &(rel, a, b)) in srels.iter().enumerate() {
        if let (Some(x), Some(y)) = (node(a), node(b)) {
            if x != y && scene.relation_holds(rel, x, y) {
                matched.push(rels[i]);
                for (e, d) in [(a, x), (b, y)] {
                    if let End::Var(k) = e {
                        if !new.iter().any(|&(n, _)| n == vars[k]) {
                            new.push((vars[k], d));
                        }
                    }
                }
            }
        }
    }
    Some((value, count, new, matched))
}

/// Fallback of Algorithm 1 and first step of LDS: every database object that fits a query node,
/// best first (score, then database order).
fn ranked(cat: &Catalogue, q: &Ssg, db: &SceneDatabase, node: NodeId) -> Vec<(usize, NodeId, f64)> {
    let mut out: Vec<(usize, NodeId, f64)> = db
        .scenes
        .iter()
        .enumerate()
        .flat_map(|(s, scene)| {
            (0..scene.ssg.objects.len()).map(move |d| (s, d, object_score(cat, q, &q.objects[node], scene, d)))
        })
        .filter(|c| c.2 > 0.0)
        .collect();
    out.sort_by(|a, b| b.2.total_cmp(&a.2).then(a.0.cmp(&b.0)).then(a.1.cmp(&b.1)));
    out
}

/// Algorithm 1 (relation-first matching). Repeatedly: for every connected group of still-unmatched
/// query relations and every scene, find the assignment satisfying the most relations jointly,
/// valued as (matched relations − the object quality the touched nodes give up against their best
/// match alone), so a joint match is not bought with poor stand-ins (the paper leaves the
/// trade-off open); take the best (group, scene) and put the nodes its matched relations touch
/// into M. When no relation matches any more, each remaining object node is
/// matched on its own (best object score; a scene already in M wins ties).
pub fn relation_first(q: &Ssg, db: &SceneDatabase, cat: &Catalogue) -> MatchMap {
    let n = q.objects.len();
    let mut assign: Vec<Option<(usize, NodeId, bool)>> = vec![None; n];
    let mut used: Vec<(usize, NodeId)> = Vec::new();
    let mut open: Vec<usize> = (0..q.relations.len()).filter(|&i| usable(q, &q.relations[i])).collect();
    let alone: Vec<f64> = (0..n).map(|i| ranked(cat, q, db, i).first().map_or(0.0, |c| c.2)).collect();
    loop {
        let mut best: Option<(usize, Joint)> = None;
        for group in components(q, &open) {
            for (s, scene) in db.scenes.iter().enumerate() {
                let state = State { assign: &assign, used: &used, alone: &alone };
                if let Some(j) = match_in_scene(cat, q, (s, scene), &group, &state) {
                    let better = match &best {
                        None => true,
                        Some((_, b)) => j.0 > b.0 + 1e-9 || ((j.0 - b.0).abs() <= 1e-9 && j.1 > b.1),
                    };
                    if better {
                        best = Some((s, j));
                    }
                }
            }
        }
        // A relation match that costs more object quality than it gains is left to the fallback.
        let Some((s, (value, _, new, matched))) = best else {
            break;
        };
        if value < -1e-9 {
            break;
        }
        for (qn, d) in new {
            assign[qn] = Some((s, d, true));
            used.push((s, d));
        }
        open.retain(|r| !matched.contains(r));
        // Relations whose two ends are both placed and still unmatched can never match now.
        open.retain(|&ri| {
            let r = &q.relations[ri];
            assign[r.active].is_none() || assign[r.anchor].is_none()
        });
    }
    for qn in 0..n {
        if assign[qn].is_some() {
            continue;
        }
        let in_m: Vec<usize> = assign.iter().flatten().map(|a| a.0).collect();
        let pick = ranked(cat, q, db, qn)
            .into_iter()
            .filter(|c| !used.contains(&(c.0, c.1)))
            .map(|c| (c.0, c.1, c.2 + if in_m.contains(&c.0) { 0.01 } else { 0.0 }))
            .fold(None::<(usize, NodeId, f64)>, |acc, c| match acc {
                Some(a) if a.2 >= c.2 => Some(a),
                _ => Some(c),
            });
        if let Some((s, d, _)) = pick {
            assign[qn] = Some((s, d, false));
            used.push((s, d));
        }
    }
    MatchMap::build(n, &assign)
}

/// How many top-ranked candidates per object LDS looks at when it checks relations.
pub const LDS_TOP: usize = 3;

/// The LDS baseline (object-first): each object takes its best-ranked database object on its own;
/// then, relation by relation, a relation that does not hold is repaired only by choosing among the
/// [`LDS_TOP`] top returned objects of its two ends (both in one scene, relation holding), keeping
/// ends that an earlier satisfied relation fixed.
pub fn object_first(q: &Ssg, db: &SceneDatabase, cat: &Catalogue) -> MatchMap {
    let n = q.objects.len();
    let ranks: Vec<Vec<(usize, NodeId, f64)>> = (0..n).map(|i| ranked(cat, q, db, i)).collect();
    let mut assign: Vec<Option<(usize, NodeId, bool)>> = vec![None; n];
    for i in 0..n {
        let pick = ranks[i].iter().find(|c| !assign.iter().flatten().any(|a| a.0 == c.0 && a.1 == c.1));
        assign[i] = pick.map(|c| (c.0, c.1, false));
    }
    let top = |i: usize| ranks[i].iter().take(LDS_TOP).map(|c| (c.0, c.1)).collect::<Vec<_>>();
    let mut locked = vec![false; n];
    for r in q.relations.iter().filter(|r| usable(q, r)) {
        let (u, v) = (r.active, r.anchor);
        let holds_now = match (assign[u], assign[v]) {
            (Some(a), Some(b)) => a.0 == b.0 && db.scenes[a.0].relation_holds(r.relation, a.1, b.1),
            _ => false,
        };
        let free = |cand: (usize, NodeId), assign: &[Option<(usize, NodeId, bool)>], me: usize, other: usize| {
            !assign
                .iter()
                .enumerate()
                .any(|(k, a)| k != me && k != other && a.is_some_and(|a| a.0 == cand.0 && a.1 == cand.1))
        };
        if holds_now {
            locked[u] = true;
            locked[v] = true;
            continue;
        }
        let cu: Vec<(usize, NodeId)> =
            if locked[u] { assign[u].map(|a| vec![(a.0, a.1)]).unwrap_or_default() } else { top(u) };
        let cv: Vec<(usize, NodeId)> =
            if locked[v] { assign[v].map(|a| vec![(a.0, a.1)]).unwrap_or_default() } else { top(v) };
        'pairs: for &a in &cu {
            for &b in &cv {
                if a.0 == b.0
                    && a.1 != b.1
                    && db.scenes[a.0].relation_holds(r.relation, a.1, b.1)
                    && free(a, &assign, u, v)
                    && free(b, &assign, v, u)
                {
                    assign[u] = Some((a.0, a.1, true));
                    assign[v] = Some((b.0, b.1, true));
                    locked[u] = true;
                    locked[v] = true;
                    break 'pairs;
                }
            }
        }
    }
    MatchMap::build(n, &assign)
}

/// Matching score in [0, 1]: (Σ over query objects of how well the object they map to fits (1 same
/// category, 0.5 otherwise: the matchers only map to classmates; 0 unmatched) + the number of query relations whose two
/// ends map into the same scene where the relation holds) / (objects + relations). A query with
/// neither scores 1 (nothing to match). It rewards finding the objects and, as the paper argues,
/// keeping their relations (Fig. 8).
pub fn score(q: &Ssg, db: &SceneDatabase, map: &MatchMap) -> f64 {
    let rels: Vec<&RelationNode> = q.relations.iter().filter(|r| usable(q, r)).collect();
    let total = q.objects.len() + rels.len();
    if total == 0 {
        return 1.0;
    }
    let objects: f64 = map
        .entries
        .iter()
        .filter(|e| e.query_node < q.objects.len())
        .map(|e| {
            if q.objects[e.query_node].category == db.scenes[e.scene].ssg.objects[e.db_node].category {
                1.0
            } else {
                0.5
            }
        })
        .sum();
    let relations = rels
        .iter()
        .filter(|r| match (map.get(r.active), map.get(r.anchor)) {
            (Some(a), Some(b)) => {
                a.scene == b.scene && db.scenes[a.scene].relation_holds(r.relation, a.db_node, b.db_node)
            }
            _ => false,
        })
        .count();
    (objects + relations as f64) / total as f64
}

// ---------------------------------------------------------------------------------------------
// The Fig. 8 experiment.

fn query(cat: &Catalogue, room: Option<&str>, objects: &[(&str, &[&str])], rels: &[(usize, Relation, usize)]) -> Ssg {
    let objects = objects
        .iter()
        .map(|&(w, attrs)| ObjectNode {
            category: cat.resolve(w).map_or_else(|| w.to_string(), |c| c.name.clone()),
            attributes: attrs.iter().map(|s| s.to_string()).collect(),
            count: 1,
            word: w.to_string(),
            sentence: 0,
        })
        .collect();
    let relations =
        rels.iter().map(|&(active, relation, anchor)| RelationNode { relation, active, anchor, sentence: 0 }).collect();
    Ssg { room: room.map(str::to_string), objects, relations, ..Ssg::default() }
}

/// Ten hand-written query SSGs: the paper's scene sentences (Fig. 1, 4, 5, 7 and §6's "Put a vase
/// and a teapot on the table") as the parser would build them.
pub fn handwritten_queries(cat: &Catalogue) -> Vec<Ssg> {
    use Relation::*;
    vec![
        query(cat, Some("room"), &[("desk", &["organized", "office"]), ("bed", &[])], &[(0, Near, 1)]),
        query(
            cat,
            Some("gallery"),
            &[("horsesculpture", &[]), ("oilpainting", &[]), ("sculpture", &[]), ("picture", &[]), ("bench", &[])],
            &[(4, InFrontOf, 1), (2, Behind, 0)],
        ),
        query(
            cat,
            Some("meetingroom"),
            &[("blackboard", &[]), ("table", &["arranged"]), ("chair", &[]), ("chair", &[]), ("clock", &[])],
            &[(2, InFrontOf, 1), (3, Behind, 1), (4, Above, 0)],
        ),
        query(
            cat,
            Some("workshop"),
            &[("table", &[]), ("hammer", &[]), ("wood", &[]), ("shelf", &[]), ("sofa", &[])],
            &[(1, On, 0), (2, On, 0), (3, InFrontOf, 0), (4, InFrontOf, 0)],
        ),
        query(
            cat,
            Some("musicroom"),
            &[("desk", &[]), ("computer", &[]), ("recorder", &[]), ("piano", &[]), ("chair", &[])],
            &[(1, On, 0), (2, On, 0), (4, InFrontOf, 0)],
        ),
        query(
            cat,
            Some("boxinggym"),
            &[("boxingring", &[]), ("boxingbag", &[]), ("stool", &[]), ("desk", &[]), ("bottle", &[])],
            &[(1, Above, 0), (2, NextTo, 0), (4, On, 3)],
        ),
        query(
            cat,
            None,
            &[("table", &[]), ("desklamp", &[]), ("chair", &[]), ("chair", &[])],
            &[(1, On, 0), (2, InFrontOf, 0), (3, Behind, 0)],
        ),
        query(cat, None, &[("table", &[]), ("vase", &[]), ("teapot", &[])], &[(1, On, 0), (2, On, 0)]),
        query(
            cat,
            Some("office"),
            &[
                ("desk", &[]),
                ("computer", &[]),
                ("keyboard", &[]),
                ("officechair", &[]),
                ("picture", &[]),
                ("trashcan", &[]),
            ],
            &[(1, On, 0), (2, On, 0), (3, InFrontOf, 0), (4, Above, 0), (5, NextTo, 0)],
        ),
        query(
            cat,
            Some("bedroom"),
            &[("bed", &[]), ("nightstand", &[]), ("lamp", &[]), ("rug", &[]), ("picture", &[])],
            &[(1, NextTo, 0), (2, On, 1), (3, InFrontOf, 0), (4, Above, 0)],
        ),
    ]
}

/// A connected sub-graph of 2–4 relation nodes of a database scene (Near avoided when something
/// more specific is at hand), with categories swapped for classmates (p = 0.25) and half the
/// attributes dropped: a query that resembles the database without copying it.
fn sampled_query(db: &SceneDatabase, cat: &Catalogue, rng: &mut impl Rng) -> Ssg {
    let scene = &db.scenes[rng.random_range(0..db.scenes.len())];
    let rels = &scene.ssg.relations;
    let specific: Vec<usize> = (0..rels.len()).filter(|&i| rels[i].relation != Relation::Near).collect();
    let pool = if specific.is_empty() { (0..rels.len()).collect() } else { specific };
    let mut out = Ssg { room: rng.random_bool(0.5).then(|| scene.room.name.clone()), ..Ssg::default() };
    if pool.is_empty() {
        return out;
    }
    let mut chosen = vec![pool[rng.random_range(0..pool.len())]];
    let want = rng.random_range(2..=4);
    while chosen.len() < want {
        let nodes: Vec<NodeId> = chosen.iter().flat_map(|&i| [rels[i].active, rels[i].anchor]).collect();
        let next: Vec<usize> = pool
            .iter()
            .copied()
            .filter(|i| !chosen.contains(i) && (nodes.contains(&rels[*i].active) || nodes.contains(&rels[*i].anchor)))
            .collect();
        if next.is_empty() {
            break;
        }
        chosen.push(next[rng.random_range(0..next.len())]);
    }
    let mut map: Vec<(NodeId, NodeId)> = Vec::new();
    for &i in &chosen {
        let r = &rels[i];
        let mut id = |d: NodeId, out: &mut Ssg, rng: &mut dyn rand::RngCore| -> NodeId {
            if let Some(&(_, q)) = map.iter().find(|m| m.0 == d) {
                return q;
            }
            let o = &scene.ssg.objects[d];
            let mut category = o.category.clone();
            if rng.random_bool(0.25) {
                let mates: Vec<&str> = cat
                    .categories()
                    .iter()
                    .map(|c| c.name.as_str())
                    .filter(|c| *c != o.category && cat.class_of(c) == cat.class_of(&o.category))
                    .collect();
                if !mates.is_empty() {
                    category = mates[rng.random_range(0..mates.len())].to_string();
                }
            }
            let attributes = o.attributes.iter().filter(|_| rng.random_bool(0.5)).cloned().collect();
            out.objects.push(ObjectNode { word: category.clone(), category, attributes, count: 1, sentence: 0 });
            map.push((d, out.objects.len() - 1));
            out.objects.len() - 1
        };
        let active = id(r.active, &mut out, rng);
        let anchor = id(r.anchor, &mut out, rng);
        out.relations.push(RelationNode { relation: r.relation, active, anchor, sentence: 0 });
    }
    out
}

/// The pool of 20 query SSGs ("20 scripts", §5.3): the ten [`handwritten_queries`] and ten sampled
/// from the database, half of them two sub-graphs of different scenes merged (one script describing
/// several corners of a room). Seeded.
pub fn query_pool(db: &SceneDatabase, cat: &Catalogue, seed: u64) -> Vec<Ssg> {
    let mut pool = handwritten_queries(cat);
    let mut rng = inbetween_core::seed::rng(inbetween_core::seed::derive(seed, 0x5547));
    while pool.len() < 20 && !db.scenes.is_empty() {
        let mut q = sampled_query(db, cat, &mut rng);
        if rng.random_bool(0.5) {
            let other = sampled_query(db, cat, &mut rng);
            q.merge(other);
        }
        if !q.objects.is_empty() {
            pool.push(q);
        }
    }
    pool
}

/// `n` distinct pool indices drawn with `seed` (all of them when `n` ≥ the pool).
pub fn query_sets(pool_len: usize, n: usize, seed: u64) -> Vec<usize> {
    let mut idx: Vec<usize> = (0..pool_len).collect();
    let mut rng = inbetween_core::seed::rng(seed);
    let n = n.min(pool_len);
    for i in 0..n {
        let j = rng.random_range(i..pool_len);
        idx.swap(i, j);
    }
    idx.truncate(n);
    idx
}

/// One box of Fig. 8: the per-query scores of both matchers on a set of `n` queries.
#[derive(Debug, Clone, PartialEq)]
pub struct Fig8Set {
    pub n: usize,
    /// Pool indices of the queries, in draw order.
    pub queries: Vec<usize>,
    pub relation_first: Vec<f64>,
    pub object_first: Vec<f64>,
}

/// The Fig. 8 experiment: for each size in `sizes` (the paper: 5, 10, 15), draw that many queries
/// from `pool` (seeded) and score both matchers on each.
pub fn fig8(db: &SceneDatabase, cat: &Catalogue, pool: &[Ssg], sizes: &[usize], seed: u64) -> Vec<Fig8Set> {
    sizes
        .iter()
        .enumerate()
        .map(|(k, &n)| {
            let queries = query_sets(pool.len(), n, inbetween_core::seed::derive(seed, k as u64));
            let relation_first =
                queries.iter().map(|&i| score(&pool[i], db, &relation_first(&pool[i], db, cat))).collect();
            let object_first = queries.iter().map(|&i| score(&pool[i], db, &object_first(&pool[i], db, cat))).collect();
            Fig8Set { n, queries, relation_first, object_first }
        })
        .collect()
}
