//! PNG charts (line, scatter, grouped bars) drawn with plotters.
//!
//! plotters' default text path asks fontconfig for system fonts, which a fresh CI machine does not
//! have. We build plotters with its `ab_glyph` text backend instead and register Noto Sans (SIL Open
//! Font License, bytes shipped by the `notosans` crate) as the "sans-serif" family, so labels render
//! identically everywhere.

use crate::stick::DEFAULT_COLORS;
use crate::RenderError;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::Path;
use std::sync::OnceLock;

/// One named curve or point set.
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    pub name: String,
    pub points: Vec<(f64, f64)>,
    /// None picks the next default colour.
    pub color: Option<[u8; 3]>,
}

impl Series {
    pub fn new(name: impl Into<String>, points: Vec<(f64, f64)>) -> Series {
        Series { name: name.into(), points, color: None }
    }
}

/// Chart size in pixels.
pub const PLOT_WIDTH: u32 = 900;
pub const PLOT_HEIGHT: u32 = 560;
const FONT: &str = "sans-serif";
/// Charts are drawn at this multiple of the output size and averaged down, which anti-aliases the
/// lines, markers and text that plotters' bitmap backend draws with hard edges.
const SUPERSAMPLE: i32 = 2;
const TITLE_SIZE: i32 = 26 * SUPERSAMPLE;
const LABEL_SIZE: i32 = 17 * SUPERSAMPLE;

/// A length in output pixels, in the supersampled drawing.
const fn px(v: i32) -> i32 {
    v * SUPERSAMPLE
}

/// Registers the bundled font with plotters once per process.
pub(crate) fn ensure_fonts() -> Result<(), RenderError> {
    static DONE: OnceLock<bool> = OnceLock::new();
    let ok = *DONE.get_or_init(|| {
        let regular = plotters::style::register_font(FONT, FontStyle::Normal, notosans::REGULAR_TTF).is_ok();
        let bold = plotters::style::register_font(FONT, FontStyle::Bold, notosans::BOLD_TTF).is_ok();
        regular && bold
    });
    if ok {
        Ok(())
    } else {
        Err(RenderError::Encode("the bundled Noto Sans font could not be registered with plotters".into()))
    }
}

fn plot_err(title: &str, e: impl std::fmt::Display) -> RenderError {
    RenderError::Plot { title: title.to_string(), message: e.to_string() }
}

fn rgb(c: [u8; 3]) -> RGBColor {
    RGBColor(c[0], c[1], c[2])
}

fn series_color(series: &Series, i: usize) -> RGBColor {
    rgb(series.color.unwrap_or(DEFAULT_COLORS[i % DEFAULT_COLORS.len()]))
}

/// `lo..hi` widened by 5% on each side; a single value becomes a unit-wide range around it.
fn padded(lo: f64, hi: f64) -> std::ops::Range<f64> {
    let span = hi - lo;
    if span <= f64::EPSILON * hi.abs().max(1.0) {
        let half = (lo.abs() * 0.1).max(0.5);
        return lo - half..hi + half;
    }
    lo - span * 0.05..hi + span * 0.05
}

/// Data ranges over all series, rejecting empty input and non-finite points.
fn data_ranges(title: &str, series: &[Series]) -> Result<(std::ops::Range<f64>, std::ops::Range<f64>), RenderError> {
    let mut lo = (f64::INFINITY, f64::INFINITY);
    let mut hi = (f64::NEG_INFINITY, f64::NEG_INFINITY);
    for s in series {
        if let Some(i) = s.points.iter().position(|p| !(p.0.is_finite() && p.1.is_finite())) {
            return Err(plot_err(title, format!("series '{}', point {i}: {:?} is not finite", s.name, s.points[i])));
        }
        for &(x, y) in &s.points {
            lo = (lo.0.min(x), lo.1.min(y));
            hi = (hi.0.max(x), hi.1.max(y));
        }
    }
    if !lo.0.is_finite() {
        return Err(plot_err(title, "no data points in any series"));
    }
    Ok((padded(lo.0, hi.0), padded(lo.1, hi.1)))
}

/// Draws into an RGB buffer with plotters, then writes it as PNG.
fn render_png(
    path: &Path,
    title: &str,
    draw: impl FnOnce(&DrawingArea<BitMapBackend<'_>, Shift>) -> Result<(), RenderError>,
) -> Result<(), RenderError> {
    ensure_fonts()?;
    let (w, h) = (PLOT_WIDTH * SUPERSAMPLE as u32, PLOT_HEIGHT * SUPERSAMPLE as u32);
    let mut buf = vec![255u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| plot_err(title, e))?;
        draw(&root)?;
        root.present().map_err(|e| plot_err(title, e))?;
    }
    let big = image::RgbImage::from_raw(w, h, buf).expect("buffer has the chart's size");
    crate::write_png(path, &downsample(&big, SUPERSAMPLE as u32))
}

#[derive(Clone, Copy, PartialEq)]
enum Style {
    Lines,
    Points,
}

fn xy_chart(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
    style: Style,
) -> Result<(), RenderError> {
    let (xr, yr) = data_ranges(title, series)?;
    let legend_corner = emptiest_corner(series, &xr, &yr);
    render_png(path, title, |root| {
        let e = |e: DrawingAreaErrorKind<_>| plot_err(title, e);
        let mut chart = house_axes(root, title, XAxis::Numeric(x_label), xr, y_label, yr)?;
        for (i, s) in series.iter().enumerate() {
            let color = series_color(s, i);
            let anno = match style {
                Style::Lines => {
                    chart.draw_series(LineSeries::new(s.points.iter().copied(), color.stroke_width(px(2) as u32)))
                }
                Style::Points => chart.draw_series(s.points.iter().map(|&p| Circle::new(p, px(3), color.filled()))),
            }
            .map_err(e)?;
            if !s.name.is_empty() {
                anno.label(s.name.as_str()).legend(move |(x, y)| match style {
                    Style::Lines => Rectangle::new([(x, y - px(1)), (x + px(22), y + px(1))], color.filled()),
                    Style::Points => Rectangle::new([(x + px(7), y - px(4)), (x + px(15), y + px(4))], color.filled()),
                });
            }
        }
        if series.iter().any(|s| !s.name.is_empty()) {
            chart
                .configure_series_labels()
                .label_font((FONT, LABEL_SIZE))
                .background_style(WHITE.mix(0.85))
                .border_style(RGBColor(180, 180, 180).stroke_width(px(1) as u32))
                .margin(px(8))
                .legend_area_size(px(30))
                .position(legend_corner)
                .draw()
                .map_err(e)?;
        }
        Ok(())
    })
}

/// The corner of the plot whose box (45% of the width, 40% of the height) covers the fewest data
/// points, so the legend hides as little as possible (ties go to the upper right).
fn emptiest_corner(series: &[Series], xr: &std::ops::Range<f64>, yr: &std::ops::Range<f64>) -> SeriesLabelPosition {
    let (w, h) = ((xr.end - xr.start).max(1e-12), (yr.end - yr.start).max(1e-12));
    let count = |right: bool, upper: bool| {
        let points = series.iter().flat_map(|s| s.points.iter());
        points
            .filter(|&&(x, y)| {
                let (fx, fy) = ((x - xr.start) / w, (y - yr.start) / h);
                (if right { fx >= 0.55 } else { fx <= 0.45 }) && (if upper { fy >= 0.6 } else { fy <= 0.4 })
            })
            .count()
    };
    let corners = [
        (SeriesLabelPosition::UpperRight, count(true, true)),
        (SeriesLabelPosition::UpperLeft, count(false, true)),
        (SeriesLabelPosition::LowerRight, count(true, false)),
        (SeriesLabelPosition::LowerLeft, count(false, false)),
    ];
    corners.into_iter().min_by_key(|c| c.1).map_or(SeriesLabelPosition::UpperRight, |c| c.0)
}

/// Line chart of one or more curves (points joined in the given order).
pub fn line_plot(path: &Path, title: &str, x_label: &str, y_label: &str, series: &[Series]) -> Result<(), RenderError> {
    xy_chart(path, title, x_label, y_label, series, Style::Lines)
}

/// Scatter chart of one or more point sets.
pub fn scatter_plot(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
) -> Result<(), RenderError> {
    xy_chart(path, title, x_label, y_label, series, Style::Points)
}

/// Grouped bar chart: `series[s].1[g]` is the bar of series `s` in group `g` (e.g. error per
/// method, grouped by clip).
pub fn grouped_bar_chart(
    path: &Path,
    title: &str,
    y_label: &str,
    groups: &[String],
    series: &[(String, Vec<f64>)],
) -> Result<(), RenderError> {
    if groups.is_empty() || series.is_empty() {
        return Err(plot_err(title, "a bar chart needs at least one group and one series"));
    }
    for (name, values) in series {
        if values.len() != groups.len() {
            return Err(plot_err(
                title,
                format!("series '{name}' has {} values for {} groups", values.len(), groups.len()),
            ));
        }
        if let Some(g) = values.iter().position(|v| !v.is_finite()) {
            return Err(plot_err(title, format!("series '{name}', group '{}': value is not finite", groups[g])));
        }
    }
    let all = series.iter().flat_map(|s| s.1.iter().copied());
    let (lo, hi) = all.fold((0.0f64, 0.0f64), |(a, b), v| (a.min(v), b.max(v)));
    let span = (hi - lo).max(1e-12);
    let yr = if lo < 0.0 { lo - span * 0.05 } else { 0.0 }..if hi > 0.0 { hi + span * 0.08 } else { span * 0.05 };
    let n = groups.len() as f64;
    // Each group is one unit wide: bars fill 80% of it, side by side.
    let bar_w = 0.8 / series.len() as f64;
    render_png(path, title, |root| {
        let e = |e: DrawingAreaErrorKind<_>| plot_err(title, e);
        let mut chart = house_axes(root, title, XAxis::Groups, 0.0..n, y_label, yr.clone())?;
        for (s, (name, values)) in series.iter().enumerate() {
            let color = rgb(DEFAULT_COLORS[s % DEFAULT_COLORS.len()]);
            chart
                .draw_series(values.iter().enumerate().map(|(g, &v)| {
                    let x0 = g as f64 + 0.1 + s as f64 * bar_w;
                    Rectangle::new([(x0, 0.0), (x0 + bar_w * 0.92, v)], color.filled())
                }))
                .map_err(e)?
                .label(name.as_str())
                .legend(move |(x, y)| {
                    Rectangle::new([(x + px(4), y - px(5)), (x + px(14), y + px(5))], color.filled())
                });
        }
        legend_and_groups(&mut chart, root, groups, yr.start, SeriesLabelPosition::UpperRight, title)
    })
}

/// The legend box and, under the x axis, each group's name centred on its unit-wide slot (the
/// grouped charts: bars and box plots).
fn legend_and_groups<'a>(
    chart: &mut ChartContext<
        'a,
        BitMapBackend<'a>,
        Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
    >,
    root: &DrawingArea<BitMapBackend<'a>, Shift>,
    groups: &[String],
    y_floor: f64,
    position: SeriesLabelPosition,
    title: &str,
) -> Result<(), RenderError> {
    let e = |e: DrawingAreaErrorKind<_>| plot_err(title, e);
    chart
        .configure_series_labels()
        .label_font((FONT, LABEL_SIZE))
        .background_style(WHITE.mix(0.85))
        .border_style(RGBColor(180, 180, 180).stroke_width(px(1) as u32))
        .margin(px(8))
        .legend_area_size(px(30))
        .position(position)
        .draw()
        .map_err(e)?;
    let style = TextStyle::from((FONT, LABEL_SIZE).into_font()).pos(Pos::new(HPos::Center, VPos::Top));
    for (g, name) in groups.iter().enumerate() {
        let (bx, by) = chart.backend_coord(&(g as f64 + 0.5, y_floor));
        root.draw(&Text::new(name.as_str(), (bx, by + px(8)), style.clone())).map_err(e)?;
    }
    Ok(())
}

/// Five-number summary (min, lower quartile, median, upper quartile, max) of `values`, with
/// quartiles by linear interpolation between order statistics. `None` for no finite value.
pub fn five_numbers(values: &[f64]) -> Option<[f64; 5]> {
    let v = inbetween_core::stats::sorted_finite(values);
    if v.is_empty() {
        return None;
    }
    let q = |p: f64| inbetween_core::stats::quantile_sorted(&v, p);
    Some([v[0], q(0.25), q(0.5), q(0.75), v[v.len() - 1]])
}

/// Box plot: `series[s].1[g]` holds the samples of series `s` in group `g` (e.g. matching scores per
/// method, grouped by query-set size). Boxes span the quartiles, the bar inside is the median and
/// whiskers reach the extremes.
pub fn box_plot(
    path: &Path,
    title: &str,
    y_label: &str,
    groups: &[String],
    series: &[(String, Vec<Vec<f64>>)],
) -> Result<(), RenderError> {
    if groups.is_empty() || series.is_empty() {
        return Err(plot_err(title, "a box plot needs at least one group and one series"));
    }
    let mut summaries = Vec::new();
    for (name, per_group) in series {
        if per_group.len() != groups.len() {
            return Err(plot_err(
                title,
                format!("series '{name}' has {} sample sets for {} groups", per_group.len(), groups.len()),
            ));
        }
        let mut row = Vec::new();
        for (g, samples) in per_group.iter().enumerate() {
            let five = five_numbers(samples)
                .ok_or_else(|| plot_err(title, format!("series '{name}', group '{}': no finite sample", groups[g])))?;
            row.push(five);
        }
        summaries.push(row);
    }
    let (lo, hi) =
        summaries.iter().flatten().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), f| (a.min(f[0]), b.max(f[4])));
    let span = (hi - lo).max(1e-9);
    // Room below the data for the legend.
    let yr = (lo - span * 0.3)..(hi + span * 0.12);
    let n = groups.len() as f64;
    let box_w = 0.8 / series.len() as f64;
    render_png(path, title, |root| {
        let e = |e: DrawingAreaErrorKind<_>| plot_err(title, e);
        let mut chart = house_axes(root, title, XAxis::Groups, 0.0..n, y_label, yr.clone())?;
        for (s, (name, _)) in series.iter().enumerate() {
            let color = rgb(DEFAULT_COLORS[s % DEFAULT_COLORS.len()]);
            let stroke = color.stroke_width(px(2) as u32);
            let mut elements: Vec<PathElement<(f64, f64)>> = Vec::new();
            let mut boxes = Vec::new();
            for (g, f) in summaries[s].iter().enumerate() {
                let x0 = g as f64 + 0.1 + s as f64 * box_w + box_w * 0.1;
                let x1 = x0 + box_w * 0.8;
                let xm = (x0 + x1) / 2.0;
                boxes.push(Rectangle::new([(x0, f[1]), (x1, f[3])], color.mix(0.35).filled()));
                elements.push(PathElement::new(vec![(x0, f[2]), (x1, f[2])], stroke));
                elements.push(PathElement::new(vec![(xm, f[0]), (xm, f[1])], stroke));
                elements.push(PathElement::new(vec![(xm, f[3]), (xm, f[4])], stroke));
                let cap = box_w * 0.2;
                elements.push(PathElement::new(vec![(xm - cap, f[0]), (xm + cap, f[0])], stroke));
                elements.push(PathElement::new(vec![(xm - cap, f[4]), (xm + cap, f[4])], stroke));
                elements
                    .push(PathElement::new(vec![(x0, f[1]), (x1, f[1]), (x1, f[3]), (x0, f[3]), (x0, f[1])], stroke));
            }
            chart.draw_series(boxes).map_err(e)?.label(name.as_str()).legend(move |(x, y)| {
                Rectangle::new([(x + px(4), y - px(5)), (x + px(14), y + px(5))], color.filled())
            });
            chart.draw_series(elements).map_err(e)?;
        }
        legend_and_groups(&mut chart, root, groups, yr.start, SeriesLabelPosition::LowerLeft, title)
    })
}

/// Averages each `factor` × `factor` block into one pixel.
pub(crate) fn downsample(big: &image::RgbImage, factor: u32) -> image::RgbImage {
    let (w, h) = (big.width() / factor, big.height() / factor);
    let n = factor * factor;
    image::RgbImage::from_fn(w, h, |x, y| {
        let mut sum = [0u32; 3];
        for dy in 0..factor {
            for dx in 0..factor {
                let p = big.get_pixel(x * factor + dx, y * factor + dy).0;
                for c in 0..3 {
                    sum[c] += p[c] as u32;
                }
            }
        }
        image::Rgb(sum.map(|v| ((v + n / 2) / n) as u8))
    })
}

/// What the x axis of [`house_axes`] shows.
enum XAxis<'l> {
    /// Numbers, with this description under them.
    Numeric(&'l str),
    /// Side-by-side groups, one unit of x each: no x labels or grid (the caller writes the names).
    Groups,
}

/// A chart's axes over `xr` × `yr` with the caption and the house grid drawn.
fn house_axes<'a>(
    root: &DrawingArea<BitMapBackend<'a>, Shift>,
    title: &str,
    x: XAxis<'_>,
    xr: std::ops::Range<f64>,
    y_label: &str,
    yr: std::ops::Range<f64>,
) -> Result<
    ChartContext<
        'a,
        BitMapBackend<'a>,
        Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
    >,
    RenderError,
> {
    let e = |e: DrawingAreaErrorKind<_>| plot_err(title, e);
    let x_area = match x {
        XAxis::Numeric(_) => px(52),
        XAxis::Groups => px(40),
    };
    let mut chart = ChartBuilder::on(root)
        .caption(title, (FONT, TITLE_SIZE).into_font())
        .margin(px(18))
        .x_label_area_size(x_area)
        .y_label_area_size(px(78))
        .build_cartesian_2d(xr, yr)
        .map_err(e)?;
    let mut mesh = chart.configure_mesh();
    match x {
        XAxis::Numeric(label) => mesh.x_desc(label),
        XAxis::Groups => mesh.disable_x_mesh().x_labels(0),
    };
    house_mesh(mesh.y_desc(y_label)).draw().map_err(e)?;
    Ok(chart)
}

/// The shared look of every chart's axes and grid: fonts, light grid lines, tick marks.
fn house_mesh<'m, 'a, 'b, X, Y, DB>(
    mesh: &'m mut plotters::chart::MeshStyle<'a, 'b, X, Y, DB>,
) -> &'m mut plotters::chart::MeshStyle<'a, 'b, X, Y, DB>
where
    X: plotters::coord::ranged1d::Ranged,
    Y: plotters::coord::ranged1d::Ranged,
    DB: DrawingBackend,
{
    mesh.label_style((FONT, LABEL_SIZE))
        .axis_desc_style((FONT, LABEL_SIZE + 1))
        .max_light_lines(4)
        .light_line_style(RGBColor(238, 238, 238).stroke_width(px(1) as u32))
        .bold_line_style(RGBColor(214, 214, 214).stroke_width(px(1) as u32))
        .axis_style(RGBColor(60, 60, 60).stroke_width(px(1) as u32))
        .set_all_tick_mark_size(px(5))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn five_numbers_match_hand_computed_quartiles() {
        let f = five_numbers(&[4.0, 1.0, 3.0, 2.0, 5.0, f64::NAN]).unwrap();
        assert_eq!(f, [1.0, 2.0, 3.0, 4.0, 5.0]);
        let f = five_numbers(&[0.0, 1.0]).unwrap();
        assert_eq!(f, [0.0, 0.25, 0.5, 0.75, 1.0]);
        assert!(five_numbers(&[f64::NAN]).is_none());
    }

    #[test]
    fn a_box_plot_draws_and_refuses_ragged_input() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("box.png");
        let groups = vec!["5".to_string(), "10".to_string()];
        let series = vec![
            ("a".to_string(), vec![vec![0.5, 0.6, 0.7], vec![0.4, 0.8]]),
            ("b".to_string(), vec![vec![0.2, 0.3], vec![0.1, 0.9, 0.5]]),
        ];
        box_plot(&path, "scores", "score", &groups, &series).unwrap();
        let img = image::open(&path).unwrap().to_rgb8();
        assert_eq!((img.width(), img.height()), (PLOT_WIDTH, PLOT_HEIGHT));
        let ragged = vec![("a".to_string(), vec![vec![0.5]])];
        assert!(box_plot(&path, "scores", "score", &groups, &ragged).is_err());
    }

    #[test]
    fn the_legend_goes_to_the_corner_without_data() {
        let crowded_upper_right =
            Series { name: "a".into(), points: vec![(0.0, 0.0), (0.9, 0.9), (1.0, 1.0), (0.95, 0.8)], color: None };
        let (xr, yr) = (0.0..1.0, 0.0..1.0);
        let corner = emptiest_corner(std::slice::from_ref(&crowded_upper_right), &xr, &yr);
        assert!(matches!(corner, SeriesLabelPosition::UpperLeft), "upper right holds 3 points, upper left none");
        let empty = Series { name: "b".into(), points: vec![], color: None };
        assert!(matches!(emptiest_corner(&[empty], &xr, &yr), SeriesLabelPosition::UpperRight));
    }

    fn dark_pixels(img: &image::RgbImage, region: (u32, u32, u32, u32)) -> usize {
        let (x0, y0, x1, y1) = region;
        (y0..y1)
            .flat_map(|y| (x0..x1).map(move |x| (x, y)))
            .filter(|&(x, y)| img.get_pixel(x, y).0.iter().all(|&v| v < 120))
            .count()
    }

    #[test]
    fn line_plot_renders_title_and_axis_text() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("line.png");
        let sine: Vec<(f64, f64)> = (0..100).map(|i| (i as f64 * 0.1, (i as f64 * 0.1).sin())).collect();
        let cosine: Vec<(f64, f64)> = (0..100).map(|i| (i as f64 * 0.1, (i as f64 * 0.1).cos())).collect();
        line_plot(
            &path,
            "Error over time",
            "time (s)",
            "error (cm)",
            &[Series::new("sin", sine), Series::new("cos", cosine)],
        )
        .unwrap();
        let img = image::open(&path).unwrap().to_rgb8();
        assert_eq!(img.dimensions(), (PLOT_WIDTH, PLOT_HEIGHT));
        // Title band across the top centre: text pixels, not an empty strip.
        let title = dark_pixels(&img, (PLOT_WIDTH / 2 - 150, 0, PLOT_WIDTH / 2 + 150, 45));
        assert!(title > 150, "title text pixels: {title}");
        // X axis description below the axis.
        let x_desc = dark_pixels(&img, (PLOT_WIDTH / 2 - 100, PLOT_HEIGHT - 40, PLOT_WIDTH / 2 + 100, PLOT_HEIGHT));
        assert!(x_desc > 50, "x label text pixels: {x_desc}");
        // Both curve colours appear.
        for c in &DEFAULT_COLORS[..2] {
            assert!(img.pixels().filter(|p| p.0 == *c).count() > 100);
        }
    }

    #[test]
    fn scatter_and_bars_render() {
        let dir = tempfile::tempdir().unwrap();
        let scatter = dir.path().join("s.png");
        let pts: Vec<(f64, f64)> = (0..30).map(|i| (i as f64, (i * i % 17) as f64)).collect();
        scatter_plot(&scatter, "Scatter", "x", "y", &[Series::new("", pts)]).unwrap();
        assert!(image::open(&scatter).is_ok());
        let bars = dir.path().join("b.png");
        let groups = vec!["walk".to_string(), "run".to_string(), "jump".to_string()];
        let series = vec![("uniform".to_string(), vec![3.0, 5.0, 4.0]), ("SIDQL".to_string(), vec![1.5, 2.5, 2.0])];
        grouped_bar_chart(&bars, "Reconstruction error", "cm", &groups, &series).unwrap();
        let img = image::open(&bars).unwrap().to_rgb8();
        // Group labels sit in the band under the plot area.
        let labels = dark_pixels(&img, (80, PLOT_HEIGHT - 60, PLOT_WIDTH - 20, PLOT_HEIGHT - 5));
        assert!(labels > 60, "group label pixels: {labels}");
        assert!(img.pixels().filter(|p| p.0 == DEFAULT_COLORS[1]).count() > 1000, "red bars drawn");
    }

    #[test]
    fn bad_plot_input_is_a_clear_error() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("x.png");
        let err = line_plot(&p, "t", "x", "y", &[Series::new("a", vec![(0.0, 1.0), (1.0, f64::NAN)])])
            .unwrap_err()
            .to_string();
        assert!(err.contains("series 'a', point 1"), "{err}");
        assert!(line_plot(&p, "t", "x", "y", &[]).is_err());
        let err =
            grouped_bar_chart(&p, "t", "y", &["a".into()], &[("s".into(), vec![1.0, 2.0])]).unwrap_err().to_string();
        assert!(err.contains("2 values for 1 groups"), "{err}");
        assert!(!p.exists());
    }
}
