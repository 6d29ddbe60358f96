//! The collision model of Eq. 1: each object approximated by several small boxes. Solid objects
//! are tiled into boxes of about `box_size` on a side; tables with leg room
//! ([`crate::catalogue::builtin::has_leg_room`]) become a thin top slab (tiled the same way in
//! x and z) on four corner legs, so a seated character's legs under a desk do not count as a
//! collision.

use crate::scene::PlacedObject;

/// An axis-aligned box in the object's own frame: x from the left face, y from the base, z from
/// the back face (metres), `[lo, hi]` per axis.
pub type LocalBox = ([f32; 3], [f32; 3]);

/// Thickness of a table top, metres.
pub const TOP_THICKNESS: f32 = 0.05;
/// Side of a table leg's square section, metres.
pub const LEG_SIDE: f32 = 0.06;

/// Tiles `[lo, hi]` into about `size`-sided boxes per axis (at least one per axis).
fn tile(lo: [f32; 3], hi: [f32; 3], size: f32, out: &mut Vec<LocalBox>) {
    let n = [0, 1, 2].map(|k| (((hi[k] - lo[k]) / size).ceil() as usize).max(1));
    let step = [0, 1, 2].map(|k| (hi[k] - lo[k]) / n[k] as f32);
    for c in 0..n[2] {
        for b in 0..n[1] {
            for a in 0..n[0] {
                let i = [a, b, c];
                let l = [0, 1, 2].map(|k| lo[k] + i[k] as f32 * step[k]);
                let h = [0, 1, 2].map(|k| lo[k] + (i[k] + 1) as f32 * step[k]);
                out.push((l, h));
            }
        }
    }
}

/// The boxes approximating an object (Eq. 1's "several small boxes").
pub fn object_boxes(o: &PlacedObject, box_size: f32) -> Vec<LocalBox> {
    let [w, h, d] = o.size;
    let mut out = Vec::new();
    if crate::catalogue::builtin::has_leg_room(&o.category) && h > 2.0 * TOP_THICKNESS {
        let top = (h - TOP_THICKNESS).max(0.0);
        tile([0.0, top, 0.0], [w, h, d], box_size, &mut out);
        let (lw, ld) = (LEG_SIDE.min(w / 2.0), LEG_SIDE.min(d / 2.0));
        for (x, z) in [(0.0, 0.0), (w - lw, 0.0), (0.0, d - ld), (w - lw, d - ld)] {
            tile([x, 0.0, z], [x + lw, top, z + ld], box_size, &mut out);
        }
    } else {
        tile([0.0; 3], o.size, box_size, &mut out);
    }
    out
}

/// Squared distance from point `q` to a box (0 inside).
pub fn distance2(q: [f32; 3], b: &LocalBox) -> f32 {
    (0..3)
        .map(|k| {
            let d = (b.0[k] - q[k]).max(0.0).max(q[k] - b.1[k]);
            d * d
        })
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Origin;

    fn object(category: &str, size: [f32; 3]) -> PlacedObject {
        PlacedObject {
            label: category.into(),
            category: category.into(),
            attributes: Vec::new(),
            position: [0.0; 3],
            yaw: 0.0,
            size,
            support: None,
            origin: Origin::Script { sentence: 0, node: 0 },
        }
    }

    fn volume(boxes: &[LocalBox]) -> f32 {
        boxes.iter().map(|(l, h)| (h[0] - l[0]) * (h[1] - l[1]) * (h[2] - l[2])).sum()
    }

    #[test]
    fn a_solid_object_is_tiled_exactly() {
        let o = object("sofa", [2.0, 0.85, 0.9]);
        let b = object_boxes(&o, 0.25);
        assert_eq!(b.len(), 8 * 4 * 4);
        assert!((volume(&b) - 2.0 * 0.85 * 0.9).abs() < 1e-4);
        assert!(b.iter().all(|(l, h)| (0..3).all(|k| h[k] - l[k] <= 0.25 + 1e-6)));
    }

    #[test]
    fn a_desk_leaves_room_for_seated_legs() {
        let o = object("desk", [1.4, 0.75, 0.7]);
        let b = object_boxes(&o, 0.25);
        // A knee under the middle of the desk, 10 cm below the top: free.
        let knee = [0.7, 0.6, 0.35];
        assert!(b.iter().all(|bx| distance2(knee, bx) > 0.04 * 0.04));
        // The top and the legs are still solid.
        assert!(b.iter().any(|bx| distance2([0.7, 0.74, 0.35], bx) == 0.0));
        assert!(b.iter().any(|bx| distance2([0.02, 0.3, 0.02], bx) == 0.0));
        assert!(volume(&b) < 0.1 * 1.4 * 0.75 * 0.7);
    }
}
