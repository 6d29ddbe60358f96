//! The bench's report: every table as text, Markdown and CSV beside the paper's numbers, and its
//! charts.

use crate::dataset::{Behaviour, BEHAVIOURS};
use crate::CameraError;
use inbetween_io::report::{num, Report, Table};
use inbetween_render::plot::{grouped_bar_chart, line_plot, scatter_plot, Series};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

use super::protocol::*;
use super::tables::*;

/// Everything the bench prints and writes.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct BenchReport {
    pub config: BenchConfig,
    pub sequences: usize,
    pub table1: Vec<Table1Row>,
    pub table2: Vec<Table2Row>,
    pub rails: Vec<RailsRow>,
    pub speed: Speed,
    /// How much the style code changes a track: mean distance between the tracks generated through
    /// the same keys with each behaviour's mean style code (0 = style ignored).
    pub style_spread: f64,
    /// (behaviour, main is A, z) of every evaluation sequence, for the PCA plot.
    pub styles: Vec<(Behaviour, bool, Vec<f32>)>,
}

/// A chart's PNG bytes (see [`inbetween_render::rendered_bytes`]), so that [`Report::write`]
/// writes it atomically with the rest.
pub(super) fn chart_bytes(
    name: &str,
    draw: impl FnOnce(&Path) -> Result<(), inbetween_render::RenderError>,
) -> Result<Vec<u8>, CameraError> {
    inbetween_render::rendered_bytes(name, draw).map_err(|e| CameraError::invalid(Path::new(name), e.to_string()))
}

impl BenchReport {
    /// Table 1 (`table1.csv`): ours by initialisation and the straight line, the paper's beside.
    pub fn table1(&self) -> Table {
        let headers = [
            "behaviour",
            "zero",
            "gaussian",
            "warm_start",
            "mapped",
            "toric_lerp",
            "paper_zero",
            "paper_gaussian",
            "paper_warm_start",
            "paper_mapped",
        ];
        let mut t = Table::new(
            "table1",
            "Table 1: trajectory error (Toric units) by hidden-state initialisation, 40 generated steps to a keyframe",
            &headers,
        );
        let mut avg = [0.0; 5];
        for r in &self.table1 {
            let ours = [r.zero, r.gaussian, r.warm_start, r.mapped, r.lerp];
            let paper =
                PAPER_TABLE1.iter().find(|p| p.0 == r.behaviour).map_or([f64::NAN; 4], |p| [p.1, p.2, p.3, p.4]);
            let mut cells = vec![r.behaviour.clone()];
            cells.extend(ours.iter().map(|v| num(*v, 4)));
            cells.extend(paper.iter().map(|v| if v.is_nan() { num(*v, 0) } else { v.to_string() }));
            t.row(cells);
            for (a, v) in avg.iter_mut().zip(ours) {
                *a += v / self.table1.len() as f64;
            }
        }
        let [pz, pg, pw, pm] = PAPER_TABLE1_AVERAGE;
        t.note(format!(
            "average: zero {}, gaussian {}, warm_start {}, mapped {}, toric_lerp {}; paper {pz} / {pg} / {pw} / {pm}",
            num(avg[0], 3),
            num(avg[1], 3),
            num(avg[2], 3),
            num(avg[3], 3),
            num(avg[4], 3)
        ));
        t.note("toric_lerp: no network, the straight Toric line from the start to the key (the baseline to beat)");
        t.note("warm_start reuses our network (the paper trains one per initialisation); paper_*: the paper's Table 1");
        t
    }

    /// Table 2 (`table2.csv`): SD (Eq. 8), TD and KD against the key displacement δ.
    pub fn table2(&self) -> Table {
        let headers = [
            "displacement",
            "sd_ours",
            "sd_only_style",
            "sd_interpolation",
            "td_ours",
            "td_only_style",
            "td_interpolation",
            "kd_ours",
        ];
        let mut t = Table::new("table2", "Table 2: keyframe displacement δ (rad on θ): SD (Eq. 8), TD, KD", &headers);
        for r in &self.table2 {
            let values = [
                r.sd_ours,
                r.sd_only_style,
                r.sd_interpolation,
                r.td_ours,
                r.td_only_style,
                r.td_interpolation,
                r.kd_ours,
            ];
            t.row(std::iter::once(r.displacement.to_string()).chain(values.iter().map(|v| num(*v, 4))));
        }
        let paper = |f: fn(&(f64, f64, f64, f64)) -> f64| {
            PAPER_TABLE2.iter().map(|p| f(p).to_string()).collect::<Vec<_>>().join(" / ")
        };
        let deltas = PAPER_TABLE2.iter().map(|p| p.0.to_string()).collect::<Vec<_>>().join(" / ");
        t.note(format!("paper (its Table 2 \"ours\" rows) at δ = {deltas}:"));
        t.note(format!("paper SD: {}", paper(|p| p.1)));
        t.note(format!("paper TD: {}", paper(|p| p.2)));
        t.note(format!("paper KD: {}", paper(|p| p.3)));
        t.note("SD divides distances measured by each model's own extractor: SD of different weights are on different scales");
        t
    }

    /// §6.3 (`rails.csv`): how many spline keys match our 3-key track.
    pub fn rails_table(&self) -> Table {
        let title =
            "§6.3: keys a Catmull-Rom spline through the ground truth needs to match our 3-key track (300 frames)";
        let mut t = Table::new("rails", title, &["behaviour", "ours_error", "spline_keys", "capped"]);
        for r in &self.rails {
            t.row([r.behaviour.clone(), num(r.ours_error, 4), num(r.spline_keys, 2), r.capped.to_string()]);
        }
        t.note(format!(
            "capped: sequences no spline of up to {} keys matched (counted as {})",
            self.config.max_spline_keys, self.config.max_spline_keys
        ));
        t.note("paper: up to 20 keys for camera-on-rails");
        t
    }

    /// Generation speed (`speed.csv`), frames per second on this machine.
    pub fn speed_table(&self) -> Table {
        let mut t = Table::new("speed", "Speed: frames per second, one thread", &["measure", "frames_per_s", "paper"]);
        t.row(["end to end, one 900-frame track", &num(self.speed.single_frames_per_s, 0), "> 2000"]);
        t.row([
            &format!("network only, {} trajectories batched", self.speed.batch),
            &num(self.speed.batched_frames_per_s, 0),
            "",
        ]);
        t.note("end to end: network every 5th frame, cubic fill, world poses; batched: output frames (5 per step)");
        t
    }

    /// The whole report: the tables, the style effect, `report.json` and the charts (Table 1,
    /// Table 2's TD and SD, the style PCA of Fig. 4) as PNG files.
    pub fn report(&self) -> Result<Report, CameraError> {
        let mut r = Report::new(
            "report",
            &format!("camera bench: {} held-out sequences (seed {})", self.sequences, self.config.seed),
        );
        r.table(self.table1()).table(self.table2()).table(self.rails_table());
        r.text(format!(
            "style effect: tracks through the same keys with the {} behaviour codes differ by {} on average",
            BEHAVIOURS.len(),
            num(self.style_spread, 4)
        ));
        r.table(self.speed_table());
        r.json("report.json", self).map_err(io_error)?;
        r.file("table1.png", self.table1_png()?);
        let (td, sd) = self.table2_pngs()?;
        r.file("table2_td.png", td).file("table2_sd.png", sd);
        r.file("style_pca.png", self.style_pca_png()?);
        Ok(r)
    }

    /// Writes [`BenchReport::report`] into `dir` atomically: report.txt, report.md, the table CSVs,
    /// report.json and the PNG charts. Returns the paths written.
    pub fn write(&self, dir: &Path) -> Result<Vec<PathBuf>, CameraError> {
        self.report()?.write(dir).map_err(io_error)
    }

    fn table1_png(&self) -> Result<Vec<u8>, CameraError> {
        let groups: Vec<String> = self.table1.iter().map(|r| r.behaviour.clone()).collect();
        let col = |f: fn(&Table1Row) -> f64| self.table1.iter().map(f).collect::<Vec<f64>>();
        let series = [
            ("zero".into(), col(|r| r.zero)),
            ("gaussian".into(), col(|r| r.gaussian)),
            ("warm start".into(), col(|r| r.warm_start)),
            ("mapped (H)".into(), col(|r| r.mapped)),
            ("Toric lerp".into(), col(|r| r.lerp)),
            ("paper mapped".into(), PAPER_TABLE1.iter().map(|p| p.4).collect()),
        ];
        chart_bytes("table1.png", |p| {
            grouped_bar_chart(
                p,
                "Table 1: trajectory error by hidden-state initialisation",
                "error (Toric units)",
                &groups,
                &series,
            )
        })
    }

    fn table2_pngs(&self) -> Result<(Vec<u8>, Vec<u8>), CameraError> {
        let series = |name: &str, f: fn(&Table2Row) -> f64| {
            Series::new(name, self.table2.iter().map(|r| (r.displacement, f(r))).collect())
        };
        let td = [
            series("ours", |r| r.td_ours),
            series("only style", |r| r.td_only_style),
            series("Toric lerp", |r| r.td_interpolation),
            series("KD ours", |r| r.kd_ours),
        ];
        let sd = [
            series("ours", |r| r.sd_ours),
            series("only style", |r| r.sd_only_style),
            series("Toric lerp", |r| r.sd_interpolation),
        ];
        Ok((
            chart_bytes("table2_td.png", |p| {
                line_plot(p, "Table 2: TD vs keyframe displacement", "δ (rad)", "TD", &td)
            })?,
            chart_bytes("table2_sd.png", |p| {
                line_plot(p, "Table 2: SD vs keyframe displacement", "δ (rad)", "SD", &sd)
            })?,
        ))
    }

    fn style_pca_png(&self) -> Result<Vec<u8>, CameraError> {
        let codes: Vec<Vec<f32>> = self.styles.iter().map(|s| s.2.clone()).collect();
        let pts = pca2(&codes);
        let mut series = Vec::new();
        for b in BEHAVIOURS {
            for main_is_a in [true, false] {
                let points = self
                    .styles
                    .iter()
                    .zip(&pts)
                    .filter(|(s, _)| s.0 == b && s.1 == main_is_a)
                    .map(|(_, p)| *p)
                    .collect();
                let base = [[31, 119, 180], [44, 160, 44], [255, 127, 14], [214, 39, 40]][b.index()];
                let color = if main_is_a { base } else { base.map(|c: u8| c / 2 + 100) };
                let mut s =
                    Series::new(format!("{} ({} main)", b.name(), if main_is_a { "left" } else { "right" }), points);
                s.color = Some(color);
                series.push(s);
            }
        }
        chart_bytes("style_pca.png", |p| scatter_plot(p, "Style codes z, PCA (Fig. 4)", "PC 1", "PC 2", &series))
    }
}

pub(super) fn io_error(e: inbetween_io::IoError) -> CameraError {
    match e {
        inbetween_io::IoError::Io { path, source } => CameraError::Io { path, source },
        other => CameraError::invalid(Path::new("camera bench"), other.to_string()),
    }
}
