//! `inbetween batch bench`: the same batch run by 1 and by 2 shard processes on this machine (files
//! per second, speed-up, peak memory per worker), with Dask beside them when the Python package and
//! dask are installed, and a projection to 10,000 and 100,000 inputs from the measured cost per file
//! and core. Each child runs with one compute thread (`RAYON_NUM_THREADS=1`), so the speed-up
//! measures the shards, not the engines' own threads.

use crate::results::{self, ResultLine};
use crate::BatchError;
use inbetween_io::report::{num, Report, Table};
use inbetween_io::scale::{run_measured, ChildRun};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

/// What to measure, and with which programs.
#[derive(Clone, Debug)]
pub struct BenchOptions {
    /// The `inbetween` binary the shards run.
    pub exe: PathBuf,
    /// The shared data folder (`mocap/cmu`, `video` inside it).
    pub data: PathBuf,
    /// Scratch folder for the runs' outputs (emptied first).
    pub scratch: PathBuf,
    /// A Python with `inbetween` and `dask.distributed` importable, for the Dask rows.
    pub python: Option<PathBuf>,
    /// Shard counts to run (the first is the base of the speed-up).
    pub shards: Vec<usize>,
}

impl BenchOptions {
    /// The bench's runs: 1 and 2 shards (the speed-up of a second process), their outputs in the
    /// scratch folder `out/runs`, which [`run`] removes when it is done (the report is what stays).
    pub fn new(exe: PathBuf, data: PathBuf, out: &Path, python: Option<PathBuf>) -> BenchOptions {
        BenchOptions { exe, data, scratch: out.join("runs"), python, shards: vec![1, 2] }
    }
}

/// One workload: a batch job over one folder.
struct Workload {
    job: &'static str,
    dir: PathBuf,
    flags: Vec<String>,
    /// The Dask call's options, as Python keyword arguments.
    dask_options: &'static str,
}

/// One measured run: `workers` processes (or Dask workers) over the whole folder.
struct Run {
    how: String,
    workers: usize,
    wall_s: f64,
    peak_mib: Option<f64>,
    lines: Vec<ResultLine>,
    ok: bool,
    error: String,
}

fn clear(dir: &Path) -> Result<(), BatchError> {
    if dir.exists() {
        std::fs::remove_dir_all(dir).map_err(|source| BatchError::Io { path: dir.to_path_buf(), source })?;
    }
    Ok(())
}

fn read_lines(out: &Path) -> Result<Vec<ResultLine>, BatchError> {
    let mut lines = Vec::new();
    for f in results::files_in(out)? {
        lines.extend(results::read(&f)?);
    }
    Ok(lines)
}

/// `n` shard processes at once over the workload's folder.
fn shards(opts: &BenchOptions, w: &Workload, n: usize) -> Result<Run, BatchError> {
    let out = opts.scratch.join(format!("{}-{n}-shards", w.job));
    clear(&out)?;
    let t = Instant::now();
    let runs: Vec<std::io::Result<ChildRun>> = std::thread::scope(|s| {
        let handles: Vec<_> = (0..n)
            .map(|i| {
                let out = &out;
                s.spawn(move || {
                    let mut c = Command::new(&opts.exe);
                    c.args(["batch", w.job]).arg(&w.dir).arg("-o").arg(out).args(&w.flags);
                    c.args(["--shard", &format!("{i}/{n}")]);
                    c.env("RAYON_NUM_THREADS", "1").env("INBETWEEN_NO_PROGRESS", "1");
                    run_measured(&mut c)
                })
            })
            .collect();
        handles.into_iter().map(|h| h.join().expect("bench thread")).collect()
    });
    let wall_s = t.elapsed().as_secs_f64();
    let mut run = Run {
        how: "shard processes".into(),
        workers: n,
        wall_s,
        peak_mib: None,
        lines: read_lines(&out)?,
        ok: true,
        error: String::new(),
    };
    for r in runs {
        match r {
            Ok(c) => {
                run.peak_mib = match (run.peak_mib, c.peak_mib) {
                    (Some(a), Some(b)) => Some(a.max(b)),
                    (a, b) => a.or(b),
                };
                if !c.success {
                    run.ok = false;
                    run.error = c.stderr.lines().next().unwrap_or("failed").to_string();
                }
            }
            Err(e) => {
                run.ok = false;
                run.error = e.to_string();
            }
        }
    }
    Ok(run)
}

/// `inbetween.batch.map` on a Dask `LocalCluster` of `n` single-threaded worker processes.
fn dask(opts: &BenchOptions, python: &Path, w: &Workload, n: usize) -> Result<Run, BatchError> {
    let out = opts.scratch.join(format!("{}-{n}-dask", w.job));
    clear(&out)?;
    let script = format!(
        "import glob, os, sys\n\
         from dask.distributed import Client, LocalCluster\n\
         import inbetween.batch\n\
         exts = {exts:?}\n\
         paths = sorted(p for p in glob.glob(os.path.join(sys.argv[1], '**', '*'), recursive=True) if p.lower().rsplit('.', 1)[-1] in exts)\n\
         with LocalCluster(n_workers={n}, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, Client(cluster) as client:\n\
         \x20   inbetween.batch.map({job:?}, paths, client=client, out=sys.argv[2], root=sys.argv[1]{opts})\n",
        exts = crate::Kind::parse(w.job)?.extensions(),
        job = w.job,
        opts = w.dask_options,
    );
    let mut c = Command::new(python);
    c.arg("-c").arg(script).arg(&w.dir).arg(&out);
    c.env("RAYON_NUM_THREADS", "1").env("INBETWEEN_NO_PROGRESS", "1");
    let r = run_measured(&mut c).map_err(|source| BatchError::Io { path: python.to_path_buf(), source })?;
    Ok(Run {
        how: "Dask workers".into(),
        workers: n,
        wall_s: r.seconds,
        // The scheduler's process is the one measured; workers are its children.
        peak_mib: None,
        lines: read_lines(&out)?,
        ok: r.success,
        error: r.stderr.lines().rev().find(|l| !l.trim().is_empty()).unwrap_or("").to_string(),
    })
}

/// Whether `python` imports the package and dask.distributed.
fn dask_available(python: &Path) -> Result<(), String> {
    let o = Command::new(python)
        .args(["-c", "import inbetween.batch, dask.distributed"])
        .output()
        .map_err(|e| format!("{}: {e}", python.display()))?;
    if o.status.success() {
        Ok(())
    } else {
        Err(String::from_utf8_lossy(&o.stderr).lines().last().unwrap_or("import failed").to_string())
    }
}

/// Runs the bench and returns its report (tables of runs, projection, the slowest inputs).
pub fn run(opts: &BenchOptions) -> Result<Report, BatchError> {
    let workloads = [
        Workload {
            job: "mocap-compress",
            dir: opts.data.join("mocap/cmu"),
            flags: vec!["--max-error".into(), "1cm".into()],
            dask_options: ", max_error_cm=1.0",
        },
        Workload { job: "video-analyse", dir: opts.data.join("video"), flags: vec![], dask_options: "" },
    ];
    let dask_python = match &opts.python {
        Some(p) => dask_available(p).map(|_| p.clone()),
        None => Err("no Python given".to_string()),
    };
    let mut report = Report::new("batch-bench", "Batch runs in shards on this machine");
    let mut runs_t = Table::new(
        "runs",
        "The whole folder by N workers (each one compute thread)",
        &["job", "inputs", "workers", "how", "wall s", "files/s", "speed-up vs 1", "peak MiB per worker", "failed"],
    );
    let mut proj = Table::new(
        "projection",
        "Projected wall time for a larger library at the measured cost per file and core",
        &[
            "job",
            "s per file per core",
            "10,000 files, 1 core",
            "10,000 files, 64 cores",
            "100,000 files, 64 cores",
            "100,000 files, 1,000 cores",
        ],
    );
    let mut slow =
        Table::new("slowest", "Where the time goes (1-worker run)", &["job", "input", "seconds", "share of the run"]);
    for w in &workloads {
        if !w.dir.is_dir() {
            runs_t.note(format!("{}: skipped, no folder {}", w.job, w.dir.display()));
            continue;
        }
        let mut runs = Vec::new();
        for &n in &opts.shards {
            runs.push(shards(opts, w, n)?);
        }
        if let Ok(py) = &dask_python {
            for &n in &opts.shards {
                runs.push(dask(opts, py, w, n)?);
            }
        }
        let base = |how: &str| runs.iter().find(|r| r.how == how && r.workers == opts.shards[0]).map(|r| r.wall_s);
        for r in &runs {
            let inputs = r.lines.len();
            let failed = r.lines.iter().filter(|l| !l.ok).count();
            runs_t.row([
                w.job.to_string(),
                inputs.to_string(),
                r.workers.to_string(),
                r.how.clone(),
                num(r.wall_s, 2),
                num(inputs as f64 / r.wall_s, 2),
                base(&r.how).map_or("-".into(), |b| num(b / r.wall_s, 2)),
                r.peak_mib.map_or("-".into(), |m| num(m, 0)),
                if r.ok { failed.to_string() } else { format!("{failed}; run failed: {}", r.error) },
            ]);
        }
        // The cost per file and core from the one-worker shard run (start-up included).
        if let Some(one) = runs.iter().find(|r| r.how == "shard processes" && r.workers == 1) {
            let per = one.wall_s / one.lines.len().max(1) as f64;
            let hours = |files: f64, cores: f64| format!("{} h", num(per * files / cores / 3600.0, 2));
            proj.row([
                w.job.to_string(),
                num(per, 3),
                hours(1e4, 1.0),
                hours(1e4, 64.0),
                hours(1e5, 64.0),
                hours(1e5, 1000.0),
            ]);
            let total: f64 = one.lines.iter().map(|l| l.seconds).sum();
            let mut by_time: Vec<&ResultLine> = one.lines.iter().collect();
            by_time.sort_by(|a, b| b.seconds.total_cmp(&a.seconds));
            for l in by_time.iter().take(3) {
                slow.row([
                    w.job.to_string(),
                    l.input.clone(),
                    num(l.seconds, 2),
                    format!("{} %", num(100.0 * l.seconds / total, 0)),
                ]);
            }
        }
    }
    runs_t.note(format!(
        "machine: {} cores; every child with RAYON_NUM_THREADS=1",
        std::thread::available_parallelism().map_or(0, |n| n.get())
    ));
    match &dask_python {
        Ok(_) => runs_t.note("Dask: inbetween.batch.map on a LocalCluster of single-threaded worker processes (the Python given as --python); peak memory not measured per worker"),
        Err(why) => runs_t.note(format!("Dask rows skipped: {why}")),
    };
    proj.note(
        "linear in files and cores (inputs are independent); the measured speed-up at 2 workers is the check on that",
    );
    report.table(runs_t).table(proj).table(slow);
    // The runs' outputs are scratch; the report is what stays.
    let _ = std::fs::remove_dir_all(&opts.scratch);
    Ok(report)
}
