//! Where a character stands to use an object ([`stand_point`]), clear of the spots earlier
//! characters stand or sit at, and the small plane helpers the actions share.

use super::{contacts_of, PASSING_DISTANCE};
use crate::catalogue::{Catalogue, ContactKind};
use crate::layout::geom;
use crate::layout::grid::{self, Grid};
use crate::scene::Scene;

/// Extra margin (metres) beyond [`PASSING_DISTANCE`] kept between a stand point and the spots
/// where earlier characters stand or sit.
pub(crate) const SPOT_MARGIN: f32 = 0.1;

/// Where to stand to use an object: its stand contact, else a point just past one of the four
/// sides of its support (the side nearest the object first, the front preferred); each candidate
/// also shifted sideways along its side, and moved to the nearest free cell reachable from `from`.
/// The candidate chosen keeps clear of `avoid` (where earlier characters stand or sit: two
/// characters never share a spot), then stays close to the object, then to `from`.
pub(crate) fn stand_point(
    scene: &Scene,
    cat: &Catalogue,
    grid: &Grid,
    obj: usize,
    from: [f32; 2],
    avoid: &[[f32; 2]],
) -> [f32; 2] {
    let o = &scene.objects[obj];
    // (point, where the character would ideally be for it, extra cost of the side).
    let mut candidates: Vec<([f32; 2], [f32; 2], f32)> = Vec::new();
    let stands: Vec<[f32; 2]> = contacts_of(scene, cat, obj, ContactKind::Stand).iter().map(|p| [p[0], p[2]]).collect();
    for p in &stands {
        let side = [o.yaw.cos(), -o.yaw.sin()];
        for shift in [0.0f32, -0.4, 0.4, -0.8, 0.8] {
            candidates.push(([p[0] + side[0] * shift, p[1] + side[1] * shift], *p, 0.0));
        }
    }
    if stands.is_empty() {
        // An object on a surface is used from its support's sides.
        let base = o.support.map(|s| &scene.objects[s]).unwrap_or(o);
        let local = geom::to_local(geom::center(base), base.yaw, geom::center(o));
        let (hw, hd) = (base.size[0] / 2.0, base.size[2] / 2.0);
        let out = grid::WALKER_RADIUS + 0.1;
        // (point on the side nearest the object, outward normal, along-side axis, half length, penalty)
        let sides = [
            ([local[0].clamp(-hw, hw), hd], [0.0, 1.0], [1.0, 0.0], hw, 0.0),
            ([local[0].clamp(-hw, hw), -hd], [0.0, -1.0], [1.0, 0.0], hw, 0.15),
            ([hw, local[1].clamp(-hd, hd)], [1.0, 0.0], [0.0, 1.0], hd, 0.15),
            ([-hw, local[1].clamp(-hd, hd)], [-1.0, 0.0], [0.0, 1.0], hd, 0.15),
        ];
        // Keys (keyboard, laptop, piano) are used from the side they face.
        let keys = cat.get(&o.category).is_some_and(|c| c.contacts.iter().any(|p| p.kind == ContactKind::Keys));
        let (fs, fc) = (o.yaw - base.yaw).sin_cos();
        for (at, n, along, half, penalty) in sides {
            if keys && n[0] * fs + n[1] * fc < 0.7 {
                continue;
            }
            let ideal = [at[0] + n[0] * out, at[1] + n[1] * out];
            for shift in [0.0f32, -0.4, 0.4] {
                let q = [ideal[0] + along[0] * shift, ideal[1] + along[1] * shift];
                // Stay beside the side (a shift past its end would stand at a corner).
                if shift != 0.0 && (q[0] * along[0] + q[1] * along[1]).abs() > half + 0.05 {
                    continue;
                }
                let world_ideal = geom::to_world(geom::center(base), base.yaw, ideal);
                // The side nearest the object keeps the hands' reach short.
                let reach = dist2(world_ideal, geom::center(o)).sqrt();
                candidates.push((geom::to_world(geom::center(base), base.yaw, q), world_ideal, penalty + reach));
            }
        }
    }
    let reach = grid
        .cell_of(from)
        .filter(|c| !grid.is_blocked(*c))
        .or_else(|| grid.nearest_free(from))
        .map(|c| grid.reachable_from(c));
    let snap = |p: [f32; 2]| -> Option<[f32; 2]> {
        let p = if grid.is_free_at(p) { p } else { grid.center(grid.nearest_free(p)?) };
        let ok = match (&reach, grid.cell_of(p)) {
            (Some(r), Some((i, j))) => r[j * grid.nx + i],
            _ => true,
        };
        ok.then_some(p)
    };
    let crowd = |p: [f32; 2]| {
        avoid.iter().map(|a| (PASSING_DISTANCE + SPOT_MARGIN - dist2(p, *a).sqrt()).max(0.0)).sum::<f32>()
    };
    let best = candidates
        .into_iter()
        .filter_map(|(p, ideal, penalty)| {
            let q = snap(p)?;
            let cost = 10.0 * crowd(q) + dist2(q, ideal).sqrt() + penalty + 0.01 * dist2(q, from).sqrt();
            Some((cost, q))
        })
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .map(|b| b.1);
    best.unwrap_or_else(|| grid.nearest_free(geom::center(o)).map(|c| grid.center(c)).unwrap_or(geom::center(o)))
}

pub(crate) fn dist2(a: [f32; 2], b: [f32; 2]) -> f32 {
    (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)
}

/// Heading (0 = +Z) from `a` towards `b`.
pub(crate) fn heading_to(a: [f32; 2], b: [f32; 2], default: f64) -> f64 {
    let (dx, dz) = ((b[0] - a[0]) as f64, (b[1] - a[1]) as f64);
    if dx.hypot(dz) < 1e-4 {
        default
    } else {
        dx.atan2(dz)
    }
}
