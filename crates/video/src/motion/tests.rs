//! Tests of the motion module: the flow against synthetic motion with a known answer, and each
//! equation on hand-made flows.

use super::*;
use image::GrayImage;
use inbetween_core::seed::rng;
use rand::Rng;
use std::f32::consts::{FRAC_PI_2, PI};

// ---------------------------------------------------------------- synthetic frames

/// Seeded smooth noise: a sum of 16 plane waves (wavelengths 5–16 px, random orientations and
/// phases), defined at every real position so that exact sub-pixel shifts can be sampled.
struct Texture {
    waves: Vec<(f32, f32, f32)>, // (kx, ky, phase)
}

impl Texture {
    fn new(seed: u64) -> Texture {
        let mut r = rng(seed);
        let waves = (0..16)
            .map(|_| {
                let wavelength = r.random_range(5.0f32..16.0);
                let theta = r.random_range(0.0f32..2.0 * PI);
                let k = 2.0 * PI / wavelength;
                (k * theta.cos(), k * theta.sin(), r.random_range(0.0f32..2.0 * PI))
            })
            .collect();
        Texture { waves }
    }

    fn value(&self, x: f32, y: f32) -> f32 {
        let s: f32 = self.waves.iter().map(|(kx, ky, ph)| (kx * x + ky * y + ph).sin()).sum();
        (128.0 + 100.0 * s / (self.waves.len() as f32).sqrt() * 0.9).clamp(0.0, 255.0)
    }

    /// The image whose pixel (x, y) shows the texture at `at(x, y)`.
    fn render(&self, w: u32, h: u32, at: impl Fn(f32, f32) -> (f32, f32)) -> GrayImage {
        GrayImage::from_fn(w, h, |x, y| {
            let (sx, sy) = at(x as f32, y as f32);
            image::Luma([self.value(sx, sy).round() as u8])
        })
    }
}

/// Frames (prev, next) where next(x) = prev(x − d), and the true flow d everywhere.
fn translated(w: u32, h: u32, d: [f32; 2], seed: u64) -> (GrayImage, GrayImage, Flow) {
    let t = Texture::new(seed);
    let prev = t.render(w, h, |x, y| (x, y));
    let next = t.render(w, h, |x, y| (x - d[0], y - d[1]));
    (prev, next, Flow::uniform(w as usize, h as usize, d))
}

/// Frames rotated by `angle` about the centre, and the true flow R(p − c) + c − p.
fn rotated(w: u32, h: u32, angle: f32, seed: u64) -> (GrayImage, GrayImage, Flow) {
    let t = Texture::new(seed);
    let (cx, cy) = ((w as f32 - 1.0) / 2.0, (h as f32 - 1.0) / 2.0);
    let (s, c) = angle.sin_cos();
    let prev = t.render(w, h, |x, y| (x, y));
    // next(q) = prev(R⁻¹(q − c) + c)
    let next = t.render(w, h, |x, y| {
        let (dx, dy) = (x - cx, y - cy);
        (c * dx + s * dy + cx, -s * dx + c * dy + cy)
    });
    let uv = (0..w * h)
        .map(|i| {
            let (dx, dy) = ((i % w) as f32 - cx, (i / w) as f32 - cy);
            [c * dx - s * dy - dx, s * dx + c * dy - dy]
        })
        .collect();
    (prev, next, Flow { width: w as usize, height: h as usize, uv })
}

fn epe(prev: &GrayImage, next: &GrayImage, truth: &Flow, margin: usize) -> f64 {
    let f = farneback(prev, next, &FlowParams::default());
    f.mean_endpoint_error(truth, margin).expect("same size, pixels inside the margin")
}

// ---------------------------------------------------------------- flow accuracy

#[test]
fn subpixel_translation_is_recovered() {
    let (prev, next, truth) = translated(96, 72, [2.5, -1.25], 11);
    let e = epe(&prev, &next, &truth, 10);
    println!("EPE (2.5, -1.25) px: {e:.4}");
    assert!(e < 0.3, "mean endpoint error {e}");
}

#[test]
fn large_translation_is_reached_by_the_pyramid() {
    let (prev, next, truth) = translated(96, 72, [6.0, 3.0], 12);
    let e = epe(&prev, &next, &truth, 12);
    println!("EPE (6, 3) px: {e:.4}");
    assert!(e < 0.3, "mean endpoint error {e}");
    // Without the pyramid the same shift is out of reach: the pyramid is what does it.
    let single = FlowParams { levels: 1, ..FlowParams::default() };
    let e1 = farneback(&prev, &next, &single).mean_endpoint_error(&truth, 12).unwrap();
    println!("EPE (6, 3) px, one level: {e1:.4}");
    assert!(e1 > 2.0 * e, "one level {e1} vs pyramid {e}");
}

#[test]
fn small_rotation_is_recovered() {
    let (prev, next, truth) = rotated(96, 72, 3f32.to_radians(), 13);
    let e = epe(&prev, &next, &truth, 10);
    println!("EPE rotation 3°: {e:.4}");
    assert!(e < 0.3, "mean endpoint error {e}");
}

#[test]
fn zero_motion_gives_near_zero_flow() {
    let (prev, _, _) = translated(64, 48, [0.0, 0.0], 14);
    let f = farneback(&prev, &prev, &FlowParams::default());
    let max = f.magnitudes().into_iter().fold(0.0f32, f32::max);
    assert!(max < 0.02, "largest vector {max}");
}

#[test]
fn degenerate_images_do_not_panic() {
    let p = FlowParams::default();
    let empty = GrayImage::new(0, 0);
    let f = farneback(&empty, &empty, &p);
    assert_eq!((f.width, f.height, f.uv.len()), (0, 0, 0));
    let flat = GrayImage::from_pixel(40, 30, image::Luma([90]));
    let f = farneback(&flat, &flat, &p);
    assert!(f.uv.iter().all(|v| v[0] == 0.0 && v[1] == 0.0), "uniform frames: no motion");
    let tiny = GrayImage::from_pixel(1, 1, image::Luma([3]));
    let f = farneback(&tiny, &flat, &p);
    assert!(f.uv.len() == 1 && f.magnitudes()[0] < 1e-6, "a 1×1 frame has no structure: {:?}", f.uv);
    // Another size: resampled to prev's grid, and the result is finite.
    let (prev, _, _) = translated(48, 36, [0.0, 0.0], 15);
    let f = farneback(&prev, &flat, &p);
    assert_eq!((f.width, f.height), (48, 36));
    assert!(f.uv.iter().all(|v| v[0].is_finite() && v[1].is_finite()));
    assert_eq!(farneback(&prev, &empty, &p).uv.len(), 48 * 36);
}

#[test]
fn flow_is_deterministic() {
    let (prev, next, _) = translated(64, 48, [1.5, 0.5], 16);
    let p = FlowParams::default();
    assert_eq!(farneback(&prev, &next, &p), farneback(&prev, &next, &p));
}

/// Speed at the clip-flow resolution (not a timed assertion): `cargo test -p inbetween-video --lib
/// motion::tests::flow_speed -- --ignored --nocapture`.
#[test]
#[ignore]
fn flow_speed_160x90() {
    let (prev, next, truth) = translated(160, 90, [2.5, -1.25], 17);
    let p = FlowParams::default();
    let _ = farneback(&prev, &next, &p);
    let runs = 20;
    let t = std::time::Instant::now();
    let mut f = Flow::zeros(0, 0);
    for _ in 0..runs {
        f = farneback(&prev, &next, &p);
    }
    let ms = t.elapsed().as_secs_f64() * 1000.0 / runs as f64;
    println!("160x90 farneback: {ms:.2} ms per flow, EPE {:.4}", f.mean_endpoint_error(&truth, 10).unwrap());
    let single = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
    let t = std::time::Instant::now();
    single.install(|| (0..runs).for_each(|_| drop(farneback(&prev, &next, &p))));
    println!("160x90 farneback, 1 thread: {:.2} ms per flow", t.elapsed().as_secs_f64() * 1000.0 / runs as f64);
    // A clip: each frame expanded once, 2(n − 1) flows.
    let t = Texture::new(18);
    let gray: Vec<GrayImage> = (0..40).map(|i| t.render(160, 90, |x, y| (x - 1.5 * i as f32, y))).collect();
    let m = analyse_clip(&gray, &p);
    println!("analyse_clip 40 frames 160x90: {:.3} s, {:.2} ms per flow", m.seconds, m.seconds * 1000.0 / (2.0 * 39.0));
}

// ---------------------------------------------------------------- Eq. 9

#[test]
fn eq9_normalizes_magnitudes_to_the_unit_interval() {
    let f = Flow { width: 3, height: 1, uv: vec![[1.0, 0.0], [0.0, -3.0], [3.0, 4.0]] };
    let n = normalized_magnitude(&f);
    assert_eq!(n, vec![0.0, 0.5, 1.0]);
    // Degenerate: equal magnitudes → all 1; no motion → all 0; NaN counts as no motion.
    assert_eq!(normalized_magnitude(&Flow::uniform(2, 2, [0.0, 2.0])), vec![1.0; 4]);
    assert_eq!(normalized_magnitude(&Flow::zeros(2, 2)), vec![0.0; 4]);
    let nan = Flow { width: 2, height: 1, uv: vec![[f32::NAN, 0.0], [2.0, 0.0]] };
    assert_eq!(normalized_magnitude(&nan), vec![0.0, 1.0]);
    assert!(normalized_magnitude(&Flow::zeros(0, 0)).is_empty());
}

// ---------------------------------------------------------------- Eq. 10

/// A moving block (`uv` on a 4×4 square) over a background drifting by `bg`.
fn block_flow(uv: [f32; 2], bg: [f32; 2]) -> Flow {
    let mut f = Flow::uniform(10, 10, bg);
    for y in 3..7 {
        for x in 3..7 {
            f.uv[y * 10 + x] = uv;
        }
    }
    f
}

#[test]
fn eq10_tendency_is_the_direction_of_the_dominant_motion() {
    let right = motion_tendency(&block_flow([3.0, 0.0], [0.0, 0.0]), SIGMA).unwrap();
    assert!(right.abs() < 1e-6, "{right}");
    let down = motion_tendency(&block_flow([0.0, 2.0], [0.0, 0.0]), SIGMA).unwrap();
    assert!((down - FRAC_PI_2).abs() < 1e-6, "{down}");
    // A slow background moving up-left does not vote: only normalised magnitudes > σ count.
    let t = motion_tendency(&block_flow([-4.0, 0.0], [-0.5, -0.5]), SIGMA).unwrap();
    assert!(angle_between(t, PI) < 1e-6, "{t}");
    // Unit vectors are averaged, not the raw vectors: fast right pixels and slightly slower
    // diagonal ones give a direction between them.
    let mut f = block_flow([4.0, 0.0], [0.0, 0.0]);
    for x in 3..7 {
        f.uv[3 * 10 + x] = [2.5, 2.5]; // |.| ≈ 3.54 > σ · 4
    }
    let t = motion_tendency(&f, SIGMA).unwrap();
    let want = (std::f32::consts::FRAC_1_SQRT_2 * 4.0).atan2(12.0 + 4.0 * std::f32::consts::FRAC_1_SQRT_2);
    assert!((t - want).abs() < 1e-5, "{t} vs {want}");
}

#[test]
fn eq10_has_no_tendency_without_motion_or_direction() {
    assert_eq!(motion_tendency(&Flow::zeros(5, 5), SIGMA), None);
    assert_eq!(motion_tendency(&Flow::zeros(0, 0), SIGMA), None);
    // Below the static floor: noise, no tendency (but the paper's exact form, floor 0, gives one).
    let noise = block_flow([0.05, 0.0], [0.0, 0.0]);
    assert_eq!(motion_tendency(&noise, SIGMA), None);
    assert_eq!(motion_tendency_with_floor(&noise, SIGMA, 0.0), Some(0.0));
    // Two equal blocks moving apart cancel out.
    let mut f = Flow::zeros(8, 2);
    for x in 0..4 {
        f.uv[x] = [-2.0, 0.0];
        f.uv[4 + x] = [2.0, 0.0];
    }
    assert_eq!(motion_tendency(&f, SIGMA), None);
    // σ = 1: nothing exceeds the largest normalised magnitude.
    assert_eq!(motion_tendency(&block_flow([3.0, 0.0], [0.0, 0.0]), 1.0), None);
}

// ---------------------------------------------------------------- Eq. 11

#[test]
fn eq11_marks_runs_of_at_least_four_consistent_frames() {
    let r = Some(0.0);
    // Four frames moving right, then a reversal, then three frames moving left (too short).
    let t = [r, Some(0.3), Some(-0.5), r, Some(PI), Some(PI), Some(3.0), None];
    let lms = lms_frames(&t, DELTA, LMS_MIN_LEN);
    assert_eq!(lms, vec![true, true, true, true, false, false, false, false]);
    // Anchored on T_j: 0, 0.7, 1.4 turn gradually but 1.4 is more than π/4 from 0, so the run
    // from 0 stops; the run from 0.7 (0.7, 1.4, 1.2, 1.0) is long enough on its own.
    let t = [Some(0.0), Some(0.7), Some(1.4), Some(1.2), Some(1.0)];
    assert_eq!(lms_frames(&t, DELTA, 4), vec![false, true, true, true, true]);
    // A missing tendency breaks the run.
    let t = [r, r, None, r, r, r];
    assert_eq!(lms_frames(&t, DELTA, 4), vec![false; 6]);
    assert!(lms_frames(&[], DELTA, 4).is_empty());
}

#[test]
fn eq11_wraps_angles_across_pi() {
    // Leftward motion jittering around ±π is one direction, not a flip.
    let t = [Some(3.1), Some(-3.1), Some(3.0), Some(-3.05)];
    assert_eq!(lms_frames(&t, DELTA, 4), vec![true; 4]);
    assert!((angle_between(3.1, -3.1) - (2.0 * PI - 6.2)).abs() < 1e-5);
}

#[test]
fn tendency_and_lms_of_hand_made_clip_flows() {
    // Six frames moving right then five moving left: two runs, tendency 0 then π.
    let flows: Vec<Flow> = (0..11)
        .map(|i| if i < 6 { block_flow([2.0, 0.0], [0.0, 0.0]) } else { block_flow([-2.0, 0.1], [0.0, 0.0]) })
        .collect();
    let t: Vec<Option<f32>> = flows.iter().map(|f| motion_tendency(f, SIGMA)).collect();
    assert!(t[..6].iter().all(|a| a.unwrap().abs() < 1e-6));
    assert!(t[6..].iter().all(|a| angle_between(a.unwrap(), PI) < 0.1));
    assert_eq!(lms_frames(&t, DELTA, LMS_MIN_LEN), vec![true; 11]);
    // A single reversed frame in the middle of a rightward run breaks it into 3 + 3 frames.
    let mut t2 = vec![Some(0.0f32); 7];
    t2[3] = Some(PI);
    assert_eq!(lms_frames(&t2, DELTA, LMS_MIN_LEN), vec![false; 7]);
}

// ---------------------------------------------------------------- Eq. 13–14

fn pixel(img: &[f32], w: usize, x: usize, y: usize) -> [f32; 3] {
    let i = (y * w + x) * 3;
    [img[i], img[i + 1], img[i + 2]]
}

#[test]
fn eq13_14_pseudo_images_mark_the_union_of_significant_motions() {
    // FC: a block moving right at (3..7, 3..7); FK: a block moving up at (0..2, 0..2).
    let fc = block_flow([3.0, 0.0], [0.0, 0.0]);
    let mut fk = Flow::zeros(10, 10);
    for y in 0..2 {
        for x in 0..2 {
            fk.uv[y * 10 + x] = [0.0, -1.0];
        }
    }
    let (xc, xk) = pseudo_images(&fc, &fk, MU0, 4);
    assert_eq!((xc.len(), xk.len()), (300, 300));
    // Inside FC's block: unit vector (1, 0) → (1, ½, 1) in X_c; FK is zero there → (½, ½, 1).
    assert_eq!(pixel(&xc, 10, 4, 4), [1.0, 0.5, 1.0]);
    assert_eq!(pixel(&xk, 10, 4, 4), [0.5, 0.5, 1.0]);
    // Inside FK's block: (0, −1) → (½, 0, 1) in X_k; X_c marks it with no direction.
    assert_eq!(pixel(&xk, 10, 1, 1), [0.5, 0.0, 1.0]);
    assert_eq!(pixel(&xc, 10, 1, 1), [0.5, 0.5, 1.0]);
    // Elsewhere: no significant motion in either.
    assert_eq!(pixel(&xc, 10, 9, 9), [0.5, 0.5, 0.0]);
    assert_eq!(pixel(&xk, 10, 9, 9), [0.5, 0.5, 0.0]);
    assert!(xc.iter().chain(&xk).all(|v| (0.0..=1.0).contains(v)));
}

#[test]
fn eq14_threshold_is_halved_until_enough_elements_exceed_it() {
    // Normalised magnitudes: 3 pixels at 1, 20 at 0.4, the rest (77) at 0.1.
    let mut norm = vec![0.1f32; 100];
    norm[..3].fill(1.0);
    norm[3..23].fill(0.4);
    assert_eq!(threshold(&norm, 0.5, 3), 0.5);
    assert_eq!(threshold(&norm, 0.5, 10), 0.25);
    assert_eq!(threshold(&norm, 0.5, 50), 0.0625);
    // All zero: halving stops after a bounded number of steps.
    let mu = threshold(&[0.0; 10], 0.5, 5);
    assert!(mu > 0.0 && mu < 1e-9);
    assert_eq!(threshold(&norm, f32::NAN, 3), 0.5);
}

#[test]
fn eq14_halving_widens_the_mask_of_a_flow() {
    // Magnitudes 4 on three pixels, 1.6 on 60, 0 on the rest: Eq. 9 gives 1, 0.4, 0.
    let mut f = Flow::zeros(10, 10);
    f.uv[..3].fill([4.0, 0.0]);
    f.uv[3..63].fill([0.0, 1.6]);
    let (x_few, _) = pseudo_images(&f, &f, MU0, 3);
    let (x_many, _) = pseudo_images(&f, &f, MU0, 10);
    let marked = |x: &[f32]| x.chunks(3).filter(|p| p[2] == 1.0).count();
    assert_eq!(marked(&x_few), 3);
    assert_eq!(marked(&x_many), 63);
    assert_eq!(pixel(&x_many, 10, 5, 5), [0.5, 1.0, 1.0]);
}

#[test]
fn eq14_zero_and_mismatched_flows_do_not_panic() {
    let (xc, xk) = pseudo_images(&Flow::zeros(4, 3), &Flow::zeros(4, 3), MU0, 224);
    assert!(xc.chunks(3).chain(xk.chunks(3)).all(|p| p == [0.5, 0.5, 0.0]));
    let (xc, xk) = pseudo_images(&Flow::uniform(4, 3, [1.0, 0.0]), &Flow::uniform(2, 2, [0.0, 1.0]), MU0, 1);
    assert_eq!((xc.len(), xk.len()), (36, 36));
    assert_eq!(pixel(&xk, 4, 3, 2), [0.5, 1.0, 1.0]);
    let (xc, xk) = pseudo_images(&Flow::zeros(0, 0), &Flow::zeros(0, 0), MU0, 5);
    assert!(xc.is_empty() && xk.is_empty());
}

// ---------------------------------------------------------------- Eq. 17

#[test]
fn eq17_rotations_turn_every_vector_by_a_quarter() {
    let f = Flow { width: 2, height: 1, uv: vec![[1.0, 0.0], [3.0, 4.0]] };
    let a1 = rotate_flow(&f, FRAC_PI_2);
    let a2 = rotate_flow(&f, -FRAC_PI_2);
    let close = |a: [f32; 2], b: [f32; 2]| (a[0] - b[0]).abs() < 1e-6 && (a[1] - b[1]).abs() < 1e-6;
    assert!(close(a1.uv[0], [0.0, 1.0]) && close(a2.uv[0], [0.0, -1.0]));
    assert!(close(a1.uv[1], [-4.0, 3.0]) && close(a2.uv[1], [4.0, -3.0]));
    assert_eq!(f.magnitudes(), a1.magnitudes());
    // Tendency turns with it: right → down.
    let t = motion_tendency(&rotate_flow(&block_flow([2.0, 0.0], [0.0, 0.0]), FRAC_PI_2), SIGMA).unwrap();
    assert!((t - FRAC_PI_2).abs() < 1e-6);
}

// ---------------------------------------------------------------- analyse_clip

#[test]
fn analyse_clip_finds_backward_flows_and_a_reversal() {
    // A texture panned right by 2 px per frame for 5 frames, then back left for 4.
    let t = Texture::new(21);
    let offsets = [0.0f32, 2.0, 4.0, 6.0, 8.0, 10.0, 8.0, 6.0, 4.0, 2.0];
    let gray: Vec<GrayImage> = offsets.iter().map(|&o| t.render(64, 48, |x, y| (x - o, y))).collect();
    let m = analyse_clip(&gray, &FlowParams::default());
    assert_eq!((m.backward.len(), m.tendency.len(), m.lms.len()), (10, 10, 10));
    // FC of frame c is the motion c → c−1: (−2, 0) while panning right, (+2, 0) after the turn.
    for c in 1..10 {
        let want = Flow::uniform(64, 48, [offsets[c - 1] - offsets[c], 0.0]);
        let e = m.backward[c].mean_endpoint_error(&want, 8).unwrap();
        assert!(e < 0.3, "frame {c}: EPE {e}");
    }
    let e0 = m.backward[0].mean_endpoint_error(&Flow::uniform(64, 48, [-2.0, 0.0]), 8).unwrap();
    assert!(e0 < 0.3, "frame 0 (negated forward flow): EPE {e0}");
    // Forward motion: right for frames 0..=4, left for 5..=9.
    for (c, a) in m.tendency.iter().enumerate() {
        let want = if c < 5 { 0.0 } else { PI };
        assert!(angle_between(a.expect("moving"), want) < 0.3, "frame {c}: {a:?}");
    }
    assert_eq!(m.lms, vec![true; 10]);
    assert!(m.seconds > 0.0);
}

#[test]
fn analyse_clip_handles_short_clips() {
    let m = analyse_clip(&[], &FlowParams::default());
    assert!(m.backward.is_empty() && m.tendency.is_empty() && m.lms.is_empty());
    let one = GrayImage::from_pixel(8, 6, image::Luma([50]));
    let m = analyse_clip(std::slice::from_ref(&one), &FlowParams::default());
    assert_eq!(m.backward, vec![Flow::zeros(8, 6)]);
    assert_eq!((m.tendency, m.lms), (vec![None], vec![false]));
    // Mixed sizes: resampled, flows on each frame's own grid, no panic.
    let (a, b) = (GrayImage::from_pixel(8, 6, image::Luma([50])), GrayImage::from_pixel(5, 4, image::Luma([80])));
    let m = analyse_clip(&[a.clone(), b, a], &FlowParams::default());
    let sizes: Vec<(usize, usize)> = m.backward.iter().map(|f| (f.width, f.height)).collect();
    assert_eq!(sizes, vec![(8, 6), (5, 4), (8, 6)]);
    // Still frames: no tendency, no LMS.
    let m = analyse_clip(&vec![one; 5], &FlowParams::default());
    assert_eq!(m.tendency, vec![None; 5]);
    assert_eq!(m.lms, vec![false; 5]);
}
