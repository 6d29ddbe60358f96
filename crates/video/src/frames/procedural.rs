//! Procedural test clips, drawn with `inbetween_render::Canvas`, so tests and `inbetween demo` work
//! on a fresh clone with no video files.
//!
//! Each kind exercises a part of the paper: a swinging pendulum repeats its poses (many good
//! transitions for SDPF, §5), a walker has a periodic gait, a slider moves in a straight line over
//! part of the clip (a linear-motion segment, Eq. 11), and the mixed clip has all of that plus a
//! scene cut. The background is a seeded checkerboard of jittered tones: a flat background gives
//! optical flow (§5.2) nothing to lock on to, and the cell corners give it texture. Everything comes
//! from the seed: same seed, same pixels.

use super::{Clip, DEFAULT_FPS};
use image::RgbImage;
use inbetween_core::seed::{derive, rng};
use inbetween_render::Canvas;
use rand::Rng;
use rayon::prelude::*;
use std::f32::consts::PI;
use std::ops::Range;

/// Which procedural motion to draw.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ProceduralKind {
    /// A pendulum swinging from a pivot at the top.
    Pendulum,
    /// A stick figure walking across the frame and back.
    Walker,
    /// A striped block at rest, then moving in a straight line at constant speed, then at rest.
    Slider,
    /// The striped block moving to the right at constant speed over the whole clip: motion with a
    /// known direction, so that a step to the left is a step backwards.
    Drift,
    /// Pendulum plus a ball moving linearly over part of the clip, and a scene cut (another
    /// background) for the last ~15 % of frames.
    Mixed,
}

/// What a procedural clip is known to contain, for tests of cut and linear-motion detection.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ProceduralTruth {
    /// First frame after a scene cut.
    pub cut: Option<usize>,
    /// Frames during which an object moves at constant velocity.
    pub linear: Option<Range<usize>>,
}

/// `video synth`: a procedural clip written to a file.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SynthJob {
    pub kind: ProceduralKind,
    pub frames: usize,
    /// Frame size, pixels.
    pub width: u32,
    pub height: u32,
    pub seed: u64,
}

impl Default for SynthJob {
    /// The mixed clip, 96 frames (3.84 s at 25 fps) of 320×180 pixels, seed 1.
    fn default() -> Self {
        SynthJob { kind: ProceduralKind::Mixed, frames: 96, width: 320, height: 180, seed: 1 }
    }
}

impl SynthJob {
    /// Draws the clip ([`procedural_clip`]) and writes it at `out` (GIF or MP4 by extension);
    /// returns the line saying what was written.
    pub fn write(&self, out: &std::path::Path) -> Result<String, crate::VideoError> {
        let clip = procedural_clip(self.kind, self.frames, self.width, self.height, self.seed);
        super::write_clip(out, &clip)?;
        let (w, h) = (clip.width(), clip.height());
        Ok(format!("wrote {} ({} frames, {w}x{h}, {} fps)", out.display(), clip.len(), clip.fps))
    }
}

/// The cut and linear segment of a `kind` clip of `frames` frames.
pub fn procedural_truth(kind: ProceduralKind, frames: usize) -> ProceduralTruth {
    let at = |f: f32| (frames as f32 * f).round() as usize;
    match kind {
        ProceduralKind::Pendulum | ProceduralKind::Walker => ProceduralTruth { cut: None, linear: None },
        ProceduralKind::Slider => ProceduralTruth { cut: None, linear: Some(at(0.25)..at(0.75)) },
        ProceduralKind::Drift => ProceduralTruth { cut: None, linear: Some(0..frames) },
        ProceduralKind::Mixed => {
            let cut = frames - at(0.15);
            ProceduralTruth { cut: (cut > 0 && cut < frames).then_some(cut), linear: Some(at(0.2)..at(0.6)) }
        }
    }
}

/// Renders `frames` frames of `width`×`height` at 25 fps. `seed` picks colours, texture, phases and
/// speeds; the same arguments always give the same pixels.
pub fn procedural_clip(kind: ProceduralKind, frames: usize, width: u32, height: u32, seed: u64) -> Clip {
    let scene = Scene::new(kind, frames, width, height, seed);
    let images: Vec<RgbImage> = (0..frames).into_par_iter().map(|t| scene.frame(t)).collect();
    Clip { frames: images, fps: DEFAULT_FPS, source: format!("procedural:{kind:?}:{width}x{height}:seed={seed}") }
}

/// Several shots cut together, one after the other (issue 41's clips "with several shots"): shot `i`
/// is a `kinds[i]` clip of `frames_per_shot` frames drawn with its own seed (its own background and
/// colours), every other shot in inverted colours so that each cut is as hard as a change of scene,
/// `width`×`height` at 25 fps.
pub fn multi_shot_clip(kinds: &[ProceduralKind], frames_per_shot: usize, width: u32, height: u32, seed: u64) -> Clip {
    let frames = kinds
        .iter()
        .enumerate()
        .flat_map(|(i, &k)| {
            let mut shot = procedural_clip(k, frames_per_shot, width, height, derive(seed, 100 + i as u64)).frames;
            if i % 2 == 1 {
                shot.iter_mut().for_each(|f| f.pixels_mut().for_each(|p| p.0 = p.0.map(|v| 255 - v)));
            }
            shot
        })
        .collect();
    let names: Vec<String> = kinds.iter().map(|k| format!("{k:?}")).collect();
    Clip {
        frames,
        fps: DEFAULT_FPS,
        source: format!("procedural shots:{}x{frames_per_shot}:{width}x{height}:seed={seed}", names.join("+")),
    }
}

/// Parameters drawn from the seed, and the two backgrounds.
struct Scene {
    kind: ProceduralKind,
    frames: usize,
    w: f32,
    h: f32,
    truth: ProceduralTruth,
    backgrounds: [RgbImage; 2],
    amplitude: f32,
    period: f32,
    phase: f32,
    ink: [u8; 3],
    accent: [u8; 3],
}

/// A seeded checkerboard: two base tones, each cell nudged by one of four seeded steps (few distinct
/// colours, so GIF palettes keep them exact).
fn textured_background(w: u32, h: u32, seed: u64) -> RgbImage {
    let mut r = rng(seed);
    let light: [i32; 3] = [r.random_range(170..215), r.random_range(170..215), r.random_range(170..215)];
    let dark: [i32; 3] = light.map(|c| c - r.random_range(35..55));
    let cell = (w.min(h) / 10).max(4);
    let (cols, rows) = (w.div_ceil(cell), h.div_ceil(cell));
    let steps: Vec<i32> = (0..cols * rows).map(|_| r.random_range(0..4) * 6 - 9).collect();
    RgbImage::from_fn(w, h, |x, y| {
        let (cx, cy) = (x / cell, y / cell);
        let base = if (cx + cy) % 2 == 0 { light } else { dark };
        let s = steps[(cy * cols + cx) as usize];
        image::Rgb(base.map(|c| (c + s).clamp(0, 255) as u8))
    })
}

/// A dark colour for rods, limbs and stripes.
fn dark_colour(r: &mut impl Rng) -> [u8; 3] {
    [r.random_range(20..80), r.random_range(20..80), r.random_range(20..80)]
}

impl Scene {
    fn new(kind: ProceduralKind, frames: usize, width: u32, height: u32, seed: u64) -> Scene {
        let mut r = rng(derive(seed, 1));
        Scene {
            kind,
            frames,
            w: width as f32,
            h: height as f32,
            truth: procedural_truth(kind, frames),
            backgrounds: [
                textured_background(width, height, derive(seed, 2)),
                textured_background(width, height, derive(seed, 3)),
            ],
            amplitude: r.random_range(0.45..0.75),
            period: r.random_range(22.0..34.0),
            phase: r.random_range(0.0..2.0 * PI),
            ink: dark_colour(&mut r),
            accent: [r.random_range(180..240), r.random_range(30..90), r.random_range(30..90)],
        }
    }

    /// The smaller side, the unit for sizes.
    fn unit(&self) -> f32 {
        self.w.min(self.h)
    }

    fn frame(&self, t: usize) -> RgbImage {
        let after_cut = self.truth.cut.is_some_and(|c| t >= c);
        let mut c = Canvas::from_image(self.backgrounds[after_cut as usize].clone());
        match self.kind {
            ProceduralKind::Pendulum => self.pendulum(&mut c, t),
            ProceduralKind::Walker => self.walker(&mut c, t),
            ProceduralKind::Slider | ProceduralKind::Drift => self.slider(&mut c, t),
            ProceduralKind::Mixed => {
                self.pendulum(&mut c, t);
                self.ball(&mut c, t);
            }
        }
        c.into_image()
    }

    /// Position along a segment: 0 before `range`, rising linearly to 1 at its end, 1 after.
    fn progress(&self, t: usize, range: &Range<usize>) -> f32 {
        let span = range.end.saturating_sub(range.start).max(1) as f32;
        ((t as f32 - range.start as f32) / span).clamp(0.0, 1.0)
    }

    /// θ(t) = A sin(2πt/P + φ): a rod from a pivot near the top, a bob with an off-centre mark
    /// (so its rotation is visible to flow).
    fn pendulum(&self, c: &mut Canvas, t: usize) {
        let theta = self.amplitude * (2.0 * PI * t as f32 / self.period + self.phase).sin();
        let pivot = (self.w * 0.5, self.h * 0.1);
        let len = self.h * 0.55;
        let bob = (pivot.0 + len * theta.sin(), pivot.1 + len * theta.cos());
        let r = self.unit() * 0.08;
        c.line(pivot, bob, self.ink, (self.unit() * 0.02).max(1.5));
        c.circle(pivot, (self.unit() * 0.025).max(1.5), self.ink);
        c.circle(bob, r, self.accent);
        let mark = (bob.0 + 0.5 * r * theta.cos(), bob.1 - 0.5 * r * theta.sin());
        c.circle(mark, r * 0.3, self.ink);
    }

    /// A ball crossing the lower part of the frame at constant speed during the linear segment.
    fn ball(&self, c: &mut Canvas, t: usize) {
        let range = self.truth.linear.clone().unwrap_or(0..self.frames);
        let p = self.progress(t, &range);
        let center = (self.w * (0.12 + 0.76 * p), self.h * 0.82);
        c.circle(center, self.unit() * 0.07, self.ink);
        c.circle((center.0 + self.unit() * 0.02, center.1 - self.unit() * 0.02), self.unit() * 0.025, self.accent);
    }

    /// A striped block moving from 15 % to 70 % of the width during the linear segment.
    fn slider(&self, c: &mut Canvas, t: usize) {
        let range = self.truth.linear.clone().unwrap_or(0..self.frames);
        let p = self.progress(t, &range);
        let (bw, bh) = (self.w * 0.15, self.h * 0.3);
        let (x, y) = (self.w * (0.15 + 0.55 * p), self.h * 0.35);
        c.rect(x, y, bw, bh, self.accent);
        let stripes = 4;
        for k in 0..stripes {
            let sx = x + bw * (k as f32 + 0.25) / stripes as f32;
            c.rect(sx, y, bw * 0.12, bh, self.ink);
        }
    }

    /// A side-view stick figure walking to the right and back (a triangle wave over the clip), legs
    /// and arms swinging with a gait phase that advances with the distance walked.
    fn walker(&self, c: &mut Canvas, t: usize) {
        let n = self.frames.max(2) as f32;
        let u = t as f32 / (n - 1.0);
        let there = u < 0.5;
        let along = if there { 2.0 * u } else { 2.0 - 2.0 * u };
        let dir = if there { 1.0 } else { -1.0 };
        let body = self.h * 0.6;
        let (thigh, shin) = (body * 0.24, body * 0.24);
        let x = self.w * (0.2 + 0.6 * along);
        let stride_phase = 2.0 * PI * t as f32 / self.period + self.phase;
        let leg = |s: f32| {
            let a = 0.45 * s.sin();
            let bend = 0.15 + 0.45 * (-(s.cos())).max(0.0);
            let knee = (dir * thigh * a.sin(), thigh * a.cos());
            let b = a - bend;
            (knee, (knee.0 + dir * shin * b.sin(), knee.1 + shin * b.cos()))
        };
        let legs = [leg(stride_phase), leg(stride_phase + PI)];
        let ground = self.h * 0.9;
        let hip = (x, ground - legs.iter().map(|l| l.1 .1).fold(0.0, f32::max));
        let width = (self.unit() * 0.025).max(1.5);
        for (knee, foot) in legs {
            let k = (hip.0 + knee.0, hip.1 + knee.1);
            c.line(hip, k, self.ink, width);
            c.line(k, (hip.0 + foot.0, hip.1 + foot.1), self.ink, width);
        }
        let neck = (hip.0, hip.1 - body * 0.32);
        c.line(hip, neck, self.ink, width);
        for s in [stride_phase + PI, stride_phase] {
            let a = 0.5 * s.sin();
            let elbow = (neck.0 + dir * body * 0.16 * a.sin(), neck.1 + body * 0.16 * a.cos());
            let hand = (elbow.0 + dir * body * 0.15 * (a + 0.4).sin(), elbow.1 + body * 0.15 * (a + 0.4).cos());
            c.line(neck, elbow, self.ink, width);
            c.line(elbow, hand, self.ink, width);
        }
        c.circle((neck.0, neck.1 - body * 0.09), body * 0.08, self.accent);
        c.line((0.0, ground + width), (self.w, ground + width), self.ink, width * 0.6);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn same_seed_same_pixels_other_seed_other_pixels() {
        for kind in [
            ProceduralKind::Pendulum,
            ProceduralKind::Walker,
            ProceduralKind::Slider,
            ProceduralKind::Drift,
            ProceduralKind::Mixed,
        ] {
            let a = procedural_clip(kind, 6, 48, 32, 7);
            let b = procedural_clip(kind, 6, 48, 32, 7);
            let c = procedural_clip(kind, 6, 48, 32, 8);
            assert_eq!(a.frames, b.frames, "{kind:?}");
            assert_ne!(a.frames, c.frames, "{kind:?}");
            assert_eq!((a.len(), a.width(), a.height(), a.fps), (6, 48, 32, 25.0));
            // Something moves.
            assert!(a.frames.windows(2).any(|w| w[0] != w[1]), "{kind:?}");
        }
    }

    #[test]
    fn truth_places_cut_and_linear_segment() {
        let t = procedural_truth(ProceduralKind::Mixed, 100);
        assert_eq!(t.cut, Some(85));
        assert_eq!(t.linear, Some(20..60));
        assert_eq!(procedural_truth(ProceduralKind::Slider, 40).linear, Some(10..30));
        assert_eq!(procedural_truth(ProceduralKind::Pendulum, 40), ProceduralTruth { cut: None, linear: None });
        assert_eq!(procedural_truth(ProceduralKind::Mixed, 1).cut, None);
    }

    #[test]
    fn mixed_background_changes_at_the_cut_only() {
        let clip = procedural_clip(ProceduralKind::Mixed, 40, 64, 48, 3);
        let cut = procedural_truth(ProceduralKind::Mixed, 40).cut.unwrap();
        // The top-left corner is background in every frame.
        let corner = |i: usize| clip.frames[i].get_pixel(1, 1).0;
        assert!((1..cut).all(|i| corner(i) == corner(0)));
        assert_ne!(corner(cut), corner(cut - 1));
        assert!((cut..40).all(|i| corner(i) == corner(cut)));
    }

    #[test]
    fn slider_moves_at_constant_speed_inside_its_segment_only() {
        let n = 40;
        let clip = procedural_clip(ProceduralKind::Slider, n, 96, 64, 5);
        let lin = procedural_truth(ProceduralKind::Slider, n).linear.unwrap();
        // Left edge of the block on a row through it: first column that differs from frame-free background.
        let bg = textured_background(96, 64, derive(5, 2));
        let left = |i: usize| (0..96).find(|&x| clip.frames[i].get_pixel(x, 32) != bg.get_pixel(x, 32)).unwrap();
        assert_eq!(left(0), left(lin.start));
        assert_eq!(left(lin.end), left(n - 1));
        let steps: Vec<i64> = (lin.start..lin.end).map(|i| left(i + 1) as i64 - left(i) as i64).collect();
        // 96 px × 0.55 over 20 frames = 2.64 px a frame: every step is 2 or 3 whole pixels.
        assert!(steps.iter().all(|&s| (2..=3).contains(&s)), "{steps:?}");
        assert!(left(lin.end) > left(lin.start) + 40);
    }
}
