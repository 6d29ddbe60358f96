//! Footprint geometry shared by the relation tests, the solver and the occupancy grid: oriented
//! rectangles on the floor plane (x, z), in metres.

use glam::DVec3;

use crate::scene::PlacedObject;

/// Slack for "touching" tests: placements computed in f32 land a hair off exact contact.
pub const EPS: f32 = 0.02;

/// Unit front direction (x, z) of a yaw: yaw 0 faces +z.
pub fn forward(yaw: f32) -> [f32; 2] {
    [yaw.sin(), yaw.cos()]
}

/// Angle (degrees, 0–180) between `active`'s front and the direction from it to `anchor`'s
/// centre (0 when the centres coincide).
pub fn facing_angle(active: &PlacedObject, anchor: &PlacedObject) -> f32 {
    crate::database::geometry::turned_from(center(active), active.yaw, center(anchor))
}

/// Largest [`facing_angle`] at which "in front of X" counts as facing X, degrees.
pub const FACING_TOLERANCE_DEG: f32 = 45.0;

/// A point given in an object's frame (lx along its width, lz towards its front) in world x, z.
pub fn to_world(center: [f32; 2], yaw: f32, local: [f32; 2]) -> [f32; 2] {
    let (s, c) = yaw.sin_cos();
    [center[0] + local[0] * c + local[1] * s, center[1] - local[0] * s + local[1] * c]
}

/// World x, z in the frame of an object at `center` turned by `yaw`.
pub fn to_local(center: [f32; 2], yaw: f32, p: [f32; 2]) -> [f32; 2] {
    let (s, c) = yaw.sin_cos();
    let (dx, dz) = (p[0] - center[0], p[1] - center[1]);
    [dx * c - dz * s, dx * s + dz * c]
}

/// Footprint centre (x, z).
pub fn center(o: &PlacedObject) -> [f32; 2] {
    [o.position[0], o.position[2]]
}

/// `active`'s footprint seen from `anchor`'s frame: centre and half extents along the anchor's
/// width and depth axes (the bounding box of the turned rectangle, exact for right-angle turns).
pub fn local_box(active: &PlacedObject, anchor: &PlacedObject) -> ([f32; 2], [f32; 2]) {
    let c = to_local(center(anchor), anchor.yaw, center(active));
    let rel = active.yaw - anchor.yaw;
    let (s, co) = rel.sin_cos();
    let (hw, hd) = (active.size[0] / 2.0, active.size[2] / 2.0);
    (c, [hw * co.abs() + hd * s.abs(), hw * s.abs() + hd * co.abs()])
}

/// Gap between two axis-aligned boxes (centre, half extents): 0 when they touch or overlap.
pub fn box_gap(ca: [f32; 2], ha: [f32; 2], cb: [f32; 2], hb: [f32; 2]) -> f32 {
    let gx = ((ca[0] - cb[0]).abs() - ha[0] - hb[0]).max(0.0);
    let gz = ((ca[1] - cb[1]).abs() - ha[1] - hb[1]).max(0.0);
    (gx * gx + gz * gz).sqrt()
}

/// How deep two axis-aligned boxes interpenetrate (the smaller axis overlap; ≤ 0 when apart).
pub fn box_penetration(ca: [f32; 2], ha: [f32; 2], cb: [f32; 2], hb: [f32; 2]) -> f32 {
    let px = ha[0] + hb[0] - (ca[0] - cb[0]).abs();
    let pz = ha[1] + hb[1] - (ca[1] - cb[1]).abs();
    px.min(pz)
}

/// Footprint gap between two objects in the anchor's frame.
pub fn gap(active: &PlacedObject, anchor: &PlacedObject) -> f32 {
    let (c, h) = local_box(active, anchor);
    box_gap(c, h, [0.0, 0.0], [anchor.size[0] / 2.0, anchor.size[2] / 2.0])
}

/// Whether `active`'s footprint lies inside `anchor`'s (with [`EPS`] slack).
pub fn footprint_inside(active: &PlacedObject, anchor: &PlacedObject) -> bool {
    let (c, h) = local_box(active, anchor);
    c[0].abs() + h[0] <= anchor.size[0] / 2.0 + EPS && c[1].abs() + h[1] <= anchor.size[2] / 2.0 + EPS
}

/// Whether `active`'s footprint centre lies inside `anchor`'s footprint.
pub fn center_inside(active: &PlacedObject, anchor: &PlacedObject) -> bool {
    let c = to_local(center(anchor), anchor.yaw, center(active));
    c[0].abs() <= anchor.size[0] / 2.0 + EPS && c[1].abs() <= anchor.size[2] / 2.0 + EPS
}

/// The four footprint corners in world x, z.
pub fn corners(o: &PlacedObject) -> [[f32; 2]; 4] {
    let (hw, hd) = (o.size[0] / 2.0, o.size[2] / 2.0);
    let c = center(o);
    [[-hw, -hd], [hw, -hd], [hw, hd], [-hw, hd]].map(|l| to_world(c, o.yaw, l))
}

/// Whether two footprints (oriented rectangles) overlap by more than [`EPS`], by separating axes.
pub fn footprints_overlap(a: &PlacedObject, b: &PlacedObject) -> bool {
    let (ca, cb) = (corners(a), corners(b));
    let axes = [
        forward(a.yaw),
        forward(a.yaw + std::f32::consts::FRAC_PI_2),
        forward(b.yaw),
        forward(b.yaw + std::f32::consts::FRAC_PI_2),
    ];
    for ax in axes {
        let proj = |pts: &[[f32; 2]; 4]| {
            let mut lo = f32::INFINITY;
            let mut hi = f32::NEG_INFINITY;
            for p in pts {
                let d = p[0] * ax[0] + p[1] * ax[1];
                lo = lo.min(d);
                hi = hi.max(d);
            }
            (lo, hi)
        };
        let (alo, ahi) = proj(&ca);
        let (blo, bhi) = proj(&cb);
        if ahi.min(bhi) - alo.max(blo) <= EPS {
            return false;
        }
    }
    true
}

/// Whether the vertical extents of two objects overlap by more than [`EPS`].
pub fn heights_overlap(a: &PlacedObject, b: &PlacedObject) -> bool {
    a.top().min(b.top()) - a.position[1].max(b.position[1]) > EPS
}

/// Whether the point `p` (world metres) lies inside the object's box.
pub fn point_in_box(o: &PlacedObject, p: DVec3) -> bool {
    let l = to_local(center(o), o.yaw, [p.x as f32, p.z as f32]);
    let y = p.y as f32;
    l[0].abs() <= o.size[0] / 2.0 && l[1].abs() <= o.size[2] / 2.0 && y >= o.position[1] && y <= o.top()
}

/// Whether the segment `a`–`b` passes through the object's box (slab test in its frame).
pub fn segment_hits_box(o: &PlacedObject, a: DVec3, b: DVec3) -> bool {
    let la = to_local(center(o), o.yaw, [a.x as f32, a.z as f32]);
    let lb = to_local(center(o), o.yaw, [b.x as f32, b.z as f32]);
    let p0 = [la[0], a.y as f32, la[1]];
    let p1 = [lb[0], b.y as f32, lb[1]];
    let lo = [-o.size[0] / 2.0, o.position[1], -o.size[2] / 2.0];
    let hi = [o.size[0] / 2.0, o.top(), o.size[2] / 2.0];
    let (mut t0, mut t1) = (0.0f32, 1.0f32);
    for k in 0..3 {
        let d = p1[k] - p0[k];
        if d.abs() < 1e-9 {
            if p0[k] < lo[k] || p0[k] > hi[k] {
                return false;
            }
            continue;
        }
        let (mut ta, mut tb) = ((lo[k] - p0[k]) / d, (hi[k] - p0[k]) / d);
        if ta > tb {
            std::mem::swap(&mut ta, &mut tb);
        }
        t0 = t0.max(ta);
        t1 = t1.min(tb);
        if t0 > t1 {
            return false;
        }
    }
    true
}
