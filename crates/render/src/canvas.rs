//! An RGB raster with anti-aliased drawing primitives, and a perspective camera to put 3-D points on it.
//!
//! Every primitive computes per-pixel coverage analytically (distance to the shape's edge), so lines
//! and dots are smooth at any width without supersampling.

use ab_glyph::{Font, FontRef, PxScale, ScaleFont};
use glam::DVec3;
use image::{Rgb, RgbImage};
use std::sync::OnceLock;

/// An RGB image plus drawing operations. Coordinates are pixels, x right, y down; (0.5, 0.5) is the
/// centre of the top-left pixel.
#[derive(Clone, Debug)]
pub struct Canvas {
    img: RgbImage,
}

impl Canvas {
    /// A `width` × `height` canvas filled with `background`.
    pub fn new(width: u32, height: u32, background: [u8; 3]) -> Canvas {
        Canvas { img: RgbImage::from_pixel(width, height, Rgb(background)) }
    }

    /// Wraps an existing image.
    pub fn from_image(img: RgbImage) -> Canvas {
        Canvas { img }
    }

    pub fn width(&self) -> u32 {
        self.img.width()
    }

    pub fn height(&self) -> u32 {
        self.img.height()
    }

    pub fn pixel(&self, x: u32, y: u32) -> [u8; 3] {
        self.img.get_pixel(x, y).0
    }

    pub fn image(&self) -> &RgbImage {
        &self.img
    }

    pub fn into_image(self) -> RgbImage {
        self.img
    }

    /// Mixes `color` into pixel (x, y) with weight `alpha` in 0…1; pixels outside are ignored.
    pub fn blend(&mut self, x: i64, y: i64, color: [u8; 3], alpha: f32) {
        if alpha <= 0.0 || x < 0 || y < 0 || x >= self.img.width() as i64 || y >= self.img.height() as i64 {
            return;
        }
        let a = alpha.min(1.0);
        let p = self.img.get_pixel_mut(x as u32, y as u32);
        for (d, s) in p.0.iter_mut().zip(color) {
            *d = (*d as f32 + (s as f32 - *d as f32) * a).round() as u8;
        }
    }

    /// Fills the axis-aligned rectangle with top-left corner (x, y) and size w × h (pixel-exact).
    pub fn rect(&mut self, x: f32, y: f32, w: f32, h: f32, color: [u8; 3]) {
        let (x0, y0) = (x.round().max(0.0) as i64, y.round().max(0.0) as i64);
        let x1 = ((x + w).round() as i64).min(self.img.width() as i64);
        let y1 = ((y + h).round() as i64).min(self.img.height() as i64);
        for py in y0..y1 {
            for px in x0..x1 {
                self.img.put_pixel(px as u32, py as u32, Rgb(color));
            }
        }
    }

    /// Blends a translucent rectangle (for legend and label backdrops).
    pub fn rect_alpha(&mut self, x: f32, y: f32, w: f32, h: f32, color: [u8; 3], alpha: f32) {
        let (x0, y0) = (x.round() as i64, y.round() as i64);
        let (x1, y1) = ((x + w).round() as i64, (y + h).round() as i64);
        for py in y0..y1 {
            for px in x0..x1 {
                self.blend(px, py, color, alpha);
            }
        }
    }

    /// A filled, anti-aliased disc.
    pub fn circle(&mut self, center: (f32, f32), radius: f32, color: [u8; 3]) {
        if !(center.0.is_finite() && center.1.is_finite() && radius > 0.0) {
            return;
        }
        let (cx, cy) = center;
        let reach = radius + 1.0;
        for py in (cy - reach).floor() as i64..=(cy + reach).ceil() as i64 {
            for px in (cx - reach).floor() as i64..=(cx + reach).ceil() as i64 {
                let d = ((px as f32 + 0.5 - cx).powi(2) + (py as f32 + 0.5 - cy).powi(2)).sqrt();
                self.blend(px, py, color, radius + 0.5 - d);
            }
        }
    }

    /// An anti-aliased line `width` pixels thick with round caps. Only the pixels near the segment are
    /// visited (a band along its major axis), so long thin lines cost what their length costs.
    pub fn line(&mut self, a: (f32, f32), b: (f32, f32), color: [u8; 3], width: f32) {
        if !(a.0.is_finite() && a.1.is_finite() && b.0.is_finite() && b.1.is_finite()) || width <= 0.0 {
            return;
        }
        let Some((a, b)) = self.clip_to_view(a, b, width) else { return };
        let r = width * 0.5;
        let (dx, dy) = (b.0 - a.0, b.1 - a.1);
        let len = (dx * dx + dy * dy).sqrt();
        if len < 1e-3 {
            self.circle(a, r, color);
            return;
        }
        let coverage = |px: i64, py: i64| {
            let (qx, qy) = (px as f32 + 0.5, py as f32 + 0.5);
            let t = (((qx - a.0) * dx + (qy - a.1) * dy) / (len * len)).clamp(0.0, 1.0);
            let d = ((qx - a.0 - t * dx).powi(2) + (qy - a.1 - t * dy).powi(2)).sqrt();
            r + 0.5 - d
        };
        let x_major = dx.abs() >= dy.abs();
        // Half-height of the band across the major axis that can be touched by the thick line.
        let band = (r + 1.0) * len / if x_major { dx.abs() } else { dy.abs() };
        let (lo, hi) = if x_major { (a.0.min(b.0), a.0.max(b.0)) } else { (a.1.min(b.1), a.1.max(b.1)) };
        for major in (lo - r - 1.0).floor() as i64..=(hi + r + 1.0).ceil() as i64 {
            let m = (major as f32 + 0.5).clamp(lo, hi);
            let center = if x_major { a.1 + dy * (m - a.0) / dx } else { a.0 + dx * (m - a.1) / dy };
            for minor in (center - band).floor() as i64..=(center + band).ceil() as i64 {
                let (px, py) = if x_major { (major, minor) } else { (minor, major) };
                self.blend(px, py, color, coverage(px, py));
            }
        }
    }

    /// Clips a segment to the canvas (plus a margin for its width) so that huge off-screen
    /// coordinates from near-plane projections never cost a long loop.
    fn clip_to_view(&self, a: (f32, f32), b: (f32, f32), width: f32) -> Option<((f32, f32), (f32, f32))> {
        let m = width + 2.0;
        let (xmin, ymin) = (-m, -m);
        let (xmax, ymax) = (self.img.width() as f32 + m, self.img.height() as f32 + m);
        let (dx, dy) = (b.0 - a.0, b.1 - a.1);
        let (mut t0, mut t1) = (0.0f32, 1.0f32);
        // Liang–Barsky: each pair is (p, q) for one boundary.
        for (p, q) in [(-dx, a.0 - xmin), (dx, xmax - a.0), (-dy, a.1 - ymin), (dy, ymax - a.1)] {
            if p == 0.0 {
                if q < 0.0 {
                    return None;
                }
            } else {
                let t = q / p;
                if p < 0.0 {
                    t0 = t0.max(t);
                } else {
                    t1 = t1.min(t);
                }
            }
        }
        (t0 <= t1).then_some(((a.0 + t0 * dx, a.1 + t0 * dy), (a.0 + t1 * dx, a.1 + t1 * dy)))
    }

    /// Draws `text` with its top-left corner at `pos`; `size` is the font's pixel height.
    /// Returns the advance width drawn.
    pub fn text(&mut self, pos: (f32, f32), text: &str, size: f32, color: [u8; 3]) -> f32 {
        let font = font().as_scaled(PxScale::from(size));
        let baseline = pos.1 + font.ascent();
        let mut x = pos.0;
        let mut prev = None;
        for c in text.chars() {
            let id = font.glyph_id(c);
            if let Some(p) = prev {
                x += font.kern(p, id);
            }
            let glyph = id.with_scale_and_position(size, ab_glyph::point(x, baseline));
            if let Some(outlined) = font.outline_glyph(glyph) {
                let bounds = outlined.px_bounds();
                outlined.draw(|gx, gy, cov| {
                    self.blend(bounds.min.x as i64 + gx as i64, bounds.min.y as i64 + gy as i64, color, cov);
                });
            }
            x += font.h_advance(id);
            prev = Some(id);
        }
        x - pos.0
    }

    /// Copies `other` onto this canvas with its top-left corner at (x, y) (picture-in-picture);
    /// parts outside are cut off.
    pub fn blit(&mut self, other: &RgbImage, x: i64, y: i64) {
        for (sx, sy, p) in other.enumerate_pixels() {
            let (tx, ty) = (x + sx as i64, y + sy as i64);
            if tx >= 0 && ty >= 0 && tx < self.img.width() as i64 && ty < self.img.height() as i64 {
                self.img.put_pixel(tx as u32, ty as u32, *p);
            }
        }
    }
}

impl Canvas {
    /// Copies `other` resized to `w` × `h` (smooth filter) with its top-left corner at (x, y), e.g. a
    /// camera view inset in a corner.
    pub fn blit_scaled(&mut self, other: &RgbImage, x: i64, y: i64, w: u32, h: u32) {
        if w == 0 || h == 0 {
            return;
        }
        let small = image::imageops::resize(other, w, h, image::imageops::FilterType::Triangle);
        self.blit(&small, x, y);
    }

    /// A one-pixel frame around the rectangle at (x, y) of size w × h (for picture-in-picture).
    pub fn rect_outline(&mut self, x: f32, y: f32, w: f32, h: f32, color: [u8; 3]) {
        self.rect(x, y, w, 1.0, color);
        self.rect(x, y + h - 1.0, w, 1.0, color);
        self.rect(x, y, 1.0, h, color);
        self.rect(x + w - 1.0, y, 1.0, h, color);
    }
}

/// Width in pixels that [`Canvas::text`] would use for `text` at `size`.
pub fn text_width(text: &str, size: f32) -> f32 {
    let font = font().as_scaled(PxScale::from(size));
    let mut w = 0.0;
    let mut prev = None;
    for c in text.chars() {
        let id = font.glyph_id(c);
        if let Some(p) = prev {
            w += font.kern(p, id);
        }
        w += font.h_advance(id);
        prev = Some(id);
    }
    w
}

/// Noto Sans Regular (SIL Open Font License), shipped as bytes by the `notosans` crate, so text
/// renders the same on any machine, with or without system fonts.
pub(crate) fn font() -> &'static FontRef<'static> {
    static FONT: OnceLock<FontRef<'static>> = OnceLock::new();
    FONT.get_or_init(|| FontRef::try_from_slice(notosans::REGULAR_TTF).expect("the bundled Noto Sans font parses"))
}

/// A perspective pinhole camera looking from `eye` at `target`, `fov_y_deg` degrees of vertical field
/// of view, projecting onto a `width` × `height` pixel viewport (y down).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera3 {
    pub eye: DVec3,
    pub target: DVec3,
    pub up: DVec3,
    pub fov_y_deg: f64,
    pub width: u32,
    pub height: u32,
}

/// A projected point: pixel x, pixel y (down), depth along the view axis.
pub type Projected = (f32, f32, f32);

/// Points closer to the eye than this (along the view axis) are not projected.
pub const NEAR: f64 = 1e-3;

impl Camera3 {
    /// A camera on a 480 × 360 viewport; change it with [`Camera3::with_viewport`].
    pub fn new(eye: DVec3, target: DVec3, up: DVec3, fov_y_deg: f64) -> Camera3 {
        Camera3 { eye, target, up, fov_y_deg, width: 480, height: 360 }
    }

    pub fn with_viewport(self, width: u32, height: u32) -> Camera3 {
        Camera3 { width, height, ..self }
    }

    /// Orthonormal camera basis (right, up, forward), forward pointing from the eye to the target.
    pub fn basis(&self) -> (DVec3, DVec3, DVec3) {
        let forward = (self.target - self.eye).normalize_or(DVec3::NEG_Z);
        let mut right = forward.cross(self.up);
        if right.length_squared() < 1e-12 {
            // `up` is parallel to the view direction: any perpendicular will do.
            right = forward.any_orthonormal_vector();
        }
        let right = right.normalize();
        (right, right.cross(forward), forward)
    }

    /// Focal length in pixels: a point at depth d and height h above the axis lands f·h/d pixels
    /// from the centre.
    pub fn focal_px(&self) -> f64 {
        self.height as f64 * 0.5 / (self.fov_y_deg.to_radians() * 0.5).tan()
    }

    /// Camera-space coordinates (right, up, depth along the view axis).
    pub fn to_camera(&self, p: DVec3) -> DVec3 {
        let (r, u, f) = self.basis();
        let d = p - self.eye;
        DVec3::new(d.dot(r), d.dot(u), d.dot(f))
    }

    /// Pixel position and depth of `p`, or None when it is behind (or too close to) the eye.
    pub fn project(&self, p: DVec3) -> Option<Projected> {
        self.project_camera(self.to_camera(p))
    }

    fn project_camera(&self, c: DVec3) -> Option<Projected> {
        if !c.is_finite() || c.z <= NEAR {
            return None;
        }
        let f = self.focal_px();
        let x = self.width as f64 * 0.5 + f * c.x / c.z;
        let y = self.height as f64 * 0.5 - f * c.y / c.z;
        Some((x as f32, y as f32, c.z as f32))
    }

    /// Projects the part of segment a–b in front of the eye (clipped at the near plane).
    pub fn project_segment(&self, a: DVec3, b: DVec3) -> Option<(Projected, Projected)> {
        let (mut ca, mut cb) = (self.to_camera(a), self.to_camera(b));
        let near = NEAR * 10.0;
        if ca.z < near && cb.z < near {
            return None;
        }
        if ca.z < near {
            ca = ca.lerp(cb, (near - ca.z) / (cb.z - ca.z));
        } else if cb.z < near {
            cb = cb.lerp(ca, (near - cb.z) / (ca.z - cb.z));
        }
        Some((self.project_camera(ca)?, self.project_camera(cb)?))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cam() -> Camera3 {
        Camera3::new(DVec3::new(3.0, 2.0, 10.0), DVec3::new(0.0, 1.0, 0.0), DVec3::Y, 40.0).with_viewport(400, 300)
    }

    #[test]
    fn point_on_the_axis_projects_to_the_centre() {
        let c = cam();
        let on_axis = c.eye + (c.target - c.eye) * 2.5;
        let (x, y, depth) = c.project(on_axis).unwrap();
        assert!((x - 200.0).abs() < 1e-3 && (y - 150.0).abs() < 1e-3, "{x} {y}");
        assert!((depth as f64 - 2.5 * (c.target - c.eye).length()).abs() < 1e-3);
    }

    #[test]
    fn points_behind_the_eye_are_none() {
        let c = cam();
        assert!(c.project(c.eye - (c.target - c.eye)).is_none());
        assert!(c.project(c.eye).is_none());
    }

    #[test]
    fn up_and_right_map_to_screen_directions() {
        let c = cam();
        let (r, u, _) = c.basis();
        let (cx, cy, _) = c.project(c.target).unwrap();
        let (rx, _, _) = c.project(c.target + r).unwrap();
        let (_, uy, _) = c.project(c.target + u).unwrap();
        assert!(rx > cx, "world right goes right on screen");
        assert!(uy < cy, "world up goes up on screen (y down)");
        // The field of view: a point at the top edge of the frustum lands on row 0.
        let depth = (c.target - c.eye).length();
        let top = c.target + u * depth * (20.0f64.to_radians()).tan();
        assert!(c.project(top).unwrap().1.abs() < 1e-2);
    }

    #[test]
    fn segment_crossing_the_eye_plane_is_clipped() {
        let c = cam();
        let (a, b) = c.project_segment(c.target, c.eye - (c.target - c.eye)).unwrap();
        assert!(a.2 > b.2 && b.2 > 0.0);
        assert!(c.project_segment(c.eye * 2.0 - c.target, c.eye * 3.0 - c.target * 2.0).is_none());
    }

    #[test]
    fn line_covers_its_pixels_and_nothing_far_away() {
        let mut cv = Canvas::new(50, 50, [255, 255, 255]);
        cv.line((5.0, 25.0), (45.0, 25.0), [0, 0, 0], 3.0);
        assert_eq!(cv.pixel(25, 25), [0, 0, 0]);
        assert_eq!(cv.pixel(25, 20), [255, 255, 255]);
        assert_eq!(cv.pixel(48, 25), [255, 255, 255]);
        // Diagonal and steep lines too.
        cv.line((10.0, 0.0), (12.0, 49.0), [255, 0, 0], 2.0);
        assert_eq!(cv.pixel(11, 25), [255, 0, 0]);
        // Lines far outside the canvas are cheap and harmless.
        cv.line((-1e9, -1e9), (1e9, 1e9), [0, 255, 0], 1.0);
        assert_eq!(cv.pixel(30, 30)[1], 255);
    }

    #[test]
    fn circle_rect_blit_and_text_draw() {
        let mut cv = Canvas::new(120, 60, [255, 255, 255]);
        cv.circle((10.0, 10.0), 4.0, [0, 0, 255]);
        assert_eq!(cv.pixel(10, 10), [0, 0, 255]);
        assert_eq!(cv.pixel(10, 16), [255, 255, 255]);
        cv.rect(20.0, 0.0, 5.0, 5.0, [0, 255, 0]);
        assert_eq!(cv.pixel(22, 2), [0, 255, 0]);
        let small = RgbImage::from_pixel(4, 4, Rgb([9, 9, 9]));
        cv.blit(&small, 118, 58);
        assert_eq!(cv.pixel(119, 59), [9, 9, 9]);
        cv.blit_scaled(&small, 100, 0, 10, 8);
        assert_eq!(cv.pixel(109, 7), [9, 9, 9]);
        cv.rect_outline(60.0, 40.0, 10.0, 10.0, [1, 2, 3]);
        assert_eq!(cv.pixel(69, 45), [1, 2, 3]);
        assert_eq!(cv.pixel(65, 45), [255, 255, 255]);
        let w = cv.text((30.0, 20.0), "Hello", 20.0, [0, 0, 0]);
        assert!((w - text_width("Hello", 20.0)).abs() < 1e-3 && w > 30.0);
        let dark = (30..30 + w as u32)
            .flat_map(|x| (20..40).map(move |y| (x, y)))
            .filter(|&(x, y)| cv.pixel(x, y)[0] < 100)
            .count();
        assert!(dark > 40, "text left {dark} dark pixels");
    }
}
