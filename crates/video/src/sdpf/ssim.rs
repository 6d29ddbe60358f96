//! SSIM (Wang, Bovik, Sheikh & Simoncelli, "Image Quality Assessment: From Error Visibility to
//! Structural Similarity", 2004) on luma: a perceptual proxy for the bench that needs no download.
//! The paper reports no SSIM (§6.3 has M_D and Δo only); the bench uses it to compare each
//! transition of a new order with the source's own adjacent pairs.
//!
//! As in Wang et al.'s reference code:
//! - an 11×11 Gaussian window with σ = 1.5, normalised to sum 1 (separable: the outer product of a
//!   1-D window);
//! - C1 = (K1·L)² and C2 = (K2·L)² with K1 = 0.01, K2 = 0.03 and L = 1 (pixels in [0, 1]);
//! - the local statistics at every position where the window lies inside the image ("valid"),
//!   and SSIM the mean of that map.
//!
//! An image smaller than 11 pixels on a side uses the largest window that fits (the same Gaussian,
//! truncated and renormalised). No scaling happens here: the caller picks the resolution (the bench
//! uses Rec. 601 luma area-averaged to at most [`SSIM_SIDE`] pixels on the longer side).

use image::{GrayImage, RgbImage};

use crate::VideoError;

/// Side of the Gaussian window.
pub const SSIM_WINDOW: usize = 11;
/// σ of the Gaussian window, in pixels.
pub const SSIM_SIGMA: f64 = 1.5;
/// K1 and K2 of Eq. 7 and 9 of Wang et al.; with L = 1, C1 = K1² and C2 = K2².
pub const SSIM_K1: f64 = 0.01;
pub const SSIM_K2: f64 = 0.03;
/// Longer side of the luma frames the bench compares (1280×720 becomes 160×90).
pub const SSIM_SIDE: u32 = 160;

/// A luma plane, row-major, values in [0, 1].
#[derive(Clone, Debug, PartialEq)]
pub struct Plane {
    pub width: usize,
    pub height: usize,
    pub data: Vec<f64>,
}

impl Plane {
    /// `data` must hold `width · height` values.
    pub fn new(width: usize, height: usize, data: Vec<f64>) -> Result<Plane, VideoError> {
        if data.len() != width * height {
            return Err(VideoError::Invalid(format!(
                "SSIM: a {width}x{height} plane needs {} values, got {}",
                width * height,
                data.len()
            )));
        }
        Ok(Plane { width, height, data })
    }

    /// The plane whose pixel (x, y) is `f(x, y)`.
    pub fn from_fn(width: usize, height: usize, f: impl Fn(usize, usize) -> f64) -> Plane {
        let data = (0..height).flat_map(|y| (0..width).map(move |x| (x, y))).map(|(x, y)| f(x, y)).collect();
        Plane { width, height, data }
    }

    /// A grey image, 0…255 mapped to [0, 1].
    pub fn from_gray(img: &GrayImage) -> Plane {
        let data = img.as_raw().iter().map(|&v| v as f64 / 255.0).collect();
        Plane { width: img.width() as usize, height: img.height() as usize, data }
    }
}

/// The frames as SSIM planes: Rec. 601 luma, area-averaged so that the longer side is at most
/// `max_side` (never upscaled), in [0, 1].
pub fn ssim_planes(frames: &[RgbImage], max_side: u32) -> Vec<Plane> {
    crate::frames::gray_downscaled(frames, max_side).iter().map(Plane::from_gray).collect()
}

/// The 1-D Gaussian of `size` taps and deviation `sigma`, centred and normalised to sum 1.
pub fn gaussian_window(size: usize, sigma: f64) -> Vec<f64> {
    let c = (size as f64 - 1.0) / 2.0;
    let w: Vec<f64> = (0..size).map(|i| (-((i as f64 - c).powi(2)) / (2.0 * sigma * sigma)).exp()).collect();
    let s: f64 = w.iter().sum();
    w.into_iter().map(|v| v / s).collect()
}

/// Separable filtering with the window `k` (horizontal, then vertical), keeping only the positions
/// where the window lies inside the image: `(w − k + 1) × (h − k + 1)` values.
fn filter_valid(data: &[f64], w: usize, h: usize, k: &[f64]) -> Vec<f64> {
    let n = k.len();
    let (ow, oh) = (w + 1 - n, h + 1 - n);
    let mut rows = vec![0.0; h * ow];
    for y in 0..h {
        let src = &data[y * w..(y + 1) * w];
        for x in 0..ow {
            rows[y * ow + x] = k.iter().zip(&src[x..x + n]).map(|(a, b)| a * b).sum();
        }
    }
    let mut out = vec![0.0; oh * ow];
    for y in 0..oh {
        for x in 0..ow {
            out[y * ow + x] = k.iter().enumerate().map(|(j, a)| a * rows[(y + j) * ow + x]).sum();
        }
    }
    out
}

/// Mean SSIM of two planes of the same size, in [−1, 1] (1 for identical planes).
pub fn ssim(a: &Plane, b: &Plane) -> Result<f64, VideoError> {
    if (a.width, a.height) != (b.width, b.height) {
        return Err(VideoError::Invalid(format!(
            "SSIM: a {}x{} plane against a {}x{} one",
            a.width, a.height, b.width, b.height
        )));
    }
    if a.width == 0 || a.height == 0 {
        return Err(VideoError::Invalid("SSIM: empty planes".into()));
    }
    let (w, h) = (a.width, a.height);
    let k = gaussian_window(SSIM_WINDOW.min(w).min(h), SSIM_SIGMA);
    let f = |d: &[f64]| filter_valid(d, w, h, &k);
    let prod = |x: &[f64], y: &[f64]| x.iter().zip(y).map(|(p, q)| p * q).collect::<Vec<f64>>();
    let (mu_a, mu_b) = (f(&a.data), f(&b.data));
    let (e_aa, e_bb, e_ab) = (f(&prod(&a.data, &a.data)), f(&prod(&b.data, &b.data)), f(&prod(&a.data, &b.data)));
    let (c1, c2) = (SSIM_K1 * SSIM_K1, SSIM_K2 * SSIM_K2);
    let mut sum = 0.0;
    for i in 0..mu_a.len() {
        let (ma, mb) = (mu_a[i], mu_b[i]);
        let (va, vb, cov) = (e_aa[i] - ma * ma, e_bb[i] - mb * mb, e_ab[i] - ma * mb);
        sum += ((2.0 * ma * mb + c1) * (2.0 * cov + c2)) / ((ma * ma + mb * mb + c1) * (va + vb + c2));
    }
    // Rounding in E[x²] − μ² could carry the mean a hair outside [−1, 1].
    Ok((sum / mu_a.len() as f64).clamp(-1.0, 1.0))
}

/// SSIM of every transition `order[i] → order[i + 1]`, frames given as planes.
pub fn transition_ssims(planes: &[Plane], order: &[usize]) -> Result<Vec<f64>, VideoError> {
    if let Some(&bad) = order.iter().find(|&&i| i >= planes.len()) {
        return Err(VideoError::Invalid(format!(
            "SSIM: frame {bad} is out of range (the clip has {} frames)",
            planes.len()
        )));
    }
    order.windows(2).map(|p| ssim(&planes[p[0]], &planes[p[1]])).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// A smooth texture with structure at several scales, in [0.2, 0.8].
    fn texture(w: usize, h: usize) -> Plane {
        Plane::from_fn(w, h, |x, y| {
            0.5 + 0.2 * (x as f64 / 3.0).sin() * (y as f64 / 4.0).cos() + 0.1 * ((x + 2 * y) as f64 / 7.0).sin()
        })
    }

    /// 3×3 box blur with clamped edges.
    fn blurred(p: &Plane) -> Plane {
        Plane::from_fn(p.width, p.height, |x, y| {
            let mut s = 0.0;
            for dy in -1i64..=1 {
                for dx in -1i64..=1 {
                    let xx = (x as i64 + dx).clamp(0, p.width as i64 - 1) as usize;
                    let yy = (y as i64 + dy).clamp(0, p.height as i64 - 1) as usize;
                    s += p.data[yy * p.width + xx];
                }
            }
            s / 9.0
        })
    }

    /// Uniform noise in ±amp from a fixed integer hash (deterministic, no RNG state).
    fn noisy(p: &Plane, amp: f64) -> Plane {
        Plane::from_fn(p.width, p.height, |x, y| {
            let mut z = (x as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ (y as u64).wrapping_mul(0xC2B2_AE3D_27D4_EB4F);
            z ^= z >> 29;
            z = z.wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z ^= z >> 32;
            let u = (z >> 11) as f64 / (1u64 << 53) as f64;
            (p.data[y * p.width + x] + amp * (2.0 * u - 1.0)).clamp(0.0, 1.0)
        })
    }

    #[test]
    fn the_window_is_a_normalised_symmetric_gaussian() {
        let w = gaussian_window(SSIM_WINDOW, SSIM_SIGMA);
        assert_eq!(w.len(), 11);
        assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        for i in 0..11 {
            assert!((w[i] - w[10 - i]).abs() < 1e-15);
        }
        // Ratio of neighbouring taps: exp(-(1² - 0²) / (2 · 1.5²)) at the centre.
        assert!((w[6] / w[5] - (-1.0f64 / 4.5).exp()).abs() < 1e-12);
    }

    #[test]
    fn identical_images_score_one() {
        let t = texture(40, 30);
        assert_eq!(ssim(&t, &t).unwrap(), 1.0);
        let flat = Plane::from_fn(20, 20, |_, _| 0.3);
        assert_eq!(ssim(&flat, &flat).unwrap(), 1.0);
    }

    #[test]
    fn a_brightness_shift_on_a_flat_image_lowers_it_by_the_luminance_term() {
        // Flat planes have no variance: the contrast-structure term is C2 / C2 = 1, and SSIM is
        // (2·0.5·0.6 + C1) / (0.5² + 0.6² + C1) = 0.6001 / 0.6101.
        let (a, b) = (Plane::from_fn(24, 16, |_, _| 0.5), Plane::from_fn(24, 16, |_, _| 0.6));
        let s = ssim(&a, &b).unwrap();
        assert!((s - 0.6001 / 0.6101).abs() < 1e-12, "{s}");
        assert!((s - 0.983_609).abs() < 1e-6);
        // The same shift on a texture costs the same luminance factor at most and no structure:
        // the score stays within that of the flat case and 1.
        let t = texture(32, 32);
        let shifted = Plane::from_fn(32, 32, |x, y| t.data[y * 32 + x] + 0.1);
        let st = ssim(&t, &shifted).unwrap();
        assert!(st < 1.0 && st > 0.97, "{st}");
    }

    #[test]
    fn it_is_symmetric() {
        let t = texture(37, 23);
        let n = noisy(&t, 0.2);
        assert_eq!(ssim(&t, &n).unwrap(), ssim(&n, &t).unwrap());
        let b = blurred(&t);
        assert_eq!(ssim(&b, &n).unwrap(), ssim(&n, &b).unwrap());
    }

    #[test]
    fn a_noisy_copy_scores_below_a_blurred_copy() {
        let t = texture(64, 48);
        let (sb, sn) = (ssim(&t, &blurred(&t)).unwrap(), ssim(&t, &noisy(&t, 0.15)).unwrap());
        assert!(sb > 0.9, "blurred {sb}");
        assert!(sn < sb - 0.1, "noisy {sn} against blurred {sb}");
        // More noise, lower score.
        assert!(ssim(&t, &noisy(&t, 0.3)).unwrap() < sn);
    }

    #[test]
    fn an_inverted_image_scores_negative_but_not_below_minus_one() {
        let t = texture(40, 40);
        let inv = Plane::from_fn(40, 40, |x, y| 1.0 - t.data[y * 40 + x]);
        let s = ssim(&t, &inv).unwrap();
        assert!((-1.0..0.0).contains(&s), "{s}");
    }

    #[test]
    fn small_images_use_a_window_that_fits_and_bad_inputs_are_errors() {
        let (a, b) = (texture(6, 5), noisy(&texture(6, 5), 0.2));
        let s = ssim(&a, &b).unwrap();
        assert!(s.is_finite() && s < 1.0);
        assert!(ssim(&a, &texture(5, 6)).is_err());
        assert!(ssim(&Plane::from_fn(0, 0, |_, _| 0.0), &Plane::from_fn(0, 0, |_, _| 0.0)).is_err());
        assert!(Plane::new(3, 3, vec![0.0; 8]).is_err());
        assert!(transition_ssims(&[a.clone(), b.clone()], &[0, 2]).is_err());
        let t = transition_ssims(&[a.clone(), b.clone()], &[0, 1, 0, 0]).unwrap();
        assert_eq!(t.len(), 3);
        assert_eq!(t[0], t[1]);
        assert_eq!(t[2], 1.0);
    }

    #[test]
    fn planes_from_frames_are_luma_in_unit_range_and_downscaled() {
        let white = RgbImage::from_pixel(320, 180, image::Rgb([255, 255, 255]));
        let p = ssim_planes(&[white], SSIM_SIDE);
        assert_eq!((p[0].width, p[0].height), (160, 90));
        assert!(p[0].data.iter().all(|&v| (v - 1.0).abs() < 1e-12));
    }

    proptest! {
        #![proptest_config(ProptestConfig { rng_seed: proptest::test_runner::RngSeed::Fixed(inbetween_core::seed::PROPTEST_SEED), ..ProptestConfig::with_cases(48) })]
        #[test]
        fn the_score_lies_in_minus_one_to_one(
            w in 1usize..16,
            h in 1usize..16,
            seed in any::<u64>(),
        ) {
            let gen = |s: u64| Plane::from_fn(w, h, |x, y| {
                let mut z = s ^ ((x as u64) << 32 | y as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15);
                z ^= z >> 31;
                z = z.wrapping_mul(0xBF58_476D_1CE4_E5B9);
                z ^= z >> 29;
                (z >> 11) as f64 / (1u64 << 53) as f64
            });
            let (a, b) = (gen(seed), gen(seed.wrapping_add(1)));
            let s = ssim(&a, &b).unwrap();
            prop_assert!((-1.0..=1.0).contains(&s), "{}", s);
            prop_assert_eq!(s, ssim(&b, &a).unwrap());
        }
    }
}
