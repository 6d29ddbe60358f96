//! Scene composition (§4.1): the parsed script's SSGs → one query SSG → database matching
//! (relation-first, Algorithm 1) → a layout problem whose hints come from the matched database
//! sub-graphs → the furnished [`Scene`].
//!
//! This is an offline "build" job in the ozz sense: inputs ([`ComposeInput`]), validation (the
//! parser's diagnostics, objects the room cannot hold), run ([`compose`]), outputs
//! ([`Composition`]).

use std::collections::HashMap;
use std::time::Instant;

use crate::catalogue::{Catalogue, Support};
use crate::database::{Placement, SceneDatabase};
use crate::error::Diagnostic;
use crate::layout::{self, LayoutConstraint, LayoutItem, LayoutPlace, LayoutProblem, RoomPlace, Violations};
use crate::matching::{self, MatchMap};
use crate::parse::ParsedScript;
use crate::scene::{Origin, PlacedObject, Room, Scene};
use crate::sentences::SentenceKind;
use crate::ssg::{Command, NodeId, Place, PlaceNode, Relation, Ssg};

/// Which matcher picks the database sub-graphs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Matcher {
    /// The paper's Algorithm 1: relation nodes first, single objects as the fallback.
    RelationFirst,
    /// The LDS baseline: single objects first, relations checked afterwards.
    ObjectFirst,
}

/// Settings of a composition.
#[derive(Debug, Clone)]
pub struct ComposeConfig {
    pub seed: u64,
    pub matcher: Matcher,
    /// When the script names a room kind ("There is a music room$"), also bring in the other
    /// objects of the best-matching database scene of that kind, so the room is furnished rather
    /// than holding only what the text names.
    pub furnish: bool,
}

impl Default for ComposeConfig {
    fn default() -> ComposeConfig {
        ComposeConfig { seed: 1, matcher: Matcher::RelationFirst, furnish: true }
    }
}

/// Identity of an object across edits: its category and which instance of that category it is,
/// counting through the script in order ("the second chair"). Sentence numbers shift when a line
/// is inserted, and a sentence's text changes when an object is added to it; neither moves
/// the identity of the objects that stay.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct ObjectKey {
    pub category: String,
    pub occurrence: usize,
}

/// A pose kept from the previous version, with the relations it was placed under. The pin holds
/// only while the object's relations (its signature) are the same.
#[derive(Debug, Clone, PartialEq)]
pub struct Pin {
    pub position: [f32; 3],
    pub yaw: f32,
    pub signature: String,
}

/// Everything composition needs.
pub struct ComposeInput<'a> {
    pub parsed: &'a ParsedScript,
    pub catalogue: &'a Catalogue,
    pub database: &'a SceneDatabase,
    /// Poses to keep, by object identity (see [`ObjectKey`]).
    pub pins: &'a HashMap<ObjectKey, Pin>,
}

/// Seconds spent in each stage of one composition.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ComposeTimes {
    pub matching: f64,
    pub layout: f64,
}

/// The furnished scene with everything learnt on the way.
#[derive(Debug, Clone)]
pub struct Composition {
    pub scene: Scene,
    /// The merged query SSG (G_q) of every scene sentence plus the objects characters target.
    pub query: Ssg,
    pub matches: MatchMap,
    /// Matching score of `matches` (see [`matching::score`]).
    pub match_score: f64,
    /// The relations of the layout, as (relation, active, anchor) indices into `scene.objects`.
    pub relations: Vec<(Relation, usize, usize)>,
    pub violations: Violations,
    /// Problems found while composing (objects dropped for lack of room); the parser's come first.
    pub diagnostics: Vec<Diagnostic>,
    /// Identity and relation signature of each scene object, for the next edit's pins.
    pub keys: Vec<(ObjectKey, String)>,
    pub times: ComposeTimes,
}

/// Size adjectives and the factors they scale a category's default size by (width, height,
/// depth): within about ±30 % of the category's size, so a small table is still a table.
pub const SIZE_WORDS: &[(&str, [f32; 3])] = &[
    ("small", [0.75, 0.9, 0.75]),
    ("little", [0.75, 0.9, 0.75]),
    ("tiny", [0.7, 0.85, 0.7]),
    ("large", [1.3, 1.05, 1.3]),
    ("big", [1.3, 1.05, 1.3]),
    ("huge", [1.35, 1.1, 1.35]),
    ("tall", [1.0, 1.3, 1.0]),
    ("high", [1.0, 1.3, 1.0]),
    ("low", [1.0, 0.7, 1.0]),
    ("short", [1.0, 0.75, 1.0]),
    ("wide", [1.3, 1.0, 1.0]),
    ("narrow", [0.75, 1.0, 1.0]),
];

/// A category's default `size` (width, height, depth, metres) scaled by the size adjectives
/// among `attributes` ([`SIZE_WORDS`]).
pub fn sized(size: [f32; 3], attributes: &[String]) -> [f32; 3] {
    let mut out = size;
    for a in attributes {
        if let Some((_, f)) = SIZE_WORDS.iter().find(|(w, _)| w == a) {
            for k in 0..3 {
                out[k] *= f[k];
            }
        }
    }
    // Shape words (issue 39): a round or square top is as deep as it is wide (a round table is
    // drawn as its square bounding box), a long one half as long again.
    if attributes.iter().any(|a| matches!(a.as_str(), "round" | "square" | "circular")) {
        let side = (out[0] + out[2]) / 2.0;
        out[0] = side;
        out[2] = side;
    }
    if attributes.iter().any(|a| matches!(a.as_str(), "long" | "rectangular")) {
        out[0] *= SHAPE_LONG;
    }
    out
}

/// How much longer a "long" object is than its category's default width.
pub const SHAPE_LONG: f32 = 1.5;

/// Builds the query SSG: every scene sentence's graph, then the objects that direction sentences
/// target and no scene sentence names (a character walking "to the house" needs a house).
///
/// Co-reference: "the desk" in a later sentence is the desk already named ("A lamp is on the
/// desk$" after "A desk is near a bed$"), and a character's target is the scene's object of that
/// category. An indefinite "a desk" in a scene sentence is a new desk.
pub fn query_graph(parsed: &ParsedScript) -> Ssg {
    let mut query = Ssg::default();
    let scene_first = parsed.sentences.iter().filter(|s| s.raw.kind != SentenceKind::Direction);
    let directions = parsed.sentences.iter().filter(|s| s.raw.kind == SentenceKind::Direction);
    for s in scene_first.chain(directions) {
        let direction = s.raw.kind == SentenceKind::Direction;
        let lower = s.raw.at.text.to_lowercase();
        let mut remap: Vec<NodeId> = Vec::with_capacity(s.ssg.objects.len());
        for o in &s.ssg.objects {
            // "the table" after "a dining table" is that table: the same category, else one
            // whose name ends in it (diningtable, coffeetable; floorlamp for "the lamp").
            let existing = query
                .objects
                .iter()
                .rposition(|q| q.category == o.category)
                .or_else(|| query.objects.iter().rposition(|q| q.category.ends_with(&o.category)));
            match existing {
                // "it" (a scene sentence's pronoun) is the object named before.
                Some(q) if direction || o.word == "it" || is_definite(&lower, &o.word) => remap.push(q),
                _ => {
                    remap.push(query.objects.len());
                    query.objects.push(o.clone());
                }
            }
        }
        if query.room.is_none() {
            query.room = s.ssg.room.clone();
        }
        for r in &s.ssg.relations {
            let (active, anchor) = (remap[r.active], remap[r.anchor]);
            // A node related to itself is "each other" (two armchairs face each other).
            if active != anchor || r.active == r.anchor {
                query.relations.push(crate::ssg::RelationNode { active, anchor, ..r.clone() });
            }
        }
        for p in &s.ssg.places {
            let place = match p.place {
                Place::Between { first, second } => Place::Between { first: remap[first], second: remap[second] },
                other => other,
            };
            query.places.push(PlaceNode { place, active: remap[p.active], ..p.clone() });
        }
        for c in &s.ssg.characters {
            let mut c = c.clone();
            for a in &mut c.actions {
                a.target = a.target.map(|t| remap[t]);
                if let Some((_, d)) = &mut a.destination {
                    *d = remap[*d];
                }
            }
            query.characters.push(c);
        }
        query.commands.extend(s.ssg.commands.iter().cloned());
    }
    query
}

/// Whether `word` is written with a definite article in `sentence` ("the desk", "the organized
/// office desk"): up to three modifiers may stand between them.
fn is_definite(sentence: &str, word: &str) -> bool {
    let words: Vec<&str> = sentence.split(|c: char| !c.is_alphanumeric()).filter(|w| !w.is_empty()).collect();
    let word = word.to_lowercase();
    let head = word.split_whitespace().last().unwrap_or("");
    words.iter().enumerate().filter(|(_, w)| **w == head).any(|(i, _)| {
        words[i.saturating_sub(4)..i]
            .iter()
            .rev()
            .take_while(|w| !matches!(**w, "a" | "an"))
            .any(|w| matches!(*w, "the" | "this" | "that" | "its" | "his" | "her" | "their"))
    })
}

/// The room: the kind the script names (the matched database scene's size when one of that kind
/// matched), else the default "room".
fn choose_room(query: &Ssg, cat: &Catalogue, db: &SceneDatabase, matches: &MatchMap) -> (Room, Option<usize>) {
    let kind = query.room.as_deref().and_then(|w| cat.resolve_room(w)).or_else(|| cat.resolve_room("room"));
    let Some(kind) = kind else {
        return (Room { name: "room".into(), width: 5.0, depth: 4.0, height: 2.8 }, None);
    };
    // The database scene of that kind with the most matched nodes, else any of that kind.
    let mut votes: HashMap<usize, usize> = HashMap::new();
    for e in &matches.entries {
        if db.scenes[e.scene].room.name == kind.name {
            *votes.entry(e.scene).or_default() += 1;
        }
    }
    let best = votes
        .into_iter()
        .max_by_key(|&(s, n)| (n, std::cmp::Reverse(s)))
        .map(|(s, _)| s)
        .or_else(|| db.scenes.iter().position(|s| s.room.name == kind.name && query.room.is_some()));
    let mut room = match best {
        Some(s) => db.scenes[s].room.clone(),
        None => Room { name: kind.name.clone(), width: kind.size[0], depth: kind.size[2], height: kind.size[1] },
    };
    // "the room" names no kind: like no room at all, it grows to hold what the text puts in it.
    if kind.name == "room" {
        fit_unnamed_room(&mut room, query, cat);
    }
    (room, best.filter(|_| query.room.is_some()))
}

/// A room the text does not name (or calls just "room") grows to hold what the text puts in it: every object fits with
/// a metre to spare, and the floor is at least three times the objects' footprint. Outdoor
/// objects (a house, a road) make it a street.
fn fit_unnamed_room(room: &mut Room, query: &Ssg, cat: &Catalogue) {
    let (mut longest, mut area) = (0.0f32, 0.0f32);
    let mut outdoor = false;
    for o in &query.objects {
        let Some(c) = cat.get(&o.category) else { continue };
        longest = longest.max(c.size[0].max(c.size[2]));
        if c.support == Support::Floor {
            area += c.size[0] * c.size[2] * o.count.max(1) as f32;
        }
        outdoor |= matches!(cat.class_of(&c.name), "building" | "ground");
    }
    if outdoor {
        if let Some(street) = cat.resolve_room("street") {
            room.name = street.name.clone();
            room.height = street.size[1];
        }
    }
    let side = (longest + 1.0).max((3.0 * area).sqrt());
    room.width = room.width.max(side);
    room.depth = room.depth.max(side);
}

/// A database pose moved into our room: kept when the rooms are the same size, else scaled by the
/// ratio of the room extents so the arrangement stays recognisable.
fn hint_in_room(p: &Placement, from: &Room, to: &Room) -> Placement {
    let sx = to.width / from.width.max(1e-3);
    let sz = to.depth / from.depth.max(1e-3);
    Placement { position: [p.position[0] * sx, p.position[1], p.position[2] * sz], ..p.clone() }
}

/// Composes the scene of a parsed script.
pub fn compose(input: &ComposeInput, cfg: &ComposeConfig) -> Composition {
    let (cat, db) = (input.catalogue, input.database);
    let query = query_graph(input.parsed);
    let t0 = Instant::now();
    let matches = match cfg.matcher {
        Matcher::RelationFirst => matching::relation_first(&query, db, cat),
        Matcher::ObjectFirst => matching::object_first(&query, db, cat),
    };
    let match_score = matching::score(&query, db, &matches);
    let (room, room_scene) = choose_room(&query, cat, db, &matches);
    let t_match = t0.elapsed().as_secs_f64();

    let hint_of: HashMap<NodeId, Placement> = matches
        .entries
        .iter()
        .map(|e| {
            let s = &db.scenes[e.scene];
            (e.query_node, hint_in_room(&s.placements[e.db_node], &s.room, &room))
        })
        .collect();

    // One layout item per object instance ("two chairs" → two items), labelled uniquely.
    let mut items: Vec<LayoutItem> = Vec::new();
    let mut item_keys: Vec<ObjectKey> = Vec::new();
    let mut instances: Vec<Vec<usize>> = Vec::new();
    let mut label_count: HashMap<String, usize> = HashMap::new();
    // The label doubles as the identity: "chair 2" is the second chair of the script.
    let mut label = |category: &str| {
        let n = label_count.entry(category.to_string()).or_default();
        *n += 1;
        let key = ObjectKey { category: category.to_string(), occurrence: *n };
        let label = if *n == 1 { category.to_string() } else { format!("{category} {n}") };
        (label, key)
    };
    for (node, o) in query.objects.iter().enumerate() {
        let Some(c) = cat.get(&o.category) else { continue };
        let mut mine = Vec::new();
        for k in 0..o.count.max(1) {
            let (label, key) = label(&c.name);
            mine.push(items.len());
            items.push(LayoutItem {
                label,
                category: c.name.clone(),
                attributes: o.attributes.clone(),
                size: sized(c.size, &o.attributes),
                support: c.support,
                surface: c.surface,
                origin: Origin::Script { sentence: o.sentence, node },
                hint: if k == 0 { hint_of.get(&node).cloned() } else { None },
                pinned: None,
                seat: c.is_seat(),
            });
            item_keys.push(key);
        }
        instances.push(mine);
    }
    let mut constraints = Vec::new();
    for r in &query.relations {
        let mine = &instances[r.active];
        if r.active == r.anchor {
            // "each other": every instance to the next one.
            for (k, &a) in mine.iter().enumerate().filter(|_| mine.len() > 1) {
                constraints.push(LayoutConstraint {
                    relation: r.relation,
                    active: a,
                    anchor: mine[(k + 1) % mine.len()],
                });
            }
            continue;
        }
        for (k, &a) in mine.iter().enumerate() {
            // Several actives share one anchor: "two lamps on the desk" puts both on the desk;
            // "on either side" gives them its sides in turn, "around" its edges.
            let relation = match r.relation {
                Relation::EitherSide if k % 2 == 0 => Relation::LeftOf,
                Relation::EitherSide => Relation::RightOf,
                Relation::Around => Relation::At,
                r => r,
            };
            if let Some(&b) = instances[r.anchor].first() {
                constraints.push(LayoutConstraint { relation, active: a, anchor: b });
            }
        }
    }
    let mut places = Vec::new();
    for p in &query.places {
        let place = match p.place {
            Place::Middle => RoomPlace::Middle,
            Place::Corner => RoomPlace::Corner,
            Place::Wall => RoomPlace::Wall,
            Place::Door => RoomPlace::Door,
            Place::Between { first, second } => {
                // "between the armchairs": the first two instances of one plural node.
                let (a, b) = if first == second {
                    (instances[first].first(), instances[first].get(1))
                } else {
                    (instances[first].first(), instances[second].first())
                };
                let (Some(&a), Some(&b)) = (a, b) else { continue };
                RoomPlace::Between(a, b)
            }
        };
        for &item in &instances[p.active] {
            places.push(LayoutPlace { place, item });
        }
    }

    // Furnishing: the rest of the matched room's database scene, with its own relations.
    if let (true, Some(s)) = (cfg.furnish && query.room.is_some(), room_scene) {
        let scene = &db.scenes[s];
        let used: Vec<NodeId> = matches.entries.iter().filter(|e| e.scene == s).map(|e| e.db_node).collect();
        let taken: Vec<&str> = items.iter().map(|i| i.category.as_str()).collect::<Vec<_>>();
        let mut db_item: HashMap<NodeId, usize> = HashMap::new();
        let mut extra = Vec::new();
        for (n, o) in scene.ssg.objects.iter().enumerate() {
            if used.contains(&n) || taken.contains(&o.category.as_str()) {
                continue;
            }
            let Some(c) = cat.get(&o.category) else { continue };
            db_item.insert(n, items.len() + extra.len());
            extra.push(LayoutItem {
                label: String::new(),
                category: c.name.clone(),
                attributes: o.attributes.clone(),
                size: scene.placements[n].size,
                support: c.support,
                surface: c.surface,
                origin: Origin::Database { scene: scene.name.clone(), node: n },
                hint: Some(hint_in_room(&scene.placements[n], &scene.room, &room)),
                pinned: None,
                seat: c.is_seat(),
            });
        }
        for mut e in extra {
            let (l, key) = label(&e.category);
            e.label = l;
            items.push(e);
            item_keys.push(key);
        }
        for r in &scene.ssg.relations {
            if let (Some(&a), Some(&b)) = (db_item.get(&r.active), db_item.get(&r.anchor)) {
                constraints.push(LayoutConstraint { relation: r.relation, active: a, anchor: b });
            }
        }
    }

    let signatures = signatures(&items, &constraints, &item_keys);
    apply_pins(&mut items, &constraints, &item_keys, &signatures, input.pins, &room);

    let t1 = Instant::now();
    let n_script = items.iter().filter(|i| matches!(i.origin, Origin::Script { .. })).count();
    let solved = solve_layout(&room, &items, &constraints, &places, n_script, cfg.seed);
    let t_layout = t1.elapsed().as_secs_f64();

    let mut diagnostics = input.parsed.diagnostics.clone();
    // One message per sentence and category: "8 of 10 'piano' left out: …", not eight lines.
    let mut groups: Vec<((usize, String), Vec<&str>, &str)> = Vec::new();
    for (item, why) in &solved.dropped {
        let it = &items[*item];
        if let Origin::Script { sentence, .. } = it.origin {
            let key = (sentence, it.category.clone());
            match groups.iter_mut().find(|g| g.0 == key) {
                Some(g) => g.1.push(&it.label),
                None => groups.push((key, vec![&it.label], why)),
            }
        }
    }
    for ((sentence, category), labels, why) in groups {
        let Some(s) = input.parsed.sentences.iter().find(|s| s.raw.at.sentence == sentence + 1) else { continue };
        let asked = items
            .iter()
            .filter(|i| {
                i.category == category && matches!(i.origin, Origin::Script { sentence: t, .. } if t == sentence)
            })
            .count();
        let message = if labels.len() == 1 {
            format!("'{}' left out: {why}", labels[0])
        } else {
            format!("{} of {asked} '{category}' left out ({}): {why}", labels.len(), labels.join(", "))
        };
        diagnostics.push(Diagnostic { at: s.raw.at.clone(), word: Some(category), message, suggestions: Vec::new() });
    }
    let relations: Vec<(Relation, usize, usize)> = constraints
        .iter()
        .filter_map(|c| Some((c.relation, solved.placed[c.active]?, solved.placed[c.anchor]?)))
        .collect();
    diagnostics.extend(unkept(input.parsed, &items, &constraints, &places, &solved, &room));
    let mut keys = vec![(ObjectKey { category: String::new(), occurrence: 0 }, String::new()); solved.objects.len()];
    for (item, placed) in solved.placed.iter().enumerate() {
        if let Some(p) = placed {
            keys[*p] = (item_keys[item].clone(), signatures[item].clone());
        }
    }
    let outcome = solved;
    let mut camera = Vec::new();
    let mut weather = None;
    for c in &query.commands {
        match c {
            Command::Camera { view, .. } => camera.push(view.clone()),
            Command::Weather { weather: w, .. } => weather = Some(w.clone()),
            Command::Time { .. } => {}
        }
    }
    let scene = Scene { room, objects: outcome.objects, camera, weather };
    Composition {
        scene,
        query,
        matches,
        match_score,
        relations,
        violations: outcome.violations,
        diagnostics,
        keys,
        times: ComposeTimes { matching: t_match, layout: t_layout },
    }
}

/// A warning for every relation and place of the script's own objects that the layout could not
/// keep (issue 39: every phrase is realised or named in a warning).
fn unkept(
    parsed: &ParsedScript,
    items: &[LayoutItem],
    constraints: &[LayoutConstraint],
    places: &[LayoutPlace],
    solved: &Solved,
    room: &Room,
) -> Vec<Diagnostic> {
    let object = |i: usize| solved.placed[i].map(|p| &solved.objects[p]);
    let sentence_of = |i: usize| match items[i].origin {
        Origin::Script { sentence, .. } => parsed.sentences.iter().find(|s| s.raw.at.sentence == sentence + 1),
        Origin::Database { .. } => None,
    };
    let mut out = Vec::new();
    let mut warn = |i: usize, phrase: &str, message: String| {
        if let Some(s) = sentence_of(i) {
            out.push(Diagnostic {
                at: s.raw.at.clone(),
                word: Some(phrase.to_string()),
                message,
                suggestions: Vec::new(),
            });
        }
    };
    for c in constraints {
        let (Some(a), Some(b)) = (object(c.active), object(c.anchor)) else { continue };
        if !layout::relation_holds(c.relation, a, b) {
            let phrase = c.relation.phrase();
            warn(
                c.active,
                phrase,
                format!("'{}' {phrase} '{}' not kept: no free place in the room keeps it", a.label, b.label),
            );
        }
    }
    for p in places {
        let Some(o) = object(p.item) else { continue };
        if !layout::place_holds(p.place, o, room, object) {
            let phrase = match p.place {
                RoomPlace::Middle => "in the middle of the room",
                RoomPlace::Corner => "in the corner",
                RoomPlace::Wall => "against the wall",
                RoomPlace::Door => "by the door",
                RoomPlace::Between(..) => "between",
            };
            warn(p.item, phrase, format!("'{}' {phrase} not kept: no free place in the room keeps it", o.label));
        }
    }
    out
}

/// A layout where the script's objects come first.
struct Solved {
    objects: Vec<PlacedObject>,
    /// Per original item, its index in `objects`.
    placed: Vec<Option<usize>>,
    /// Script items left out, with the solver's reason.
    dropped: Vec<(usize, String)>,
    violations: Violations,
}

/// Lays out the script's own objects (`items[..n_script]`) first, then the furnishing around
/// them with the script's poses pinned. Furnishing is optional: a furnishing object that does not
/// fit, or takes part in a violation, is left out quietly, so the user's objects never give way to
/// objects they did not ask for.
fn solve_layout(
    room: &Room,
    items: &[LayoutItem],
    constraints: &[LayoutConstraint],
    places: &[LayoutPlace],
    n_script: usize,
    seed: u64,
) -> Solved {
    let sub = |keep: &[usize], pins: &HashMap<usize, ([f32; 3], f32)>| {
        let index: HashMap<usize, usize> = keep.iter().enumerate().map(|(k, &i)| (i, k)).collect();
        let items: Vec<LayoutItem> = keep
            .iter()
            .map(|&i| {
                let mut it = items[i].clone();
                if let Some(&p) = pins.get(&i) {
                    it.pinned = Some(p);
                }
                it
            })
            .collect();
        let relations = constraints
            .iter()
            .filter_map(|c| {
                Some(LayoutConstraint { active: *index.get(&c.active)?, anchor: *index.get(&c.anchor)?, ..*c })
            })
            .collect();
        let places = places
            .iter()
            .filter_map(|p| {
                let place = match p.place {
                    RoomPlace::Between(a, b) => RoomPlace::Between(*index.get(&a)?, *index.get(&b)?),
                    other => other,
                };
                Some(LayoutPlace { place, item: *index.get(&p.item)? })
            })
            .collect();
        LayoutProblem { room: room.clone(), items, relations, places }
    };
    let script: Vec<usize> = (0..n_script).collect();
    let first = layout::solve(&sub(&script, &HashMap::new()), seed);
    let dropped: Vec<(usize, String)> = first.dropped.iter().map(|(k, why)| (script[*k], why.clone())).collect();
    let mut pins = HashMap::new();
    for (k, p) in first.placed.iter().enumerate() {
        if let Some(p) = p {
            let o = &first.objects[*p];
            pins.insert(script[k], (o.position, o.yaw));
        }
    }
    let mut keep: Vec<usize> =
        script.iter().copied().filter(|i| pins.contains_key(i)).chain(n_script..items.len()).collect();
    let mut best = (keep.clone(), first);
    for round in 0..4 {
        if keep.len() == pins.len() && round > 0 {
            break;
        }
        let problem = sub(&keep, &pins);
        let outcome = layout::solve(&problem, seed);
        // Furnishing objects that were dropped or take part in a violation go; then solve again.
        let mut bad: Vec<usize> = outcome.dropped.iter().map(|(k, _)| *k).collect();
        let item_of_object: HashMap<usize, usize> =
            outcome.placed.iter().enumerate().filter_map(|(k, p)| p.map(|p| (p, k))).collect();
        let v = &outcome.violations;
        let placed_relations: Vec<(usize, usize)> = problem
            .relations
            .iter()
            .filter(|c| outcome.placed[c.active].is_some() && outcome.placed[c.anchor].is_some())
            .map(|c| (c.active, c.anchor))
            .collect();
        for &(a, b) in &v.overlaps {
            bad.extend([item_of_object.get(&a), item_of_object.get(&b)].into_iter().flatten());
        }
        for &r in &v.unmet {
            if let Some(&(a, b)) = placed_relations.get(r) {
                bad.extend([a, b]);
            }
        }
        for &o in v.outside.iter().chain(&v.unreachable) {
            bad.extend(item_of_object.get(&o));
        }
        bad.retain(|&k| keep[k] >= n_script);
        best = (keep.clone(), outcome);
        if bad.is_empty() {
            break;
        }
        keep = keep.iter().enumerate().filter(|(k, _)| !bad.contains(k)).map(|(_, &i)| i).collect();
    }
    let (keep, outcome) = best;
    let mut placed = vec![None; items.len()];
    for (k, p) in outcome.placed.iter().enumerate() {
        placed[keep[k]] = *p;
    }
    Solved { objects: outcome.objects, placed, dropped, violations: outcome.violations }
}

/// Each item's attributes and relations as text ("office|Near:bed 1"): a pin holds only while
/// this is unchanged, so editing a relation in the text moves the objects it names.
fn signatures(items: &[LayoutItem], constraints: &[LayoutConstraint], keys: &[ObjectKey]) -> Vec<String> {
    let name = |i: usize| format!("{} {}", keys[i].category, keys[i].occurrence);
    (0..items.len())
        .map(|i| {
            // Only the relations where the item is the active side: a new lamp on the desk must
            // not move the desk.
            let mut parts: Vec<String> = constraints
                .iter()
                .filter(|c| c.active == i)
                .map(|c| format!("{:?}:{}", c.relation, name(c.anchor)))
                .collect();
            parts.sort();
            format!("{}|{}", items[i].attributes.join(","), parts.join("|"))
        })
        .collect()
}

/// Pins every item whose previous pose is known, whose relations are unchanged and whose room
/// still holds it; then releases, transitively, every item resting on or related as the active
/// side to a released anchor (a lamp on a desk that moves must move with it).
fn apply_pins(
    items: &mut [LayoutItem],
    constraints: &[LayoutConstraint],
    keys: &[ObjectKey],
    signatures: &[String],
    pins: &HashMap<ObjectKey, Pin>,
    room: &Room,
) {
    let mut pinned: Vec<bool> = (0..items.len())
        .map(|i| {
            pins.get(&keys[i]).is_some_and(|p| {
                p.signature == signatures[i]
                    && (0.0..=room.width).contains(&p.position[0])
                    && (0.0..=room.depth).contains(&p.position[2])
            })
        })
        .collect();
    loop {
        let mut changed = false;
        for c in constraints {
            if pinned[c.active] && !pinned[c.anchor] {
                pinned[c.active] = false;
                changed = true;
            }
        }
        if !changed {
            break;
        }
    }
    for (i, item) in items.iter_mut().enumerate() {
        if pinned[i] {
            let p = &pins[&keys[i]];
            item.pinned = Some((p.position, p.yaw));
        }
    }
}

/// Whether an object stands on the floor (for previews and counts).
pub fn on_floor(o: &PlacedObject, cat: &Catalogue) -> bool {
    o.support.is_none() && cat.get(&o.category).is_some_and(|c| c.support == Support::Floor)
}
