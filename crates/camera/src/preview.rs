//! Preview GIF of a generated camera: the scene from above (characters with their facing, the whole
//! camera path, keyframes, the camera and its field of view) and a picture-in-picture of what the
//! camera sees (stick torsos and heads projected through the generated pose).

use crate::dataset::Scene;
use crate::infer::GeneratedTrack;
use glam::{DVec2, DVec3};
use inbetween_render::Canvas;

const W: u32 = 480;
const H: u32 = 360;
const PIP_W: u32 = 192;
const PIP_H: u32 = 108;
/// Height of the top-down map (above the picture-in-picture).
const MAP_H: f64 = (H - PIP_H) as f64 - 46.0;
const BG: [u8; 3] = [250, 250, 247];
const PATH: [u8; 3] = [120, 150, 210];
const CAM: [u8; 3] = [200, 40, 40];
const KEY: [u8; 3] = [230, 120, 0];
const CHAR: [[u8; 3]; 2] = [[30, 110, 60], [120, 60, 160]];

/// Ground (x, z) → pixel mapping that fits every character and camera position.
struct TopDown {
    centre: DVec2,
    scale: f64,
}

impl TopDown {
    fn fit(points: impl Iterator<Item = DVec2>) -> TopDown {
        let (mut lo, mut hi) = (DVec2::splat(f64::MAX), DVec2::splat(f64::MIN));
        for p in points {
            lo = lo.min(p);
            hi = hi.max(p);
        }
        let span = (hi - lo).max(DVec2::splat(1.0));
        let scale = ((W as f64 - 40.0) / span.x).min(MAP_H / span.y);
        TopDown { centre: (lo + hi) * 0.5, scale }
    }

    fn px(&self, p: DVec3) -> (f32, f32) {
        let d = DVec2::new(p.x, p.z) - self.centre;
        ((W as f64 * 0.5 + d.x * self.scale) as f32, (28.0 + MAP_H * 0.5 + d.y * self.scale) as f32)
    }
}

/// What the camera sees at one frame (picture-in-picture).
fn camera_view(track: &GeneratedTrack, scene: &Scene, i: usize) -> image::RgbImage {
    let f = &track.frames[i];
    let mut c = Canvas::new(PIP_W, PIP_H, [235, 238, 245]);
    let lens = &track.lens;
    let to_px = |p: DVec2| ((p.x + 1.0) * 0.5 * PIP_W as f64, (1.0 - p.y) * 0.5 * PIP_H as f64);
    // Ground grid for a sense of motion.
    for k in -10..=10 {
        for (a, b) in [
            (DVec3::new(k as f64, 0.0, -10.0), DVec3::new(k as f64, 0.0, 10.0)),
            (DVec3::new(-10.0, 0.0, k as f64), DVec3::new(10.0, 0.0, k as f64)),
        ] {
            let centre = DVec3::new(f.pose.position.x.round(), 0.0, f.pose.position.z.round());
            if let (Some(pa), Some(pb)) = (f.pose.project(lens, a + centre), f.pose.project(lens, b + centre)) {
                let (pa, pb) = (to_px(pa), to_px(pb));
                c.line((pa.0 as f32, pa.1 as f32), (pb.0 as f32, pb.1 as f32), [205, 208, 215], 1.0);
            }
        }
    }
    for (ci, ch) in scene.characters.iter().enumerate() {
        let fr = ch.frame(f.frame);
        let col = CHAR[ci % 2];
        let mid = (fr.shoulder_l + fr.shoulder_r) * 0.5;
        let foot = DVec3::new(fr.root.x, 0.0, fr.root.z);
        let segs = [(foot, fr.root), (fr.root, mid), (fr.shoulder_l, fr.shoulder_r)];
        for (a, b) in segs {
            if let (Some(pa), Some(pb)) = (f.pose.project(lens, a), f.pose.project(lens, b)) {
                let (pa, pb) = (to_px(pa), to_px(pb));
                c.line((pa.0 as f32, pa.1 as f32), (pb.0 as f32, pb.1 as f32), col, 2.5);
            }
        }
        if let Some(p) = f.pose.project(lens, fr.target()) {
            let p = to_px(p);
            c.circle((p.0 as f32, p.1 as f32), 4.0, col);
        }
    }
    c.into_image()
}

/// One GIF frame per `stride` frames of the track.
pub fn render_frames(track: &GeneratedTrack, scene: &Scene, stride: usize) -> Vec<image::RgbImage> {
    let pts = track.frames.iter().flat_map(|f| {
        let c = &scene.characters;
        [f.pose.position, c[f.targets[0]].root[f.frame], c[f.targets[1]].root[f.frame]].map(|p| DVec2::new(p.x, p.z))
    });
    let map = TopDown::fit(pts);
    let path: Vec<(f32, f32)> = track.frames.iter().map(|f| map.px(f.pose.position)).collect();
    let keys: Vec<usize> =
        track.key_residuals.iter().filter_map(|k| track.frames.iter().position(|f| f.frame == k.frame)).collect();
    let mut out = Vec::new();
    for i in (0..track.frames.len()).step_by(stride.max(1)) {
        let f = &track.frames[i];
        let mut c = Canvas::new(W, H, BG);
        for w in path.windows(2) {
            c.line(w[0], w[1], PATH, 1.5);
        }
        for &k in &keys {
            c.circle(path[k], 4.0, KEY);
        }
        for (ci, ch) in scene.characters.iter().enumerate() {
            let fr = ch.frame(f.frame);
            let p = map.px(fr.root);
            let front = fr.front();
            let tip = map.px(fr.root + front * 0.6);
            c.circle(p, 6.0, CHAR[ci % 2]);
            c.line(p, tip, CHAR[ci % 2], 2.0);
            c.text((p.0 + 7.0, p.1 - 16.0), &ch.name, 13.0, CHAR[ci % 2]);
        }
        // Camera and the horizontal edges of its view.
        let cam = map.px(f.pose.position);
        let half = (track.lens.fovy * 0.5).tan() * track.lens.aspect;
        for side in [-1.0, 1.0] {
            let dir = f.pose.rotation * DVec3::new(side * half, 0.0, -1.0).normalize();
            c.line(cam, map.px(f.pose.position + dir * 1.5), CAM, 1.5);
        }
        c.circle(cam, 5.0, CAM);
        c.text((8.0, 6.0), &format!("{}  frame {}", track.style, f.frame), 14.0, [40, 40, 40]);
        let view = camera_view(track, scene, i);
        c.rect((W - PIP_W - 10) as f32, (H - PIP_H - 10) as f32, (PIP_W + 4) as f32, (PIP_H + 4) as f32, [60, 60, 60]);
        c.blit(&view, (W - PIP_W - 8) as i64, (H - PIP_H - 8) as i64);
        out.push(c.into_image());
    }
    out
}

/// Writes the preview GIF (every `stride`-th frame, played at the matching rate).
pub fn write_preview(
    path: &std::path::Path,
    track: &GeneratedTrack,
    scene: &Scene,
    stride: usize,
) -> Result<(), crate::CameraError> {
    let frames = render_frames(track, scene, stride);
    inbetween_render::write_gif(path, &frames, track.fps / stride.max(1) as f64)
        .map_err(|e| crate::CameraError::invalid(path, e.to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn preview_shows_characters_in_both_views() {
        let scene = Scene::procedural(3, 90, 30.0);
        let device = inbetween_nn::backend::cpu();
        let cfg = crate::model::ModelConfig { hidden: 8, tta_dim: 8, ..Default::default() };
        let model = crate::infer::FastModel::from_burn(&cfg.init(&device), cfg);
        let keys = crate::infer::example_keys(&scene, &[0, 89]);
        let style = crate::infer::Style { name: "t".into(), code: vec![0.0; 4] };
        let track = crate::infer::GenerateJob::new(&model, &scene, &keys, &style).run().unwrap();
        let frames = render_frames(&track, &scene, 30);
        assert_eq!(frames.len(), 3);
        let img = &frames[1];
        let is_char = |p: &image::Rgb<u8>| CHAR.contains(&p.0);
        let in_pip = |x: u32, y: u32| x >= W - PIP_W - 8 && y >= H - PIP_H - 8;
        let top = img.enumerate_pixels().filter(|(x, y, p)| !in_pip(*x, *y) && is_char(p)).count();
        let pip = img.enumerate_pixels().filter(|(x, y, p)| in_pip(*x, *y) && is_char(p)).count();
        assert!(top > 50 && pip > 20, "character pixels: top-down {top}, camera view {pip}");
        if let Some(dir) = std::env::var_os("CAMERA_PREVIEW_PNG") {
            inbetween_render::write_png(&std::path::Path::new(&dir).join("preview.png"), img).unwrap();
        }
    }
}
