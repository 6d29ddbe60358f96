//! The evaluation (`inbetween face bench`): §5 of the paper on our data, ours beside the paper's
//! numbers.
//!
//! * Held-out captures, split by file: masked MSE and the six distance errors for linear, cubic and
//!   the networks, by constraint type and gap length (0.5, 1, 2, 3 s).
//! * Table 4 protocol: the whole clip masked, guidance only.
//! * Plausibility ([`plausibility`]): a fresh two-sample classifier's AUC (real vs filled windows) and
//!   blink / eye-closure / mouth-speed ratios inside the gap against the same capture outside it, for gaps of
//!   1, 2, 3 and 5 s and for the Table 4 whole-window protocol.
//! * Table 3: Bézier keys per edit at tolerance 0.01 and the CPU time of an edit.
//! * Visemes on procedural clips (the captures have no phoneme labels).
//!
//! Every edit goes through [`crate::infer::EditJob`], the same path as `face edit`.

pub mod bezier;
pub mod loco;
pub mod plausibility;
mod protocol;
mod tables;
pub mod timing;

use protocol::*;
pub use protocol::{libraries, test_clips, viseme_runs, FaceBenchConfig, Library, GAPS_S, PLAUSIBILITY_GAPS_S};
use tables::*;

use inbetween_core::seed::derive;
use inbetween_io::report::{BenchOptions, Report};
use inbetween_io::Progress;
use std::path::PathBuf;

use crate::data::split::{TEST_FILES, TRAIN_FILES};
use crate::data::FaceError;
use crate::edit::ConstraintKind;
use crate::procedural;
use crate::weights::NetworkSet;

/// The face bench's own options (beside [`BenchOptions`], whose `data` is the captures folder).
#[derive(Clone, Debug, Default)]
pub struct FaceBench {
    /// A folder of weights trained on procedural clips to bench instead of the committed ones.
    pub weights: Option<PathBuf>,
    /// A folder of weights trained on the real captures, compared too.
    pub real_weights: Option<PathBuf>,
}

/// `inbetween face bench`: the captures ([`crate::infer::plan::captures_dir`] of `data`),
/// [`FaceBenchConfig::quick`] or [`FaceBenchConfig::full`] (`seed` replacing the configuration's),
/// the weight sets, then [`evaluate`].
pub fn run(opts: &BenchOptions<FaceBench>) -> Result<Report, FaceError> {
    let captures = crate::infer::plan::captures_dir(opts.data.as_deref())?;
    let cfg = if opts.quick { FaceBenchConfig::quick(captures) } else { FaceBenchConfig::full(captures) };
    let cfg = FaceBenchConfig { seed: opts.seed.unwrap_or(cfg.seed), ..cfg };
    let mut sets = vec![match &opts.engine.weights {
        Some(dir) => crate::weights::set_from_dir(dir, "procedural")?,
        None => crate::weights::committed_set()?,
    }];
    if let Some(dir) = &opts.engine.real_weights {
        sets.push(crate::weights::set_from_dir(dir, "real")?);
    }
    evaluate(&cfg, &sets, &opts.progress)
}

/// Run the whole evaluation.
pub fn evaluate(cfg: &FaceBenchConfig, sets: &[NetworkSet], progress: &Progress) -> Result<Report, FaceError> {
    let mut report = Report::new("face-bench", "Face engine benchmark (facial animation editing, Berson et al.)");
    let tests = test_clips(&cfg.captures, cfg.one_test_file)?;
    let libs = libraries(cfg)?;
    let real_kinds = [ConstraintKind::None, ConstraintKind::Keyframes, ConstraintKind::Noisy];
    let proc_clips = procedural::generate_corpus(cfg.procedural_clips, cfg.procedural_seconds, derive(cfg.seed, 99));
    progress.set_length(((tests.len() + proc_clips.len()) * GAPS_S.len() * cfg.edits_per_gap) as u64);
    progress.set_message("held-out edits");
    let mut cells: Cells = Vec::new();
    for (i, (_, clip)) in tests.iter().enumerate() {
        evaluate_clip(
            clip,
            None,
            &real_kinds,
            sets,
            &libs,
            cfg.edits_per_gap,
            derive(cfg.seed, i as u64),
            &mut cells,
            progress,
        )?;
    }
    report.table(heldout_table(
        "heldout_by_gap",
        "Held-out captures: error inside the gap by constraint, gap length and method",
        &cells,
    ));
    report.table(heldout_table("heldout", "Held-out captures: all gap lengths together", &by_constraint(&cells)));
    let mut vcells: Cells = Vec::new();
    for (i, p) in proc_clips.iter().enumerate() {
        let kinds = [ConstraintKind::Visemes, ConstraintKind::None];
        evaluate_clip(
            &p.clip,
            Some(&p.visemes),
            &kinds,
            sets,
            &libs,
            cfg.edits_per_gap,
            derive(cfg.seed, 1000 + i as u64),
            &mut vcells,
            progress,
        )?;
    }
    report.table(heldout_table(
        "visemes",
        "Viseme editing on held-out procedural clips (the captures have no phoneme labels)",
        &by_constraint(&vcells),
    ));
    let (auc_t, stats_t) = plausibility_tables(&tests, sets, &libs, cfg, progress)?;
    report.table(auc_t);
    report.table(stats_t);
    let captures = if cfg.one_test_file { 2 } else { TEST_FILES.len() + TRAIN_FILES.len() };
    report.table(loco::loco_table(&cfg.captures, captures, sets, cfg.edits_per_gap, cfg.seed, progress)?);
    report.table(table4(&tests, &proc_clips, sets, &libs, cfg.seed)?);
    report.table(table3(&tests, &proc_clips, sets, cfg.seed)?);
    charts(&mut report, &cells);
    progress.finish();
    Ok(report)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::MODEL_FPS;
    use crate::visemes::Viseme;

    #[test]
    fn quick_bench_on_real_captures_fills_every_table_with_finite_errors() {
        inbetween_io::data::with_shared_data("face bench", |data| {
            let data = Some(data.join("face/neurosync"));
            let report = run(&BenchOptions { data, quick: true, ..BenchOptions::new(FaceBench::default()) })
                .expect("bench runs");
            let names: Vec<&str> = report.tables().map(|t| t.name.as_str()).collect();
            for n in [
                "heldout_by_gap",
                "heldout",
                "plausibility_by_gap",
                "plausibility",
                "plausibility_loco",
                "visemes",
                "table4",
                "table3",
            ] {
                assert!(names.contains(&n), "{names:?}");
            }
            // Leave-one-capture-out: a real row and the default fill of every constraint, with AUCs.
            let loco = report.tables().find(|t| t.name == "plausibility_loco").unwrap().to_csv();
            println!("{loco}");
            for kind in ["unguided", "visemes", "noisy", "keyframes"] {
                let rows: Vec<&str> = loco.lines().filter(|l| l.starts_with(&format!("{kind},"))).collect();
                assert!(rows.iter().any(|l| l.contains("real capture")), "{kind}: {loco}");
                let auto = rows.iter().find(|l| l.contains(",auto")).unwrap_or_else(|| panic!("{kind}: {loco}"));
                let auc: f64 = auto.split(',').nth(2).unwrap().parse().unwrap();
                assert!((0.0..=1.0).contains(&auc), "{auto}");
            }
            let csv = report.tables().find(|t| t.name == "heldout").unwrap().to_csv();
            assert!(
                csv.contains("ours (procedural)") && csv.contains("cubic") && csv.contains("noisy guide as is"),
                "{csv}"
            );
            for line in csv.lines().skip(1) {
                let mse: f64 = line.split(',').nth(3).unwrap().parse().unwrap();
                assert!(mse.is_finite() && mse >= 0.0, "{line}");
            }
            // Pooled plausibility: every filled method has an AUC in [0, 1], the real capture none.
            let csv = report.tables().find(|t| t.name == "plausibility").unwrap().to_csv();
            println!("{csv}");
            let mut aucs = 0;
            for line in csv.lines().skip(1) {
                let cols: Vec<&str> = line.split(',').collect();
                if cols[2] == "real capture" {
                    assert_eq!(cols[3], "-", "{line}");
                } else {
                    let auc: f64 = cols[3].parse().unwrap();
                    assert!((0.0..=1.0).contains(&auc), "{line}");
                    aucs += 1;
                }
            }
            assert!(aucs >= 6, "{csv}");
        });
    }

    #[test]
    fn viseme_runs_cover_the_frames() {
        let labels = [Viseme::Sil, Viseme::Sil, Viseme::MBP, Viseme::AaAeAy];
        let runs = viseme_runs(&labels);
        assert_eq!(runs.len(), 3);
        assert_eq!(runs[1].2, Viseme::MBP);
        assert!((runs[1].0 - 1.5 / MODEL_FPS).abs() < 1e-12 && (runs[1].1 - 2.5 / MODEL_FPS).abs() < 1e-12);
    }
}
