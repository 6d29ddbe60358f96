//! Filled shapes on a [`Canvas`]: convex polygons with hard edges (box faces, floor, skinned
//! triangles), anti-aliased polygons clipped by one another (the schematic face) and triangles
//! coloured from a texture.
//!
//! ```
//! use inbetween_render::Canvas;
//! let mut cv = Canvas::new(40, 30, [255, 255, 255]);
//! cv.fill_convex(&[(2.0, 2.0), (20.0, 2.0), (11.0, 20.0)], [200, 60, 40]);
//! let eye: &[(f32, f32)] = &[(22.0, 10.0), (38.0, 10.0), (38.0, 20.0), (22.0, 20.0)];
//! let iris: &[(f32, f32)] = &[(26.0, 6.0), (34.0, 6.0), (34.0, 24.0), (26.0, 24.0)];
//! cv.fill_polygons(&[iris, eye], [40, 90, 160], 1.0); // the iris, clipped to the eye
//! let (px, uv) = ([(2.0, 28.0), (20.0, 28.0), (2.0, 22.0)], [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]);
//! cv.fill_textured_triangle(px, uv, 2, |uv| [(255.0 * uv[0]) as u8, 0, 0]);
//! assert_eq!(cv.pixel(30, 15), [40, 90, 160]);
//! assert_eq!(cv.pixel(30, 22), [255, 255, 255], "outside the eye");
//! ```

use crate::canvas::Canvas;

impl Canvas {
    /// Fills a convex polygon given in pixels (either winding); pixel centres inside are painted.
    pub fn fill_convex(&mut self, pts: &[(f32, f32)], color: [u8; 3]) {
        if pts.len() < 3 || pts.iter().any(|p| !(p.0.is_finite() && p.1.is_finite())) {
            return;
        }
        let (mut x0, mut y0, mut x1, mut y1) = (f32::MAX, f32::MAX, f32::MIN, f32::MIN);
        for p in pts {
            x0 = x0.min(p.0);
            y0 = y0.min(p.1);
            x1 = x1.max(p.0);
            y1 = y1.max(p.1);
        }
        let (w, h) = (self.width() as f32, self.height() as f32);
        let (x0, y0) = (x0.max(0.0).floor() as i64, y0.max(0.0).floor() as i64);
        let (x1, y1) = (x1.min(w).ceil() as i64, y1.min(h).ceil() as i64);
        let n = pts.len();
        let area: f32 = (0..n).map(|i| pts[i].0 * pts[(i + 1) % n].1 - pts[(i + 1) % n].0 * pts[i].1).sum();
        let sign = if area >= 0.0 { 1.0 } else { -1.0 };
        for py in y0..y1 {
            for px in x0..x1 {
                let (qx, qy) = (px as f32 + 0.5, py as f32 + 0.5);
                let inside = (0..n).all(|i| {
                    let (a, b) = (pts[i], pts[(i + 1) % n]);
                    sign * ((b.0 - a.0) * (qy - a.1) - (b.1 - a.1) * (qx - a.0)) >= 0.0
                });
                if inside {
                    self.blend(px, py, color, 1.0);
                }
            }
        }
    }

    /// Fills the pixel triangle `px` whose corners carry texture coordinates `uv`: the triangle is
    /// split at its edge midpoints `levels` times (4^levels pieces, in pixels and uv alike) and each
    /// piece filled ([`Canvas::fill_convex`]) with `color_at` its centre's uv. A cheap look at a
    /// texture on a preview, not a renderer.
    pub fn fill_textured_triangle(
        &mut self,
        px: [(f32, f32); 3],
        uv: [[f32; 2]; 3],
        levels: u32,
        color_at: impl Fn([f32; 2]) -> [u8; 3],
    ) {
        for (sub, suv) in subdivide_triangle(px, uv, levels) {
            let c = [0, 1].map(|k| (suv[0][k] + suv[1][k] + suv[2][k]) / 3.0);
            self.fill_convex(&sub, color_at(c));
        }
    }
}

/// A pixel triangle and its texture coordinates.
pub type UvTriangle = ([(f32, f32); 3], [[f32; 2]; 3]);

/// Midpoint subdivision, `levels` times (4^levels triangles), of a pixel triangle and its uvs, in
/// the order [`Canvas::fill_textured_triangle`] paints them.
pub fn subdivide_triangle(px: [(f32, f32); 3], uv: [[f32; 2]; 3], levels: u32) -> Vec<UvTriangle> {
    let mut tris = vec![(px, uv)];
    for _ in 0..levels {
        tris = tris
            .into_iter()
            .flat_map(|(p, u)| {
                let mp = |i: usize, j: usize| ((p[i].0 + p[j].0) / 2.0, (p[i].1 + p[j].1) / 2.0);
                let mu = |i: usize, j: usize| [(u[i][0] + u[j][0]) / 2.0, (u[i][1] + u[j][1]) / 2.0];
                let (p01, p12, p20, u01, u12, u20) = (mp(0, 1), mp(1, 2), mp(2, 0), mu(0, 1), mu(1, 2), mu(2, 0));
                [
                    ([p[0], p01, p20], [u[0], u01, u20]),
                    ([p01, p[1], p12], [u01, u[1], u12]),
                    ([p20, p12, p[2]], [u20, u12, u[2]]),
                    ([p01, p12, p20], [u01, u12, u20]),
                ]
            })
            .collect();
    }
    tris
}

/// Vertical samples per pixel row for polygon coverage (horizontal coverage is exact).
const SUBROWS: usize = 4;

/// Crossings of the horizontal line at `y` with the polygon's edges, sorted: consecutive pairs are the
/// inside spans (even-odd rule).
fn crossings(poly: &[(f32, f32)], y: f32, out: &mut Vec<f32>) {
    out.clear();
    let n = poly.len();
    for i in 0..n {
        let (a, b) = (poly[i], poly[(i + 1) % n]);
        if (a.1 <= y) != (b.1 <= y) {
            let x = a.0 + (y - a.1) * (b.0 - a.0) / (b.1 - a.1);
            if x.is_finite() {
                out.push(x);
            }
        }
    }
    out.sort_by(f32::total_cmp);
}

/// Intersection of two sorted span lists (`[x0, x1, x2, x3, …]` = spans x0..x1, x2..x3, …).
fn intersect_spans(a: &[f32], b: &[f32]) -> Vec<f32> {
    let mut out = Vec::new();
    let (mut i, mut j) = (0, 0);
    while i + 1 < a.len() && j + 1 < b.len() {
        let (lo, hi) = (a[i].max(b[j]), a[i + 1].min(b[j + 1]));
        if lo < hi {
            out.extend([lo, hi]);
        }
        if a[i + 1] < b[j + 1] {
            i += 2;
        } else {
            j += 2;
        }
    }
    out
}

impl Canvas {
    /// Fills the intersection of `polys` (each by the even-odd rule) with `color` at opacity `alpha`,
    /// anti-aliased: exact coverage across each row, [`SUBROWS`] samples down it. One polygon fills
    /// its inside; a second clips the first (an iris inside the eye opening).
    pub fn fill_polygons(&mut self, polys: &[&[(f32, f32)]], color: [u8; 3], alpha: f32) {
        if polys.is_empty() || polys.iter().any(|p| p.len() < 3) || alpha <= 0.0 {
            return;
        }
        let (mut x0, mut y0, mut x1, mut y1) = (0.0f32, 0.0f32, self.width() as f32, self.height() as f32);
        for p in polys {
            let (lo_x, hi_x) = p.iter().fold((f32::INFINITY, f32::NEG_INFINITY), |(l, h), q| (l.min(q.0), h.max(q.0)));
            let (lo_y, hi_y) = p.iter().fold((f32::INFINITY, f32::NEG_INFINITY), |(l, h), q| (l.min(q.1), h.max(q.1)));
            (x0, y0, x1, y1) = (x0.max(lo_x), y0.max(lo_y), x1.min(hi_x), y1.min(hi_y));
        }
        if !(x0 < x1 && y0 < y1) {
            return;
        }
        let (px0, px1) = (x0.floor() as i64, x1.ceil() as i64);
        let width = (px1 - px0) as usize;
        // Per row: coverage of the pixels a span edge cuts (`edge`), plus a difference array of the
        // pixels spans cover fully (`inner`), so a span costs O(1) whatever its length.
        let mut edge = vec![0.0f32; width + 1];
        let mut inner = vec![0.0f32; width + 1];
        let mut xs = Vec::new();
        let share = 1.0 / SUBROWS as f32;
        for py in y0.floor() as i64..y1.ceil() as i64 {
            edge.iter_mut().for_each(|a| *a = 0.0);
            inner.iter_mut().for_each(|a| *a = 0.0);
            for k in 0..SUBROWS {
                let sy = py as f32 + (k as f32 + 0.5) * share;
                crossings(polys[0], sy, &mut xs);
                let mut spans = xs.clone();
                for p in &polys[1..] {
                    crossings(p, sy, &mut xs);
                    spans = intersect_spans(&spans, &xs);
                }
                for s in spans.chunks_exact(2) {
                    let (a, b) = (s[0].max(x0) - px0 as f32, s[1].min(x1) - px0 as f32);
                    if a >= b {
                        continue;
                    }
                    let (ia, ib) = (a.floor() as usize, b.floor() as usize);
                    if ia == ib {
                        edge[ia] += (b - a) * share;
                    } else {
                        edge[ia] += (ia as f32 + 1.0 - a) * share;
                        edge[ib] += (b - ib as f32) * share;
                        inner[ia + 1] += share;
                        inner[ib] -= share;
                    }
                }
            }
            // Fully covered opaque pixels are written in runs; the rest are blended.
            let (mut run, mut solid_from) = (0.0, None);
            for i in 0..=width {
                run += inner[i];
                let a = (edge[i] + run).min(1.0) * alpha;
                let solid = i < width && a >= 0.999;
                match (solid, solid_from) {
                    (true, None) => solid_from = Some(i),
                    (false, Some(from)) => {
                        self.rect((px0 + from as i64) as f32, py as f32, (i - from) as f32, 1.0, color);
                        solid_from = None;
                    }
                    _ => {}
                }
                if !solid && i < width && a > 1e-4 {
                    self.blend(px0 + i as i64, py, color, a);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn span_intersection() {
        assert_eq!(intersect_spans(&[0.0, 5.0, 7.0, 9.0], &[3.0, 8.0]), vec![3.0, 5.0, 7.0, 8.0]);
        assert!(intersect_spans(&[0.0, 1.0], &[2.0, 3.0]).is_empty());
    }

    #[test]
    fn convex_fill_paints_pixel_centres_inside_either_winding() {
        for pts in [[(1.0, 1.0), (7.0, 1.0), (7.0, 5.0), (1.0, 5.0)], [(1.0, 5.0), (7.0, 5.0), (7.0, 1.0), (1.0, 1.0)]]
        {
            let mut cv = Canvas::new(10, 8, [0, 0, 0]);
            cv.fill_convex(&pts, [200, 10, 10]);
            assert_eq!(cv.pixel(1, 1), [200, 10, 10]);
            assert_eq!(cv.pixel(6, 4), [200, 10, 10]);
            assert_eq!(cv.pixel(7, 4), [0, 0, 0]);
            assert_eq!(cv.pixel(3, 5), [0, 0, 0]);
            let painted = cv.image().pixels().filter(|p| p.0 != [0, 0, 0]).count();
            assert_eq!(painted, 6 * 4);
        }
        // Degenerate or non-finite input paints nothing and does not panic.
        let mut cv = Canvas::new(4, 4, [0, 0, 0]);
        cv.fill_convex(&[(0.0, 0.0), (3.0, 3.0)], [255, 255, 255]);
        cv.fill_convex(&[(0.0, 0.0), (f32::NAN, 3.0), (3.0, 0.0)], [255, 255, 255]);
        assert!(cv.image().pixels().all(|p| p.0 == [0, 0, 0]));
    }

    #[test]
    fn polygon_fill_is_anti_aliased_and_clipped_by_the_second_polygon() {
        let mut cv = Canvas::new(20, 10, [0, 0, 0]);
        let square: &[(f32, f32)] = &[(2.0, 2.0), (12.5, 2.0), (12.5, 8.0), (2.0, 8.0)];
        let clip: &[(f32, f32)] = &[(6.0, 0.0), (20.0, 0.0), (20.0, 10.0), (6.0, 10.0)];
        cv.fill_polygons(&[square, clip], [0, 200, 0], 1.0);
        assert_eq!(cv.pixel(3, 4), [0, 0, 0], "clipped away");
        assert_eq!(cv.pixel(8, 4), [0, 200, 0]);
        let edge = cv.pixel(12, 4)[1];
        assert!(edge > 80 && edge < 120, "half-covered pixel is blended: {edge}");
        assert_eq!(cv.pixel(14, 4), [0, 0, 0]);
        let mut faint = Canvas::new(20, 10, [0, 0, 0]);
        faint.fill_polygons(&[square], [0, 200, 0], 0.5);
        assert_eq!(faint.pixel(8, 4), [0, 100, 0]);
    }

    #[test]
    fn textured_triangles_colour_each_piece_at_its_centre() {
        let pieces = subdivide_triangle([(0.0, 0.0), (8.0, 0.0), (0.0, 8.0)], [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]], 2);
        assert_eq!(pieces.len(), 16);
        let area = |p: &[(f32, f32); 3]| {
            ((p[1].0 - p[0].0) * (p[2].1 - p[0].1) - (p[2].0 - p[0].0) * (p[1].1 - p[0].1)).abs() / 2.0
        };
        assert!(pieces.iter().all(|(p, _)| (area(p) - 2.0).abs() < 1e-6), "16 equal pieces of a 32 px² triangle");
        let mut cv = Canvas::new(10, 10, [0, 0, 0]);
        // u runs left to right: red on the left, green on the right.
        cv.fill_textured_triangle(
            [(0.0, 0.0), (8.0, 0.0), (0.0, 8.0)],
            [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]],
            2,
            |uv| {
                if uv[0] < 0.5 {
                    [255, 0, 0]
                } else {
                    [0, 255, 0]
                }
            },
        );
        assert_eq!(cv.pixel(0, 0), [255, 0, 0]);
        assert_eq!(cv.pixel(6, 0), [0, 255, 0]);
        assert_eq!(cv.pixel(8, 8), [0, 0, 0], "outside the triangle");
    }
}
