//! The bench's output through the shared harness (`inbetween_io::report`): the paper's Table 3
//! with its figures beside ours, position errors, every row as CSV (`mocap_bench.csv`), the two
//! reconstructions, the codec, throughput and a bar chart (`table3.png`).

use super::measure::{BothReconstructions, CodecRatio, Throughput};
use super::{paper_decision_ms, paper_value, Method, Protocol, Row};
use crate::{MocapError, Result};
use inbetween_io::report::{num, Report, Table};
use std::collections::BTreeSet;
use std::path::Path;

/// The report's table of every row ([`rows_table`], written as `mocap_bench.csv`).
pub const ROWS_TABLE: &str = "mocap_bench";
/// The report's bar chart of the mean angle error (Table 3).
pub const CHART_FILE: &str = "table3.png";

/// Everything one bench run measured (see [`super::run::measure`]).
#[derive(Clone, Debug)]
pub struct BenchResults {
    /// Where the clips came from, as shown in the report.
    pub source: String,
    pub takes: usize,
    /// Takes per source (`4 cgspeed, 1 asf_amc, …`).
    pub sources: String,
    /// Which length unit the clips were read in and why ([`crate::corpus::Corpus::unit_notes`]).
    pub unit_notes: Vec<String>,
    pub protocol: Protocol,
    pub windows: usize,
    pub joints: BTreeSet<usize>,
    pub train: Vec<String>,
    pub test: Vec<String>,
    pub test_windows: usize,
    /// Which SIDQL policy the table scores and what it was trained on.
    pub policy: String,
    /// Lines about SIDQL training when the bench trained one.
    pub log: Vec<String>,
    pub ks: Vec<usize>,
    /// Split `all`, then split `test` when it has windows.
    pub rows: Vec<Row>,
    pub throughput: Throughput,
    pub reconstructions: Vec<BothReconstructions>,
    /// One entry per error bound; empty when no clip is in CMU units.
    pub codec: Vec<CodecRatio>,
    /// The take-level k-fold of SIDQL, when run.
    pub kfold: Option<KFold>,
}

/// The take-level k-fold (see [`super::run::kfold`]).
#[derive(Clone, Debug)]
pub struct KFold {
    /// The takes of each fold.
    pub folds: Vec<Vec<String>>,
    /// Pooled over every window: UC, Greedy, SIDQL before and after fine-tuning, Optimal per K.
    pub rows: Vec<KFoldRow>,
    /// Training seconds and windows per fold.
    pub train_seconds: Vec<f64>,
    pub train_windows: Vec<usize>,
    pub options: crate::dqn::TrainOptions,
    pub stride: usize,
}

/// One selector at one K, over every window of the k-fold.
#[derive(Clone, Debug, PartialEq)]
pub struct KFoldRow {
    pub variant: String,
    pub k: usize,
    pub mean_angle_error: f64,
    pub paper_units: f64,
    pub decision_ms: f64,
    pub windows: usize,
}

impl KFold {
    pub fn get(&self, variant: &str, k: usize) -> Option<&KFoldRow> {
        self.rows.iter().find(|r| r.variant == variant && r.k == k)
    }

    /// Share of the UC → Optimal gap `variant` closes at `k`, in %.
    pub fn gap_closed(&self, variant: &str, k: usize) -> Option<f64> {
        let (uc, opt, v) = (self.get("UC", k)?, self.get("Optimal", k)?, self.get(variant, k)?);
        let gap = uc.mean_angle_error - opt.mean_angle_error;
        (gap > 0.0).then(|| 100.0 * (uc.mean_angle_error - v.mean_angle_error) / gap)
    }

    /// The table: error per K, gap closed per K, paper units, decision ms.
    pub fn table(&self, ks: &[usize]) -> Table {
        let windows = self.rows.first().map(|r| r.windows).unwrap_or(0);
        let mut headers = vec!["method".to_string()];
        headers.extend(ks.iter().map(|k| format!("K={k}")));
        headers.extend(ks.iter().map(|k| format!("gap closed K={k}")));
        headers.extend(ks.iter().map(|k| format!("paper units K={k}")));
        headers.push(format!("decision ms (K={})", ks.iter().map(|k| k.to_string()).collect::<Vec<_>>().join("/")));
        let h: Vec<&str> = headers.iter().map(String::as_str).collect();
        let mut t = Table::new(
            "kfold",
            &format!("Table 3, take-level {}-fold: every one of {windows} windows scored by a policy that never saw its take (mean angle error, rad)", self.folds.len()),
            &h,
        );
        let mut names: Vec<&str> = Vec::new();
        for r in &self.rows {
            if !names.contains(&r.variant.as_str()) {
                names.push(&r.variant);
            }
        }
        for v in names {
            let mut cells = vec![v.to_string()];
            cells.extend(ks.iter().map(|&k| self.get(v, k).map(|r| num(r.mean_angle_error, 4)).unwrap_or_default()));
            cells.extend(ks.iter().map(|&k| match (v, self.gap_closed(v, k)) {
                ("UC" | "Optimal", _) | (_, None) => String::new(),
                (_, Some(g)) => format!("{} %", num(g, 1)),
            }));
            cells.extend(ks.iter().map(|&k| self.get(v, k).map(|r| num(r.paper_units, 4)).unwrap_or_default()));
            cells.push(
                ks.iter()
                    .filter_map(|&k| self.get(v, k))
                    .map(|r| fmt_ms(r.decision_ms))
                    .collect::<Vec<_>>()
                    .join(" / "),
            );
            t.row(cells);
        }
        let paper: Vec<String> = ks
            .iter()
            .filter_map(|&k| {
                let (uc, g, s) =
                    (paper_value(Method::Uc, k)?, paper_value(Method::Greedy, k)?, paper_value(Method::Sidql, k)?);
                Some(format!("{} % at K={k}", num(100.0 * (uc - s) / (uc - g), 1)))
            })
            .collect();
        t.note(format!("gap closed: (UC − method) / (UC − Optimal); the paper's SIDQL closes {} of its UC → Greedy gap (it has no Optimal)", paper.join(", ")));
        t.note(format!(
            "folds: takes dealt into {} groups (seeded); per fold a policy trained from scratch on the other takes' windows at stride {} ({} windows on average), {:.0} s of training per fold on average (both stages)",
            self.folds.len(),
            self.stride,
            self.train_windows.iter().sum::<usize>() / self.train_windows.len().max(1),
            self.train_seconds.iter().sum::<f64>() / self.train_seconds.len().max(1) as f64
        ));
        let o = &self.options;
        t.note(format!(
            "training: K drawn per episode in {}..={}; pretraining {} steps × {} states on exact cost-to-go (lr {}); fine-tuning {} epochs of the paper's DQN (lr {}, γ = {}, batch {}, memory {}, target every {} updates)",
            o.min_keys, o.max_keys, o.pretrain_steps, o.pretrain_batch, o.pretrain_lr, o.episodes, o.lr, o.gamma, o.batch, o.memory, o.target_every
        ));
        t.note("paper units: no division by 2, φ from atan2 at every frame (not unwrapped over time), |Δφ| not wrapped (bench::measure::paper_units_error)");
        t.note("SIDQL rows without \"checked\" are the network's keys alone; checked: replaced by uniform keys when those cost less; refined: then each key moved to the best frame between its neighbours until none moves (select::refine); the default policy does both");
        t
    }
}

impl BenchResults {
    /// The split the headline figures use: `test` when it has windows, else `all`.
    pub fn main_split(&self) -> &'static str {
        if self.rows.iter().any(|r| r.split == "test") {
            "test"
        } else {
            "all"
        }
    }

    fn row(&self, split: &str, method: Method, k: usize) -> Option<&Row> {
        self.rows.iter().find(|r| r.split == split && r.method == method && r.k == k)
    }

    /// The splits shown side by side in Table 3: `test` then `all` (or `all` alone).
    fn splits(&self) -> Vec<&'static str> {
        if self.main_split() == "test" {
            vec!["test", "all"]
        } else {
            vec!["all"]
        }
    }

    fn methods(&self) -> Vec<Method> {
        Method::ALL.into_iter().filter(|&m| self.rows.iter().any(|r| r.method == m)).collect()
    }

    /// The corpus, split and policy lines above the tables.
    pub fn header(&self) -> String {
        let p = &self.protocol;
        let mut s = format!(
            "{} takes ({}) from {}: {} windows of {} frames at {} fps, joints per skeleton {:?}\n",
            self.takes, self.sources, self.source, self.windows, p.window, p.fps, self.joints
        );
        for note in &self.unit_notes {
            s += &format!("{note}\n");
        }
        s +=
            &format!("test split ({} windows): {:?}\ntraining split: {:?}\n", self.test_windows, self.test, self.train);
        s += &format!("SIDQL: {}\n", self.policy);
        for l in &self.log {
            s += &format!("SIDQL: {l}\n");
        }
        if self.main_split() == "all" {
            s += "the test split has no windows (too few or too short clips): only the `all` rows are shown\n";
        }
        s
    }

    /// Table 3: mean angle error per method and K, ours (test / all) beside the paper's, and the
    /// decision time per window beside §5.4's.
    pub fn table3(&self) -> Table {
        let splits = self.splits();
        let mut headers = vec!["method".to_string()];
        for k in &self.ks {
            headers.push(format!("K={k} ours"));
            headers.push("paper units".into());
            headers.push("paper".into());
        }
        let ks_label = self.ks.iter().map(|k| k.to_string()).collect::<Vec<_>>().join("/");
        headers.push(format!("decision ms (K={ks_label})"));
        headers.push("paper ms (K=5)".into());
        let h: Vec<&str> = headers.iter().map(String::as_str).collect();
        let mut t = Table::new("table3", "Table 3: mean angle error (rad) by keyframe selection method", &h);
        for m in self.methods() {
            let mut cells = vec![m.label().to_string()];
            for &k in &self.ks {
                let ours: Vec<String> =
                    splits.iter().filter_map(|s| self.row(s, m, k)).map(|r| num(r.mean_angle_error, 4)).collect();
                cells.push(ours.join(" / "));
                let units: Vec<String> =
                    splits.iter().filter_map(|s| self.row(s, m, k)).map(|r| num(r.paper_units, 4)).collect();
                cells.push(units.join(" / "));
                cells.push(paper_value(m, k).map(|v| num(v, 4)).unwrap_or_default());
            }
            let ms: Vec<String> =
                self.ks.iter().filter_map(|&k| self.row(splits[0], m, k)).map(|r| fmt_ms(r.decision_ms)).collect();
            cells.push(ms.join(" / "));
            cells.push(paper_decision_ms(m).map(|v| format!("{v}")).unwrap_or_default());
            t.row(cells);
        }
        let windows = |s: &str| self.rows.iter().find(|r| r.split == s).map(|r| r.windows).unwrap_or(0);
        let label = |s: &str| {
            if s == "all" {
                format!("all {} windows", windows(s))
            } else {
                format!("{s} split ({} windows)", windows(s))
            }
        };
        let ours = splits.iter().map(|s| label(s)).collect::<Vec<_>>().join(" / ");
        t.note(format!("ours: {ours}; Eq. 24 over 60-frame windows at 30 fps, 23 major joints"));
        t.note("paper: the SIDQL paper's Table 3 (CMU test set) and §5.4's decision times (Greedy 0.9 s, SIDQL 0.004 s at K=5)");
        t.note("paper units: the same keys scored as the paper's equations read literally: no division by 2 (θ and φ terms), φ from atan2 at every frame (not unwrapped over time) and |Δφ| not wrapped, so bones crossing the ±π azimuth seam between keys count the long way round");
        t.note(format!("decision ms: selection time per window on the {} split, this machine", splits[0]));
        t.note(format!("SIDQL: {}", self.policy));
        if self.policy.contains("every CMU take") {
            t.note("SIDQL here saw every take in training (these rows are not held out; the k-fold table is); its keys are checked against uniform keys by their exact cost and replaced when worse, then refined (each key moved to the best frame between its neighbours until none moves)");
        }
        t
    }

    /// Mean / max position error (cm) of the main split per method and K.
    pub fn positions(&self) -> Table {
        let split = self.main_split();
        let mut headers = vec!["method".to_string()];
        headers.extend(self.ks.iter().map(|k| format!("K={k}")));
        let h: Vec<&str> = headers.iter().map(String::as_str).collect();
        let mut t = Table::new("positions", &format!("Position error (cm), {split} split: mean / max"), &h);
        for m in self.methods() {
            let mut cells = vec![m.label().to_string()];
            for &k in &self.ks {
                cells.push(
                    self.row(split, m, k)
                        .map(|r| format!("{} / {}", num(r.mean_cm, 2), num(r.max_cm, 1)))
                        .unwrap_or_default(),
                );
            }
            t.row(cells);
        }
        t.note("max: the largest error of any joint in any frame of any window; the paper reports no position error");
        t
    }

    /// The two reconstructions with the same optimal keys.
    pub fn reconstructions(&self) -> Table {
        let mut t = Table::new(
            "reconstructions",
            &format!(
                "Spherical (paper, Eq. 9–13) vs rotation (quaternion Hermite, BVH output) reconstruction, same optimal keys, all {} windows",
                self.reconstructions.first().map(|r| r.windows).unwrap_or(0)
            ),
            &["K", "spherical mean cm", "spherical max cm", "rotation mean cm", "rotation max cm", "rotation error deg"],
        );
        for r in &self.reconstructions {
            t.row([
                r.k.to_string(),
                num(r.spherical_mean_cm, 3),
                num(r.spherical_max_cm, 2),
                num(r.rotation_mean_cm, 3),
                num(r.rotation_max_cm, 2),
                num(r.rotation_mean_deg, 2),
            ]);
        }
        t.note("rotation error deg: mean local joint rotation error of the rotation reconstruction");
        t
    }

    /// Codec size and error at each bound.
    pub fn codec(&self) -> Table {
        let (clips, frames) = self.codec.first().map(|c| (c.clips, c.frames)).unwrap_or((0, 0));
        let mut t = Table::new(
            "codec",
            &format!("Codec (.ibk) on {clips} full-rate clips (cgspeed or plain folder), full skeleton, first frame dropped ({frames} frames)"),
            &["max error cm", "keys", "bytes", "raw f32 bytes", "ratio", "decoded max cm", "seconds"],
        );
        for c in &self.codec {
            t.row([
                format!("{}", c.bound_cm),
                c.keys.to_string(),
                c.bytes.to_string(),
                c.raw_bytes.to_string(),
                format!("{}x", num(c.ratio(), 1)),
                num(c.decoded_max_cm, 3),
                num(c.seconds, 1),
            ]);
        }
        t.note("ratio: raw f32 channel bytes / .ibk bytes; decoded max: the largest error of the decoded files");
        t
    }

    /// Every row as measured (`mocap_bench.csv`).
    pub fn rows_table(&self) -> Table {
        rows_table(&self.rows)
    }

    /// The throughput line.
    pub fn throughput_text(&self) -> String {
        format!(
            "reconstruction throughput (spherical, K = {}, skeletons of {:?} joints): {:.0} frames/s",
            self.throughput.k, self.throughput.joints, self.throughput.frames_per_s
        )
    }

    /// The whole report: header, Table 3, positions, reconstructions, codec, throughput, all rows
    /// and (when `plot` is set) the chart as `table3.png`.
    pub fn report(&self, plot: bool) -> Result<Report> {
        let mut r = Report::new("report", "mocap bench: keyframe selection on CMU motion capture (SIDQL paper §5)");
        r.text(self.header());
        r.table(self.table3());
        if let Some(k) = &self.kfold {
            r.table(k.table(&self.ks));
        }
        r.table(self.positions());
        r.table(self.reconstructions());
        if self.codec.is_empty() {
            r.text("codec: no full-rate clip (cgspeed or a plain folder), not measured");
        } else {
            r.table(self.codec());
        }
        r.text(self.throughput_text());
        r.table(self.rows_table());
        if plot {
            r.file(CHART_FILE, self.plot_png()?);
        }
        Ok(r)
    }

    /// Bar chart of the mean angle error per method and K (main split), written to `path`.
    pub fn plot(&self, path: &Path) -> Result<()> {
        let split = self.main_split();
        let groups: Vec<String> = self.ks.iter().map(|k| format!("K = {k}")).collect();
        let series: Vec<(String, Vec<f64>)> = Method::ALL
            .into_iter()
            .filter_map(|m| {
                let vals: Vec<f64> =
                    self.ks.iter().filter_map(|&k| self.row(split, m, k)).map(|r| r.mean_angle_error).collect();
                (vals.len() == self.ks.len()).then(|| (m.label().to_string(), vals))
            })
            .collect();
        let title =
            format!("Mean angle error, {} 60-frame windows", if split == "test" { "test-split" } else { "all" });
        inbetween_render::plot::grouped_bar_chart(path, &title, "mean angle error (rad)", &groups, &series).map_err(
            |e| MocapError::Io { path: path.display().to_string(), source: std::io::Error::other(e.to_string()) },
        )
    }

    /// The chart as PNG bytes (see [`inbetween_render::rendered_bytes`]).
    pub fn plot_png(&self) -> Result<Vec<u8>> {
        inbetween_render::rendered_bytes(CHART_FILE, |path| {
            self.plot(path).map_err(|e| inbetween_render::RenderError::InvalidInput(e.to_string()))
        })
        .map_err(|e| MocapError::Io { path: CHART_FILE.into(), source: std::io::Error::other(e.to_string()) })
    }
}

/// Selection time as a short cell: `<0.01`, `0.42`, `5.3`, `900`.
fn fmt_ms(ms: f64) -> String {
    if ms < 0.01 {
        "<0.01".into()
    } else if ms < 1.0 {
        num(ms, 2)
    } else if ms < 100.0 {
        num(ms, 1)
    } else {
        num(ms, 0)
    }
}

/// Every row, one per split, method and K: the CSV columns
/// `method,k,mean_angle_error,mean_cm,max_cm,decision_ms,split,windows,paper_mean_angle_error`.
pub fn rows_table(rows: &[Row]) -> Table {
    let mut t = Table::new(
        ROWS_TABLE,
        "Every row (mocap_bench.csv): mean angle error (rad), position error (cm), decision ms per window",
        &[
            "method",
            "k",
            "mean_angle_error",
            "mean_cm",
            "max_cm",
            "decision_ms",
            "split",
            "windows",
            "paper_mean_angle_error",
            "paper_units_angle_error",
        ],
    );
    for r in rows {
        t.row([
            r.method.name().to_string(),
            r.k.to_string(),
            format!("{:.6}", r.mean_angle_error),
            format!("{:.4}", r.mean_cm),
            format!("{:.4}", r.max_cm),
            format!("{:.4}", r.decision_ms),
            r.split.clone(),
            r.windows.to_string(),
            paper_value(r.method, r.k).map(|v| format!("{v}")).unwrap_or_default(),
            format!("{:.6}", r.paper_units),
        ]);
    }
    t
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(split: &str, method: Method, k: usize, angle: f64) -> Row {
        Row {
            split: split.into(),
            method,
            k,
            mean_angle_error: angle,
            mean_cm: 10.0 * angle,
            max_cm: 100.0 * angle,
            decision_ms: angle,
            windows: if split == "test" { 2 } else { 9 },
            paper_units: 3.0 * angle,
        }
    }

    fn results(with_test: bool) -> BenchResults {
        let mut rows = Vec::new();
        let splits: &[&str] = if with_test { &["all", "test"] } else { &["all"] };
        for s in splits {
            for (i, m) in [Method::Uc, Method::Greedy, Method::Optimal].into_iter().enumerate() {
                for k in [5, 10] {
                    rows.push(row(s, m, k, 0.1 / (1 + i) as f64 / k as f64 + if *s == "test" { 0.001 } else { 0.0 }));
                }
            }
        }
        BenchResults {
            source: "a folder".into(),
            takes: 3,
            sources: "3 bvh".into(),
            unit_notes: vec!["3 bvh takes: length unit: cm (given)".into()],
            protocol: Protocol::paper(),
            windows: 9,
            joints: [23].into(),
            train: vec!["a".into(), "b".into()],
            test: vec!["c".into()],
            test_windows: if with_test { 2 } else { 0 },
            policy: "none".into(),
            log: vec![],
            ks: vec![5, 10],
            rows,
            throughput: Throughput { k: 10, frames_per_s: 1234.4, joints: [23].into() },
            reconstructions: vec![],
            codec: vec![],
            kfold: None,
        }
    }

    #[test]
    fn table3_puts_test_and_all_beside_the_paper() {
        let t = results(true).table3();
        assert_eq!(
            t.headers,
            [
                "method",
                "K=5 ours",
                "paper units",
                "paper",
                "K=10 ours",
                "paper units",
                "paper",
                "decision ms (K=5/10)",
                "paper ms (K=5)"
            ]
        );
        assert_eq!(t.rows.len(), 3, "only the methods measured");
        assert_eq!(t.rows[0][..4], ["UC", "0.0210 / 0.0200", "0.0630 / 0.0600", "0.0945"]);
        assert_eq!(t.rows[1][0], "Greedy");
        assert_eq!(t.rows[1][8], "900");
        assert_eq!(t.rows[2][3], "", "the paper has no optimal row");
        let md = t.to_markdown();
        assert!(
            md.contains(
                "| UC | 0.0210 / 0.0200 | 0.0630 / 0.0600 | 0.0945 | 0.0110 / 0.0100 | 0.0330 / 0.0300 | 0.0490 |"
            ),
            "{md}"
        );
    }

    #[test]
    fn without_a_test_split_everything_uses_all_windows() {
        let r = results(false);
        assert_eq!(r.main_split(), "all");
        assert!(r.header().contains("test split has no windows"));
        assert!(r.header().contains("\n3 bvh takes: length unit: cm (given)\n"), "{}", r.header());
        assert_eq!(r.table3().rows[0][1], "0.0200");
        assert_eq!(r.positions().rows[0][1], "0.20 / 2.0");
        let report = r.report(false).unwrap();
        let text = report.to_text();
        assert!(text.contains("codec: no full-rate clip") && text.contains("1234 frames/s"), "{text}");
        let names: Vec<&str> = report.tables().map(|t| t.name.as_str()).collect();
        assert_eq!(names, ["table3", "positions", "reconstructions", "mocap_bench"]);
    }

    #[test]
    fn the_report_folder_holds_text_tables_and_chart() {
        let dir = tempfile::tempdir().unwrap();
        let files = results(true).report(true).unwrap().write(dir.path()).unwrap();
        let names: Vec<String> = files.iter().map(|p| p.file_name().unwrap().to_string_lossy().into_owned()).collect();
        assert_eq!(
            names,
            [
                "report.txt",
                "report.md",
                "table3.csv",
                "positions.csv",
                "reconstructions.csv",
                "mocap_bench.csv",
                "table3.png"
            ]
        );
        let png = std::fs::read(dir.path().join("table3.png")).unwrap();
        assert!(png.starts_with(b"\x89PNG") && png.len() > 1000);
        let csv = std::fs::read_to_string(dir.path().join("mocap_bench.csv")).unwrap();
        assert_eq!(csv.lines().count(), 1 + 12);
        assert!(csv.contains("\nuc,5,0.020000,0.2000,2.0000,0.0200,all,9,0.0945,0.060000\n"), "{csv}");
    }
}
