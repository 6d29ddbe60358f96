//! PNG previews a person can check a layout with: a top-down plan (room outline, rotated
//! footprints in category colours, labels, front ticks, a metre scale bar) and a perspective view
//! of shaded boxes drawn back to front (painter's algorithm) over a floor grid.

use glam::DVec3;
use image::RgbImage;
use inbetween_render::canvas::{text_width, Camera3, NEAR};
use inbetween_render::Canvas;

use crate::catalogue::Catalogue;
use crate::layout::geom;
use crate::scene::{PlacedObject, Scene};

use super::category_color;

/// Views [`perspective`] knows; anything else is drawn from the front.
pub const VIEWS: [&str; 5] = ["front", "back", "left", "right", "top"];

const BACKGROUND: [u8; 3] = [255, 255, 255];
const FLOOR: [u8; 3] = [236, 233, 226];
const GRID: [u8; 3] = [212, 208, 200];
const INK: [u8; 3] = [40, 40, 40];
/// Polygons are clipped a little in front of the camera's near plane (cameras inside the room).
const NEAR_CLIP: f64 = NEAR * 20.0;

/// `c` darkened (or lightened) by the factor `k`, for shading faces.
pub(crate) fn scale_color(c: [u8; 3], k: f32) -> [u8; 3] {
    c.map(|v| (v as f32 * k).round().clamp(0.0, 255.0) as u8)
}

/// Projects a planar polygon, clipped to the part in front of the near plane (Sutherland–Hodgman
/// in camera space); None when nothing of it is in front.
fn project_polygon(cam: &Camera3, pts: &[DVec3]) -> Option<Vec<(f32, f32)>> {
    let near = NEAR_CLIP;
    let c: Vec<DVec3> = pts.iter().map(|&p| cam.to_camera(p)).collect();
    let mut out = Vec::with_capacity(c.len() + 2);
    for i in 0..c.len() {
        let (a, b) = (c[i], c[(i + 1) % c.len()]);
        if a.z >= near {
            out.push(a);
        }
        if (a.z >= near) != (b.z >= near) {
            out.push(a.lerp(b, (near - a.z) / (b.z - a.z)));
        }
    }
    if out.len() < 3 {
        return None;
    }
    let f = cam.focal_px();
    let (w, h) = (cam.width as f64 * 0.5, cam.height as f64 * 0.5);
    Some(out.iter().map(|p| ((w + f * p.x / p.z) as f32, (h - f * p.y / p.z) as f32)).collect())
}

/// One object as a shaded box (faces turned away from the camera skipped).
/// Draws `o` as its placeholder boxes ([`super::placeholder_boxes`]), farthest first.
pub(crate) fn draw_object(cv: &mut Canvas, cam: &Camera3, o: &PlacedObject, cat: &Catalogue) {
    let color = super::category_color(cat, &o.category);
    let mut parts: Vec<PlacedObject> =
        super::placeholder_boxes(o, cat).iter().map(|b| super::placed_box(o, b)).collect();
    let depth = |p: &PlacedObject| {
        let c = geom::center(p);
        cam.to_camera(DVec3::new(c[0] as f64, (p.position[1] + p.size[1] / 2.0) as f64, c[1] as f64)).z
    };
    parts.sort_by(|a, b| depth(b).total_cmp(&depth(a)));
    for p in &parts {
        draw_box(cv, cam, p, color);
    }
}

fn draw_box(cv: &mut Canvas, cam: &Camera3, o: &PlacedObject, color: [u8; 3]) {
    let light = DVec3::new(0.4, 1.0, 0.6).normalize();
    let c = geom::center(o);
    let (y0, y1) = (o.position[1] as f64, o.top() as f64);
    let foot = geom::corners(o).map(|p| (p[0] as f64, p[1] as f64));
    let v = |k: usize, top: bool| DVec3::new(foot[k].0, if top { y1 } else { y0 }, foot[k].1);
    let centre = DVec3::new(c[0] as f64, (y0 + y1) / 2.0, c[1] as f64);
    let mut faces: Vec<([DVec3; 4], DVec3)> = vec![
        ([v(0, true), v(1, true), v(2, true), v(3, true)], DVec3::Y),
        ([v(0, false), v(1, false), v(2, false), v(3, false)], DVec3::NEG_Y),
    ];
    for k in 0..4 {
        let f = [v(k, false), v((k + 1) % 4, false), v((k + 1) % 4, true), v(k, true)];
        let fc = (f[0] + f[1] + f[2] + f[3]) / 4.0;
        let n = fc - centre;
        faces.push((f, DVec3::new(n.x, 0.0, n.z).normalize_or_zero()));
    }
    for (f, nn) in faces {
        let fc = (f[0] + f[1] + f[2] + f[3]) / 4.0;
        if nn.dot(cam.eye - fc) <= 0.0 {
            continue;
        }
        let Some(pts) = project_polygon(cam, &f) else { continue };
        let shade = 0.55 + 0.45 * nn.dot(light).max(0.0) as f32;
        cv.fill_convex(&pts, scale_color(color, shade));
        for k in 0..pts.len() {
            cv.line(pts[k], pts[(k + 1) % pts.len()], scale_color(color, 0.45), 1.0);
        }
    }
}

/// Floor, grid and room edges.
pub(crate) fn draw_room(cv: &mut Canvas, cam: &Camera3, scene: &Scene) {
    let r = &scene.room;
    let (w, d, h) = (r.width as f64, r.depth as f64, r.height as f64);
    let floor = [DVec3::ZERO, DVec3::new(w, 0.0, 0.0), DVec3::new(w, 0.0, d), DVec3::new(0.0, 0.0, d)];
    if let Some(f) = project_polygon(cam, &floor) {
        cv.fill_convex(&f, FLOOR);
    }
    let seg = |cv: &mut Canvas, a: DVec3, b: DVec3, color: [u8; 3], width: f32| {
        if let Some((p, q)) = cam.project_segment(a, b) {
            cv.line((p.0, p.1), (q.0, q.1), color, width);
        }
    };
    for k in 0..=w.floor() as usize {
        seg(cv, DVec3::new(k as f64, 0.0, 0.0), DVec3::new(k as f64, 0.0, d), GRID, 1.0);
    }
    for k in 0..=d.floor() as usize {
        seg(cv, DVec3::new(0.0, 0.0, k as f64), DVec3::new(w, 0.0, k as f64), GRID, 1.0);
    }
    for k in 0..4 {
        let (a, b) = (floor[k], floor[(k + 1) % 4]);
        seg(cv, a, b, [120, 120, 120], 1.5);
        seg(cv, a, a + DVec3::Y * h, [190, 190, 190], 1.0);
        seg(cv, a + DVec3::Y * h, b + DVec3::Y * h, [190, 190, 190], 1.0);
    }
}

/// Pixel of floor point `[x, z]` (metres) on [`top_down`]'s plan (same scale and margins).
pub fn plan_pixel(scene: &Scene, p: [f32; 2]) -> (f32, f32) {
    let r = &scene.room;
    let (rw, rd) = (r.width.max(0.5), r.depth.max(0.5));
    let s = (720.0 / rw).min(540.0 / rd).clamp(20.0, 200.0);
    let (ml, mt) = (60.0, 50.0);
    (ml + p[0] * s, mt + p[1] * s)
}

/// A label centred at `at` on a light backdrop, moved down past labels already drawn (`taken`
/// holds their boxes) so a lamp's label does not hide its desk's.
fn label(cv: &mut Canvas, taken: &mut Vec<[f32; 4]>, at: (f32, f32), text: &str, size: f32) {
    let w = text_width(text, size) + 4.0;
    let h = size * 1.25;
    let (x, mut y) = (at.0 - w / 2.0, at.1 - size / 2.0);
    for _ in 0..6 {
        let clash = taken.iter().any(|b| x < b[0] + b[2] && b[0] < x + w && y < b[1] + b[3] && b[1] < y + h);
        if !clash {
            break;
        }
        y += h;
    }
    taken.push([x, y, w, h]);
    cv.rect_alpha(x, y, w, h, BACKGROUND, 0.75);
    cv.text((x + 2.0, y), text, size, INK);
}

/// Objects drawn lowest first, so things on tables show over them.
fn by_height(scene: &Scene) -> Vec<&PlacedObject> {
    let mut objs: Vec<&PlacedObject> = scene.objects.iter().collect();
    objs.sort_by(|a, b| a.position[1].total_cmp(&b.position[1]).then(a.top().total_cmp(&b.top())));
    objs
}

/// The plan view: x to the right, z downwards (the door wall, z = depth, at the bottom).
pub fn top_down(scene: &Scene, cat: &Catalogue) -> RgbImage {
    let r = &scene.room;
    let (rw, rd) = (r.width.max(0.5), r.depth.max(0.5));
    let s = (720.0 / rw).min(540.0 / rd).clamp(20.0, 200.0);
    let (ml, mt, mb) = (60.0, 50.0, 80.0);
    let (w, h) = ((rw * s + 2.0 * ml).ceil() as u32, (rd * s + mt + mb).ceil() as u32);
    let mut cv = Canvas::new(w, h, BACKGROUND);
    let px = |p: [f32; 2]| plan_pixel(scene, p);
    cv.rect(ml, mt, rw * s, rd * s, FLOOR);
    for k in 1..rw.ceil() as usize {
        let x = ml + k as f32 * s;
        cv.line((x, mt), (x, mt + rd * s), GRID, 1.0);
    }
    for k in 1..rd.ceil() as usize {
        let y = mt + k as f32 * s;
        cv.line((ml, y), (ml + rw * s, y), GRID, 1.0);
    }
    let corners = [px([0.0, 0.0]), px([rw, 0.0]), px([rw, rd]), px([0.0, rd])];
    for k in 0..4 {
        cv.line(corners[k], corners[(k + 1) % 4], INK, 3.0);
    }
    // The door the reachability check starts from.
    let d = crate::layout::door(r);
    let door_color = [200, 90, 60];
    cv.line(px([d[0] - 0.45, d[1]]), px([d[0] + 0.45, d[1]]), door_color, 6.0);
    let dw = text_width("door", 12.0);
    cv.text((px(d).0 - dw / 2.0, px(d).1 + 6.0), "door", 12.0, door_color);

    let objs = by_height(scene);
    for o in &objs {
        let color = category_color(cat, &o.category);
        let pts: Vec<(f32, f32)> = geom::corners(o).iter().map(|&c| px(c)).collect();
        cv.fill_convex(&pts, color);
        for k in 0..4 {
            cv.line(pts[k], pts[(k + 1) % 4], scale_color(color, 0.55), 1.5);
        }
        // Front tick: across the middle of the front edge, poking out.
        let c = geom::center(o);
        let hd = o.size[2] / 2.0;
        let inner = geom::to_world(c, o.yaw, [0.0, hd - hd.min(0.2)]);
        let tip = geom::to_world(c, o.yaw, [0.0, hd + 0.12]);
        cv.line(px(inner), px(tip), INK, 2.0);
    }
    let mut taken = Vec::new();
    for o in &objs {
        label(&mut cv, &mut taken, px(geom::center(o)), &o.label, 13.0);
    }
    // Title and scale bar.
    let title = format!("{} — {:.1} × {:.1} m, top view", r.name, r.width, r.depth);
    cv.text((ml, 14.0), &title, 18.0, INK);
    let metres = if s >= 40.0 { 1.0 } else { 2.0 };
    let (bx, by) = (ml, mt + rd * s + 45.0);
    cv.line((bx, by), (bx + metres * s, by), INK, 3.0);
    for x in [bx, bx + metres * s] {
        cv.line((x, by - 6.0), (x, by + 6.0), INK, 2.0);
    }
    cv.text((bx + metres * s + 8.0, by - 9.0), &format!("{metres:.0} m"), 15.0, INK);
    cv.into_image()
}

/// The camera for a named view of the room (see [`VIEWS`]); unknown names give "front".
pub fn view_camera(scene: &Scene, view: &str, width: u32, height: u32) -> Camera3 {
    let r = &scene.room;
    let (w, d, h) = (r.width.max(0.5) as f64, r.depth.max(0.5) as f64, r.height.max(0.5) as f64);
    let target = DVec3::new(w / 2.0, h * 0.25, d / 2.0);
    let fov = 45.0f64;
    let radius = 0.5 * (w * w + d * d + h * h).sqrt();
    let dist = radius / (fov.to_radians() / 2.0).sin() * 0.8;
    let (elev, az) = (
        30f64.to_radians(),
        match view {
            "back" => DVec3::NEG_Z,
            "left" => DVec3::NEG_X,
            "right" => DVec3::X,
            _ => DVec3::Z,
        },
    );
    let (eye, up) = if view == "top" {
        (DVec3::new(w / 2.0, h + dist * 1.4, d / 2.0), DVec3::NEG_Z)
    } else {
        (target + az * dist * elev.cos() + DVec3::Y * dist * elev.sin(), DVec3::Y)
    };
    Camera3::new(eye, target, up, fov).with_viewport(width, height)
}

/// A rasterised 3-D view: floor with a 1 m grid, room edges, every object a shaded box drawn
/// back to front, labels on top.
pub fn perspective(scene: &Scene, cat: &Catalogue, view: &str) -> RgbImage {
    let view = if VIEWS.contains(&view) { view } else { "front" };
    let (wpx, hpx) = (960u32, 640u32);
    let cam = view_camera(scene, view, wpx, hpx);
    let mut cv = Canvas::new(wpx, hpx, [246, 247, 250]);
    let r = &scene.room;
    let proj = |p: DVec3| cam.project(p).map(|q| (q.0, q.1));
    let seg = |cv: &mut Canvas, a: DVec3, b: DVec3, color: [u8; 3], width: f32| {
        if let Some((p, q)) = cam.project_segment(a, b) {
            cv.line((p.0, p.1), (q.0, q.1), color, width);
        }
    };
    draw_room(&mut cv, &cam, scene);

    // Objects farthest first (by the view depth of their box centre).
    let depth = |o: &PlacedObject| {
        let c = DVec3::new(o.position[0] as f64, (o.position[1] + o.size[1] / 2.0) as f64, o.position[2] as f64);
        cam.to_camera(c).z
    };
    let mut objs: Vec<&PlacedObject> = scene.objects.iter().collect();
    objs.sort_by(|a, b| depth(b).total_cmp(&depth(a)));
    for o in &objs {
        draw_object(&mut cv, &cam, o, cat);
        let c = geom::center(o);
        let y1 = o.top() as f64;
        // Front marker on the top face.
        let tip = geom::to_world(c, o.yaw, [0.0, o.size[2] / 2.0]);
        seg(&mut cv, DVec3::new(c[0] as f64, y1, c[1] as f64), DVec3::new(tip[0] as f64, y1, tip[1] as f64), INK, 1.5);
    }
    let mut taken = Vec::new();
    for o in objs.iter().rev() {
        let c = geom::center(o);
        if let Some(p) = proj(DVec3::new(c[0] as f64, o.top() as f64 + 0.12, c[1] as f64)) {
            label(&mut cv, &mut taken, p, &o.label, 14.0);
        }
    }
    let title = format!("{} — {view} view", r.name);
    cv.text((16.0, 12.0), &title, 18.0, INK);
    cv.into_image()
}
