//! Stick figures: bones as lines, joints and end sites as dots, several figures overlaid in different
//! colours over a ground grid, seen through a perspective camera that frames every frame of every
//! figure automatically.

use crate::canvas::{text_width, Camera3, Canvas};
use crate::RenderError;
use glam::DVec3;
use image::RgbImage;
use inbetween_core::{forward_clip, Motion};
use rayon::prelude::*;
use std::path::Path;

/// Figure colours used when [`StickOptions::colors`] has fewer entries than there are figures
/// (blue, red, green, orange, purple, cyan: distinct for colour-blind viewers in the first two).
pub const DEFAULT_COLORS: [[u8; 3]; 6] =
    [[31, 119, 180], [214, 39, 40], [44, 160, 44], [255, 127, 14], [148, 103, 189], [23, 190, 207]];

/// How to draw stick figures.
#[derive(Clone, Debug)]
pub struct StickOptions {
    pub width: u32,
    pub height: u32,
    /// GIF frame rate. None plays every source frame at the clip's own rate; either way frames are
    /// skipped evenly so that playback stays real-time and at most `max_frames` frames are written.
    pub fps: Option<f64>,
    /// Upper bound on GIF frames (keeps files small).
    pub max_frames: usize,
    /// One colour per figure, in order; missing entries come from [`DEFAULT_COLORS`].
    pub colors: Vec<[u8; 3]>,
    pub background: [u8; 3],
    /// None: auto-framed 3/4 front-side view from slightly above that fits all frames of all figures.
    pub camera: Option<Camera3>,
    /// Draw the ground grid (at the lowest point any figure reaches) and the figures' shadows.
    pub grid: bool,
    /// Legend names, one per figure (e.g. "original", "reconstructed"); empty shows no legend.
    pub labels: Vec<String>,
    pub title: Option<String>,
    /// Print "frame i / n" and the time in the bottom-left corner.
    pub show_frame_number: bool,
    /// Source frame rate of raw joint positions given to [`render_positions_gif`] (a Motion knows its own).
    pub positions_fps: f64,
}

impl Default for StickOptions {
    fn default() -> Self {
        StickOptions {
            width: 480,
            height: 360,
            fps: None,
            max_frames: 150,
            colors: Vec::new(),
            background: [250, 250, 247],
            camera: None,
            grid: true,
            labels: Vec::new(),
            title: None,
            show_frame_number: true,
            positions_fps: 30.0,
        }
    }
}

impl StickOptions {
    /// Colour of figure `i`.
    pub fn color(&self, i: usize) -> [u8; 3] {
        self.colors.get(i).copied().unwrap_or(DEFAULT_COLORS[i % DEFAULT_COLORS.len()])
    }
}

/// One figure's points over time: joints plus end sites, each point with its parent (None for roots).
#[derive(Clone, Debug)]
struct Figure {
    parents: Vec<Option<usize>>,
    frames: Vec<Vec<DVec3>>,
    fps: f64,
    /// Facing direction on the ground at the first frame, when known.
    heading: Option<DVec3>,
}

impl Figure {
    fn from_motion(m: &Motion) -> Figure {
        let sk = &m.skeleton;
        let mut parents: Vec<Option<usize>> = sk.joints().iter().map(|j| j.parent).collect();
        let ends: Vec<usize> = (0..sk.len()).filter(|&j| sk.joint(j).end_site.is_some()).collect();
        parents.extend(ends.iter().map(|&j| Some(j)));
        let globals = forward_clip(m);
        let heading = globals.first().map(|g| g.rotations[0] * DVec3::Z);
        let frames = globals
            .iter()
            .map(|g| {
                let mut pts = g.positions.clone();
                pts.extend(ends.iter().map(|&j| g.end_site(sk, j).expect("joint has an end site")));
                pts
            })
            .collect();
        Figure { parents, frames, fps: m.fps(), heading: heading.map(|h| DVec3::new(h.x, 0.0, h.z)) }
    }

    fn duration(&self) -> f64 {
        self.frames.len().saturating_sub(1) as f64 / self.fps
    }

    /// The frame shown at time `t` seconds (held at the last frame once the clip ends).
    fn frame_at(&self, t: f64) -> usize {
        ((t * self.fps).round().max(0.0) as usize).min(self.frames.len().saturating_sub(1))
    }
}

/// Checks raw positions and turns them into figures.
fn figures_from_positions(
    parents: &[Option<usize>],
    figures: &[Vec<Vec<DVec3>>],
    fps: f64,
) -> Result<Vec<Figure>, RenderError> {
    if figures.is_empty() {
        return Err(RenderError::InvalidInput("no figures to draw".into()));
    }
    if !(fps.is_finite() && fps > 0.0) {
        return Err(RenderError::InvalidInput(format!("positions_fps {fps} must be a positive number")));
    }
    if let Some((j, p)) =
        parents.iter().enumerate().find_map(|(j, p)| p.filter(|&p| p >= parents.len()).map(|p| (j, p)))
    {
        return Err(RenderError::InvalidInput(format!(
            "joint {j} has parent {p}, but there are only {} joints",
            parents.len()
        )));
    }
    for (fi, fig) in figures.iter().enumerate() {
        if fig.is_empty() {
            return Err(RenderError::InvalidInput(format!("figure {fi} has no frames")));
        }
        for (f, pts) in fig.iter().enumerate() {
            if pts.len() != parents.len() {
                return Err(RenderError::InvalidInput(format!(
                    "figure {fi}, frame {f}: {} joint positions, expected {} (one per parent entry)",
                    pts.len(),
                    parents.len()
                )));
            }
            if let Some(j) = pts.iter().position(|p| !p.is_finite()) {
                return Err(RenderError::InvalidInput(format!(
                    "figure {fi}, frame {f}, joint {j}: position is not finite"
                )));
            }
        }
    }
    Ok(figures.iter().map(|fr| Figure { parents: parents.to_vec(), frames: fr.clone(), fps, heading: None }).collect())
}

fn figures_from_motions(motions: &[&Motion]) -> Result<Vec<Figure>, RenderError> {
    if motions.is_empty() {
        return Err(RenderError::InvalidInput("no motions to draw".into()));
    }
    if let Some(i) = motions.iter().position(|m| m.num_frames() == 0) {
        return Err(RenderError::InvalidInput(format!("motion {i} has no frames")));
    }
    Ok(motions.iter().map(|m| Figure::from_motion(m)).collect())
}

/// Everything that stays the same from frame to frame.
struct Scene {
    cam: Camera3,
    ground_y: f64,
    /// Background, grid, title and legend, drawn once.
    base: RgbImage,
    line_width: f32,
    /// Distance from the eye to the framing target, for perspective line widths.
    ref_depth: f32,
}

/// At most this many frames per figure are looked at when framing the camera.
const FRAMING_SAMPLES: usize = 400;

fn sample_points(figs: &[Figure]) -> Vec<DVec3> {
    figs.iter()
        .flat_map(|f| {
            let step = f.frames.len().div_ceil(FRAMING_SAMPLES).max(1);
            f.frames.iter().step_by(step).chain(f.frames.last()).flatten().copied()
        })
        .collect()
}

fn bounds(points: &[DVec3]) -> (DVec3, DVec3) {
    points
        .iter()
        .fold((DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)), |(lo, hi), &p| (lo.min(p), hi.max(p)))
}

/// Height of the tallest single pose (not the whole path), the scale for grid spacing.
fn figure_height(figs: &[Figure]) -> f64 {
    figs.iter()
        .flat_map(|f| f.frames.iter().step_by(f.frames.len().div_ceil(50).max(1)))
        .map(|pts| {
            let (lo, hi) = bounds(pts);
            (hi - lo).max_element()
        })
        .fold(0.0, f64::max)
        .max(1e-6)
}

/// The ground direction the view looks from: the first figure's facing, else its direction of
/// travel, else +Z (the CMU rest-pose facing).
fn view_heading(figs: &[Figure], height: f64) -> DVec3 {
    let f = &figs[0];
    let travel = f.frames.last().map(|l| l[0] - f.frames[0][0]).map(|d| DVec3::new(d.x, 0.0, d.z));
    f.heading
        .filter(|h| h.length() > 1e-3)
        .or(travel.filter(|d| d.length() > 0.5 * height))
        .map(|h| h.normalize())
        .unwrap_or(DVec3::Z)
}

/// Vertical field of view of the automatic camera, degrees.
const AUTO_FOV_Y: f64 = 35.0;
/// View direction: this many degrees off the figure's front, and this many above the ground.
const AUTO_AZIMUTH: f64 = 55.0;
const AUTO_ELEVATION: f64 = 14.0;
/// Fraction of the image the framed points may fill.
const FILL: f64 = 0.86;

/// A camera looking along the 3/4 front-side direction whose distance and aim make every point fit
/// between `top` and `height - bottom` pixels (bands kept free for the title, legend and caption).
/// The eye distance is exact: a point p (relative to the target) with screen offsets x, y and
/// depth D − p·d fits when |x| ≤ tx·(D − p·d), so D = max(|x|/tx, |y|/ty) + p·d over all points.
pub fn auto_camera(points: &[DVec3], heading: DVec3, width: u32, height: u32, top: f64, bottom: f64) -> Camera3 {
    let (lo, hi) = bounds(points);
    let side = DVec3::Y.cross(heading).normalize_or(DVec3::X);
    let (az, el) = (AUTO_AZIMUTH.to_radians(), AUTO_ELEVATION.to_radians());
    let to_eye = (heading * az.cos() + side * az.sin()) * el.cos() + DVec3::Y * el.sin();
    let (w, h) = (width as f64, height.max(1) as f64);
    let avail = (h - top - bottom).max(h * 0.3);
    let half_tan = (AUTO_FOV_Y.to_radians() * 0.5).tan();
    let ty = half_tan * FILL * avail / h;
    let tx = half_tan * FILL * w / h;
    // Where the centre of the framed points should land on screen.
    let (want_x, want_y) = (w * 0.5, top + avail * 0.5);
    let mut target = (lo + hi) * 0.5;
    // Coincident points fit at any distance; keep the eye well beyond the near plane.
    let min_dist = ((hi - lo).length() * 0.5).max(1.0);
    let mut cam = Camera3::new(target + to_eye * min_dist, target, DVec3::Y, AUTO_FOV_Y).with_viewport(width, height);
    for _ in 0..4 {
        let (right, up, _) = cam.basis();
        let dist = points
            .iter()
            .map(|&p| {
                let q = p - target;
                (q.dot(right).abs() / tx).max(q.dot(up).abs() / ty) + q.dot(to_eye)
            })
            .fold(f64::MIN, f64::max);
        let dist = if dist > 1e-9 { dist } else { min_dist };
        cam = Camera3::new(target + to_eye * dist, target, DVec3::Y, AUTO_FOV_Y).with_viewport(width, height);
        // Re-aim so that the projected bounding box is centred in the free area.
        let proj: Vec<(f32, f32, f32)> = points.iter().filter_map(|&p| cam.project(p)).collect();
        if proj.is_empty() {
            break;
        }
        let (x0, x1) = proj.iter().fold((f32::MAX, f32::MIN), |(a, b), p| (a.min(p.0), b.max(p.0)));
        let (y0, y1) = proj.iter().fold((f32::MAX, f32::MIN), |(a, b), p| (a.min(p.1), b.max(p.1)));
        let (dx, dy) = ((x0 + x1) as f64 * 0.5 - want_x, (y0 + y1) as f64 * 0.5 - want_y);
        let px_to_world = dist / cam.focal_px();
        target += right * dx * px_to_world - up * dy * px_to_world;
    }
    cam
}

/// A "nice" grid step (1, 2 or 5 × 10^k) near `approx`.
fn nice_step(approx: f64) -> f64 {
    let mag = 10f64.powf(approx.log10().floor());
    let r = approx / mag;
    mag * if r < 1.5 {
        1.0
    } else if r < 3.5 {
        2.0
    } else if r < 7.5 {
        5.0
    } else {
        10.0
    }
}

const GRID_COLOR: [u8; 3] = [196, 200, 206];
const TEXT_COLOR: [u8; 3] = [40, 40, 40];
/// Most grid lines along one axis.
const MAX_GRID_LINES: usize = 60;

fn draw_grid(canvas: &mut Canvas, cam: &Camera3, points: &[DVec3], ground_y: f64, fig_height: f64) {
    let (lo, hi) = bounds(points);
    let pad = fig_height * 0.4;
    let extent = (hi.x - lo.x).max(hi.z - lo.z) + 2.0 * pad;
    let mut step = nice_step(fig_height / 3.0);
    while extent / step > MAX_GRID_LINES as f64 {
        step = nice_step(step * 2.1);
    }
    let (x0, x1) = (((lo.x - pad) / step).floor() * step, ((hi.x + pad) / step).ceil() * step);
    let (z0, z1) = (((lo.z - pad) / step).floor() * step, ((hi.z + pad) / step).ceil() * step);
    let mut lines = Vec::new();
    let mut x = x0;
    while x <= x1 + 1e-9 {
        lines.push((DVec3::new(x, ground_y, z0), DVec3::new(x, ground_y, z1)));
        x += step;
    }
    let mut z = z0;
    while z <= z1 + 1e-9 {
        lines.push((DVec3::new(x0, ground_y, z), DVec3::new(x1, ground_y, z)));
        z += step;
    }
    for (a, b) in lines {
        if let Some((pa, pb)) = cam.project_segment(a, b) {
            canvas.line((pa.0, pa.1), (pb.0, pb.1), GRID_COLOR, 1.2);
        }
    }
}

fn text_size(opts: &StickOptions) -> f32 {
    (opts.height as f32 / 24.0).clamp(10.0, 28.0)
}

/// Where the title and legend go: the title at the top left, the legend box at the top right, or
/// below the title when both do not fit side by side.
struct Header {
    size: f32,
    pad: f32,
    /// Legend box: x, y, width, height (None without labels).
    legend: Option<(f32, f32, f32, f32)>,
    /// Pixels at the top that figures keep clear of.
    height: f32,
}

fn header(opts: &StickOptions, figure_count: usize) -> Header {
    let size = text_size(opts);
    let pad = size * 0.5;
    let title_w = opts.title.as_deref().map_or(0.0, |t| text_width(t, size * 1.1) + pad);
    let title_h = if opts.title.is_some() { size * 1.9 } else { 0.0 };
    let labels = &opts.labels[..opts.labels.len().min(figure_count)];
    if labels.is_empty() {
        return Header { size, pad, legend: None, height: title_h };
    }
    let swatch = size * 0.9;
    let box_w = labels.iter().map(|l| text_width(l, size)).fold(0.0, f32::max) + swatch + 3.0 * pad;
    let box_h = labels.len() as f32 * size * 1.35 + pad;
    let side_by_side = title_w + box_w + 2.0 * pad <= opts.width as f32;
    let y = if side_by_side { pad } else { title_h };
    Header {
        size,
        pad,
        legend: Some((opts.width as f32 - box_w - pad, y, box_w, box_h)),
        height: title_h.max(y + box_h + pad),
    }
}

/// Pixel heights of the bands at the top (title, legend) and bottom (caption) that figures keep clear of.
fn reserved_bands(opts: &StickOptions, figure_count: usize) -> (f64, f64) {
    let caption = if opts.show_frame_number { text_size(opts) * 1.8 } else { 0.0 };
    (header(opts, figure_count).height as f64, caption as f64)
}

fn draw_title_and_legend(canvas: &mut Canvas, opts: &StickOptions, figure_count: usize) {
    let Header { size, pad, legend, .. } = header(opts, figure_count);
    if let Some(title) = &opts.title {
        canvas.text((pad, pad * 0.6), title, size * 1.1, TEXT_COLOR);
    }
    let Some((x, y0, box_w, box_h)) = legend else { return };
    let swatch = size * 0.9;
    canvas.rect_alpha(x, y0, box_w, box_h, [255, 255, 255], 0.8);
    for (i, label) in opts.labels.iter().take(figure_count).enumerate() {
        let y = y0 + pad * 0.5 + i as f32 * size * 1.35;
        canvas.rect(x + pad, y + (size * 1.3 - swatch) * 0.5, swatch, swatch, opts.color(i));
        canvas.text((x + 2.0 * pad + swatch, y), label, size, TEXT_COLOR);
    }
}

fn build_scene(figs: &[Figure], opts: &StickOptions) -> Result<Scene, RenderError> {
    if opts.width < 16 || opts.height < 16 || opts.width > 8192 || opts.height > 8192 {
        return Err(RenderError::InvalidInput(format!(
            "image size {}×{} must be between 16 and 8192 pixels per side",
            opts.width, opts.height
        )));
    }
    let points = sample_points(figs);
    let fig_height = figure_height(figs);
    let ground_y = bounds(&points).0.y;
    let cam = match opts.camera {
        Some(c) => c.with_viewport(opts.width, opts.height),
        None => {
            let (top, bottom) = reserved_bands(opts, figs.len());
            auto_camera(&points, view_heading(figs, fig_height), opts.width, opts.height, top, bottom)
        }
    };
    let mut canvas = Canvas::new(opts.width, opts.height, opts.background);
    if opts.grid {
        draw_grid(&mut canvas, &cam, &points, ground_y, fig_height);
    }
    draw_title_and_legend(&mut canvas, opts, figs.len());
    let ref_depth = (cam.target - cam.eye).length() as f32;
    Ok(Scene {
        cam,
        ground_y,
        base: canvas.into_image(),
        line_width: (opts.height as f32 / 110.0).clamp(1.5, 8.0),
        ref_depth,
    })
}

/// Colour `c` mixed toward black by `amount` (0…1).
fn darken(c: [u8; 3], amount: f32) -> [u8; 3] {
    c.map(|v| (v as f32 * (1.0 - amount)).round() as u8)
}

fn shadow_color(bg: [u8; 3]) -> [u8; 3] {
    darken(bg, 0.13)
}

/// Something to draw, sorted back to front by depth.
enum Prim {
    Bone { a: (f32, f32), b: (f32, f32), width: f32, color: [u8; 3] },
    Dot { at: (f32, f32), radius: f32, color: [u8; 3] },
}

fn draw_frame(
    scene: &Scene,
    figs: &[Figure],
    frames: &[usize],
    opts: &StickOptions,
    caption: Option<&str>,
) -> RgbImage {
    let mut canvas = Canvas::from_image(scene.base.clone());
    let cam = &scene.cam;
    let persp = |depth: f32| (scene.ref_depth / depth.max(1e-6)).clamp(0.6, 1.7);
    if opts.grid {
        let shadow = shadow_color(opts.background);
        let flat = |p: DVec3| DVec3::new(p.x, scene.ground_y, p.z);
        for (fig, &f) in figs.iter().zip(frames) {
            let pts = &fig.frames[f];
            for (j, parent) in fig.parents.iter().enumerate() {
                if let Some((a, b)) = parent.and_then(|p| cam.project_segment(flat(pts[p]), flat(pts[j]))) {
                    canvas.line((a.0, a.1), (b.0, b.1), shadow, scene.line_width * 1.6 * persp((a.2 + b.2) * 0.5));
                }
            }
        }
    }
    let mut prims: Vec<(f32, Prim)> = Vec::new();
    for (i, (fig, &f)) in figs.iter().zip(frames).enumerate() {
        let color = opts.color(i);
        // Overlaid figures that coincide (a clip and its reconstruction) would otherwise swap
        // places bone by bone on rounding noise; a small bias keeps later figures on top.
        let layer_bias = i as f32 * scene.ref_depth * 2e-3;
        let pts = &fig.frames[f];
        for (j, parent) in fig.parents.iter().enumerate() {
            if let Some((a, b)) = parent.and_then(|p| cam.project_segment(pts[p], pts[j])) {
                let depth = (a.2 + b.2) * 0.5;
                prims.push((
                    depth - layer_bias,
                    Prim::Bone { a: (a.0, a.1), b: (b.0, b.1), width: scene.line_width * persp(depth), color },
                ));
            }
            if let Some((x, y, depth)) = cam.project(pts[j]) {
                let full = scene.line_width * 0.95 * persp(depth);
                // Joints at the end of short bones (fingers, toes) get small dots, so hands stay
                // hands instead of blobs.
                let bone_px =
                    parent.and_then(|p| cam.project(pts[p])).map(|q| ((q.0 - x).powi(2) + (q.1 - y).powi(2)).sqrt());
                let radius = bone_px.map_or(full, |l| full * (l / (4.0 * full)).clamp(0.3, 1.0));
                // Dots sit just in front of the bones that meet at them.
                prims.push((depth * 0.999 - layer_bias, Prim::Dot { at: (x, y), radius, color: darken(color, 0.35) }));
            }
        }
    }
    prims.sort_by(|a, b| b.0.total_cmp(&a.0));
    for (_, p) in prims {
        match p {
            Prim::Bone { a, b, width, color } => canvas.line(a, b, color, width),
            Prim::Dot { at, radius, color } => canvas.circle(at, radius, color),
        }
    }
    if let Some(c) = caption {
        let size = text_size(opts);
        canvas.text((size * 0.5, opts.height as f32 - size * 1.6), c, size, TEXT_COLOR);
    }
    canvas.into_image()
}

/// Fastest GIF frame rate that plays at its nominal speed (2 cs per frame).
const MAX_GIF_FPS: f64 = 50.0;

/// The GIF timeline: for each GIF frame, the frame of every figure, plus the GIF frame rate.
/// Time follows the first figure's rate; the animation lasts as long as the longest figure.
fn timeline(figs: &[Figure], opts: &StickOptions) -> Result<(Vec<Vec<usize>>, f64), RenderError> {
    let base_fps = figs[0].fps;
    let wanted = opts.fps.unwrap_or(base_fps);
    if !(wanted.is_finite() && wanted > 0.0) {
        return Err(RenderError::InvalidInput(format!("GIF frame rate {wanted} must be a positive number")));
    }
    if opts.max_frames == 0 {
        return Err(RenderError::InvalidInput("max_frames must be at least 1".into()));
    }
    let duration = figs.iter().map(Figure::duration).fold(0.0, f64::max);
    let source_frames = (duration * base_fps).round() as usize + 1;
    let mut step = (base_fps / wanted).round().max(1.0) as usize;
    // GIF delays are whole hundredths of a second and viewers slow anything under 2 cs down, so
    // faster sources are stepped to at most 50 frames per second to keep playback real-time.
    step = step.max((base_fps / MAX_GIF_FPS - 1e-9).ceil() as usize);
    step = step.max(source_frames.div_ceil(opts.max_frames));
    let frames = (0..source_frames)
        .step_by(step)
        .map(|k| {
            let t = k as f64 / base_fps;
            figs.iter().map(|f| f.frame_at(t)).collect()
        })
        .collect();
    Ok((frames, base_fps / step as f64))
}

fn caption(opts: &StickOptions, figs: &[Figure], frame: usize) -> Option<String> {
    opts.show_frame_number.then(|| {
        let f = &figs[0];
        format!("frame {} / {}   {:.2} s", frame, f.frames.len() - 1, frame as f64 / f.fps)
    })
}

fn render_gif(
    path: &Path,
    figs: &[Figure],
    opts: &StickOptions,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<(), RenderError> {
    let scene = build_scene(figs, opts)?;
    let (frames, gif_fps) = timeline(figs, opts)?;
    let images: Vec<RgbImage> = frames
        .par_iter()
        .map(|idx| draw_frame(&scene, figs, idx, opts, caption(opts, figs, idx[0]).as_deref()))
        .collect();
    crate::write_gif_with_progress(path, &images, gif_fps, progress)
}

/// Frame `frame` of the first motion (the others at the same time) as an image. Bad input (a
/// frame past the end, an empty motion list, a zero size) gives a blank background image;
/// [`try_render_motion_frame`] says what was wrong.
pub fn render_motion_frame(motions: &[&Motion], frame: usize, opts: &StickOptions) -> RgbImage {
    try_render_motion_frame(motions, frame, opts)
        .unwrap_or_else(|_| Canvas::new(opts.width.max(1), opts.height.max(1), opts.background).into_image())
}

/// Like [`render_motion_frame`], but reports bad input (no motions, frame out of range, bad size).
pub fn try_render_motion_frame(
    motions: &[&Motion],
    frame: usize,
    opts: &StickOptions,
) -> Result<RgbImage, RenderError> {
    let figs = figures_from_motions(motions)?;
    render_figures_frame(&figs, frame, opts)
}

fn render_figures_frame(figs: &[Figure], frame: usize, opts: &StickOptions) -> Result<RgbImage, RenderError> {
    let n = figs[0].frames.len();
    if frame >= n {
        return Err(RenderError::InvalidInput(format!(
            "frame {frame} is out of range: the clip has {n} frames (0…{})",
            n - 1
        )));
    }
    let scene = build_scene(figs, opts)?;
    let t = frame as f64 / figs[0].fps;
    let idx: Vec<usize> = figs.iter().map(|f| f.frame_at(t)).collect();
    Ok(draw_frame(&scene, figs, &idx, opts, caption(opts, figs, frame).as_deref()))
}

/// Writes frame `frame` as a PNG.
pub fn render_motion_png(
    path: &Path,
    motions: &[&Motion],
    frame: usize,
    opts: &StickOptions,
) -> Result<(), RenderError> {
    crate::write_png(path, &try_render_motion_frame(motions, frame, opts)?)
}

/// Writes an animated GIF of all motions overlaid (one colour each), real-time playback.
pub fn render_motion_gif(path: &Path, motions: &[&Motion], opts: &StickOptions) -> Result<(), RenderError> {
    render_motion_gif_with_progress(path, motions, opts, &mut |_, _| {})
}

/// [`render_motion_gif`] reporting `(frames_encoded, total)` as it goes.
pub fn render_motion_gif_with_progress(
    path: &Path,
    motions: &[&Motion],
    opts: &StickOptions,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<(), RenderError> {
    render_gif(path, &figures_from_motions(motions)?, opts, progress)
}

/// Animated GIF of raw joint positions (`figures[figure][frame][joint]`, all with the same
/// hierarchy `parents`), sampled at `opts.positions_fps`.
pub fn render_positions_gif(
    path: &Path,
    parents: &[Option<usize>],
    figures: &[Vec<Vec<DVec3>>],
    opts: &StickOptions,
) -> Result<(), RenderError> {
    render_gif(path, &figures_from_positions(parents, figures, opts.positions_fps)?, opts, &mut |_, _| {})
}

/// One frame of raw joint positions as an image.
pub fn render_positions_frame(
    parents: &[Option<usize>],
    figures: &[Vec<Vec<DVec3>>],
    frame: usize,
    opts: &StickOptions,
) -> Result<RgbImage, RenderError> {
    render_figures_frame(&figures_from_positions(parents, figures, opts.positions_fps)?, frame, opts)
}

/// Writes one frame of raw joint positions as a PNG.
pub fn render_positions_png(
    path: &Path,
    parents: &[Option<usize>],
    figures: &[Vec<Vec<DVec3>>],
    frame: usize,
    opts: &StickOptions,
) -> Result<(), RenderError> {
    crate::write_png(path, &render_positions_frame(parents, figures, frame, opts)?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use image::AnimationDecoder;
    use inbetween_core::procedural::{gait, GaitParams};

    fn walk(frames: usize) -> Motion {
        gait(&GaitParams { frames, ..GaitParams::walk() })
    }

    fn count_near(img: &RgbImage, color: [u8; 3], tol: i32, region: (u32, u32, u32, u32)) -> usize {
        let (x0, y0, x1, y1) = region;
        img.enumerate_pixels()
            .filter(|(x, y, p)| {
                *x >= x0
                    && *x < x1
                    && *y >= y0
                    && *y < y1
                    && p.0.iter().zip(color).all(|(&a, b)| (a as i32 - b as i32).abs() <= tol)
            })
            .count()
    }

    #[test]
    fn frame_shows_both_figures_the_grid_and_fits_the_image() {
        let a = walk(60);
        let b = gait(&GaitParams { frames: 60, ..GaitParams::walk().jittered(3, 0.3) });
        let opts = StickOptions { labels: vec!["original".into(), "other".into()], ..StickOptions::default() };
        let img = render_motion_frame(&[&a, &b], 30, &opts);
        assert_eq!(img.dimensions(), (480, 360));
        let whole = (0, 0, 480, 360);
        let blue = count_near(&img, DEFAULT_COLORS[0], 2, whole);
        let red = count_near(&img, DEFAULT_COLORS[1], 2, whole);
        assert!(blue > 150 && red > 150, "figure pixels: blue {blue}, red {red}");
        // The figures lie inside the image, away from the borders (not cut off).
        let border = 8;
        let inner = (border, border, 480 - border, 360 - border);
        let blue_inner = count_near(&img, DEFAULT_COLORS[0], 2, inner);
        assert!(blue - blue_inner < 30, "blue pixels at the border: {}", blue - blue_inner);
        // The ground grid shows in the lower half.
        let grid = count_near(&img, GRID_COLOR, 3, (0, 180, 480, 360));
        assert!(grid > 300, "grid pixels: {grid}");
    }

    #[test]
    fn single_figure_is_centred_and_large() {
        let m = walk(1);
        let opts = StickOptions { grid: false, show_frame_number: false, ..StickOptions::default() };
        let img = render_motion_frame(&[&m], 0, &opts);
        let c = DEFAULT_COLORS[0];
        let pts: Vec<(u32, u32)> = img
            .enumerate_pixels()
            .filter(|(_, _, p)| p.0.iter().zip(c).all(|(&a, b)| (a as i32 - b as i32).abs() <= 2))
            .map(|(x, y, _)| (x, y))
            .collect();
        let (ymin, ymax) = (pts.iter().map(|p| p.1).min().unwrap(), pts.iter().map(|p| p.1).max().unwrap());
        let (xmin, xmax) = (pts.iter().map(|p| p.0).min().unwrap(), pts.iter().map(|p| p.0).max().unwrap());
        assert!(ymax - ymin > 250, "a standing figure fills most of the height: {ymin}..{ymax}");
        let cx = (xmin + xmax) as f64 / 2.0;
        assert!((cx - 240.0).abs() < 40.0, "horizontally centred: {xmin}..{xmax}");
    }

    #[test]
    fn gif_has_one_frame_per_motion_frame_and_steps_long_clips() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("walk.gif");
        let m = walk(24);
        let opts = StickOptions { width: 160, height: 120, ..StickOptions::default() };
        render_motion_gif(&path, &[&m], &opts).unwrap();
        let decode = |p: &Path| {
            let file = std::io::BufReader::new(std::fs::File::open(p).unwrap());
            image::codecs::gif::GifDecoder::new(file).unwrap().into_frames().collect_frames().unwrap()
        };
        assert_eq!(decode(&path).len(), 24);
        let long = walk(100);
        render_motion_gif(&path, &[&long], &StickOptions { max_frames: 30, ..opts.clone() }).unwrap();
        assert_eq!(decode(&path).len(), 25, "100 frames stepped by 4");
        render_motion_gif(&path, &[&long], &StickOptions { fps: Some(10.0), ..opts.clone() }).unwrap();
        assert_eq!(decode(&path).len(), 34, "30 fps source at 10 fps: every 3rd frame");
        let fast = gait(&GaitParams { frames: 40, fps: 120.0, ..GaitParams::walk() });
        render_motion_gif(&path, &[&fast], &opts).unwrap();
        let frames = decode(&path);
        assert_eq!(frames.len(), 14, "120 fps is stepped by 3 to 40 fps");
        let (num, den) = frames[0].delay().numer_denom_ms();
        assert!((num as f64 / den as f64 - 25.0).abs() <= 10.0, "about 25 ms per frame");
    }

    #[test]
    fn positions_gif_and_bad_positions() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("pos.gif");
        let parents = vec![None, Some(0), Some(1)];
        let frames: Vec<Vec<DVec3>> = (0..10)
            .map(|f| vec![DVec3::ZERO, DVec3::new(0.0, 1.0, 0.0), DVec3::new(f as f64 * 0.1, 2.0, 0.0)])
            .collect();
        let opts = StickOptions { width: 100, height: 80, ..StickOptions::default() };
        render_positions_gif(&path, &parents, &[frames.clone(), frames.clone()], &opts).unwrap();
        assert!(path.exists());
        let mut bad = frames.clone();
        bad[4][2] = DVec3::NAN;
        let err = render_positions_gif(&path, &parents, &[bad], &opts).unwrap_err().to_string();
        assert!(err.contains("frame 4") && err.contains("joint 2"), "{err}");
        let err = render_positions_gif(&path, &parents[..2], &[frames], &opts).unwrap_err().to_string();
        assert!(err.contains("expected 2"), "{err}");
    }

    #[test]
    fn legend_moves_below_a_title_too_long_to_share_the_row() {
        let labels = vec!["original".to_string(), "reconstructed".to_string()];
        let short = StickOptions { title: Some("walk".into()), labels: labels.clone(), ..StickOptions::default() };
        let (_, y, _, _) = header(&short, 2).legend.unwrap();
        assert!(y < 10.0, "short title: legend on the first row");
        let long = StickOptions {
            title: Some("a title long enough to run across most of the image, and then some more".into()),
            labels,
            ..short
        };
        let h = header(&long, 2);
        let (_, y, _, bh) = h.legend.unwrap();
        assert!(y >= text_size(&long) * 1.5, "legend below the title, got y = {y}");
        assert!(h.height >= y + bh, "figures keep clear of the legend");
    }

    #[test]
    fn degenerate_figures_render_without_panicking() {
        let opts = StickOptions { width: 64, height: 48, ..StickOptions::default() };
        // One joint, one frame: a single dot in the middle.
        let img = render_positions_frame(&[None], &[vec![vec![DVec3::new(5.0, 1.0, -2.0)]]], 0, &opts).unwrap();
        let dots = img.pixels().filter(|p| p.0 != opts.background && p.0 != GRID_COLOR).count();
        assert!(dots > 0);
        // All joints at one place, and a huge unit scale.
        let same = vec![vec![DVec3::splat(3.0); 3]; 4];
        render_positions_frame(&[None, Some(0), Some(1)], &[same], 2, &opts).unwrap();
        let far: Vec<Vec<DVec3>> =
            (0..3).map(|f| vec![DVec3::new(1e6, 0.0, f as f64 * 1e5), DVec3::new(1e6, 2e5, 0.0)]).collect();
        render_positions_frame(&[None, Some(0)], &[far], 1, &opts).unwrap();
    }

    #[test]
    fn out_of_range_frame_is_a_clear_error() {
        let m = walk(5);
        let err = try_render_motion_frame(&[&m], 9, &StickOptions::default()).unwrap_err().to_string();
        assert!(err.contains("frame 9") && err.contains("5 frames"), "{err}");
        assert!(try_render_motion_frame(&[], 0, &StickOptions::default()).is_err());
    }
}
