//! What RSFNet sees: frames (or the float pseudo-images of Eq. 14–15) resized by area averaging to
//! `side × side`, RGB in [0, 1], laid out channels-first (`[3, side, side]`) for the network.
//! Non-square frames are squeezed to a square (the aspect ratio is not kept).

use burn::tensor::{Device, Tensor, TensorData};
use image::RgbImage;

/// One resized image: `3 · side · side` values in [0, 1], channels-first.
pub type Planes = Vec<f32>;

/// Area-average resize of a channels-last float image (`w × h × 3`, row-major) to `side × side`,
/// channels-first. Each output pixel is the mean of the source pixels whose centres fall in its
/// footprint (at least the nearest one), so any size works, up- or downscaling.
pub fn resize_planes(pixels: &[f32], w: usize, h: usize, side: usize) -> Planes {
    resize_with(w, h, side, |x, y, c| pixels[(y * w + x) * 3 + c])
}

/// [`resize_planes`] of an 8-bit RGB frame, scaled to [0, 1].
pub fn frame_planes(frame: &RgbImage, side: usize) -> Planes {
    let (w, h) = (frame.width() as usize, frame.height() as usize);
    let raw = frame.as_raw();
    resize_with(w, h, side, |x, y, c| f32::from(raw[(y * w + x) * 3 + c]) / 255.0)
}

/// Source index range `[start, end)` covered by output cell `i` of `side` cells over `n` pixels.
fn footprint(i: usize, side: usize, n: usize) -> (usize, usize) {
    let start = i * n / side;
    let end = ((i + 1) * n / side).max(start + 1).min(n);
    (start.min(n - 1), end)
}

fn resize_with(w: usize, h: usize, side: usize, at: impl Fn(usize, usize, usize) -> f32) -> Planes {
    let mut out = vec![0.0f32; 3 * side * side];
    if w == 0 || h == 0 {
        return out;
    }
    for oy in 0..side {
        let (y0, y1) = footprint(oy, side, h);
        for ox in 0..side {
            let (x0, x1) = footprint(ox, side, w);
            let mut sum = [0.0f32; 3];
            for y in y0..y1 {
                for x in x0..x1 {
                    for (c, s) in sum.iter_mut().enumerate() {
                        *s += at(x, y, c);
                    }
                }
            }
            let count = ((y1 - y0) * (x1 - x0)) as f32;
            for (c, s) in sum.iter().enumerate() {
                out[(c * side + oy) * side + ox] = s / count;
            }
        }
    }
    out
}

/// A `[n, 3, side, side]` batch of the images `which` picks out of `planes`.
pub fn batch_tensor(planes: &[Planes], which: &[usize], side: usize, device: &Device) -> Tensor<4> {
    let mut values = Vec::with_capacity(which.len() * 3 * side * side);
    for &i in which {
        values.extend_from_slice(&planes[i]);
    }
    Tensor::from_data(TensorData::new(values, [which.len(), 3, side, side]), device)
}

/// Mean squared error between two resized images.
pub fn mse(a: &[f32], b: &[f32]) -> f64 {
    let sum: f64 = a.iter().zip(b).map(|(x, y)| f64::from(x - y).powi(2)).sum();
    sum / a.len().max(1) as f64
}

/// PSNR in dB for values in [0, 1] (`10 · log10(1 / MSE)`); `+∞` for identical images.
pub fn psnr(a: &[f32], b: &[f32]) -> f64 {
    -10.0 * mse(a, b).log10()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn area_resize_averages_blocks_and_keeps_constant_images() {
        // 4×2 image: left half black, right half white → 2×2: [0, 1] per row.
        let mut img = RgbImage::new(4, 2);
        for (x, _, p) in img.enumerate_pixels_mut() {
            *p = if x >= 2 { image::Rgb([255, 255, 255]) } else { image::Rgb([0, 0, 0]) };
        }
        let planes = frame_planes(&img, 2);
        assert_eq!(planes.len(), 12);
        for c in 0..3 {
            assert_eq!(&planes[c * 4..c * 4 + 4], &[0.0, 1.0, 0.0, 1.0]);
        }
        // Upscaling a 1×1 float image repeats it; channels go to their own planes.
        let up = resize_planes(&[0.25, 0.5, 0.75], 1, 1, 3);
        assert!(up[..9].iter().all(|&v| v == 0.25) && up[18..].iter().all(|&v| v == 0.75));
        // An empty image gives zeros rather than a panic.
        assert!(frame_planes(&RgbImage::new(0, 0), 4).iter().all(|&v| v == 0.0));
    }

    #[test]
    fn psnr_matches_the_definition() {
        let a = vec![0.0f32; 4];
        let b = vec![0.1f32, 0.1, 0.1, 0.1];
        assert!((psnr(&a, &b) - 20.0).abs() < 1e-5);
        assert!(psnr(&a, &a).is_infinite());
    }
}
