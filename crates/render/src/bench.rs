//! Speed of the previews on procedural motion: `render_bench` rows, printed as a table by the
//! `render_bench` example (and by any CLI `bench` that wants them).

use crate::plot::{grouped_bar_chart, line_plot, Series};
use crate::stick::{render_motion_gif, render_motion_png, StickOptions};
use crate::RenderError;
use inbetween_core::procedural::{gait, GaitParams};
use inbetween_io::report::{num, Table};
use std::path::Path;
use std::time::Instant;

/// One measured task: best wall time over the repeats and the size of the file it wrote.
#[derive(Clone, Debug, PartialEq)]
pub struct BenchRow {
    pub task: String,
    pub seconds: f64,
    pub bytes: u64,
}

/// Writes one benchmark output file.
type Task<'a> = Box<dyn Fn(&Path) -> Result<(), RenderError> + 'a>;

/// Times each preview task `repeats` times (best time kept), writing the files under `dir`.
pub fn render_bench(dir: &Path, repeats: usize) -> Result<Vec<BenchRow>, RenderError> {
    let walk = gait(&GaitParams { frames: 120, ..GaitParams::walk() });
    let other = gait(&GaitParams { frames: 120, ..GaitParams::walk().jittered(5, 0.3) });
    let opts = StickOptions::default();
    let curve: Vec<(f64, f64)> = (0..1000).map(|i| (i as f64 / 120.0, (i as f64 * 0.05).sin())).collect();
    let groups: Vec<String> = (1..=6).map(|i| format!("clip {i}")).collect();
    let bars = vec![("a".to_string(), vec![1.0; 6]), ("b".to_string(), vec![2.0; 6]), ("c".to_string(), vec![1.5; 6])];
    let tasks: Vec<(&str, &str, Task)> = vec![
        ("GIF, 1 figure, 120 frames, 480x360", "walk.gif", Box::new(|p| render_motion_gif(p, &[&walk], &opts))),
        (
            "GIF, 2 figures, 120 frames, 480x360",
            "compare.gif",
            Box::new(|p| render_motion_gif(p, &[&walk, &other], &opts)),
        ),
        (
            "PNG, 2 figures, 1 frame, 480x360",
            "compare.png",
            Box::new(|p| render_motion_png(p, &[&walk, &other], 60, &opts)),
        ),
        (
            "line plot, 1000 points, 900x560",
            "line.png",
            Box::new(|p| line_plot(p, "bench", "t", "y", &[Series::new("sin", curve.clone())])),
        ),
        (
            "bar chart, 6 groups x 3, 900x560",
            "bars.png",
            Box::new(|p| grouped_bar_chart(p, "bench", "y", &groups, &bars)),
        ),
    ];
    let mut rows = Vec::new();
    for (task, file, run) in tasks {
        let path = dir.join(file);
        let mut best = f64::INFINITY;
        for _ in 0..repeats.max(1) {
            let t = Instant::now();
            run(&path)?;
            best = best.min(t.elapsed().as_secs_f64());
        }
        let bytes = std::fs::metadata(&path).map(|m| m.len()).unwrap_or(0);
        rows.push(BenchRow { task: task.to_string(), seconds: best, bytes });
    }
    Ok(rows)
}

/// The rows as a report table (`.to_text()` for the terminal).
pub fn table(rows: &[BenchRow]) -> Table {
    let mut t = Table::new("render_bench", "previews: best time over repeats", &["task", "best (s)", "size (KiB)"]);
    for r in rows {
        t.row([r.task.clone(), num(r.seconds, 3), num(r.bytes as f64 / 1024.0, 1)]);
    }
    t
}
