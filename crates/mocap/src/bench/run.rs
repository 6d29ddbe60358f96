//! `inbetween mocap bench` as one library call: read the corpus, cut it by the paper's protocol,
//! get a SIDQL policy (committed, from a file, or trained here on the training split), score every
//! selector on all windows and on the test split, run the take-level k-fold (a policy trained per
//! fold, every window scored once by a policy that never saw its take), add the extra
//! measurements, and make the report.

use super::measure::{both_reconstructions, codec_ratio, reconstruction_throughput};
use super::report::BenchResults;
use super::report::{KFold, KFoldRow};
use super::{
    clip_windows, describe_sources, evaluate_with_progress, split_clips, training_windows, Clip, Method, PolicyFn,
    Protocol, Window,
};
use crate::dqn::{DqnConfig, Finish, SidqlPolicy, TrainOptions};
use crate::representation::SphericalMotion;
use crate::{MocapError, Result};
use inbetween_core::units::{LengthUnit, UnitChoice};
use inbetween_io::report::{BenchOptions, Report};
use inbetween_io::Progress;
use std::collections::BTreeSet;
use std::path::PathBuf;

/// Which SIDQL policy the bench scores.
#[derive(Clone, Debug, PartialEq)]
pub enum PolicyChoice {
    /// The policy compiled into the crate (trained on our procedural gaits).
    Committed,
    /// A policy written by `inbetween mocap train`.
    File(PathBuf),
    /// Train here on the training split (windows at stride 10, [`TrainOptions::default`] with this
    /// many fine-tuning epochs), and save the policy to `output`.
    Train { episodes: usize, output: PathBuf },
}

impl PolicyChoice {
    /// Train here with this many fine-tuning epochs and save the policy where `mocap train` does
    /// ([`crate::dqn::DEFAULT_POLICY_PATH`]).
    pub fn train(episodes: usize) -> PolicyChoice {
        PolicyChoice::Train { episodes, output: PathBuf::from(crate::dqn::DEFAULT_POLICY_PATH) }
    }
}

/// The take-level k-fold: takes dealt into `folds` groups (seeded shuffle); for each, a policy
/// is trained on the other groups' takes (windows at `stride`) with `train` and scored on the
/// group's windows.
#[derive(Clone, Debug)]
pub struct KFoldConfig {
    pub folds: usize,
    pub stride: usize,
    pub train: TrainOptions,
}

impl Default for KFoldConfig {
    fn default() -> KFoldConfig {
        KFoldConfig { folds: 5, stride: 10, train: TrainOptions { progress: false, ..TrainOptions::default() } }
    }
}

/// What `inbetween mocap bench` runs, beside [`BenchOptions`]: its `data` is the folder (every
/// CMU take under `<dir>/mocap/cmu`, or each .bvh in it; None: the shared corpus), its `seed` the
/// protocol's, its `quick` skips the k-fold.
#[derive(Clone, Debug)]
pub struct BenchConfig {
    /// Length unit of every clip, overriding the corpus's known units and the per-clip inference
    /// ([`crate::corpus::load`]).
    pub unit: Option<LengthUnit>,
    /// The paper's protocol (§5.1–5.2); its seed also seeds RC and SIDQL training.
    pub protocol: Protocol,
    pub ks: Vec<usize>,
    pub policy: PolicyChoice,
    /// Codec error bounds (cm) measured on the full-rate clips in CMU units.
    pub codec_bounds_cm: Vec<f64>,
    /// Put the bar chart (`table3.png`) into the report even when it is not written to a folder.
    pub chart: bool,
    /// The take-level k-fold of SIDQL (None: skipped).
    pub kfold: Option<KFoldConfig>,
}

impl Default for BenchConfig {
    /// The paper's protocol on the shared corpus with the committed policy, codec at 1 and 0.1 cm.
    fn default() -> BenchConfig {
        BenchConfig {
            unit: None,
            protocol: Protocol::paper(),
            ks: vec![5, 10, 15],
            policy: PolicyChoice::Committed,
            codec_bounds_cm: vec![1.0, 0.1],
            chart: false,
            kfold: Some(KFoldConfig::default()),
        }
    }
}

/// Runs the whole bench ([`measure`]); its report holds the chart (`table3.png`) when it will be
/// written to a folder or `chart` asks.
pub fn run(opts: &BenchOptions<BenchConfig>) -> Result<Report> {
    measure(opts)?.report(opts.out.is_some() || opts.engine.chart)
}

pub use crate::corpus::data_dir;
pub use crate::protocol::{training_set, TrainingData};

/// Deals the takes that have windows into `folds` groups: sorted, shuffled with `seed`, dealt in
/// turn.
pub fn fold_takes(all: &[Window], folds: usize, seed: u64) -> Vec<Vec<String>> {
    use rand::seq::SliceRandom;
    use rand::SeedableRng;
    let mut names: Vec<String> = all.iter().map(|w| w.clip.clone()).collect::<BTreeSet<_>>().into_iter().collect();
    names.shuffle(&mut rand_chacha::ChaCha8Rng::seed_from_u64(seed));
    let folds = folds.clamp(1, names.len().max(1));
    let mut out = vec![Vec::new(); folds];
    for (i, n) in names.into_iter().enumerate() {
        out[i % folds].push(n);
    }
    out
}

/// The take-level k-fold ([`KFoldConfig`]): per fold, train on the other takes and score UC,
/// Greedy, both SIDQL stages and Optimal on the fold's windows; rows pooled over every window.
pub fn kfold(
    clips: &[Clip],
    all: &[Window],
    protocol: &Protocol,
    cfg: &KFoldConfig,
    ks: &[usize],
    progress: &Progress,
) -> Result<KFold> {
    let groups = fold_takes(all, cfg.folds, protocol.seed);
    progress.phase(groups.len() as u64, "k-fold");
    let variants = [
        "UC",
        "Greedy",
        "SIDQL before fine-tuning",
        "SIDQL fine-tuned",
        "SIDQL fine-tuned, checked against UC",
        "SIDQL before fine-tuning, checked and refined",
        "SIDQL fine-tuned, checked and refined (default)",
        "Optimal",
    ];
    // (variant, k) → sums over windows of angle, paper units, seconds; windows.
    let mut sums = vec![(0.0, 0.0, 0.0, 0usize); variants.len() * ks.len()];
    let (mut train_seconds, mut train_windows) = (Vec::new(), Vec::new());
    for (i, test) in groups.iter().enumerate() {
        progress.set_message(format!("fold {}/{}: training", i + 1, groups.len()));
        let train: Vec<String> =
            groups.iter().enumerate().filter(|(j, _)| *j != i).flat_map(|(_, g)| g.clone()).collect();
        let windows = training_windows(clips, &train, protocol, cfg.stride)?;
        let opts = TrainOptions {
            seed: inbetween_core::seed::derive(protocol.seed, i as u64),
            data: format!("fold {i}"),
            ..cfg.train.clone()
        };
        let trained = crate::dqn::train(&windows, &DqnConfig::default(), &opts)?;
        train_seconds.push(trained.report.seconds);
        train_windows.push(windows.len());
        let held: Vec<Window> = all.iter().filter(|w| test.contains(&w.clip)).cloned().collect();
        progress.set_message(format!("fold {}/{}: scoring {} windows", i + 1, groups.len(), held.len()));
        let mut add = |v: usize, rows: Vec<super::Row>| {
            for r in rows {
                let ki = ks.iter().position(|&k| k == r.k).expect("a K of the bench");
                let s = &mut sums[v * ks.len() + ki];
                let w = r.windows as f64;
                (s.0, s.1, s.2, s.3) =
                    (s.0 + r.mean_angle_error * w, s.1 + r.paper_units * w, s.2 + r.decision_ms * w, s.3 + r.windows);
            }
        };
        let seed = protocol.seed;
        for (v, m) in [(0, Method::Uc), (1, Method::Greedy), (7, Method::Optimal)] {
            add(v, super::evaluate("fold", &held, &[m], ks, seed, None)?);
        }
        let finetuned = trained.finetuned.as_ref().unwrap_or(&trained.pretrained);
        let policies = [
            (2, &trained.pretrained, Finish::NetworkAlone),
            (3, finetuned, Finish::NetworkAlone),
            (4, finetuned, Finish::CheckedAgainstUc),
            (5, &trained.pretrained, Finish::CheckedAndRefined),
            (6, finetuned, Finish::CheckedAndRefined),
        ];
        for (v, p, finish) in policies {
            let f = |rep: &SphericalMotion, k: usize| p.select_with(rep, k, finish);
            add(v, super::evaluate("fold", &held, &[Method::Sidql], ks, seed, Some(&f))?);
        }
        progress.inc(1);
    }
    let mut rows = Vec::new();
    for (v, name) in variants.iter().enumerate() {
        for (ki, &k) in ks.iter().enumerate() {
            let s = sums[v * ks.len() + ki];
            let n = s.3.max(1) as f64;
            rows.push(KFoldRow {
                variant: name.to_string(),
                k,
                mean_angle_error: s.0 / n,
                paper_units: s.1 / n,
                decision_ms: s.2 / n,
                windows: s.3,
            });
        }
    }
    Ok(KFold { folds: groups, rows, train_seconds, train_windows, options: cfg.train.clone(), stride: cfg.stride })
}

/// Every measurement of the bench, no files written.
pub fn measure(opts: &BenchOptions<BenchConfig>) -> Result<BenchResults> {
    let progress = &opts.progress;
    let cfg = &BenchConfig {
        protocol: Protocol { seed: opts.seed.unwrap_or(opts.engine.protocol.seed), ..opts.engine.protocol.clone() },
        kfold: opts.engine.kfold.clone().filter(|_| !opts.quick),
        ..opts.engine.clone()
    };
    let dir = data_dir(opts.data.as_deref())?;
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
    // A k-fold needs at least two takes with windows (one to train on, one to test).
    let kfold = match &cfg.kfold {
        Some(k) if fold_takes(&all, k.folds, seed).len() >= 2 => {
            Some(kfold(clips, &all, protocol, k, &cfg.ks, progress)?)
        }
        _ => None,
    };
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
        source: if opts.data.is_some() { dir.display().to_string() } else { "the shared corpus".into() },
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
        kfold,
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
                ..TrainOptions::default()
            };
            progress.phase(1, "SIDQL");
            progress.set_message(format!("training on {} windows", train_windows.len()));
            let trained = crate::dqn::train(&train_windows, &DqnConfig::default(), &opts)?;
            if let Some(parent) = output.parent().filter(|d| !d.as_os_str().is_empty()) {
                std::fs::create_dir_all(parent)
                    .map_err(|source| MocapError::Io { path: parent.display().to_string(), source })?;
            }
            let policy = trained.finetuned.unwrap_or(trained.pretrained);
            policy.save(output)?;
            let r = &trained.report;
            let log = vec![
                format!(
                    "trained on {} windows of the training split: pretraining {} steps in {:.0} s, fine-tuning {} epochs ({} updates) in {:.0} s",
                    train_windows.len(),
                    r.pretrain_steps,
                    r.pretrain_seconds,
                    r.episodes,
                    r.updates,
                    r.finetune_seconds
                ),
                format!("saved {}", output.display()),
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
            ks: vec![5, 10],
            codec_bounds_cm: vec![1.0],
            kfold: Some(KFoldConfig {
                folds: 2,
                stride: 30,
                train: TrainOptions {
                    pretrain_steps: 100,
                    pretrain_batch: 4,
                    episodes: 4,
                    batch: 8,
                    progress: false,
                    ..TrainOptions::default()
                },
            }),
            ..BenchConfig::default()
        };
        let opts = BenchOptions { data: Some(data.clone()), ..BenchOptions::new(cfg) };
        let r = &measure(&opts).unwrap();
        assert_eq!((r.takes, r.windows, r.test_windows, r.test.len()), (2, 4, 2, 1));
        assert_eq!(r.rows.len(), 2 * 5 * 2, "two splits, five methods, two K");
        assert!(r.policy.starts_with("the committed policy (trained on: every CMU take"), "{}", r.policy);
        let kf = r.kfold.as_ref().unwrap();
        assert_eq!(kf.folds.len(), 2);
        assert_eq!(kf.rows.len(), 8 * 2, "eight selectors, two K");
        assert!(kf.rows.iter().all(|row| row.windows == 4), "every window scored once: {:?}", kf.rows);
        assert_eq!(r.codec.len(), 1);
        // The bench entry: quick skips the k-fold; the chart only for a folder (or when asked).
        let quick = BenchOptions { quick: true, out: Some(dir.path().join("report")), ..opts.clone() };
        let report = run(&quick).unwrap();
        assert_eq!(quick.write(&report).unwrap().len(), 2 + 5 + 1, "txt, md, five CSVs (no k-fold), the chart");
        assert!(run(&BenchOptions { quick: true, ..opts.clone() }).unwrap().file_bytes("table3.png").is_none());
        let text = std::fs::read_to_string(dir.path().join("report/report.txt")).unwrap();
        assert_eq!(text, report.to_text());
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
        let e = run(&BenchOptions { data: Some(short), quick: true, ..BenchOptions::new(BenchConfig::default()) })
            .unwrap_err()
            .to_string();
        assert!(e.contains("long enough") && e.contains("short"), "{e}");
    }
}

/// Training the committed policy and the k-fold from the test harness (the library calls
/// `inbetween mocap train --all-takes` and `inbetween mocap bench` make), for machines where the
/// CLI is not built: `INBETWEEN_SIDQL_OUT=crates/mocap/weights/sidql.bpk cargo test -p
/// inbetween-mocap --lib committed_recipe -- --ignored --nocapture`.
#[cfg(test)]
mod recipe {
    use super::*;

    #[test]
    #[ignore]
    fn committed_recipe_trains_on_every_take() {
        let Some(out) = std::env::var_os("INBETWEEN_SIDQL_OUT").map(PathBuf::from) else {
            println!("skipped: set INBETWEEN_SIDQL_OUT to the policy file to write");
            return;
        };
        inbetween_io::data::with_shared_data("SIDQL training", |dir| {
            let (windows, data) = training_set(TrainingData::CmuAll, Some(&dir), None, 0, 10).unwrap();
            let opts = TrainOptions { checkpoint: Some(out.clone()), data, progress: false, ..TrainOptions::default() };
            let t = crate::dqn::train(&windows, &DqnConfig::default(), &opts).unwrap();
            println!("{:?}", t.report);
        });
    }

    #[test]
    #[ignore]
    fn kfold_of_the_default_recipe() {
        inbetween_io::data::with_shared_data("SIDQL k-fold", |dir| {
            let corpus = crate::corpus::load(&dir, None).unwrap();
            let all = windows(&corpus.clips, &Protocol::paper(), &Progress::hidden()).unwrap();
            let k = kfold(
                &corpus.clips,
                &all,
                &Protocol::paper(),
                &KFoldConfig::default(),
                &[5, 10, 15],
                &Progress::hidden(),
            )
            .unwrap();
            println!("{}", k.table(&[5, 10, 15]).to_text());
        });
    }
}
