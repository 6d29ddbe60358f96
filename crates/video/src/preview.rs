//! Pictures of a resequencing: a contact sheet of the new order (each thumbnail labelled with its
//! position and source frame, jumps marked) and a heat map of the frame-distance graph (the paper's
//! Fig. 12, ours for any clip).

use std::path::Path;

use image::RgbImage;
use inbetween_render::canvas::text_width;
use inbetween_render::{write_png, Canvas};

use crate::VideoError;

/// Layout of a contact sheet.
#[derive(Clone, Debug)]
pub struct SheetOptions {
    /// Thumbnails per row.
    pub columns: usize,
    /// Width of a thumbnail in pixels (height follows the clip's aspect).
    pub thumb_width: u32,
    /// Title drawn above the grid.
    pub title: String,
    /// Positions entered by a cut to another shot ([`SdpfPath::cut_positions`](crate::sdpf::SdpfPath::cut_positions)):
    /// framed in blue, labelled "CUT".
    pub cuts: Vec<usize>,
    /// Positions entered by a loop back: framed in purple, labelled "LOOP".
    pub loops: Vec<usize>,
    /// Positions entered by a matched transition (Schödl et al. 2000; forward or back in the
    /// source): framed in teal, labelled "MATCH".
    pub transitions: Vec<usize>,
    /// Mark backward steps (to one of this many previous source frames, see
    /// [`is_backward_step`](crate::sdpf::is_backward_step)) in red, labelled "BACK"; 0: none.
    pub backward_window: usize,
}

impl Default for SheetOptions {
    fn default() -> Self {
        SheetOptions {
            columns: 8,
            thumb_width: 160,
            title: String::new(),
            cuts: Vec::new(),
            loops: Vec::new(),
            transitions: Vec::new(),
            backward_window: 3,
        }
    }
}

const BACKGROUND: [u8; 3] = [250, 250, 248];
const INK: [u8; 3] = [30, 30, 30];
/// A transition that follows the source order (f → f + 1).
const SOURCE_STEP: [u8; 3] = [120, 170, 120];
/// A transition to a frame the source does not follow with: a new transition.
const JUMP: [u8; 3] = [214, 96, 40];
/// A cut to another shot.
const CUT: [u8; 3] = [40, 90, 210];
/// A loop back to an earlier frame of the path.
const LOOP: [u8; 3] = [150, 60, 170];
/// A matched transition.
const MATCH: [u8; 3] = [20, 150, 150];
/// A step back to one of the previous source frames: motion played backwards.
const BACKWARD: [u8; 3] = [220, 20, 30];
const LABEL_SIZE: f32 = 13.0;
const TITLE_SIZE: f32 = 16.0;

/// Whether the step into position `i` of `order` is a jump (not the source's next frame).
pub fn is_jump(order: &[usize], i: usize) -> bool {
    i > 0 && order[i] != order[i - 1] + 1
}

/// The contact sheet of `order` (source frame indices into `frames`): row-major thumbnails, each
/// labelled `position: source`, framed in green where the order follows the source, orange where
/// it jumps, and, with a word in the label, red for a backward step ("BACK"), blue for a cut
/// ("CUT"), purple for a loop back ("LOOP") and teal for a matched transition ("MATCH").
pub fn contact_sheet(frames: &[RgbImage], order: &[usize], opts: &SheetOptions) -> Result<RgbImage, VideoError> {
    if let Some(&bad) = order.iter().find(|&&f| f >= frames.len()) {
        return Err(VideoError::Invalid(format!("the order names frame {bad} of a {}-frame clip", frames.len())));
    }
    let first = frames.first().ok_or_else(|| VideoError::Invalid("a contact sheet needs at least one frame".into()))?;
    let columns = opts.columns.max(1);
    let tw = opts.thumb_width.max(16);
    let th = ((f64::from(tw) * f64::from(first.height()) / f64::from(first.width().max(1))).round() as u32).max(1);
    let (pad, label_h) = (6u32, LABEL_SIZE as u32 + 4);
    let title_h = if opts.title.is_empty() { 0 } else { TITLE_SIZE as u32 + 10 };
    let rows = order.len().div_ceil(columns).max(1) as u32;
    let cell_w = tw + pad;
    let cell_h = th + label_h + pad;
    let width = pad + columns as u32 * cell_w;
    let height = title_h + pad + rows * cell_h;
    let mut canvas = Canvas::new(width, height, BACKGROUND);
    if !opts.title.is_empty() {
        canvas.text((pad as f32, 4.0), &opts.title, TITLE_SIZE, INK);
    }
    for (i, &src) in order.iter().enumerate() {
        let (col, row) = ((i % columns) as u32, (i / columns) as u32);
        let x = pad + col * cell_w;
        let y = title_h + pad + row * cell_h;
        canvas.blit_scaled(&frames[src], i64::from(x), i64::from(y), tw, th);
        let backward =
            i > 0 && opts.backward_window > 0 && crate::sdpf::is_backward_step(order[i - 1], src, opts.backward_window);
        let (border, word) = if opts.cuts.contains(&i) {
            (CUT, " CUT")
        } else if opts.loops.contains(&i) {
            (LOOP, " LOOP")
        } else if opts.transitions.contains(&i) {
            (MATCH, " MATCH")
        } else if backward {
            (BACKWARD, " BACK")
        } else if is_jump(order, i) {
            (JUMP, "")
        } else {
            (SOURCE_STEP, "")
        };
        let thick = if word.is_empty() { 2 } else { 3 };
        if i > 0 {
            for inset in 0..thick {
                let k = inset as f32;
                canvas.rect_outline(
                    x as f32 - 1.0 - k,
                    y as f32 - 1.0 - k,
                    (tw + 2) as f32 + 2.0 * k,
                    (th + 2) as f32 + 2.0 * k,
                    border,
                );
            }
        }
        let label = format!("{i}: frame {src}{word}");
        let lx = x as f32 + (tw as f32 - text_width(&label, LABEL_SIZE)).max(0.0) / 2.0;
        canvas.text((lx, (y + th + 2) as f32), &label, LABEL_SIZE, INK);
    }
    Ok(canvas.into_image())
}

/// [`contact_sheet`] written as a PNG (atomic write).
pub fn write_contact_sheet(
    path: &Path,
    frames: &[RgbImage],
    order: &[usize],
    opts: &SheetOptions,
) -> Result<(), VideoError> {
    let img = contact_sheet(frames, order, opts)?;
    write_png(path, &img).map_err(|e| VideoError::Encode { path: path.to_path_buf(), message: e.to_string() })
}

/// A heat map of an `n`×`n` distance matrix (row-major), dark = near, light = far, scaled so that
/// each cell is at least `cell` pixels (the paper's Fig. 12).
pub fn distance_heatmap(dist: &[f32], n: usize, cell: u32) -> Result<RgbImage, VideoError> {
    if n == 0 || dist.len() != n * n {
        return Err(VideoError::Invalid(format!(
            "a distance heat map needs n×n values, got {} for n = {n}",
            dist.len()
        )));
    }
    let finite = dist.iter().copied().filter(|d| d.is_finite());
    let (lo, hi) = finite.fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), d| (lo.min(d), hi.max(d)));
    let span = if hi > lo { hi - lo } else { 1.0 };
    let cell = cell.max(1);
    let side = n as u32 * cell;
    let img = RgbImage::from_fn(side, side, |x, y| {
        let d = dist[(y / cell) as usize * n + (x / cell) as usize];
        let t = if d.is_finite() { ((d - lo) / span).clamp(0.0, 1.0) } else { 1.0 };
        heat(t)
    });
    Ok(img)
}

/// Dark blue (0) → teal → yellow (1).
fn heat(t: f32) -> image::Rgb<u8> {
    let stops = [(0.0, [20.0, 24.0, 82.0]), (0.5, [33.0, 145.0, 140.0]), (1.0, [253.0, 231.0, 37.0])];
    let (a, b) = if t <= 0.5 { (stops[0], stops[1]) } else { (stops[1], stops[2]) };
    let u = (t - a.0) / (b.0 - a.0);
    let mix = |i: usize| (a.1[i] + (b.1[i] - a.1[i]) * u).round() as u8;
    image::Rgb([mix(0), mix(1), mix(2)])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn solid(v: u8) -> RgbImage {
        RgbImage::from_pixel(32, 18, image::Rgb([v, v, v]))
    }

    #[test]
    fn sheet_has_one_cell_per_position_and_marks_jumps() {
        let frames: Vec<RgbImage> = (0..6).map(|i| solid(i as u8 * 40)).collect();
        let order = [2, 3, 4, 0, 1];
        assert!(!is_jump(&order, 0));
        assert!(!is_jump(&order, 1));
        assert!(is_jump(&order, 3));
        let opts = SheetOptions { columns: 3, thumb_width: 64, title: "t".into(), ..SheetOptions::default() };
        let img = contact_sheet(&frames, &order, &opts).unwrap();
        assert_eq!(img.width(), 6 + 3 * 70);
        // The thumbnail of position 4 (row 1, column 1) shows source frame 1.
        let (x, y) = (6 + 70 + 32, 26 + 6 + (36 + 17 + 6) + 18);
        assert_eq!(img.get_pixel(x, y).0, [40, 40, 40]);
        // Position 3 jumps (4 → 0): orange frame; position 1 follows the source: green.
        let y3 = 26 + 6 + (36 + 17 + 6) - 1;
        assert_eq!(img.get_pixel(6 + 10, y3).0, JUMP);
        assert_eq!(img.get_pixel(6 + 70 + 10, 26 + 6 - 1).0, SOURCE_STEP);
    }

    #[test]
    fn sheet_refuses_bad_orders() {
        let frames = vec![solid(0); 3];
        assert!(contact_sheet(&frames, &[0, 3], &SheetOptions::default()).unwrap_err().to_string().contains("frame 3"));
        assert!(contact_sheet(&[], &[], &SheetOptions::default()).is_err());
    }

    #[test]
    fn heatmap_maps_near_to_dark_and_far_to_light() {
        let d = [0.0, 2.0, 2.0, 0.0];
        let img = distance_heatmap(&d, 2, 3).unwrap();
        assert_eq!(img.dimensions(), (6, 6));
        assert_eq!(img.get_pixel(0, 0).0, [20, 24, 82]);
        assert_eq!(img.get_pixel(4, 0).0, [253, 231, 37]);
        assert!(distance_heatmap(&d, 3, 1).is_err());
    }
}
