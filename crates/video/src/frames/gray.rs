//! Luma frames at flow resolution.
//!
//! Optical flow (§5.2) only needs brightness, and the paper works on frames of side 224; a
//! 1280x720 clip has 20 times more pixels than flow needs. Area averaging (each output pixel is the
//! mean of the source area it covers, fractional edges weighted by overlap) removes the detail that
//! would alias at the lower resolution, which nearest or bilinear sampling would keep.

use image::{GrayImage, RgbImage};
use rayon::prelude::*;

/// Rec. 601 luma of an RGB pixel, in 0…255.
fn luma(p: [u8; 3]) -> f32 {
    0.299 * p[0] as f32 + 0.587 * p[1] as f32 + 0.114 * p[2] as f32
}

/// Output size: the longer side becomes `max_side` (at least 1), the other keeps the aspect ratio;
/// frames already small enough keep their size.
pub(crate) fn target_size(w: u32, h: u32, max_side: u32) -> (u32, u32) {
    let max_side = max_side.max(1);
    let longer = w.max(h);
    if longer <= max_side {
        return (w, h);
    }
    let scale = max_side as f64 / longer as f64;
    let side = |s: u32| ((s as f64 * scale).round() as u32).clamp(1, max_side);
    (side(w), side(h))
}

/// For each of `dst` output cells, the source indices it overlaps and the overlap weights
/// (summing to 1): cell `i` covers source interval [i·src/dst, (i+1)·src/dst).
fn area_weights(src: u32, dst: u32) -> Vec<Vec<(usize, f32)>> {
    let step = src as f64 / dst as f64;
    (0..dst)
        .map(|i| {
            let (a, b) = (i as f64 * step, (i + 1) as f64 * step);
            let first = a.floor() as usize;
            let last = (b.ceil() as usize).min(src as usize);
            (first..last)
                .filter_map(|s| {
                    let overlap = (b.min(s as f64 + 1.0) - a.max(s as f64)) / step;
                    (overlap > 1e-9).then_some((s, overlap as f32))
                })
                .collect()
        })
        .collect()
}

/// One frame: luma, then separable area averaging (rows, then columns).
fn downscale_one(img: &RgbImage, tw: u32, th: u32) -> GrayImage {
    let (w, h) = img.dimensions();
    let y: Vec<f32> = img.pixels().map(|p| luma(p.0)).collect();
    let wx = area_weights(w, tw);
    let wy = area_weights(h, th);
    // Horizontal pass: h rows of tw values.
    let mut rows = vec![0f32; (h * tw) as usize];
    for r in 0..h as usize {
        let src = &y[r * w as usize..(r + 1) * w as usize];
        for (c, ws) in wx.iter().enumerate() {
            rows[r * tw as usize + c] = ws.iter().map(|&(s, k)| src[s] * k).sum();
        }
    }
    // Vertical pass.
    let mut out = GrayImage::new(tw, th);
    for (r, ws) in wy.iter().enumerate() {
        for c in 0..tw as usize {
            let v: f32 = ws.iter().map(|&(s, k)| rows[s * tw as usize + c] * k).sum();
            out.put_pixel(c as u32, r as u32, image::Luma([v.round().clamp(0.0, 255.0) as u8]));
        }
    }
    out
}

/// Luma frames with the longer side at most `max_side` (0 counts as 1), in parallel over frames.
pub(crate) fn gray_downscaled(frames: &[RgbImage], max_side: u32) -> Vec<GrayImage> {
    frames
        .par_iter()
        .map(|f| {
            let (tw, th) = target_size(f.width(), f.height(), max_side);
            if f.width() == 0 || f.height() == 0 {
                return GrayImage::new(f.width(), f.height());
            }
            downscale_one(f, tw, th)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use image::Rgb;

    #[test]
    fn target_size_keeps_aspect_and_never_upscales() {
        assert_eq!(target_size(1280, 720, 320), (320, 180));
        assert_eq!(target_size(720, 1280, 320), (180, 320));
        assert_eq!(target_size(100, 50, 320), (100, 50));
        assert_eq!(target_size(1000, 3, 10), (10, 1));
    }

    #[test]
    fn area_weights_sum_to_one_and_cover_fractions() {
        for (src, dst) in [(10, 3), (7, 7), (1280, 224), (5, 2)] {
            for ws in area_weights(src, dst) {
                let s: f32 = ws.iter().map(|w| w.1).sum();
                assert!((s - 1.0).abs() < 1e-5, "{src}->{dst}: {s}");
            }
        }
        // 5 -> 2: cell 0 covers pixels 0, 1 and half of 2.
        assert_eq!(area_weights(5, 2)[0], vec![(0, 0.4), (1, 0.4), (2, 0.2)]);
    }

    #[test]
    fn downscale_averages_areas_and_uses_luma() {
        // 4x2 image: left half black, right half white -> 2x1: [0, 255].
        let mut img = RgbImage::new(4, 2);
        for (x, _, p) in img.enumerate_pixels_mut() {
            *p = if x < 2 { Rgb([0, 0, 0]) } else { Rgb([255, 255, 255]) };
        }
        let g = gray_downscaled(&[img.clone()], 2);
        assert_eq!(g[0].dimensions(), (2, 1));
        assert_eq!(g[0].as_raw(), &vec![0u8, 255]);
        // 4x2 -> 1x1 (max side 1): the mean, 127.5 -> 128.
        let g = gray_downscaled(&[img], 1);
        assert_eq!(g[0].as_raw(), &vec![128u8]);
        // Pure green luma is 0.587 * 255.
        let green = RgbImage::from_pixel(3, 3, Rgb([0, 255, 0]));
        assert_eq!(gray_downscaled(&[green], 8)[0].get_pixel(1, 1).0[0], 150);
    }
}
