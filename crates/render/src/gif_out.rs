//! Animated GIF encoding with one global palette built for the whole animation.
//!
//! Previews are flat colours plus anti-aliased edges. A per-frame neural-net quantiser spends palette
//! entries on the background and can shift a figure's colour from frame to frame; instead we keep
//! the most frequent colours exactly (background, grid, every figure's solid colour) and spread the
//! remaining entries over the blended edge shades. Each frame after the first stores only the
//! rectangle that changed, and inside it marks unchanged pixels transparent (long runs of one index
//! compress to almost nothing), which keeps files small.

use crate::RenderError;
use image::RgbImage;
use rayon::prelude::*;
use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

/// Hash for packed RGB keys: one multiply (Fibonacci hashing) instead of SipHash, which would
/// dominate the time spent counting and mapping millions of pixels.
#[derive(Default)]
struct ColorHasher(u64);

impl Hasher for ColorHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0 ^ b as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15);
        }
    }
    fn write_u32(&mut self, v: u32) {
        self.0 = (v as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15).rotate_left(26);
    }
}

type ColorMap<V> = HashMap<u32, V, BuildHasherDefault<ColorHasher>>;

/// Frames per batch: drawn into indices and LZW-compressed in parallel, then written in order.
const BATCH: usize = 16;

/// Palette entries for colours; the 256th entry of a GIF palette is kept for "unchanged" pixels.
const MAX_COLORS: usize = 255;

/// Colours closer than this (Euclidean RGB) to an already chosen entry are skipped in the first
/// passes, so that rare shades still find a nearby entry.
const SPREAD_THRESHOLDS: [u32; 4] = [40, 20, 8, 0];

fn pack(p: [u8; 3]) -> u32 {
    (p[0] as u32) << 16 | (p[1] as u32) << 8 | p[2] as u32
}

fn unpack(c: u32) -> [u8; 3] {
    [(c >> 16) as u8, (c >> 8) as u8, c as u8]
}

fn dist2(a: [u8; 3], b: [u8; 3]) -> u32 {
    a.iter().zip(b).map(|(&x, y)| (x as i32 - y as i32).pow(2) as u32).sum()
}

/// Counts of every exact colour in one frame (runs of one colour counted at once).
fn frame_histogram(f: &RgbImage) -> ColorMap<u64> {
    let mut counts = ColorMap::default();
    let mut run_color = u32::MAX;
    let mut run = 0u64;
    for p in f.pixels() {
        let c = pack(p.0);
        if c == run_color {
            run += 1;
        } else {
            if run > 0 {
                *counts.entry(run_color).or_default() += run;
            }
            run_color = c;
            run = 1;
        }
    }
    if run > 0 {
        *counts.entry(run_color).or_default() += run;
    }
    counts
}

/// Counts of every exact colour over all frames.
fn histogram(frames: &[RgbImage]) -> ColorMap<u64> {
    frames.par_iter().map(frame_histogram).reduce(ColorMap::default, |mut a, b| {
        for (c, n) in b {
            *a.entry(c).or_default() += n;
        }
        a
    })
}

/// Up to 256 colours: all of them when few enough, otherwise a popularity pick that skips
/// near-duplicates of already chosen colours (threshold relaxed pass by pass).
fn build_palette(counts: &ColorMap<u64>) -> Vec<[u8; 3]> {
    let mut by_count: Vec<(u32, u64)> = counts.iter().map(|(&c, &n)| (c, n)).collect();
    // Ties broken by the colour value so the palette is deterministic.
    by_count.sort_unstable_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
    if by_count.len() <= MAX_COLORS {
        return by_count.iter().map(|&(c, _)| unpack(c)).collect();
    }
    let mut chosen: Vec<[u8; 3]> = Vec::with_capacity(MAX_COLORS);
    let mut taken = vec![false; by_count.len()];
    for threshold in SPREAD_THRESHOLDS {
        let t2 = threshold * threshold;
        for (i, &(c, _)) in by_count.iter().enumerate() {
            if chosen.len() == MAX_COLORS {
                return chosen;
            }
            let rgb = unpack(c);
            if !taken[i] && chosen.iter().all(|&q| dist2(q, rgb) >= t2) {
                taken[i] = true;
                chosen.push(rgb);
            }
        }
    }
    chosen
}

/// Nearest palette index of every colour that occurs (computed once, in parallel).
fn nearest_lookup(counts: &ColorMap<u64>, palette: &[[u8; 3]]) -> ColorMap<u8> {
    let colors: Vec<u32> = counts.keys().copied().collect();
    colors
        .par_iter()
        .map(|&c| {
            let rgb = unpack(c);
            let best = (0..palette.len()).min_by_key(|&i| dist2(palette[i], rgb)).expect("palette is not empty");
            (c, best as u8)
        })
        .collect::<Vec<_>>()
        .into_iter()
        .collect()
}

/// Palette indices of every pixel.
fn indices(img: &RgbImage, lookup: &ColorMap<u8>) -> Vec<u8> {
    let mut out = Vec::with_capacity((img.width() * img.height()) as usize);
    let mut last = (u32::MAX, 0u8);
    for p in img.pixels() {
        let c = pack(p.0);
        if c != last.0 {
            last = (c, lookup[&c]);
        }
        out.push(last.1);
    }
    out
}

/// Bounding box (x0, y0, x1, y1), exclusive ends, of the pixels whose index differs.
fn changed_rect(prev: &[u8], cur: &[u8], width: usize) -> Option<(usize, usize, usize, usize)> {
    let height = cur.len() / width;
    let (mut x0, mut y0, mut x1, mut y1) = (width, height, 0, 0);
    for y in 0..height {
        let (a, b) = (&prev[y * width..(y + 1) * width], &cur[y * width..(y + 1) * width]);
        if a == b {
            continue;
        }
        let first = a.iter().zip(b).position(|(p, q)| p != q).expect("rows differ");
        let last = width - 1 - a.iter().rev().zip(b.iter().rev()).position(|(p, q)| p != q).expect("rows differ");
        x0 = x0.min(first);
        x1 = x1.max(last + 1);
        y0 = y0.min(y);
        y1 = y + 1;
    }
    (x1 > x0).then_some((x0, y0, x1, y1))
}

/// Frame delays in hundredths of a second whose running sum follows `fps` exactly (e.g. 30 fps gives
/// 3, 3, 4, 3, 3, 4…), with a 2 cs floor because browsers slow anything faster down to 10 cs.
pub(crate) fn delays_cs(count: usize, fps: f64) -> Vec<u16> {
    let mut out = Vec::with_capacity(count);
    let mut shown = 0u64;
    for i in 0..count {
        let due = ((i + 1) as f64 * 100.0 / fps).round() as u64;
        let d = due.saturating_sub(shown).max(2);
        shown += d;
        out.push(d.min(u16::MAX as u64) as u16);
    }
    out
}

/// Encodes the frames into GIF bytes, calling `progress(done, total)` after each frame.
pub(crate) fn encode(
    frames: &[RgbImage],
    fps: f64,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<Vec<u8>, RenderError> {
    let first = frames.first().ok_or_else(|| RenderError::InvalidInput("a GIF needs at least one frame".into()))?;
    let (w, h) = first.dimensions();
    if w == 0 || h == 0 || w > u16::MAX as u32 || h > u16::MAX as u32 {
        return Err(RenderError::InvalidInput(format!("GIF size {w}×{h} must be between 1 and 65535 pixels")));
    }
    if let Some(i) = frames.iter().position(|f| f.dimensions() != (w, h)) {
        return Err(RenderError::InvalidInput(format!(
            "frame {i} is {:?} but frame 0 is {w}×{h}; all GIF frames must have one size",
            frames[i].dimensions()
        )));
    }
    if !(fps.is_finite() && fps > 0.0) {
        return Err(RenderError::InvalidInput(format!("GIF frame rate {fps} must be a positive number")));
    }
    let counts = histogram(frames);
    let palette = build_palette(&counts);
    let lookup = nearest_lookup(&counts, &palette);
    let transparent = palette.len() as u8;
    let mut flat: Vec<u8> = palette.iter().flatten().copied().collect();
    // A GIF palette has a power-of-two size; pad with black (the pad includes the transparent entry).
    flat.resize(3 * (palette.len() + 1).next_power_of_two().max(2), 0);
    let delays = delays_cs(frames.len(), fps);
    let mut bytes = Vec::new();
    {
        let mut enc = gif::Encoder::new(&mut bytes, w as u16, h as u16, &flat).map_err(gif_err)?;
        enc.set_repeat(gif::Repeat::Infinite).map_err(gif_err)?;
        let mut prev_last: Option<Vec<u8>> = None;
        for start in (0..frames.len()).step_by(BATCH) {
            let end = (start + BATCH).min(frames.len());
            let indices: Vec<Vec<u8>> = frames[start..end].par_iter().map(|f| indices(f, &lookup)).collect();
            let encoded: Vec<gif::Frame<'static>> = (start..end)
                .into_par_iter()
                .map(|i| {
                    let prev = if i == start { prev_last.as_deref() } else { Some(indices[i - start - 1].as_slice()) };
                    let mut frame = delta_frame(prev, &indices[i - start], w as usize, h as usize, transparent);
                    frame.delay = delays[i];
                    frame.make_lzw_pre_encoded();
                    frame
                })
                .collect();
            for (k, frame) in encoded.iter().enumerate() {
                enc.write_lzw_pre_encoded_frame(frame).map_err(gif_err)?;
                progress(start + k + 1, frames.len());
            }
            prev_last = indices.into_iter().last();
        }
    }
    Ok(bytes)
}

/// The GIF frame that turns `prev` into `cur`: only the changed rectangle, with pixels that did not
/// change set to the `transparent` index (the whole image when there is no previous frame).
fn delta_frame(prev: Option<&[u8]>, cur: &[u8], w: usize, h: usize, transparent: u8) -> gif::Frame<'static> {
    let rect = match prev {
        None => Some((0, 0, w, h)),
        Some(p) => changed_rect(p, cur, w),
    };
    // An unchanged frame still needs its delay: a 1×1 patch of an unchanged pixel.
    let (x0, y0, x1, y1) = rect.unwrap_or((0, 0, 1, 1));
    let mut sub = Vec::with_capacity((x1 - x0) * (y1 - y0));
    for y in y0..y1 {
        let row = y * w + x0..y * w + x1;
        match prev {
            None => sub.extend_from_slice(&cur[row]),
            Some(p) => {
                sub.extend(cur[row.clone()].iter().zip(&p[row]).map(|(&c, &o)| if c == o { transparent } else { c }))
            }
        }
    }
    gif::Frame {
        transparent: prev.map(|_| transparent),
        left: x0 as u16,
        top: y0 as u16,
        width: (x1 - x0) as u16,
        height: (y1 - y0) as u16,
        buffer: std::borrow::Cow::Owned(sub),
        ..gif::Frame::default()
    }
}

fn gif_err(e: gif::EncodingError) -> RenderError {
    RenderError::Encode(format!("GIF: {e}"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use image::Rgb;

    #[test]
    fn delays_follow_the_frame_rate() {
        let d = delays_cs(30, 30.0);
        assert_eq!(d.iter().map(|&x| x as u32).sum::<u32>(), 100);
        assert!(d.iter().all(|&x| x == 3 || x == 4));
        assert_eq!(delays_cs(3, 200.0), vec![2, 2, 2]);
    }

    #[test]
    fn palette_keeps_solid_colours_exact_among_many_shades() {
        // 600 shades of grey in a gradient plus two small solid patches.
        let mut img = RgbImage::new(600, 20);
        for (x, _, p) in img.enumerate_pixels_mut() {
            let v = (x * 255 / 599) as u8;
            *p = Rgb([v, v, (x % 7) as u8 * 30]);
        }
        for y in 0..3 {
            for x in 0..40 {
                img.put_pixel(x, y, Rgb([31, 119, 180]));
                img.put_pixel(x + 100, y, Rgb([214, 39, 40]));
            }
        }
        let pal = build_palette(&histogram(&[img]));
        assert_eq!(pal.len(), 255);
        assert!(pal.contains(&[31, 119, 180]) && pal.contains(&[214, 39, 40]));
    }

    #[test]
    fn changed_rect_finds_the_difference() {
        let a = vec![0u8; 20];
        let mut b = a.clone();
        b[7] = 1; // row 1, column 2 of a 5-wide image
        b[13] = 1; // row 2, column 3
        assert_eq!(changed_rect(&a, &b, 5), Some((2, 1, 4, 3)));
        assert_eq!(changed_rect(&a, &a, 5), None);
    }
}
