//! Animated GIF in and out.
//!
//! Reading composites each frame onto the canvas left by the previous ones (GIF frames are often
//! patches with a disposal method), so every frame comes out full size; the image crate's decoder
//! does that composition. Pixels left transparent are shown over white, as a browser page would.
//! Writing uses `inbetween_render::write_gif`: one global palette for the whole clip (frequent
//! colours kept exact), which keeps a figure's colour stable from frame to frame.

use super::{decode_err, Clip, DecodeReport};
use crate::VideoError;
use image::{AnimationDecoder, RgbImage, RgbaImage};
use std::path::Path;

/// Frame rate assumed when every delay is 0 (browsers then show about 10 frames per second).
const ZERO_DELAY_FPS: f64 = 10.0;

/// RGBA over white, to RGB.
fn flatten(img: &RgbaImage) -> RgbImage {
    let mut out = RgbImage::new(img.width(), img.height());
    for (o, p) in out.pixels_mut().zip(img.pixels()) {
        let a = p.0[3] as u32;
        for c in 0..3 {
            o.0[c] = ((p.0[c] as u32 * a + 255 * (255 - a) + 127) / 255) as u8;
        }
    }
    out
}

/// Frames per second from the total of the frame delays (in milliseconds).
fn fps_from_delays(frames: usize, total_ms: f64) -> f64 {
    if total_ms > 0.0 {
        frames as f64 * 1000.0 / total_ms
    } else {
        ZERO_DELAY_FPS
    }
}

/// Reads every frame of an animated GIF (at most `max_frames`).
pub(crate) fn read_gif(
    path: &Path,
    max_frames: Option<usize>,
) -> Result<(Vec<RgbImage>, f64, DecodeReport), VideoError> {
    let file = std::fs::File::open(path).map_err(|e| VideoError::io(path, e))?;
    let decoder = image::codecs::gif::GifDecoder::new(std::io::BufReader::new(file))
        .map_err(|e| decode_err(path, None, format!("not a readable GIF: {e}")))?;
    let mut frames = Vec::new();
    let mut total_ms = 0.0;
    for (i, frame) in decoder.into_frames().enumerate() {
        if max_frames.is_some_and(|m| frames.len() >= m) {
            break;
        }
        let frame = frame.map_err(|e| decode_err(path, Some(i), format!("GIF frame does not decode: {e}")))?;
        let (n, d) = frame.delay().numer_denom_ms();
        total_ms += n as f64 / d.max(1) as f64;
        frames.push(flatten(frame.buffer()));
    }
    if frames.is_empty() {
        return Err(decode_err(path, None, "the GIF holds no frames"));
    }
    let mut notes = Vec::new();
    if total_ms == 0.0 {
        notes.push(format!("all GIF delays are 0: assumed {ZERO_DELAY_FPS} fps"));
    }
    let fps = fps_from_delays(frames.len(), total_ms);
    let report = DecodeReport { decoder: "gif".into(), frames: frames.len(), notes };
    Ok((frames, fps, report))
}

/// Writes the clip as a looping GIF (atomic write through the render crate).
pub(crate) fn write_gif(path: &Path, clip: &Clip) -> Result<(), VideoError> {
    inbetween_render::write_gif(path, &clip.frames, clip.fps)
        .map_err(|e| VideoError::Encode { path: path.to_path_buf(), message: e.to_string() })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flatten_shows_transparency_over_white() {
        let mut img = RgbaImage::new(2, 1);
        img.put_pixel(0, 0, image::Rgba([10, 20, 30, 255]));
        img.put_pixel(1, 0, image::Rgba([0, 0, 0, 0]));
        let rgb = flatten(&img);
        assert_eq!(rgb.get_pixel(0, 0).0, [10, 20, 30]);
        assert_eq!(rgb.get_pixel(1, 0).0, [255, 255, 255]);
    }

    #[test]
    fn fps_follows_delays() {
        assert_eq!(fps_from_delays(25, 1000.0), 25.0);
        assert_eq!(fps_from_delays(3, 0.0), ZERO_DELAY_FPS);
    }
}
