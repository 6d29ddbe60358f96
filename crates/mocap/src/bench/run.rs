//! `inbetween mocap bench` as one library call: read the corpus, cut it by the paper's protocol,
//! get a SIDQL policy (committed, from a file, or trained here on the training split), score every
//! selector on all windows and on the test split, add the extra measurements, and write the report.

use super::measure::{both_reconstructions, codec_ratio, reconstruction_throughput};
use super::report::BenchResults;
use super::{
    clip_windows, describe_sources, evaluate_with_progress, split_clips, training_windows, Clip, Method, PolicyFn,
    Protocol, Window,
};
use crate::dqn::{DqnConfig, SidqlPolicy, TrainOptions};
use crate::representation::SphericalMotion;
use crate::{MocapError, Result};
use inbetween_core::units::{LengthUnit, UnitChoice};
use inbetween_io::report::Report;
use inbetween_io::Progress;
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// Which SIDQL policy the bench scores.
#[derive(Clone, Debug, PartialEq)]
pub enum PolicyChoice {
    /// The policy compiled into the crate (trained on our procedural gaits).
    Committed,
    /// A policy written by `inbetween mocap train`.
    File(PathBuf),
    /// Train here on the training split (windows at stride 10, the paper's settings) for this many
    /// episodes, and save the policy to `output`.
    Train { episodes: usize, output: PathBuf },
}

/// What `inbetween mocap bench` runs and where it writes.
#[derive(Clone, Debug)]
pub struct BenchConfig {
    /// Data folder: every CMU take under `<dir>/mocap/cmu`, or each .bvh in it. None: the shared
    /// corpus (`inbetween_io::data::shared_data_dir`).
    pub data: Option<PathBuf>,
    /// Length unit of every clip, overriding the corpus's known units and the per-clip inference
    /// ([`crate::corpus::load`]).
    pub unit: Option<LengthUnit>,
    /// The paper's protocol (§5.1–5.2); its seed also seeds RC and SIDQL training.
    pub protocol: Protocol,
    pub ks: Vec<usize>,
    pub policy: PolicyChoice,
    /// Codec error bounds (cm) measured on the full-rate clips in CMU units.
    pub codec_bounds_cm: Vec<f64>,
    /// Write the whole report here (report.txt/.md, one CSV per table, table3.png).
    pub output_dir: Option<PathBuf>,
    /// Also write every row as CSV here (the columns of `mocap_bench.csv`).
    pub csv: Option<PathBuf>,
    /// Also write the bar chart here.
    pub plot: Option<PathBuf>,
}

impl Default for BenchConfig {
    /// The paper's protocol on the shared corpus with the committed policy, codec at 1 and 0.1 cm.
    fn default() -> BenchConfig {
        BenchConfig {
            data: None,
            unit: None,
            protocol: Protocol::paper(),
            ks: vec![5, 10, 15],
            policy: PolicyChoice::Committed,
            codec_bounds_cm: vec![1.0, 0.1],
            output_dir: None,
            csv: None,
            plot: None,
        }
    }
}

/// A finished bench: the report (print `report.to_text()`) and the files written.
#[derive(Debug)]
pub struct BenchOutput {
    pub results: BenchResults,
    pub report: Report,
    pub written: Vec<PathBuf>,
}

/// Runs the whole bench ([`measure`]) and writes what `cfg` asks for.
pub fn run(cfg: &BenchConfig, progress: &Progress) -> Result<BenchOutput> {
    let results = measure(cfg, progress)?;
    let report = results.report(cfg.output_dir.is_some())?;
    let mut written = Vec::new();
    if let Some(dir) = &cfg.output_dir {
        written.extend(report.write(dir)?);
    }
    if let Some(p) = &cfg.csv {
        inbetween_io::write_atomic(p, results.rows_table().to_csv().as_bytes())
            .map_err(|source| MocapError::Io { path: p.display().to_string(), source })?;
        written.push(p.clone());
    }
    if let Some(p) = &cfg.plot {
        results.plot(p)?;
        written.push(p.clone());
    }
    Ok(BenchOutput { results, report, written })
}

/// The data folder: `data`, else the shared corpus.
pub fn data_dir(data: Option<&Path>) -> Result<PathBuf> {
    match data {
        Some(d) => Ok(d.to_path_buf()),
        None => inbetween_io::data::shared_data_dir()
            .map_err(|p| MocapError::Invalid(format!("no data at {} (give --data DIR)", p.display()))),
    }
}

/// SIDQL's training windows and their description in words (written in the policy's card):
/// 24 procedural gaits, or the CMU training split of the corpus in `data` (the test split held out
/// by the bench protocol with `seed`).
pub fn training_set(procedural: bool, data: Option<&Path>, unit: Option<LengthUnit>, seed: u64, stride: usize) -> Result<(Vec<SphericalMotion>, String)> {
    let protocol = Protocol { seed, ..Protocol::paper() };
    if procedural {
        let clips = super::procedural_clips(seed, 24);
        let names: Vec<String> = clips.iter().map(|c| c.name.clone()).collect();
        let p = Protocol { skip_first_frame: false, ..protocol };
        let windows = super::training_windows(&clips, &names, &p, stride)?;
        let data = format!("{} procedural gaits (seed {seed}), {} windows of 60 frames at stride {stride}", clips.len(), windows.len());
        return Ok((windows, data));
    }
    let dir = data_dir(data)?;
    let clips = crate::corpus::load(&dir, unit)?.clips;
    let names: Vec<String> = clips.iter().map(|c| c.name.clone()).collect();
    let (train, test) = super::split_clips(&names, &protocol);
    let windows = super::training_windows(&clips, &train, &protocol, stride)?;
    let data = format!(
        "CMU training split (seed {seed}) {train:?}, {} windows of 60 frames at stride {stride}; test split {test:?} held out",
        windows.len()
    );
    Ok((windows, data))
}

/// Every measurement of the bench, no files written.
pub fn measure(cfg: &BenchConfig, progress: &Progress) -> Result<BenchResults> {
    let dir = data_dir(cfg.data.as_deref())?;
    progress.phase(1, "corpus");
    progress.set_message(dir.display().to_string());
    let corpus = crate::corpus::load(&dir, cfg.unit)?;
    let unit_notes = corpus.unit_notes();
    let clips = &corpus.clips;
    let protocol = &cfg.protocol;
    let names: Vec<String> = clips.iter().map(|c| c.name.clone()).collect();
    let (train, test) = split_clips(&names, protocol);
    let all = windows(clips, protocol, progress)?;
    if all.is_empty() {
        return Err(MocapError::Invalid(format!(
            "no clip in {} is long enough for one {}-frame window at {} fps",
            dir.display(),
            protocol.window,
            protocol.fps
        )));
    }
    let test_windows: Vec<Window> = all.iter().filter(|w| test.contains(&w.clip)).cloned().collect();
    let (policy, policy_text, log) = policy(cfg, clips, &train, progress)?;
    let policy_fn = |rep: &SphericalMotion, k: usize| policy.select(rep, k);
    let pf: Option<PolicyFn> = Some(&policy_fn);
    let per_split = (Method::ALL.len() * cfg.ks.len()) as u64;
    progress.phase(per_split * (all.len() + test_windows.len()) as u64, "selectors");
    let seed = protocol.seed;
    let mut rows = evaluate_with_progress("all", &all, &Method::ALL, &cfg.ks, seed, pf, progress)?;
    if !test_windows.is_empty() {
        rows.extend(evaluate_with_progress("test", &test_windows, &Method::ALL, &cfg.ks, seed, pf, progress)?);
    }
    progress.phase(1, "throughput");
    let throughput = reconstruction_throughput(&all, 10)?;
    progress.phase(all.len() as u64, "reconstruct");
    let reconstructions = both_reconstructions(&all, &cfg.ks, progress)?;
    // The codec on the full-rate source clips: the cgspeed takes, or the clips of a plain folder
    // (the 100-joint iClone retargets would dominate the run time).
    let full_rate: Vec<(&Clip, &UnitChoice)> =
        clips.iter().zip(&corpus.units).filter(|(c, _)| c.source == "cgspeed" || c.source == "bvh").collect();
    let mut codec = Vec::new();
    if !full_rate.is_empty() {
        progress.phase((full_rate.len() * cfg.codec_bounds_cm.len()) as u64, "codec");
        for &bound in &cfg.codec_bounds_cm {
            codec.push(codec_ratio(&full_rate, bound, progress)?);
        }
    }
    Ok(BenchResults {
        source: if cfg.data.is_some() { dir.display().to_string() } else { "the shared corpus".into() },
        takes: clips.len(),
        sources: describe_sources(clips),
        unit_notes,
        protocol: protocol.clone(),
        windows: all.len(),
        joints: all.iter().map(|w| w.rep.num_joints).collect::<BTreeSet<usize>>(),
        train,
        test,
        test_windows: test_windows.len(),
        policy: policy_text,
        log,
        ks: cfg.ks.clone(),
        rows,
        throughput,
        reconstructions,
        codec,
    })
}

/// All windows of all clips (one unit on `progress` per clip).
fn windows(clips: &[Clip], protocol: &Protocol, progress: &Progress) -> Result<Vec<Window>> {
    progress.phase(clips.len() as u64, "windows");
    let mut all = Vec::new();
    for clip in clips {
        progress.set_message(clip.name.clone());
        all.extend(clip_windows(clip, protocol)?);
        progress.inc(1);
    }
    Ok(all)
}

/// The policy to score, a line saying which it is, and training log lines.
fn policy(
    cfg: &BenchConfig,
    clips: &[Clip],
    train: &[String],
    progress: &Progress,
) -> Result<(SidqlPolicy, String, Vec<String>)> {
    match &cfg.policy {
        PolicyChoice::Committed => {
            let policy = SidqlPolicy::committed()?;
            let text = format!("the committed policy (trained on: {})", policy.info.trained_on);
            Ok((policy, text, Vec::new()))
        }
        PolicyChoice::File(p) => {
            let policy = SidqlPolicy::load(p)?;
            let text = format!("{} (trained on: {})", p.display(), policy.info.trained_on);
            Ok((policy, text, Vec::new()))
        }
        PolicyChoice::Train { episodes, output } => {
            let train_windows = training_windows(clips, train, &cfg.protocol, 10)?;
            let opts = TrainOptions {
                episodes: *episodes,
                seed: cfg.protocol.seed,
                data: format!("CMU training split {train:?}, {} windows at stride 10", train_windows.len()),
                ..TrainOptions::paper()
            };
            progress.phase(1, "SIDQL");
            progress.set_message(format!("training {} episodes on {} windows", opts.episodes, train_windows.len()));
            let (policy, report) = crate::dqn::train(&train_windows, &DqnConfig::default(), &opts)?;
            if let Some(parent) = output.parent().filter(|d| !d.as_os_str().is_empty()) {
                std::fs::create_dir_all(parent)
                    .map_err(|source| MocapError::Io { path: parent.display().to_string(), source })?;
            }
            policy.save(output)?;
            let log = vec![
                format!(
                    "trained {} episodes on {} windows of the training split in {:.0} s, {} updates, loss per 50 episodes {:?}",
                    opts.episodes,
                    train_windows.len(),
                    report.seconds,
                    report.updates,
                    report.loss_curve.iter().map(|l| format!("{l:.4}")).collect::<Vec<_>>()
                ),
                format!("saved {} (weights trained on CMU data: keep out of the repository)", output.display()),
            ];
            let text = format!("trained here, {} (trained on: {})", output.display(), policy.info.trained_on);
            Ok((policy, text, log))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two procedural walks in a plain folder: the whole bench runs, writes every file and keeps
    /// the protocol's split.
    #[test]
    fn the_bench_runs_on_a_folder_and_writes_its_report() {
        let dir = tempfile::tempdir().unwrap();
        let data = dir.path().join("clips");
        std::fs::create_dir_all(&data).unwrap();
        for (i, frames) in [(0, 130), (1, 125)] {
            let mut p = inbetween_core::procedural::GaitParams::walk();
            p.frames = frames;
            p.speed *= 1.0 + 0.2 * i as f64;
            inbetween_io::write_bvh(&data.join(format!("walk{i}.bvh")), &inbetween_core::procedural::gait(&p)).unwrap();
        }
        let cfg = BenchConfig {
            data: Some(data.clone()),
            ks: vec![5, 10],
            codec_bounds_cm: vec![1.0],
            output_dir: Some(dir.path().join("report")),
            csv: Some(dir.path().join("rows.csv")),
            ..BenchConfig::default()
        };
        let progress = Progress::hidden();
        let out = run(&cfg, &progress).unwrap();
        let r = &out.results;
        assert_eq!((r.takes, r.windows, r.test_windows, r.test.len()), (2, 4, 2, 1));
        assert_eq!(r.rows.len(), 2 * 5 * 2, "two splits, five methods, two K");
        assert!(r.policy.starts_with("the committed policy (trained on: 24 procedural gaits"), "{}", r.policy);
        assert_eq!(r.codec.len(), 1);
        assert_eq!(out.written.len(), 2 + 5 + 1 + 1, "txt, md, five CSVs, the chart, rows.csv");
        let csv = std::fs::read_to_string(dir.path().join("rows.csv")).unwrap();
        assert_eq!(csv, std::fs::read_to_string(dir.path().join("report/mocap_bench.csv")).unwrap());
        let text = std::fs::read_to_string(dir.path().join("report/report.txt")).unwrap();
        assert_eq!(text, out.report.to_text());
        assert!(text.contains("Table 3: mean angle error") && text.contains("frames/s"), "{text}");
        assert!(
            r.unit_notes.len() == 1 && text.contains(&r.unit_notes[0]),
            "the report says which unit and why: {text}"
        );
        // Nothing too short: a clear error naming the folder.
        let short = dir.path().join("short");
        std::fs::create_dir_all(&short).unwrap();
        let mut p = inbetween_core::procedural::GaitParams::walk();
        p.frames = 40;
        inbetween_io::write_bvh(&short.join("w.bvh"), &inbetween_core::procedural::gait(&p)).unwrap();
        let e = run(&BenchConfig { data: Some(short), ..BenchConfig::default() }, &progress).unwrap_err().to_string();
        assert!(e.contains("long enough") && e.contains("short"), "{e}");
    }
}
