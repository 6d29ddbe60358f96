//! A PNG of edited curves: one small panel per curve, stacked, each showing the curve before
//! (grey) and after (blue) an edit, an optional third curve (a baseline or a guide, dashed green),
//! the edited spans shaded and the constraints (e.g. keyframes) as red dots. Time runs along x in
//! seconds. Drawn with plotters like [`crate::plot`], in the same bundled font, supersampled for
//! smooth lines.

use crate::canvas::text_width;
use crate::RenderError;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::ops::Range;
use std::path::Path;

/// One curve of an [`EditPlot`]: values per frame, before and after the edit.
#[derive(Clone, Debug, PartialEq)]
pub struct EditCurve {
    pub name: String,
    pub before: Vec<f32>,
    pub after: Vec<f32>,
    /// A third curve to compare with (e.g. ("linear", baseline) or ("guide", noisy input)).
    pub extra: Option<(String, Vec<f32>)>,
}

/// Everything [`write_edit_plot`] draws.
#[derive(Clone, Debug, PartialEq)]
pub struct EditPlot {
    pub title: String,
    /// Time of each frame in seconds (non-decreasing); every curve has one value per time.
    pub times_s: Vec<f64>,
    pub curves: Vec<EditCurve>,
    /// Edited (masked) time spans `(start_s, end_s)`, shaded.
    pub spans: Vec<(f64, f64)>,
    /// Constraints drawn as dots: (curve name, time in seconds, value).
    pub markers: Vec<(String, f64, f32)>,
    /// Legend names of the before and after curves and of the markers.
    pub before_label: String,
    pub after_label: String,
    pub marker_label: String,
}

impl EditPlot {
    /// An empty plot with legend names "original", "edited" and "key".
    pub fn new(title: impl Into<String>, times_s: Vec<f64>) -> EditPlot {
        EditPlot {
            title: title.into(),
            times_s,
            curves: Vec::new(),
            spans: Vec::new(),
            markers: Vec::new(),
            before_label: "original".into(),
            after_label: "edited".into(),
            marker_label: "key".into(),
        }
    }
}

/// Output width and layout heights, in output pixels.
pub const EDIT_PLOT_WIDTH: u32 = 900;
const TITLE_H: u32 = 40;
const LEGEND_H: u32 = 30;
const PANEL_H: u32 = 132;
/// Extra height of the bottom panel for the time axis description.
const AXIS_H: u32 = 26;
/// Most curves one plot stacks.
pub const MAX_EDIT_CURVES: usize = 24;

/// Colours: before, after, extra, markers, shaded spans.
pub const BEFORE_COLOR: [u8; 3] = [150, 150, 150];
pub const AFTER_COLOR: [u8; 3] = [31, 119, 180];
pub const EXTRA_COLOR: [u8; 3] = [44, 160, 44];
pub const MARKER_COLOR: [u8; 3] = [214, 39, 40];
pub const SPAN_COLOR: [u8; 3] = [255, 231, 196];

const FONT: &str = "sans-serif";
const SUPERSAMPLE: u32 = 2;

/// A length in output pixels, in the supersampled drawing.
const fn px(v: u32) -> i32 {
    (v * SUPERSAMPLE) as i32
}

/// Height in output pixels of a plot of `curves` curves.
pub fn edit_plot_height(curves: usize) -> u32 {
    TITLE_H + LEGEND_H + curves as u32 * PANEL_H + AXIS_H
}

fn rgb(c: [u8; 3]) -> RGBColor {
    RGBColor(c[0], c[1], c[2])
}

fn err(plot: &EditPlot, message: impl std::fmt::Display) -> RenderError {
    RenderError::Plot { title: plot.title.clone(), message: message.to_string() }
}

/// Rejects plots that cannot be drawn: no curves or times, length mismatches, non-finite values,
/// decreasing times, bad spans, markers on unknown curves.
fn check(plot: &EditPlot) -> Result<(), RenderError> {
    let n = plot.times_s.len();
    if n == 0 || plot.curves.is_empty() {
        return Err(err(plot, "an edit plot needs at least one frame and one curve"));
    }
    if plot.curves.len() > MAX_EDIT_CURVES {
        return Err(err(plot, format!("{} curves; at most {MAX_EDIT_CURVES} fit one plot", plot.curves.len())));
    }
    if let Some(i) = plot.times_s.iter().position(|t| !t.is_finite()) {
        return Err(err(plot, format!("time of frame {i} is not finite")));
    }
    if let Some(i) = plot.times_s.windows(2).position(|w| w[1] < w[0]) {
        return Err(err(
            plot,
            format!("times decrease at frame {}: {} after {}", i + 1, plot.times_s[i + 1], plot.times_s[i]),
        ));
    }
    for c in &plot.curves {
        let mut series = vec![("before", &c.before), ("after", &c.after)];
        if let Some((_, v)) = &c.extra {
            series.push(("extra", v));
        }
        for (what, v) in series {
            if v.len() != n {
                return Err(err(plot, format!("curve '{}': {what} has {} values for {n} frames", c.name, v.len())));
            }
            if let Some(i) = v.iter().position(|x| !x.is_finite()) {
                return Err(err(plot, format!("curve '{}': {what} value at frame {i} is not finite", c.name)));
            }
        }
    }
    if let Some(s) = plot.spans.iter().find(|s| !(s.0.is_finite() && s.1.is_finite() && s.0 <= s.1)) {
        return Err(err(plot, format!("span {:?} must be finite with start <= end", s)));
    }
    for (name, t, v) in &plot.markers {
        if !plot.curves.iter().any(|c| &c.name == name) {
            return Err(err(plot, format!("marker at {t} s names curve '{name}', which is not plotted")));
        }
        if !(t.is_finite() && v.is_finite()) {
            return Err(err(plot, format!("marker on '{name}' at ({t}, {v}) is not finite")));
        }
    }
    Ok(())
}

/// Time axis range: the frames' times (one second around a single frame).
fn time_range(times: &[f64]) -> Range<f64> {
    let (lo, hi) = (times[0], times[times.len() - 1]);
    if hi - lo < 1e-9 {
        lo - 0.5..hi + 0.5
    } else {
        lo..hi
    }
}

/// Value range of one panel: from 0 (or the lowest value) to a little above the highest value.
fn value_range(plot: &EditPlot, c: &EditCurve) -> Range<f64> {
    let markers = plot.markers.iter().filter(|m| m.0 == c.name).map(|m| m.2);
    let extra = c.extra.iter().flat_map(|e| e.1.iter().copied());
    let all = c.before.iter().copied().chain(c.after.iter().copied()).chain(extra).chain(markers);
    let (lo, hi) = all.fold((0.0f64, f64::NEG_INFINITY), |(l, h), v| (l.min(v as f64), h.max(v as f64)));
    let hi = hi.max(lo + 0.05);
    let pad = 0.08 * (hi - lo);
    (if lo < 0.0 { lo - pad } else { lo })..hi + pad
}

/// Renders the plot to an image of [`EDIT_PLOT_WIDTH`] × [`edit_plot_height`] pixels.
pub fn render_edit_plot(plot: &EditPlot) -> Result<image::RgbImage, RenderError> {
    check(plot)?;
    crate::plot::ensure_fonts()?;
    let (w, h) = (EDIT_PLOT_WIDTH * SUPERSAMPLE, edit_plot_height(plot.curves.len()) * SUPERSAMPLE);
    let mut buf = vec![255u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| err(plot, e))?;
        let title = TextStyle::from((FONT, px(22)).into_font()).pos(Pos::new(HPos::Center, VPos::Top));
        root.draw(&Text::new(plot.title.as_str(), (w as i32 / 2, px(8)), title)).map_err(|e| err(plot, e))?;
        draw_legend(&root, plot)?;
        let (_, body) = root.split_vertically(px(TITLE_H + LEGEND_H));
        let breaks: Vec<i32> = (1..plot.curves.len() as u32).map(|i| px(i * PANEL_H)).collect();
        let panels = body.split_by_breakpoints::<i32, i32, _, _>([], &breaks);
        for (i, (area, c)) in panels.iter().zip(&plot.curves).enumerate() {
            draw_panel(area, plot, c, i + 1 == plot.curves.len())?;
        }
        root.present().map_err(|e| err(plot, e))?;
    }
    let big = image::RgbImage::from_raw(w, h, buf).expect("buffer has the plot's size");
    Ok(crate::plot::downsample(&big, SUPERSAMPLE))
}

/// Writes the plot as PNG (atomic write).
pub fn write_edit_plot(path: &Path, plot: &EditPlot) -> Result<(), RenderError> {
    crate::write_png(path, &render_edit_plot(plot)?)
}

/// The legend: one row under the title, entries left to right.
fn draw_legend(root: &DrawingArea<BitMapBackend<'_>, Shift>, plot: &EditPlot) -> Result<(), RenderError> {
    let e = |x| err(plot, x);
    let mut entries: Vec<(String, [u8; 3], u8)> =
        vec![(plot.before_label.clone(), BEFORE_COLOR, 0), (plot.after_label.clone(), AFTER_COLOR, 0)];
    if let Some((name, _)) = plot.curves.iter().find_map(|c| c.extra.as_ref()) {
        entries.push((name.clone(), EXTRA_COLOR, 1));
    }
    if !plot.markers.is_empty() {
        entries.push((plot.marker_label.clone(), MARKER_COLOR, 2));
    }
    if !plot.spans.is_empty() {
        entries.push(("edited span".into(), SPAN_COLOR, 3));
    }
    let size = 15.0;
    let total: f32 = entries.iter().map(|(l, _, _)| 34.0 + text_width(l, size) + 22.0).sum();
    let mut x = ((EDIT_PLOT_WIDTH as f32 - total) * 0.5).max(8.0) as u32;
    let y = TITLE_H + LEGEND_H / 2;
    let style = TextStyle::from((FONT, px(15)).into_font()).pos(Pos::new(HPos::Left, VPos::Center));
    for (label, color, kind) in &entries {
        let c = rgb(*color);
        let (x0, yc) = (px(x), px(y));
        match kind {
            0 => root.draw(&Rectangle::new([(x0, yc - px(1)), (x0 + px(26), yc + px(1))], c.filled())).map_err(e)?,
            1 => {
                for k in 0..3 {
                    let a = x0 + px(k * 10);
                    root.draw(&Rectangle::new([(a, yc - px(1)), (a + px(6), yc + px(1))], c.filled())).map_err(e)?;
                }
            }
            2 => root.draw(&Circle::new((x0 + px(13), yc), px(4), c.filled())).map_err(e)?,
            _ => root.draw(&Rectangle::new([(x0, yc - px(8)), (x0 + px(26), yc + px(8))], c.filled())).map_err(e)?,
        }
        root.draw(&Text::new(label.as_str(), (x0 + px(34), yc), style.clone())).map_err(e)?;
        x += 34 + text_width(label, size).ceil() as u32 + 22;
    }
    Ok(())
}

/// One curve's panel: shaded spans, before, extra, after, markers.
fn draw_panel(
    area: &DrawingArea<BitMapBackend<'_>, Shift>,
    plot: &EditPlot,
    c: &EditCurve,
    last: bool,
) -> Result<(), RenderError> {
    let e = |x| err(plot, x);
    let (xr, yr) = (time_range(&plot.times_s), value_range(plot, c));
    let mut chart = ChartBuilder::on(area)
        .caption(c.name.as_str(), (FONT, px(15)).into_font())
        .margin_left(px(8))
        .margin_right(px(24))
        .margin_bottom(px(2))
        .x_label_area_size(if last { px(44) } else { px(18) })
        .y_label_area_size(px(72))
        .build_cartesian_2d(xr.clone(), yr.clone())
        .map_err(e)?;
    let mut mesh = chart.configure_mesh();
    mesh.label_style((FONT, px(12)))
        .axis_desc_style((FONT, px(13)))
        .y_desc("weight")
        .y_labels(3)
        .x_labels(12)
        .max_light_lines(2)
        .light_line_style(RGBColor(240, 240, 240).stroke_width(px(1) as u32))
        .bold_line_style(RGBColor(218, 218, 218).stroke_width(px(1) as u32))
        .axis_style(RGBColor(60, 60, 60).stroke_width(px(1) as u32))
        .set_all_tick_mark_size(px(4));
    if last {
        mesh.x_desc("time (s)");
    }
    mesh.draw().map_err(e)?;
    let spans = plot.spans.iter().map(|&(a, b)| (a.max(xr.start), b.min(xr.end))).filter(|(a, b)| a < b);
    chart
        .draw_series(spans.map(|(a, b)| Rectangle::new([(a, yr.start), (b, yr.end)], rgb(SPAN_COLOR).filled())))
        .map_err(e)?;
    let points = |v: &[f32]| -> Vec<(f64, f64)> { plot.times_s.iter().zip(v).map(|(&t, &y)| (t, y as f64)).collect() };
    // The original is drawn wider, so it shows beside the edited curve where both agree.
    chart.draw_series(LineSeries::new(points(&c.before), rgb(BEFORE_COLOR).stroke_width(px(4) as u32))).map_err(e)?;
    if let Some((_, v)) = &c.extra {
        let style = rgb(EXTRA_COLOR).stroke_width(px(2) as u32);
        chart.draw_series(DashedLineSeries::new(points(v), px(6), px(4), style)).map_err(e)?;
    }
    chart.draw_series(LineSeries::new(points(&c.after), rgb(AFTER_COLOR).stroke_width(px(2) as u32))).map_err(e)?;
    let marks = plot.markers.iter().filter(|m| m.0 == c.name);
    chart
        .draw_series(marks.map(|m| {
            EmptyElement::at((m.1, m.2 as f64))
                + Circle::new((0, 0), px(5), WHITE.filled())
                + Circle::new((0, 0), px(4), rgb(MARKER_COLOR).filled())
        }))
        .map_err(e)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample_plot() -> EditPlot {
        let n = 101;
        let times: Vec<f64> = (0..n).map(|i| i as f64 * 0.04).collect();
        let wave = |f: f32| -> Vec<f32> { (0..n).map(|i| 0.5 + 0.4 * (i as f32 * f).sin()).collect() };
        let mut plot = EditPlot::new("edit of two curves", times);
        plot.curves.push(EditCurve {
            name: "JawOpen".into(),
            before: wave(0.2),
            after: wave(0.3),
            extra: Some(("linear".into(), wave(0.1))),
        });
        plot.curves.push(EditCurve { name: "EyeBlinkLeft".into(), before: wave(0.5), after: wave(0.5), extra: None });
        // The middle fifth of the time axis is edited.
        plot.spans.push((1.6, 2.4));
        plot.markers.push(("JawOpen".into(), 2.0, 0.9));
        plot
    }

    /// Output-pixel x of time `t` in a panel, approximately (plot area between the y-label area and
    /// the right margin).
    fn approx_x(t: f64, t_end: f64) -> u32 {
        let (left, right) = (8 + 72, EDIT_PLOT_WIDTH - 24);
        left + ((right - left) as f64 * t / t_end) as u32
    }

    fn span_pixels_in_column(img: &image::RgbImage, x: u32) -> usize {
        (0..img.height()).filter(|&y| img.get_pixel(x, y).0 == SPAN_COLOR).count()
    }

    #[test]
    fn plot_has_its_size_and_shades_only_the_span() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("edit.png");
        let plot = sample_plot();
        write_edit_plot(&path, &plot).unwrap();
        let img = image::open(&path).unwrap().to_rgb8();
        assert_eq!(img.dimensions(), (EDIT_PLOT_WIDTH, edit_plot_height(2)));
        // Inside the span, most of both panels' height is shade; outside it, no pixel is.
        let inside = span_pixels_in_column(&img, approx_x(2.2, 4.0));
        assert!(inside > 2 * PANEL_H as usize / 2, "shaded pixels in a column inside the span: {inside}");
        for t in [0.4, 1.2, 2.9, 3.6] {
            assert_eq!(span_pixels_in_column(&img, approx_x(t, 4.0)), 0, "no shade at {t} s");
        }
        // Curves and the marker are drawn in their colours.
        for c in [AFTER_COLOR, BEFORE_COLOR, MARKER_COLOR, EXTRA_COLOR] {
            assert!(img.pixels().filter(|p| p.0 == c).count() > 10, "colour {c:?} is missing");
        }
    }

    #[test]
    fn bad_plots_are_errors_naming_the_problem() {
        let mut p = sample_plot();
        p.curves[1].after.pop();
        assert!(render_edit_plot(&p).unwrap_err().to_string().contains("'EyeBlinkLeft': after has 100 values"));
        let mut p = sample_plot();
        p.curves[0].before[3] = f32::NAN;
        assert!(render_edit_plot(&p).unwrap_err().to_string().contains("frame 3"));
        let mut p = sample_plot();
        p.markers.push(("MouthClose".into(), 1.0, 0.1));
        assert!(render_edit_plot(&p).unwrap_err().to_string().contains("MouthClose"));
        let mut p = sample_plot();
        p.times_s[10] = 0.0;
        assert!(render_edit_plot(&p).unwrap_err().to_string().contains("decrease"));
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bad.png");
        assert!(write_edit_plot(&path, &EditPlot::new("empty", vec![])).is_err());
        assert!(!path.exists());
    }

    #[test]
    fn a_single_frame_still_draws() {
        let mut plot = EditPlot::new("one frame", vec![0.0]);
        plot.curves.push(EditCurve { name: "JawOpen".into(), before: vec![0.2], after: vec![0.3], extra: None });
        let img = render_edit_plot(&plot).unwrap();
        assert_eq!(img.height(), edit_plot_height(1));
    }
}
