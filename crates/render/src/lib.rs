//! Previews a person can look at: stick figures of motions (PNG frames and animated GIFs, several
//! clips overlaid in different colours, perspective camera, ground grid) and PNG charts of scalar
//! curves. Text uses a font shipped inside a crate dependency, so output is the same on any machine.
//!
//! Every file is written through [`inbetween_io::write_atomic`]: a failed render never leaves a
//! half-written file.

pub mod bench;
pub mod canvas;
pub mod curves;
mod error;
pub mod face;
mod fill;
mod gif_out;
pub mod plot;
pub mod preview;
pub mod stick;

pub use canvas::{Camera3, Canvas};
pub use curves::{render_edit_plot, write_edit_plot, EditCurve, EditPlot};
pub use error::RenderError;
pub use face::{draw_face, render_face_frames, render_face_panels, write_face_gif, FaceGifOptions, FacePose};
pub use fill::{subdivide_triangle, UvTriangle};
pub use stick::{render_motion_frame, render_motion_gif, render_motion_png, render_positions_gif, StickOptions};

use image::RgbImage;
use std::path::Path;

/// Writes `bytes` to `path` atomically, naming the path in the error.
pub(crate) fn write_file(path: &Path, bytes: &[u8]) -> Result<(), RenderError> {
    inbetween_io::write_atomic(path, bytes).map_err(|source| RenderError::Io { path: path.to_path_buf(), source })
}

/// PNG bytes of an RGB image.
pub fn png_bytes(img: &RgbImage) -> Result<Vec<u8>, RenderError> {
    use image::ImageEncoder;
    let mut out = Vec::new();
    image::codecs::png::PngEncoder::new(&mut out)
        .write_image(img.as_raw(), img.width(), img.height(), image::ExtendedColorType::Rgb8)
        .map_err(|e| RenderError::Encode(format!("PNG: {e}")))?;
    Ok(out)
}

/// The bytes of a file that `draw` writes to the path it is given (a chart, a GIF), drawn in a
/// private temporary folder that is removed afterwards: for callers that collect outputs in memory
/// and write them together (e.g. `inbetween_io::report::Report::file`). `name` is the file's name,
/// whose extension some writers read.
pub fn rendered_bytes(name: &str, draw: impl FnOnce(&Path) -> Result<(), RenderError>) -> Result<Vec<u8>, RenderError> {
    let dir = tempfile::tempdir().map_err(|source| RenderError::Io { path: std::env::temp_dir(), source })?;
    let path = dir.path().join(name);
    draw(&path)?;
    std::fs::read(&path).map_err(|source| RenderError::Io { path, source })
}

/// Writes an RGB image as PNG (atomic write).
pub fn write_png(path: &Path, img: &RgbImage) -> Result<(), RenderError> {
    write_file(path, &png_bytes(img)?)
}

/// Writes an animated GIF that loops forever, `fps` frames per second, with one global palette
/// (atomic write).
pub fn write_gif(path: &Path, frames: &[RgbImage], fps: f64) -> Result<(), RenderError> {
    write_gif_with_progress(path, frames, fps, &mut |_, _| {})
}

/// [`write_gif`] calling `progress(frames_done, total)` after each encoded frame (for progress bars).
pub fn write_gif_with_progress(
    path: &Path,
    frames: &[RgbImage],
    fps: f64,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<(), RenderError> {
    let bytes = gif_out::encode(frames, fps, progress)?;
    write_file(path, &bytes)
}

#[cfg(test)]
mod rendered_bytes_tests {
    use super::*;

    #[test]
    fn rendered_bytes_are_the_file_the_drawing_wrote_and_errors_pass_through() {
        let img = RgbImage::from_pixel(3, 2, image::Rgb([10, 20, 30]));
        let bytes = rendered_bytes("x.png", |p| write_png(p, &img)).unwrap();
        assert_eq!(bytes, png_bytes(&img).unwrap());
        let err = rendered_bytes("x.png", |_| Err(RenderError::InvalidInput("no data".into()))).unwrap_err();
        assert!(err.to_string().contains("no data"), "{err}");
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use image::{AnimationDecoder, Rgb};

    #[test]
    fn gif_round_trips_frame_count_and_colours() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.gif");
        let frames: Vec<RgbImage> = (0..7)
            .map(|i| {
                let mut c = Canvas::new(64, 48, [250, 250, 250]);
                c.line((4.0, 4.0), (10.0 + 6.0 * i as f32, 40.0), [214, 39, 40], 3.0);
                c.circle((50.0, 10.0), 5.0, [31, 119, 180]);
                c.into_image()
            })
            .collect();
        write_gif(&path, &frames, 30.0).unwrap();
        let file = std::io::BufReader::new(std::fs::File::open(&path).unwrap());
        let decoded = image::codecs::gif::GifDecoder::new(file).unwrap().into_frames().collect_frames().unwrap();
        assert_eq!(decoded.len(), 7);
        let last = decoded[6].buffer();
        assert_eq!(last.get_pixel(50, 10).0[..3], [31, 119, 180]);
        assert_eq!(last.get_pixel(1, 46).0[..3], [250, 250, 250]);
        assert_eq!(*frames[6].get_pixel(30, 24), Rgb(last.get_pixel(30, 24).0[..3].try_into().unwrap()));
    }

    #[test]
    fn bad_gif_input_is_an_error_and_leaves_no_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("b.gif");
        assert!(write_gif(&path, &[], 30.0).is_err());
        let frames = vec![RgbImage::new(4, 4), RgbImage::new(5, 4)];
        let err = write_gif(&path, &frames, 30.0).unwrap_err().to_string();
        assert!(err.contains("frame 1"), "{err}");
        assert!(write_gif(&path, &frames[..1], 0.0).is_err());
        assert!(!path.exists());
    }
}
