//! The bench's pictures: contact sheets of orders and the SSIM box plot.

use super::protocol::CONFIGS;
use super::ClipResult;
use crate::frames::Clip;
use crate::job::BACKWARD_WINDOW;
use crate::preview::{contact_sheet, SheetOptions};
use crate::VideoError;

/// A contact sheet as PNG bytes, small thumbnails, cuts/loops/backward steps marked.
pub(super) fn sheet_png(
    clip: &Clip,
    order: &[usize],
    cuts: Vec<usize>,
    loops: Vec<usize>,
    title: String,
) -> Result<Vec<u8>, VideoError> {
    let opts = SheetOptions {
        columns: 16,
        thumb_width: 72,
        title,
        cuts,
        loops,
        transitions: Vec::new(),
        backward_window: BACKWARD_WINDOW,
    };
    let img = contact_sheet(&clip.frames, order, &opts)?;
    let mut bytes = Vec::new();
    img.write_to(&mut std::io::Cursor::new(&mut bytes), image::ImageFormat::Png)
        .map_err(|e| VideoError::Invalid(format!("contact sheet PNG: {e}")))?;
    Ok(bytes)
}

/// A file-name-safe version of a clip name.
pub(super) fn slug(name: &str) -> String {
    name.chars().map(|c| if c.is_ascii_alphanumeric() { c.to_ascii_lowercase() } else { '-' }).collect()
}

/// Box plot of the SSIM of every transition, per method, grouped by clip (`ssim.png`).
pub(super) fn ssim_png(results: &[ClipResult]) -> Result<Vec<u8>, VideoError> {
    let groups: Vec<String> = results.iter().map(|r| r.name.clone()).collect();
    let mut series = vec![("source".to_string(), results.iter().map(|r| r.ssim_source.clone()).collect::<Vec<_>>())];
    for (i, name) in CONFIGS.iter().enumerate() {
        series.push((name.to_string(), results.iter().map(|r| r.ssim_configs[i].clone()).collect()));
    }
    inbetween_render::rendered_bytes("ssim.png", |p| {
        inbetween_render::plot::box_plot(
            p,
            "SSIM of transitions (source's adjacent pairs vs new orders)",
            "SSIM (luma, <= 160 px)",
            &groups,
            &series,
        )
    })
    .map_err(|e| VideoError::Invalid(format!("ssim.png: {e}")))
}
