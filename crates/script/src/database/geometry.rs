//! When a relation holds between two placed boxes. One definition for the database, the matcher
//! and the tests; `layout::relation_holds` implements the same rules on `PlacedObject`.
//!
//! Footprints are the world-axis-aligned boxes of the yawed objects (as
//! `PlacedObject::half_extents_xz`), heights run from the base `position[1]` to `base + size[1]`.
//! A's relation to B (`active` a, `anchor` b):
//! - **On**: a's base is at b's top (±[`EPS`]) and a's footprint centre is inside b's footprint.
//! - **In**: a's footprint is inside b's (±EPS) and a's base lies within b's height (from b's base
//!   to below b's top): a is contained, e.g. a book in a bookshelf. Containers are hollow, so an
//!   `In` pair is exempt from the overlap test.
//! - **Under**: the footprints overlap and either a's top ≤ b's base + EPS (b hangs or stands over
//!   a), or a's footprint centre is inside b's footprint and a's top is below b's top − EPS.
//! - **Above**: a's base ≥ b's top − EPS and the footprints overlap.
//! - **InFrontOf**: a's centre lies past b's front face (b faces +z turned by its yaw), the
//!   footprint gap is ≤ [`FRONT_GAP`] (1.5 m), and a is roughly centred: its footprint overlaps
//!   the band of b's width widened by [`FRONT_SLACK`] (0.5 m) on each side.
//! - **Behind**: the same on b's back side.
//! - **NextTo**: footprint gap ≤ [`NEXT_GAP`] (0.3 m) and side by side (their height ranges
//!   overlap by more than EPS, so neither stands on the other).
//! - **Near**: footprint gap ≤ [`NEAR_GAP`] (1.0 m).
//!
//! The gap is the Euclidean distance between the two footprint rectangles (0 when they touch or
//! overlap).

use super::Placement;
use crate::scene::Room;
use crate::ssg::{Relation, RelationNode};

/// Height tolerance, metres.
pub const EPS: f32 = 0.02;
pub const NEAR_GAP: f32 = 1.0;
pub const NEXT_GAP: f32 = 0.3;
pub const FRONT_GAP: f32 = 1.5;
pub const FRONT_SLACK: f32 = 0.5;
/// Boxes interpenetrating less than this on some axis do not count as overlapping (rugs, contact).
pub const OVERLAP_TOL: f32 = 0.02;

/// Footprint half extents along world x and z (same formula as `PlacedObject::half_extents_xz`).
pub fn half_xz(p: &Placement) -> [f32; 2] {
    let (s, c) = p.yaw.sin_cos();
    let (hw, hd) = (p.size[0] / 2.0, p.size[2] / 2.0);
    [hw * c.abs() + hd * s.abs(), hw * s.abs() + hd * c.abs()]
}

fn top(p: &Placement) -> f32 {
    p.position[1] + p.size[1]
}

/// Per-axis footprint separation (x, z): negative when the projections overlap.
fn separation(a: &Placement, b: &Placement) -> [f32; 2] {
    let (ha, hb) = (half_xz(a), half_xz(b));
    [(a.position[0] - b.position[0]).abs() - ha[0] - hb[0], (a.position[2] - b.position[2]).abs() - ha[1] - hb[1]]
}

/// Euclidean distance between the two footprints, 0 when they touch or overlap.
pub fn gap(a: &Placement, b: &Placement) -> f32 {
    let s = separation(a, b);
    (s[0].max(0.0).powi(2) + s[1].max(0.0).powi(2)).sqrt()
}

fn footprints_overlap(a: &Placement, b: &Placement) -> bool {
    let s = separation(a, b);
    s[0] < -1e-4 && s[1] < -1e-4
}

fn centre_inside(a: &Placement, b: &Placement) -> bool {
    let hb = half_xz(b);
    (a.position[0] - b.position[0]).abs() <= hb[0] + 1e-4 && (a.position[2] - b.position[2]).abs() <= hb[1] + 1e-4
}

fn footprint_inside(a: &Placement, b: &Placement) -> bool {
    let (ha, hb) = (half_xz(a), half_xz(b));
    (a.position[0] - b.position[0]).abs() + ha[0] <= hb[0] + EPS
        && (a.position[2] - b.position[2]).abs() + ha[1] <= hb[1] + EPS
}

/// a's offset from b in b's frame: (forward along b's facing, lateral), and a's footprint half
/// extent along b's lateral axis.
fn frontal(a: &Placement, b: &Placement) -> (f32, f32, f32) {
    let (s, c) = b.yaw.sin_cos();
    let d = [a.position[0] - b.position[0], a.position[2] - b.position[2]];
    let forward = d[0] * s + d[1] * c;
    let lateral = d[0] * c - d[1] * s;
    let ha = half_xz(a);
    (forward, lateral, ha[0] * c.abs() + ha[1] * s.abs())
}

fn in_front(a: &Placement, b: &Placement, sign: f32) -> bool {
    let (forward, lateral, a_half) = frontal(a, b);
    sign * forward >= b.size[2] / 2.0
        && gap(a, b) <= FRONT_GAP
        && lateral.abs() <= b.size[0] / 2.0 + a_half + FRONT_SLACK
}

/// Largest gap for [`Relation::Against`], metres.
pub const AGAINST_GAP: f32 = 0.05;
/// Largest gap for [`Relation::LeftOf`], [`Relation::RightOf`] and [`Relation::EitherSide`], metres.
pub const SIDE_GAP: f32 = 0.5;
/// Largest gap for [`Relation::At`] and [`Relation::Around`] (at an edge), metres.
pub const AT_GAP: f32 = 0.3;
/// [`Relation::Opposite`] and [`Relation::Facing`]: at most this far, metres; "opposite" at least
/// [`OPPOSITE_MIN_GAP`] away.
pub const FACING_REACH: f32 = 4.0;
pub const OPPOSITE_MIN_GAP: f32 = 0.3;
/// Turned at most this far (degrees) from the direction to the anchor's centre to face it.
pub const FACING_DEG: f32 = 45.0;

/// Angle (degrees, 0–180) between the front of something at `from` turned by `yaw` (yaw 0 faces
/// +z) and the direction to `to` (0 when the points coincide). One definition for the layout's
/// facing, these relations and the fidelity checks.
pub fn turned_from(from: [f32; 2], yaw: f32, to: [f32; 2]) -> f32 {
    let d = [to[0] - from[0], to[1] - from[1]];
    let len = d[0].hypot(d[1]);
    if len < 1e-3 {
        return 0.0;
    }
    let f = [yaw.sin(), yaw.cos()];
    ((f[0] * d[0] + f[1] * d[1]) / len).clamp(-1.0, 1.0).acos().to_degrees()
}

/// Where point `c` lies along the segment from `p` to `q`: the fraction of the way its projection
/// is (0 at `p`, 1 at `q`) and its distance off the line, metres ("between").
pub fn along_segment(p: [f32; 2], q: [f32; 2], c: [f32; 2]) -> (f32, f32) {
    let d = [q[0] - p[0], q[1] - p[1]];
    let len2 = (d[0] * d[0] + d[1] * d[1]).max(1e-6);
    let t = ((c[0] - p[0]) * d[0] + (c[1] - p[1]) * d[1]) / len2;
    let off = ((c[0] - p[0]) * d[1] - (c[1] - p[1]) * d[0]).abs() / len2.sqrt();
    (t, off)
}

/// Angle (degrees) between a's front and the direction from a's centre to b's.
pub fn facing_deg(a: &Placement, b: &Placement) -> f32 {
    turned_from([a.position[0], a.position[2]], a.yaw, [b.position[0], b.position[2]])
}

/// Which side of b a's centre lies on, in b's frame scaled by b's half extents: +1 on b's own
/// left (+x), −1 on its right, 0 in front or behind.
pub fn lateral_side(a: &Placement, b: &Placement) -> i8 {
    let (forward, lateral, _) = frontal(a, b);
    let x = lateral / (b.size[0] / 2.0).max(0.1);
    let z = forward / (b.size[2] / 2.0).max(0.1);
    if x.abs() < z.abs() {
        0
    } else if x > 0.0 {
        1
    } else {
        -1
    }
}

fn level(a: &Placement, b: &Placement) -> bool {
    a.position[1] < top(b) - EPS && b.position[1] < top(a) - EPS
}

/// Whether `rel` holds with `a` active and `b` anchor (definitions in the module docs).
pub fn holds(rel: Relation, a: &Placement, b: &Placement) -> bool {
    match rel {
        Relation::Against => gap(a, b) <= AGAINST_GAP && level(a, b),
        Relation::Opposite => {
            let (forward, _, _) = frontal(a, b);
            let g = gap(a, b);
            forward >= b.size[2] / 2.0
                && (OPPOSITE_MIN_GAP..=FACING_REACH).contains(&g)
                && facing_deg(a, b) <= FACING_DEG
        }
        Relation::Facing => gap(a, b) <= FACING_REACH && facing_deg(a, b) <= FACING_DEG,
        Relation::LeftOf => gap(a, b) <= SIDE_GAP && lateral_side(a, b) == 1,
        Relation::RightOf => gap(a, b) <= SIDE_GAP && lateral_side(a, b) == -1,
        Relation::EitherSide => gap(a, b) <= SIDE_GAP && lateral_side(a, b) != 0,
        Relation::At | Relation::Around => gap(a, b) <= AT_GAP && facing_deg(a, b) <= FACING_DEG,
        Relation::On => (a.position[1] - top(b)).abs() <= EPS && centre_inside(a, b),
        Relation::In => footprint_inside(a, b) && a.position[1] >= b.position[1] - EPS && a.position[1] < top(b) - EPS,
        Relation::Under => {
            footprints_overlap(a, b)
                && (top(a) <= b.position[1] + EPS || (centre_inside(a, b) && top(a) < top(b) - EPS))
        }
        Relation::Above => a.position[1] >= top(b) - EPS && footprints_overlap(a, b),
        Relation::InFrontOf => in_front(a, b, 1.0),
        Relation::Behind => in_front(a, b, -1.0),
        Relation::NextTo => gap(a, b) <= NEXT_GAP && a.position[1] < top(b) - EPS && b.position[1] < top(a) - EPS,
        Relation::Near => gap(a, b) <= NEAR_GAP,
    }
}

/// Whether two boxes interpenetrate by more than [`OVERLAP_TOL`] on every axis.
pub fn overlaps(a: &Placement, b: &Placement) -> bool {
    let s = separation(a, b);
    let y = top(a).min(top(b)) - a.position[1].max(b.position[1]);
    s[0] < -OVERLAP_TOL && s[1] < -OVERLAP_TOL && y > OVERLAP_TOL
}

/// Whether the box lies inside the room (1 mm slack).
pub fn inside_room(p: &Placement, room: &Room) -> bool {
    let h = half_xz(p);
    let t = 1e-3;
    p.position[0] - h[0] >= -t
        && p.position[0] + h[0] <= room.width + t
        && p.position[2] - h[1] >= -t
        && p.position[2] + h[1] <= room.depth + t
        && p.position[1] >= -t
        && top(p) <= room.height + t
}

/// Relations from most to least specific; [`derive_relations`] keeps the first that holds.
pub const SPECIFICITY: [Relation; 8] = [
    Relation::On,
    Relation::In,
    Relation::Under,
    Relation::Above,
    Relation::InFrontOf,
    Relation::Behind,
    Relation::NextTo,
    Relation::Near,
];

/// The most specific relation that holds with `a` active and `b` anchor, if any.
pub fn strongest(a: &Placement, b: &Placement) -> Option<Relation> {
    SPECIFICITY.into_iter().find(|&r| holds(r, a, b))
}

/// The relation nodes a set of placements implies, so every scene's SSG agrees with its geometry
/// (and seeded variations stay consistent): one node per pair of objects that relate, the most
/// specific relation of the two directions; on a tie the larger footprint is the anchor ("a chair
/// in front of a desk", not the other way round), then the lower index is active.
pub fn derive_relations(placements: &[Placement]) -> Vec<RelationNode> {
    let rank = |r: Relation| SPECIFICITY.iter().position(|&x| x == r).unwrap_or(usize::MAX);
    let area = |p: &Placement| p.size[0] * p.size[2];
    let mut out = Vec::new();
    for i in 0..placements.len() {
        for j in i + 1..placements.len() {
            let (a, b) = (&placements[i], &placements[j]);
            let ij = strongest(a, b);
            let ji = strongest(b, a);
            let pick = match (ij, ji) {
                (None, None) => None,
                (Some(r), None) => Some((r, i, j)),
                (None, Some(r)) => Some((r, j, i)),
                (Some(r), Some(s)) => Some(match rank(r).cmp(&rank(s)) {
                    std::cmp::Ordering::Less => (r, i, j),
                    std::cmp::Ordering::Greater => (s, j, i),
                    std::cmp::Ordering::Equal if area(a) > area(b) => (s, j, i),
                    std::cmp::Ordering::Equal => (r, i, j),
                }),
            };
            if let Some((relation, active, anchor)) = pick {
                out.push(RelationNode { relation, active, anchor, sentence: 0 });
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(x: f32, y: f32, z: f32, yaw: f32, size: [f32; 3]) -> Placement {
        Placement { position: [x, y, z], yaw, size }
    }

    #[test]
    fn the_definitions() {
        let desk = p(2.0, 0.0, 1.0, 0.0, [1.4, 0.75, 0.7]);
        let cup = p(2.2, 0.75, 1.1, 0.0, [0.1, 0.1, 0.1]);
        assert!(holds(Relation::On, &cup, &desk));
        assert!(holds(Relation::Above, &cup, &desk));
        assert!(!holds(Relation::On, &desk, &cup));
        let chair = p(2.0, 0.0, 1.75, std::f32::consts::PI, [0.5, 0.9, 0.5]);
        assert!(holds(Relation::InFrontOf, &chair, &desk));
        assert!(!holds(Relation::Behind, &chair, &desk));
        assert_eq!(strongest(&chair, &desk), Some(Relation::InFrontOf));
        // The desk is in front of the chair too (the chair faces it); the larger one anchors.
        let rel = derive_relations(&[chair.clone(), desk.clone()]);
        assert_eq!((rel[0].relation, rel[0].active, rel[0].anchor), (Relation::InFrontOf, 0, 1));
        let bin = p(2.9, 0.0, 1.0, 0.0, [0.35, 0.5, 0.35]);
        assert!(holds(Relation::NextTo, &bin, &desk));
        assert!(!holds(Relation::NextTo, &cup, &desk));
        let rug = p(2.0, 0.0, 1.0, 0.0, [2.0, 0.01, 1.4]);
        assert!(holds(Relation::Under, &rug, &desk));
        assert!(!overlaps(&rug, &desk));
        assert!(overlaps(&chair, &p(2.0, 0.0, 1.6, 0.0, [0.5, 0.9, 0.5])));
        let shelf = p(0.5, 0.0, 0.2, 0.0, [0.9, 1.8, 0.35]);
        let book = p(0.5, 0.9, 0.2, 0.0, [0.16, 0.04, 0.23]);
        assert!(holds(Relation::In, &book, &shelf));
        // A turned desk faces +x: the chair must be on its +x side.
        let turned = p(2.0, 0.0, 1.0, std::f32::consts::FRAC_PI_2, [1.4, 0.75, 0.7]);
        assert!(holds(Relation::InFrontOf, &p(2.7, 0.0, 1.0, 0.0, [0.5, 0.9, 0.5]), &turned));
        assert!(holds(Relation::Behind, &p(1.3, 0.0, 1.0, 0.0, [0.5, 0.9, 0.5]), &turned));
        assert!(holds(Relation::Near, &p(3.9, 0.0, 1.0, 0.0, [0.5, 0.9, 0.5]), &desk));
        assert!(!holds(Relation::Near, &p(4.5, 0.0, 1.0, 0.0, [0.5, 0.9, 0.5]), &desk));
    }
}
