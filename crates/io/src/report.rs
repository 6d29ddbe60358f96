//! The bench/report harness every engine's `bench` uses: [`Table`] (aligned text, CSV and Markdown
//! from one set of rows, with the paper's figures as a column beside ours), [`Report`] (a titled
//! list of tables and text plus extra files, written atomically into one folder),
//! [`BenchOptions`] (what every engine's bench takes: `run(&BenchOptions<E>) -> Result<Report, _>`,
//! `E` the engine's own options) and [`seconds_per_call`] for timings.
//!
//! ```
//! use inbetween_io::report::{num, Report, Table};
//! let mut t = Table::new("table1", "Table 1: error by method", &["method", "ours", "paper"]);
//! t.row(["uniform", &num(0.123, 3), "0.118"]);
//! t.note("paper: Table 1 of the SIDQL paper");
//! let mut r = Report::new("report", "demo bench");
//! r.table(t);
//! let dir = tempfile::tempdir().unwrap();
//! let files = r.write(dir.path()).unwrap(); // report.txt, report.md, table1.csv
//! assert_eq!(files.len(), 3);
//! ```

use std::path::{Path, PathBuf};
use std::time::Instant;

use crate::{write_atomic, IoError, Progress};

/// What every engine's bench takes: `bench::run(&BenchOptions<E>) -> Result<Report, _>`, with the
/// options all benches share here and the engine's own in `engine`. A bench writes nothing itself:
/// it returns its [`Report`], and the caller writes it into `out` ([`BenchOptions::write`]).
#[derive(Clone, Debug)]
pub struct BenchOptions<E = ()> {
    /// Folder the report will be written to (None: printed only). Benches add files that cost time
    /// to render (charts) only when it is set.
    pub out: Option<PathBuf>,
    /// Data folder (None: the bench's default, the shared corpus under [`crate::shared_data_dir`]).
    pub data: Option<PathBuf>,
    /// A reduced run (seconds to a minute) that checks the bench works; its numbers are not the
    /// bench's.
    pub quick: bool,
    /// Seed of every random choice (None: the bench's own, which may differ between quick and full).
    pub seed: Option<u64>,
    /// Advanced through the bench's phases; the caller finishes it.
    pub progress: Progress,
    /// The engine's own options.
    pub engine: E,
}

impl<E> BenchOptions<E> {
    /// A full run on the default data, printed only, with the bench's own seed and no bar.
    pub fn new(engine: E) -> BenchOptions<E> {
        BenchOptions { out: None, data: None, quick: false, seed: None, progress: Progress::hidden(), engine }
    }

    /// Writes `report` into [`BenchOptions::out`] ([`Report::write`]); nothing when it is None.
    pub fn write(&self, report: &Report) -> Result<Vec<PathBuf>, IoError> {
        self.out.as_deref().map_or(Ok(Vec::new()), |dir| report.write(dir))
    }
}

/// A number as a table cell with `decimals` digits; NaN (not measured) becomes "—".
pub fn num(x: f64, decimals: usize) -> String {
    if x.is_nan() {
        "—".into()
    } else {
        format!("{x:.decimals$}")
    }
}

/// One table of a report: a header row and rows of cells, all text (format numbers with [`num`]).
/// Put the paper's figure in a column of its own (conventionally headed "paper") so ours and the
/// paper's always stand side by side.
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    /// File stem of the CSV (`<name>.csv`).
    pub name: String,
    pub title: String,
    pub headers: Vec<String>,
    pub rows: Vec<Vec<String>>,
    /// Lines printed under the table (protocol, where the paper's figures come from, caveats).
    pub notes: Vec<String>,
}

impl Table {
    pub fn new(name: &str, title: &str, headers: &[&str]) -> Table {
        Table {
            name: name.into(),
            title: title.into(),
            headers: headers.iter().map(|h| h.to_string()).collect(),
            rows: Vec::new(),
            notes: Vec::new(),
        }
    }

    /// Appends a row; missing cells are left empty, extra cells are kept (and widen the table).
    pub fn row<I, S>(&mut self, cells: I) -> &mut Table
    where
        I: IntoIterator<Item = S>,
        S: AsRef<str>,
    {
        self.rows.push(cells.into_iter().map(|c| c.as_ref().to_string()).collect());
        self
    }

    pub fn note(&mut self, line: impl Into<String>) -> &mut Table {
        self.notes.push(line.into());
        self
    }

    fn columns(&self) -> usize {
        self.rows.iter().map(Vec::len).chain([self.headers.len()]).max().unwrap_or(0)
    }

    fn cell(row: &[String], c: usize) -> &str {
        row.get(c).map(String::as_str).unwrap_or("")
    }

    /// Whether every body cell of column `c` reads as a number (or is empty or "—").
    fn numeric(&self, c: usize) -> bool {
        self.rows
            .iter()
            .map(|r| Self::cell(r, c).trim_end_matches(['%', '×', 'x']))
            .all(|t| t.is_empty() || t == "—" || t.parse::<f64>().is_ok())
    }

    /// Aligned plain text: the title, the header, the rows (numeric columns right-aligned, text
    /// columns and the first column left-aligned), then the notes.
    pub fn to_text(&self) -> String {
        let n = self.columns();
        let all: Vec<&[String]> =
            std::iter::once(self.headers.as_slice()).chain(self.rows.iter().map(Vec::as_slice)).collect();
        let widths: Vec<usize> =
            (0..n).map(|c| all.iter().map(|r| Self::cell(r, c).chars().count()).max().unwrap_or(0)).collect();
        let right: Vec<bool> = (0..n).map(|c| c > 0 && self.numeric(c)).collect();
        let mut out = format!("{}\n", self.title);
        for row in &all {
            let cells: Vec<String> = (0..n)
                .map(|c| {
                    let (text, w) = (Self::cell(row, c), widths[c]);
                    let pad = " ".repeat(w.saturating_sub(text.chars().count()));
                    if right[c] {
                        format!("{pad}{text}")
                    } else {
                        format!("{text}{pad}")
                    }
                })
                .collect();
            out += cells.join("  ").trim_end();
            out.push('\n');
        }
        for note in &self.notes {
            out += &format!("  {note}\n");
        }
        out
    }

    /// RFC 4180 CSV: the header and the rows (no title, no notes).
    pub fn to_csv(&self) -> String {
        let n = self.columns();
        let line = |row: &[String]| (0..n).map(|c| csv_field(Self::cell(row, c))).collect::<Vec<_>>().join(",") + "\n";
        std::iter::once(line(&self.headers)).chain(self.rows.iter().map(|r| line(r))).collect()
    }

    /// A GitHub Markdown table under a bold title, notes as a list: what a README pastes.
    pub fn to_markdown(&self) -> String {
        let n = self.columns();
        let line = |row: &[String]| {
            format!("| {} |\n", (0..n).map(|c| Self::cell(row, c).replace('|', "\\|")).collect::<Vec<_>>().join(" | "))
        };
        let mut out = format!("**{}**\n\n", self.title);
        out += &line(&self.headers);
        out += &format!("|{}\n", "---|".repeat(n));
        for row in &self.rows {
            out += &line(row);
        }
        if !self.notes.is_empty() {
            out.push('\n');
            for note in &self.notes {
                out += &format!("- {note}\n");
            }
        }
        out
    }
}

fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

#[derive(Debug, Clone, PartialEq)]
enum Section {
    Table(Table),
    Text(String),
}

/// A benchmark's whole output: a title, tables and text in order, plus extra files (JSON, PNG).
#[derive(Debug, Clone, PartialEq)]
pub struct Report {
    /// File stem of the text and Markdown summaries (`<name>.txt`, `<name>.md`).
    pub name: String,
    pub title: String,
    sections: Vec<Section>,
    files: Vec<(String, Vec<u8>)>,
}

impl Report {
    pub fn new(name: &str, title: &str) -> Report {
        Report { name: name.into(), title: title.into(), sections: Vec::new(), files: Vec::new() }
    }

    pub fn table(&mut self, table: Table) -> &mut Report {
        self.sections.push(Section::Table(table));
        self
    }

    /// A paragraph of plain text (one or more lines).
    pub fn text(&mut self, text: impl Into<String>) -> &mut Report {
        self.sections.push(Section::Text(text.into()));
        self
    }

    /// Adds `value` as pretty JSON in `file` (e.g. "report.json").
    pub fn json<T: serde::Serialize>(&mut self, file: &str, value: &T) -> Result<&mut Report, IoError> {
        let text = serde_json::to_string_pretty(value)
            .map_err(|e| IoError::Io { path: PathBuf::from(file), source: std::io::Error::other(e) })?;
        Ok(self.file(file, (text + "\n").into_bytes()))
    }

    /// Adds any file (a rendered PNG, a GIF); `file` is a plain name inside the report folder.
    pub fn file(&mut self, file: &str, bytes: Vec<u8>) -> &mut Report {
        self.files.retain(|(name, _)| name != file);
        self.files.push((file.to_string(), bytes));
        self
    }

    /// The bytes of an added file ([`Report::file`]), by name.
    pub fn file_bytes(&self, file: &str) -> Option<&[u8]> {
        self.files.iter().find(|(name, _)| name == file).map(|(_, bytes)| bytes.as_slice())
    }

    /// A table by its name.
    pub fn find_table(&self, name: &str) -> Option<&Table> {
        self.tables().find(|t| t.name == name)
    }

    pub fn tables(&self) -> impl Iterator<Item = &Table> {
        self.sections.iter().filter_map(|s| match s {
            Section::Table(t) => Some(t),
            Section::Text(_) => None,
        })
    }

    /// Title, then every table and paragraph separated by blank lines.
    pub fn to_text(&self) -> String {
        self.render(format!("{}\n", self.title), Table::to_text)
    }

    /// The same as Markdown: a `#` title, tables as Markdown tables.
    pub fn to_markdown(&self) -> String {
        self.render(format!("# {}\n", self.title), Table::to_markdown)
    }

    fn render(&self, mut out: String, table: fn(&Table) -> String) -> String {
        for s in &self.sections {
            out.push('\n');
            match s {
                Section::Table(t) => out += &table(t),
                Section::Text(x) => {
                    out += x.trim_end();
                    out.push('\n');
                }
            }
        }
        out
    }

    /// Writes `<name>.txt`, `<name>.md`, one `<table>.csv` per table and every added file into
    /// `dir` (created if missing), each atomically. Returns the paths written, in that order.
    pub fn write(&self, dir: &Path) -> Result<Vec<PathBuf>, IoError> {
        std::fs::create_dir_all(dir).map_err(|source| IoError::Io { path: dir.to_path_buf(), source })?;
        let mut outputs: Vec<(String, Vec<u8>)> = vec![
            (format!("{}.txt", self.name), self.to_text().into_bytes()),
            (format!("{}.md", self.name), self.to_markdown().into_bytes()),
        ];
        outputs.extend(self.tables().map(|t| (format!("{}.csv", t.name), t.to_csv().into_bytes())));
        outputs.extend(self.files.iter().cloned());
        let mut written = Vec::with_capacity(outputs.len());
        for (name, bytes) in outputs {
            let path = dir.join(&name);
            write_atomic(&path, &bytes).map_err(|source| IoError::Io { path: path.clone(), source })?;
            written.push(path);
        }
        Ok(written)
    }
}

/// Wall-clock seconds per call of `f`, after `warmup` unmeasured calls, averaged over
/// `iterations` calls (at least one). `f` must finish its work (read a value back) before
/// returning. Compare such timings only as ratios taken in one run: machines are noisy.
pub fn seconds_per_call(warmup: usize, iterations: usize, mut f: impl FnMut()) -> f64 {
    for _ in 0..warmup {
        f();
    }
    let start = Instant::now();
    for _ in 0..iterations.max(1) {
        f();
    }
    start.elapsed().as_secs_f64() / iterations.max(1) as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Table {
        let mut t = Table::new("t1", "Table 1: errors", &["method", "ours", "paper"]);
        t.row(["uniform", "0.500", "0.480"]).row(["greedy, fast", "0.25", ""]).note("paper: Table 1");
        t.row(["random", "1.5", "—"]);
        t
    }

    #[test]
    fn text_aligns_columns_and_keeps_notes() {
        let text = sample().to_text();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines[0], "Table 1: errors");
        assert_eq!(lines[1], "method         ours  paper");
        assert_eq!(lines[2], "uniform       0.500  0.480");
        assert_eq!(lines[3], "greedy, fast   0.25");
        assert_eq!(lines[4], "random          1.5      —");
        assert_eq!(lines[5], "  paper: Table 1");
        // Text columns stay left-aligned.
        let mut words = Table::new("w", "words", &["case", "value", "unit"]);
        words.row(["a", "12.5", "frames/s"]).row(["bb", "3", "s"]);
        assert_eq!(words.to_text().lines().nth(2).unwrap(), "a      12.5  frames/s");
    }

    #[test]
    fn csv_quotes_what_needs_quoting_and_markdown_escapes_pipes() {
        let mut t = sample();
        t.row(["say \"hi\"", "a|b", "x"]);
        let csv = t.to_csv();
        assert_eq!(
            csv.lines().collect::<Vec<_>>(),
            [
                "method,ours,paper",
                "uniform,0.500,0.480",
                "\"greedy, fast\",0.25,",
                "random,1.5,—",
                "\"say \"\"hi\"\"\",a|b,x"
            ]
        );
        let md = t.to_markdown();
        assert!(md.contains("| method | ours | paper |\n|---|---|---|\n"), "{md}");
        assert!(md.contains("| say \"hi\" | a\\|b | x |"), "{md}");
        assert!(md.contains("- paper: Table 1"), "{md}");
    }

    #[test]
    fn report_writes_every_file_atomically_and_in_order() {
        let dir = tempfile::tempdir().unwrap();
        let mut r = Report::new("report", "bench");
        r.table(sample()).text("speed: 3 frames/s");
        r.json("report.json", &serde_json::json!({"x": 1.5})).unwrap();
        r.file("plot.png", vec![1, 2, 3]);
        let files = r.write(&dir.path().join("sub")).unwrap();
        let names: Vec<String> = files.iter().map(|p| p.file_name().unwrap().to_string_lossy().into_owned()).collect();
        assert_eq!(names, ["report.txt", "report.md", "t1.csv", "report.json", "plot.png"]);
        let txt = std::fs::read_to_string(&files[0]).unwrap();
        assert!(txt.starts_with("bench\n\nTable 1: errors\n") && txt.ends_with("speed: 3 frames/s\n"), "{txt}");
        assert_eq!(std::fs::read(&files[4]).unwrap(), [1, 2, 3]);
        let json: serde_json::Value = serde_json::from_slice(&std::fs::read(&files[3]).unwrap()).unwrap();
        assert_eq!(json["x"], 1.5);
        // No temporary files left behind.
        assert_eq!(std::fs::read_dir(dir.path().join("sub")).unwrap().count(), 5);
        assert_eq!(r.file_bytes("plot.png"), Some(&[1u8, 2, 3][..]));
        assert_eq!(r.file_bytes("none.png"), None);
        assert_eq!(r.find_table("t1").map(|t| t.rows.len()), Some(3));
    }

    #[test]
    fn bench_options_write_only_where_asked() {
        let mut r = Report::new("report", "bench");
        r.text("x");
        let mut opts = BenchOptions::new(());
        assert!(opts.write(&r).unwrap().is_empty());
        let dir = tempfile::tempdir().unwrap();
        opts.out = Some(dir.path().join("out"));
        assert_eq!(opts.write(&r).unwrap().len(), 2);
        assert!(dir.path().join("out/report.txt").is_file());
    }

    #[test]
    fn not_measured_reads_as_a_dash() {
        assert_eq!(num(f64::NAN, 3), "—");
        assert_eq!(num(0.12345, 3), "0.123");
    }

    #[test]
    fn seconds_per_call_counts_every_measured_call() {
        let mut calls = 0;
        let s = seconds_per_call(2, 5, || calls += 1);
        assert_eq!(calls, 7);
        assert!(s >= 0.0);
    }
}
