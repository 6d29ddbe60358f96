//! Animated previews of a story: a GIF seen through the story's camera (the look of
//! [`super::preview::perspective`]: floor with a 1 m grid, room edges, shaded boxes; plus the
//! characters as stick figures, everything painted far to near so a figure behind a desk is hidden
//! by it, roughly), and a top-down plan ([`super::top_down`]) with each character's route.

use std::path::Path;

use glam::DVec3;
use image::RgbImage;
use inbetween_core::clip::Clip;
use inbetween_render::canvas::{text_width, Camera3};
use inbetween_render::Canvas;
use rayon::prelude::*;

use super::anim_gltf::{animation_frames, check_fps, CameraFn, CHARACTER_COLORS};
pub use super::preview::plan_pixel;
use super::preview::{draw_object, draw_room, scale_color};
use super::top_down;
use crate::catalogue::Catalogue;
use crate::error::ScriptError;
use crate::layout::geom;
use crate::scene::{PlacedObject, Scene};

const INK: [u8; 3] = [40, 40, 40];
const SKY: [u8; 3] = [246, 247, 250];

/// Largest GIF width and frame rate (keeps files small).
pub const MAX_GIF_WIDTH: u32 = 480;
pub const MAX_GIF_FPS: f64 = 10.0;

/// An object's base point and yaw per story frame (see [`AnimPreviewOptions::moving`]).
pub type ObjectTrack = Vec<([f32; 3], f32)>;

/// How to draw the preview GIF.
#[derive(Clone, Debug, PartialEq)]
pub struct AnimPreviewOptions {
    /// Pixels; clamped to 64..=[`MAX_GIF_WIDTH`].
    pub width: u32,
    /// Pixels; None: two thirds of the width.
    pub height: Option<u32>,
    /// GIF frame rate; clamped to at most [`MAX_GIF_FPS`] (story frames are skipped evenly).
    pub max_fps: f64,
    /// Upper bound on GIF frames; more story frames are skipped to fit.
    pub max_frames: usize,
    /// Object labels and character names.
    pub labels: bool,
    /// Text before the frame counter in the title (e.g. the story's name); None: the room's name.
    pub title: Option<String>,
    /// Objects that move (props carried by a hand): index into the scene's objects, then base
    /// point and yaw per story frame (the last one held). Empty: every object stays put.
    pub moving: Vec<(usize, ObjectTrack)>,
}

impl Default for AnimPreviewOptions {
    fn default() -> Self {
        AnimPreviewOptions {
            width: MAX_GIF_WIDTH,
            height: None,
            max_fps: MAX_GIF_FPS,
            max_frames: 600,
            labels: true,
            title: None,
            moving: Vec::new(),
        }
    }
}

impl AnimPreviewOptions {
    fn size(&self) -> (u32, u32) {
        let w = self.width.clamp(64, MAX_GIF_WIDTH);
        (w, self.height.unwrap_or(w * 2 / 3).clamp(48, 2 * MAX_GIF_WIDTH))
    }
}

/// Story frames shown in the GIF and the GIF's frame rate: every `step`-th frame of
/// [`animation_frames`] so that the rate is at most `opts.max_fps` (≤ 10) and at most
/// `opts.max_frames` frames are written.
pub fn preview_frame_indices(characters: &[(&str, &Clip)], fps: f64, opts: &AnimPreviewOptions) -> (Vec<usize>, f64) {
    let n = animation_frames(characters, fps);
    let max_fps =
        if opts.max_fps.is_finite() && opts.max_fps > 0.0 { opts.max_fps.min(MAX_GIF_FPS) } else { MAX_GIF_FPS };
    let mut step = ((fps / max_fps) - 1e-9).ceil().max(1.0) as usize;
    let cap = opts.max_frames.max(1);
    if n.div_ceil(step) > cap {
        step = n.div_ceil(cap);
    }
    ((0..n).step_by(step).collect(), fps / step as f64)
}

/// One character's points over its frames: joints then end sites, each with its parent.
struct Figure {
    parents: Vec<Option<usize>>,
    frames: Vec<Vec<DVec3>>,
    frame_time: f64,
    /// Index among the points of the head's end site (for the head disc), if any.
    head: Option<(usize, usize)>,
    name: String,
    color: [u8; 3],
}

impl Figure {
    fn new(name: &str, m: &Clip, color: [u8; 3]) -> Figure {
        let sk = m.skeleton();
        let mut parents: Vec<Option<usize>> = sk.joints().iter().map(|j| j.parent).collect();
        let ends: Vec<usize> = (0..sk.len()).filter(|&j| sk.joint(j).end_site.is_some()).collect();
        parents.extend(ends.iter().map(|&j| Some(j)));
        let head = sk.find("Head").and_then(|h| ends.iter().position(|&e| e == h).map(|k| (h, sk.len() + k)));
        let frames = m
            .globals()
            .into_iter()
            .map(|g| {
                let mut pts = g.positions.clone();
                pts.extend(ends.iter().map(|&j| g.end_site(sk, j).expect("joint has an end site")));
                pts
            })
            .collect();
        Figure { parents, frames, frame_time: m.frame_time(), head, name: name.to_string(), color }
    }

    /// Points at story time `t` seconds (held at the last frame after the clip ends).
    fn at(&self, t: f64) -> &[DVec3] {
        let f = ((t / self.frame_time).round().max(0.0) as usize).min(self.frames.len() - 1);
        &self.frames[f]
    }
}

/// Something to paint, with its depth along the view axis (farthest painted first).
enum Item<'a> {
    Object(&'a PlacedObject),
    Bone { fig: usize, a: DVec3, b: DVec3 },
    Head { fig: usize, centre: DVec3, radius: f64 },
}

/// One GIF frame: the scene and the figures at story frame `frame` through `cam`.
#[allow(clippy::too_many_arguments)]
fn draw_frame(
    scene: &Scene,
    cat: &Catalogue,
    figs: &[Figure],
    cam: &Camera3,
    frame: usize,
    frames: usize,
    fps: f64,
    opts: &AnimPreviewOptions,
) -> RgbImage {
    let mut cv = Canvas::new(cam.width, cam.height, SKY);
    draw_room(&mut cv, cam, scene);
    let t = frame as f64 / fps;
    // Carried props where the hand has them at this frame.
    let mut placed = scene.objects.clone();
    for (i, track) in &opts.moving {
        if let (Some(o), Some(&(p, yaw))) = (placed.get_mut(*i), track.get(frame).or(track.last())) {
            (o.position, o.yaw) = (p, yaw);
        }
    }
    let mut items: Vec<(f64, Item)> = placed
        .iter()
        .map(|o| {
            let c = geom::center(o);
            let p = DVec3::new(c[0] as f64, (o.position[1] + o.size[1] / 2.0) as f64, c[1] as f64);
            (cam.to_camera(p).z, Item::Object(o))
        })
        .collect();
    for (fi, fig) in figs.iter().enumerate() {
        let pts = fig.at(t);
        for (k, p) in fig.parents.iter().enumerate() {
            let Some(p) = *p else { continue };
            let (a, b) = (pts[p], pts[k]);
            if a.distance(b) < 1e-4 {
                continue;
            }
            items.push((cam.to_camera((a + b) / 2.0).z, Item::Bone { fig: fi, a, b }));
        }
        if let Some((h, e)) = fig.head {
            let centre = (pts[h] + pts[e]) / 2.0 + (pts[e] - pts[h]) * 0.3;
            let radius = (pts[e].distance(pts[h]) * 0.9).max(0.08);
            items.push((cam.to_camera(centre).z, Item::Head { fig: fi, centre, radius }));
        }
    }
    items.sort_by(|a, b| b.0.total_cmp(&a.0));
    let f = cam.focal_px();
    for (depth, item) in &items {
        match item {
            Item::Object(o) => draw_object(&mut cv, cam, o, cat),
            Item::Bone { fig, a, b } => {
                if let Some((p, q)) = cam.project_segment(*a, *b) {
                    let w = (f * 0.05 / depth.max(0.05)).clamp(1.5, 9.0) as f32;
                    cv.line((p.0, p.1), (q.0, q.1), figs[*fig].color, w);
                }
            }
            Item::Head { fig, centre, radius } => {
                if let Some(p) = cam.project(*centre) {
                    let r = (f * radius / p.2 as f64).clamp(2.0, 40.0) as f32;
                    cv.circle((p.0, p.1), r + 1.0, scale_color(figs[*fig].color, 0.6));
                    cv.circle((p.0, p.1), r, figs[*fig].color);
                }
            }
        }
    }
    if opts.labels {
        for fig in figs {
            let pts = fig.at(t);
            let top = pts.iter().copied().max_by(|a, b| a.y.total_cmp(&b.y)).unwrap_or(DVec3::ZERO);
            if let Some(p) = cam.project(top + DVec3::Y * 0.15) {
                let tw = text_width(&fig.name, 12.0);
                cv.rect_alpha(p.0 - tw / 2.0 - 2.0, p.1 - 14.0, tw + 4.0, 15.0, [255, 255, 255], 0.7);
                cv.text((p.0 - tw / 2.0, p.1 - 14.0), &fig.name, 12.0, scale_color(fig.color, 0.7));
            }
        }
    }
    let name = opts.title.clone().unwrap_or_else(|| scene.room.name.clone());
    let title = format!("{name} · {t:.1} s · frame {}/{frames}", frame + 1);
    let tw = text_width(&title, 14.0);
    cv.rect_alpha(6.0, 5.0, tw + 8.0, 19.0, [255, 255, 255], 0.75);
    cv.text((10.0, 6.0), &title, 14.0, INK);
    cv.into_image()
}

/// The GIF's frames in memory: story frames [`preview_frame_indices`] seen from `camera(frame)`
/// (eye, target, vertical field of view in degrees), and the GIF frame rate.
pub fn preview_frames(
    scene: &Scene,
    cat: &Catalogue,
    characters: &[(&str, &Clip)],
    camera: &CameraFn,
    fps: f64,
    opts: &AnimPreviewOptions,
) -> Result<(Vec<RgbImage>, f64), ScriptError> {
    check_fps(fps)?;
    let (w, h) = opts.size();
    let n = animation_frames(characters, fps);
    let (idx, gif_fps) = preview_frame_indices(characters, fps, opts);
    let mut cams = Vec::with_capacity(idx.len());
    for &f in &idx {
        let c = camera(f);
        if !(c.is_finite() && c.fov_is_valid()) {
            return Err(ScriptError::Invalid(format!("camera pose at frame {f} is not usable")));
        }
        let (eye, target) = (c.eye.as_dvec3(), c.target.as_dvec3());
        cams.push(Camera3::new(eye, target, DVec3::Y, c.fovy_deg as f64).with_viewport(w, h));
    }
    let figs: Vec<Figure> = characters
        .iter()
        .enumerate()
        .map(|(i, (name, m))| Figure::new(name, m, CHARACTER_COLORS[i % CHARACTER_COLORS.len()]))
        .collect();
    let frames = idx
        .par_iter()
        .zip(cams.par_iter())
        .map(|(&f, cam)| draw_frame(scene, cat, &figs, cam, f, n, fps, opts))
        .collect();
    Ok((frames, gif_fps))
}

/// Writes the preview GIF (atomic, through [`inbetween_render::write_gif`]): see
/// [`preview_frames`] and [`AnimPreviewOptions`].
pub fn render_preview_gif(
    path: &Path,
    scene: &Scene,
    cat: &Catalogue,
    characters: &[(&str, &Clip)],
    camera: &CameraFn,
    fps: f64,
    opts: &AnimPreviewOptions,
) -> Result<(), ScriptError> {
    let (frames, gif_fps) = preview_frames(scene, cat, characters, camera, fps, opts)?;
    inbetween_render::write_gif(path, &frames, gif_fps)
        .map_err(|e| ScriptError::Asset { path: path.to_path_buf(), message: e.to_string() })
}

/// Floor route of each character: its root joint's `[x, z]` per frame.
pub fn root_route(m: &Clip) -> Vec<[f32; 2]> {
    (0..m.num_frames())
        .map(|f| {
            let t = m.pose(f).translations[0];
            [t.x as f32, t.z as f32]
        })
        .collect()
}

/// The plan ([`top_down`]) with each character's root path as a coloured polyline, a disc at its
/// start, a square at its end and its name at the start.
pub fn top_down_trails(scene: &Scene, cat: &Catalogue, characters: &[(&str, &Clip)]) -> RgbImage {
    let mut cv = Canvas::from_image(top_down(scene, cat));
    for (i, (name, m)) in characters.iter().enumerate() {
        let color = CHARACTER_COLORS[i % CHARACTER_COLORS.len()];
        let route = root_route(m);
        let Some(&start) = route.first() else { continue };
        let end = *route.last().expect("non-empty");
        let mut pts = vec![plan_pixel(scene, start)];
        for p in route.iter().map(|&p| plan_pixel(scene, p)) {
            let last = *pts.last().expect("non-empty");
            if (p.0 - last.0).hypot(p.1 - last.1) >= 2.0 {
                pts.push(p);
            }
        }
        pts.push(plan_pixel(scene, end));
        for w in pts.windows(2) {
            cv.line(w[0], w[1], scale_color(color, 0.55), 5.0);
        }
        for w in pts.windows(2) {
            cv.line(w[0], w[1], color, 3.0);
        }
        let (s, e) = (pts[0], *pts.last().expect("non-empty"));
        cv.rect(e.0 - 7.0, e.1 - 7.0, 14.0, 14.0, scale_color(color, 0.55));
        cv.rect(e.0 - 5.0, e.1 - 5.0, 10.0, 10.0, color);
        cv.circle(s, 8.0, scale_color(color, 0.55));
        cv.circle(s, 6.5, color);
        cv.circle(s, 2.5, [255, 255, 255]);
        let tw = text_width(name, 13.0);
        cv.rect_alpha(s.0 + 10.0, s.1 - 20.0, tw + 4.0, 16.0, [255, 255, 255], 0.75);
        cv.text((s.0 + 12.0, s.1 - 20.0), name, 13.0, scale_color(color, 0.7));
    }
    // Legend in the bottom strip, right side.
    if !characters.is_empty() {
        let (w, h) = (cv.width() as f32, cv.height() as f32);
        let (x, y) = (w - 190.0, h - 40.0);
        cv.circle((x, y + 8.0), 6.0, INK);
        cv.text((x + 10.0, y), "start", 13.0, INK);
        cv.rect(x + 55.0, y + 3.0, 10.0, 10.0, INK);
        cv.text((x + 70.0, y), "end of route", 13.0, INK);
    }
    cv.into_image()
}

/// Writes [`top_down_trails`] as PNG (atomic).
pub fn render_top_down_trails(
    path: &Path,
    scene: &Scene,
    cat: &Catalogue,
    characters: &[(&str, &Clip)],
) -> Result<(), ScriptError> {
    super::write_png(path, &top_down_trails(scene, cat, characters))
}
