//! Layout: placing objects in the room so that their relations hold, nothing interpenetrates,
//! everything is inside the room and every floor object can be walked up to (§4.1's "optimize the
//! positions", done here by a seeded constructive search).
//!
//! The solver places anchors before the objects related to them (relation graph order), samples
//! candidate poses around each anchor (or along walls, on surfaces, under the ceiling), keeps the
//! first valid one by score (relations met, then the database hint, then tidiness), and restarts
//! with derived seeds when something had to be dropped. Every loop is bounded: an object that fits
//! nowhere is dropped with a reason instead.

pub mod geom;
pub mod grid;
mod solve;

pub use solve::solve;

use rand::Rng;

use crate::catalogue::Support;
use crate::database::Placement;
use crate::scene::{Origin, PlacedObject, Room};
use crate::ssg::Relation;

use geom::EPS;
use grid::Grid;

/// Largest footprint gap for [`Relation::Near`], metres.
pub const NEAR_GAP: f32 = 1.0;
/// Largest footprint gap for [`Relation::NextTo`], metres.
pub const NEXT_TO_GAP: f32 = 0.3;
/// Farthest [`Relation::InFrontOf`] / [`Relation::Behind`] distance from the anchor's face, metres.
pub const FRONT_GAP: f32 = 1.5;
/// Thickness left for a table top: an object under a table keeps its top this far below.
pub const UNDER_CLEARANCE: f32 = 0.03;
/// Depth kept free in front of a seat, metres: a person stands there to sit down. Tables and
/// desks (surfaces, legs room beneath) and anything lower than [`SEAT_FRONT_LOW`] may reach in.
pub const SEAT_FRONT: f32 = 0.3;
/// Objects lower than this (rugs) do not block a seat's front, metres.
pub const SEAT_FRONT_LOW: f32 = 0.1;
/// How far the front of a seat "in front of" a table with leg room goes in under its top, metres
/// (the seat is tucked at it: [`crate::catalogue::builtin::tucks_under`]).
pub const TUCK: f32 = 0.15;
/// Height of the centre of wall objects (paintings, boards), metres.
pub const WALL_CENTER_HEIGHT: f32 = 1.5;

/// One object to place.
#[derive(Debug, Clone, PartialEq)]
pub struct LayoutItem {
    pub label: String,
    pub category: String,
    pub attributes: Vec<String>,
    /// Width (x), height (y), depth (z) in its own frame, metres.
    pub size: [f32; 3],
    pub support: Support,
    /// Whether other objects can rest on its top.
    pub surface: bool,
    pub origin: Origin,
    /// Pose from the matched database scene (room coordinates): tried first when valid.
    pub hint: Option<Placement>,
    /// Keep exactly here (position, yaw): incremental edits keep unchanged objects in place.
    pub pinned: Option<([f32; 3], f32)>,
    /// A seat. One the script names keeps [`SEAT_FRONT`] free in front of it (where a person
    /// stands to sit down) and, put "in front of" something, turns to face it (a chair in front
    /// of a desk faces the desk); database seats keep their authored poses and neighbours.
    pub seat: bool,
}

/// `items[active]` stands in `relation` to `items[anchor]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LayoutConstraint {
    pub relation: Relation,
    pub active: usize,
    pub anchor: usize,
}

/// Where an item must stand, in the room or between two items (issue 39; the SSG's
/// [`crate::ssg::Place`] with item indices).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RoomPlace {
    /// Its centre within [`middle_tolerance`] of the room's centre.
    Middle,
    /// Within [`CORNER_GAP`] of two walls that meet.
    Corner,
    /// Its back within [`WALL_GAP`] of a wall.
    Wall,
    /// Its footprint within [`DOOR_REACH`] of the door.
    Door,
    /// Its centre on the line joining the two items' centres, in the middle 80 %, within
    /// [`BETWEEN_OFFSET`] of the line.
    Between(usize, usize),
}

/// `items[item]` stands at `place`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LayoutPlace {
    pub place: RoomPlace,
    pub item: usize,
}

/// [`RoomPlace::Corner`]: largest gap to each of the two walls, metres.
pub const CORNER_GAP: f32 = 0.15;
/// [`RoomPlace::Wall`]: largest gap between the item's back and the wall, metres.
pub const WALL_GAP: f32 = 0.1;
/// [`RoomPlace::Door`]: largest distance from the door to the footprint, metres.
pub const DOOR_REACH: f32 = 1.0;
/// [`RoomPlace::Between`]: largest distance from the line between the two, metres.
pub const BETWEEN_OFFSET: f32 = 0.6;

/// [`RoomPlace::Middle`]: largest distance from the room's centre, metres (12 % of the smaller
/// side, at least 0.5 m).
pub fn middle_tolerance(room: &Room) -> f32 {
    (0.12 * room.width.min(room.depth)).max(0.5)
}

/// Whether `o` stands at `place` (`item` gives the placed object of an item index).
pub fn place_holds<'a>(
    place: RoomPlace,
    o: &PlacedObject,
    room: &Room,
    item: impl Fn(usize) -> Option<&'a PlacedObject>,
) -> bool {
    let c = geom::center(o);
    match place {
        RoomPlace::Middle => (c[0] - room.width / 2.0).hypot(c[1] - room.depth / 2.0) <= middle_tolerance(room),
        RoomPlace::Corner => {
            let [hx, hz] = o.half_extents_xz();
            let gx = (c[0] - hx).min(room.width - c[0] - hx);
            let gz = (c[1] - hz).min(room.depth - c[1] - hz);
            gx <= CORNER_GAP && gz <= CORNER_GAP
        }
        RoomPlace::Wall => wall_gap(o, room) <= WALL_GAP,
        RoomPlace::Door => {
            let d = geom::to_local(c, o.yaw, door(room));
            let dx = (d[0].abs() - o.size[0] / 2.0).max(0.0);
            let dz = (d[1].abs() - o.size[2] / 2.0).max(0.0);
            dx.hypot(dz) <= DOOR_REACH
        }
        RoomPlace::Between(a, b) => {
            let (Some(a), Some(b)) = (item(a), item(b)) else { return false };
            let (t, off) = crate::database::geometry::along_segment(geom::center(a), geom::center(b), c);
            t > 0.1 && t < 0.9 && off <= BETWEEN_OFFSET
        }
    }
}

/// Distance from an object's back (the middle of its back edge) to the nearest wall, metres.
pub fn wall_gap(o: &PlacedObject, room: &Room) -> f32 {
    let f = geom::forward(o.yaw);
    let d = o.size[2] / 2.0;
    let back = [o.position[0] - f[0] * d, o.position[2] - f[1] * d];
    [back[0], room.width - back[0], back[1], room.depth - back[1]].into_iter().fold(f32::INFINITY, f32::min)
}

#[derive(Debug, Clone, PartialEq)]
pub struct LayoutProblem {
    pub room: Room,
    pub items: Vec<LayoutItem>,
    pub relations: Vec<LayoutConstraint>,
    /// Places items must stand at (issue 39).
    pub places: Vec<LayoutPlace>,
}

/// What went wrong in a layout (indices into the objects, or into the relation list for `unmet`).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Violations {
    /// Pairs (i < j) of interpenetrating objects.
    pub overlaps: Vec<(usize, usize)>,
    /// Relations that do not hold.
    pub unmet: Vec<usize>,
    /// Objects not fully inside the room.
    pub outside: Vec<usize>,
    /// Floor objects whose front cannot be walked to from the door.
    pub unreachable: Vec<usize>,
    /// Places not kept (indices into the problem's places; [`check`] leaves it empty).
    pub unmet_places: Vec<usize>,
}

impl Violations {
    pub fn total(&self) -> usize {
        self.overlaps.len() + self.unmet.len() + self.outside.len() + self.unreachable.len() + self.unmet_places.len()
    }
}

#[derive(Debug, Clone, PartialEq)]
pub struct LayoutOutcome {
    /// Placed objects, in item order (dropped items left out).
    pub objects: Vec<PlacedObject>,
    /// `placed[item]` = index into `objects`, None when dropped.
    pub placed: Vec<Option<usize>>,
    /// Items that fit nowhere, with a sentence saying why.
    pub dropped: Vec<(usize, String)>,
    /// What [`check`] finds in `objects` with the relations between placed items.
    pub violations: Violations,
}

/// Whether `rel` holds between placed objects (`active` rel `anchor`): exactly
/// [`crate::database::holds`] (one definition for database scenes, matching and layout; see
/// `database::geometry` for the rules: On = base at the anchor's top with the centre inside its
/// footprint, Near = gap ≤ 1.0 m, NextTo = gap ≤ 0.3 m at the same level, InFrontOf/Behind =
/// past the front/back face within 1.5 m and roughly centred, Under/Above/In by heights and
/// footprints). The solver's candidates aim at the stricter [`strictly_holds`].
pub fn relation_holds(rel: Relation, active: &PlacedObject, anchor: &PlacedObject) -> bool {
    crate::database::holds(rel, &placement(active), &placement(anchor))
}

/// A placed object as a database placement (same pose and size).
pub fn placement(o: &PlacedObject) -> Placement {
    Placement { position: o.position, yaw: o.yaw, size: o.size }
}

/// The layout's own, tidier reading of each relation (what candidates are generated for):
/// everything in the anchor's frame; NextTo also side by side along the anchor's width axis,
/// InFrontOf/Behind wholly past the face and centred within the anchor's half width, Under and
/// In with the whole footprint inside the anchor's. Whatever holds strictly also holds for
/// [`relation_holds`].
pub fn strictly_holds(rel: Relation, active: &PlacedObject, anchor: &PlacedObject) -> bool {
    let (c, h) = geom::local_box(active, anchor);
    let (aw, ad) = (anchor.size[0] / 2.0, anchor.size[2] / 2.0);
    let gap = geom::box_gap(c, h, [0.0, 0.0], [aw, ad]);
    let centred = c[0].abs() <= aw.max(0.25);
    let held = match rel {
        Relation::On => (active.position[1] - anchor.top()).abs() <= EPS && geom::center_inside(active, anchor),
        Relation::Near => gap <= NEAR_GAP - EPS,
        Relation::NextTo => gap <= NEXT_TO_GAP - EPS && c[1].abs() < h[1] + ad && c[0].abs() >= h[0] + aw - EPS,
        Relation::InFrontOf => {
            let tuck = if tucks(active, anchor) { TUCK } else { 0.0 };
            c[1] - h[1] >= ad - tuck - EPS && c[1] >= ad && gap <= FRONT_GAP - EPS && centred
        }
        Relation::Behind => c[1] + h[1] <= -ad + EPS && gap <= FRONT_GAP - EPS && centred,
        Relation::Under => {
            active.top() <= anchor.top() - UNDER_CLEARANCE + 1e-4 && geom::footprint_inside(active, anchor)
        }
        Relation::Above => {
            active.position[1] >= anchor.top() - EPS && geom::box_penetration(c, h, [0.0, 0.0], [aw, ad]) > 0.01
        }
        Relation::In => geom::footprint_inside(active, anchor) && active.position[1] >= anchor.position[1] - EPS,
        Relation::Against
        | Relation::Opposite
        | Relation::Facing
        | Relation::LeftOf
        | Relation::RightOf
        | Relation::EitherSide
        | Relation::At
        | Relation::Around => true,
    };
    held && relation_holds(rel, active, anchor)
}

/// Whether `seat` in front of `anchor` is tucked at it (may reach [`TUCK`] in under its top).
pub fn tucks(seat: &PlacedObject, anchor: &PlacedObject) -> bool {
    crate::catalogue::builtin::tucks_under(&seat.category, &anchor.category)
}

/// Whether a layout relation lets `a` and `b` share floor space as a tucked seat and its table.
pub fn tucked_pair(rel: Relation, active: &PlacedObject, anchor: &PlacedObject) -> bool {
    matches!(rel, Relation::InFrontOf | Relation::At | Relation::Around) && tucks(active, anchor)
}

/// Relations under which two objects may share floor space (one rests on, hangs over, stands
/// under or inside the other).
fn stacking(rel: Relation) -> bool {
    matches!(rel, Relation::On | Relation::Under | Relation::Above | Relation::In)
}

/// Whether objects `i` and `j` may interpenetrate: one supports the other or a stacking relation
/// links them.
fn exempt(objects: &[PlacedObject], relations: &[(Relation, usize, usize)], i: usize, j: usize) -> bool {
    objects[i].support == Some(j)
        || objects[j].support == Some(i)
        || relations.iter().any(|&(r, a, b)| {
            ((a, b) == (i, j) || (a, b) == (j, i)) && (stacking(r) || tucked_pair(r, &objects[a], &objects[b]))
        })
}

/// The floor area in front of a seat that must stay free ([`SEAT_FRONT`] deep, the seat's
/// width), as a box from the floor to 1.2 m.
pub fn seat_front(o: &PlacedObject) -> PlacedObject {
    let c = geom::to_world(geom::center(o), o.yaw, [0.0, o.size[2] / 2.0 + SEAT_FRONT / 2.0]);
    PlacedObject {
        label: format!("front of {}", o.label),
        position: [c[0], 0.0, c[1]],
        size: [o.size[0], 1.2, SEAT_FRONT],
        support: None,
        ..o.clone()
    }
}

/// Whether `other` stands in the free front of seat `seat` (`legroom`: a surface, or what the seat
/// is in front of; what rests on something, and anything lower than [`SEAT_FRONT_LOW`], may reach
/// in).
pub fn blocks_seat(seat: &PlacedObject, other: &PlacedObject, legroom: bool) -> bool {
    !legroom && other.support.is_none() && other.top() > SEAT_FRONT_LOW && interpenetrate(&seat_front(seat), other)
}

/// Whether `o` rests on `support`: its base on the support's top, or on a shelf inside a shelf
/// unit ([`crate::catalogue::has_shelves`]), with its centre inside the support's footprint.
pub fn rests_on(o: &PlacedObject, support: &PlacedObject) -> bool {
    let y = o.position[1];
    let level = (support.top() - y).abs() <= EPS
        || (crate::catalogue::has_shelves(&support.category) && y > support.position[1] && y < support.top());
    level && geom::center_inside(o, support)
}

/// Whether two objects interpenetrate (footprints and heights both overlap by more than 2 cm).
pub fn interpenetrate(a: &PlacedObject, b: &PlacedObject) -> bool {
    geom::heights_overlap(a, b) && geom::footprints_overlap(a, b)
}

/// Whether an object lies inside the room (2 cm slack).
pub fn inside_room(room: &Room, o: &PlacedObject) -> bool {
    let [hx, hz] = o.half_extents_xz();
    let [x, y, z] = o.position;
    x - hx >= -EPS
        && z - hz >= -EPS
        && x + hx <= room.width + EPS
        && z + hz <= room.depth + EPS
        && y >= -EPS
        && o.top() <= room.height + EPS
}

/// Where people come in: the middle of the z = depth wall (the "front" wall the default camera
/// looks through).
pub fn door(room: &Room) -> [f32; 2] {
    [room.width / 2.0, room.depth]
}

/// The grid cell walks start from: the free cell nearest the door, else nearest the centre.
fn start_cell(room: &Room, g: &Grid) -> Option<grid::Cell> {
    g.nearest_free(door(room)).or_else(|| g.nearest_free([room.width / 2.0, room.depth / 2.0]))
}

/// Objects that must be walked up to: standing on the floor and not under or inside another.
fn needs_access(objects: &[PlacedObject], relations: &[(Relation, usize, usize)]) -> Vec<bool> {
    (0..objects.len())
        .map(|i| {
            objects[i].position[1] < 0.05
                && grid::blocks_walking(&objects[i])
                && objects[i].support.is_none()
                && !relations.iter().any(|&(r, a, _)| a == i && matches!(r, Relation::Under | Relation::In))
        })
        .collect()
}

/// Points a walker could stand at to use an object: along its front edge, then the front half of
/// its sides, `WALKER_RADIUS + 5 cm` out (a chair facing a desk is reached from its side).
fn access_points(o: &PlacedObject) -> Vec<[f32; 2]> {
    let (hw, hd) = (o.size[0] / 2.0, o.size[2] / 2.0);
    let out = grid::WALKER_RADIUS + 0.05;
    let mut local = Vec::new();
    let n = ((2.0 * hw / grid::CELL).ceil() as usize).clamp(1, 40);
    for k in 0..=n {
        local.push([-hw + 2.0 * hw * k as f32 / n as f32, hd + out]);
    }
    for s in [-1.0, 1.0] {
        for t in [hd, hd * 0.5, 0.0] {
            local.push([s * (hw + out), t]);
        }
    }
    if crate::catalogue::builtin::tucking_seat(&o.category) {
        // A seat that may be tucked under a table is pulled out from behind or beside its back.
        for s in [-1.0, 1.0] {
            local.push([s * (hw + out), -hd]);
        }
        local.push([0.0, -hd - out]);
    }
    local.into_iter().map(|l| geom::to_world(geom::center(o), o.yaw, l)).collect()
}

/// Indices of floor objects none of whose access points can be walked to from the door.
fn unreachable(room: &Room, objects: &[PlacedObject], relations: &[(Relation, usize, usize)]) -> Vec<usize> {
    let need = needs_access(objects, relations);
    if !need.iter().any(|&n| n) {
        return Vec::new();
    }
    let g = Grid::from_objects(room, objects, grid::CELL, grid::WALKER_RADIUS);
    let reached = match start_cell(room, &g) {
        Some(s) => g.reachable_from(s),
        None => vec![false; g.nx * g.nz],
    };
    (0..objects.len())
        .filter(|&i| need[i])
        .filter(|&i| {
            !access_points(&objects[i]).iter().any(|&p| g.cell_of(p).is_some_and(|c| reached[c.1 * g.nx + c.0]))
        })
        .collect()
}

/// Everything wrong with a layout: overlaps, unmet relations (`(relation, active, anchor)` as
/// object indices), objects outside the room, floor objects that cannot be walked up to.
pub fn check(room: &Room, objects: &[PlacedObject], relations: &[(Relation, usize, usize)]) -> Violations {
    let n = objects.len();
    let valid = |&(_, a, b): &(Relation, usize, usize)| a < n && b < n && a != b;
    let mut v = Violations::default();
    for i in 0..n {
        for j in i + 1..n {
            if !exempt(objects, relations, i, j) && interpenetrate(&objects[i], &objects[j]) {
                v.overlaps.push((i, j));
            }
        }
    }
    v.unmet = relations
        .iter()
        .enumerate()
        .filter(|(_, r)| !valid(r) || !relation_holds(r.0, &objects[r.1], &objects[r.2]))
        .map(|(k, _)| k)
        .collect();
    v.outside = (0..n).filter(|&i| !inside_room(room, &objects[i])).collect();
    let rels: Vec<_> = relations.iter().copied().filter(valid).collect();
    v.unreachable = unreachable(room, objects, &rels);
    v
}
