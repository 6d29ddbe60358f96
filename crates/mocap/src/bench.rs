//! The paper's protocol (§5.1–5.4) and the benchmark: clips resampled to 30 fps, cut into 60-frame
//! windows on the 23 major joints, split 80/20 by clip, and every selector scored for K = 5, 10, 15
//! with the mean angle error (Eq. 24), the mean and max position error in cm and the decision time
//! per window.
//!
//! - [`crate::protocol`]: the protocol (windows, split, training windows), re-exported here;
//! - this file: the scoring of one split;
//! - [`run`](mod@run): `inbetween mocap bench` as one call: corpus, policy, both splits, the extra
//!   measurements and the written report;
//! - [`measure`]: what the bench measures beyond the paper's table (reconstruction throughput, the
//!   spherical and rotation reconstructions side by side, codec ratios);
//! - [`report`]: the tables (the paper's figures beside ours), the chart and the report folder.

pub mod acl;
pub mod acl_race;
pub mod measure;
pub mod report;
pub mod run;

pub use crate::corpus::Clip;
pub use crate::protocol::{clip_windows, procedural_clips, split_clips, training_windows, Protocol, Window};
pub use report::BenchResults;
pub use run::{run, BenchConfig, PolicyChoice};

use crate::metrics::{ErrorMeasure, SegmentModel};
use crate::representation::SphericalMotion;
use crate::select;
use crate::{MocapError, Result};
use inbetween_core::KeyframeSet;
use inbetween_io::Progress;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use std::time::Instant;

/// How many takes came from which source, e.g. `4 cgspeed, 1 asf_amc, 27 iclone_cc`.
pub fn describe_sources(clips: &[Clip]) -> String {
    let mut counts: Vec<(&str, usize)> = Vec::new();
    for c in clips {
        match counts.iter_mut().find(|(s, _)| *s == c.source) {
            Some((_, n)) => *n += 1,
            None => counts.push((c.source, 1)),
        }
    }
    counts.iter().map(|(s, n)| format!("{n} {s}")).collect::<Vec<_>>().join(", ")
}

/// The selectors of the table.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    Rc,
    Uc,
    Greedy,
    Sidql,
    Optimal,
}

impl Method {
    pub const ALL: [Method; 5] = [Method::Rc, Method::Uc, Method::Greedy, Method::Sidql, Method::Optimal];

    /// The CSV name (`rc`, `uc`, …).
    pub fn name(self) -> &'static str {
        match self {
            Method::Rc => "rc",
            Method::Uc => "uc",
            Method::Greedy => "greedy",
            Method::Sidql => "sidql",
            Method::Optimal => "optimal",
        }
    }

    /// The paper's name (§5.4: RC, UC, Greedy, SIDQL; Optimal is ours).
    pub fn label(self) -> &'static str {
        match self {
            Method::Rc => "RC",
            Method::Uc => "UC",
            Method::Greedy => "Greedy",
            Method::Sidql => "SIDQL",
            Method::Optimal => "Optimal",
        }
    }
}

/// A learned selector (SIDQL) as the bench sees it.
pub type PolicyFn<'a> = &'a dyn Fn(&SphericalMotion, usize) -> Result<KeyframeSet>;

/// Selects `k` keys of one window with a method; `seed` drives RC.
pub fn select_keys(
    method: Method,
    rep: &SphericalMotion,
    k: usize,
    seed: u64,
    policy: Option<PolicyFn>,
) -> Result<KeyframeSet> {
    let n = rep.num_frames;
    match method {
        Method::Rc => select::random(n, k, &mut ChaCha8Rng::seed_from_u64(seed)),
        Method::Uc => select::uniform(n, k),
        Method::Greedy => select::greedy(rep, k, ErrorMeasure::Angle),
        Method::Optimal => select::optimal_spherical(rep, k, ErrorMeasure::Angle),
        Method::Sidql => match policy {
            Some(p) => p(rep, k),
            None => Err(MocapError::Invalid("SIDQL needs a trained model".into())),
        },
    }
}

/// One row of the table.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    pub split: String,
    pub method: Method,
    pub k: usize,
    pub mean_angle_error: f64,
    pub mean_cm: f64,
    pub max_cm: f64,
    pub decision_ms: f64,
    pub windows: usize,
    /// The mean angle error in the paper's units ([`measure::paper_units_error`]).
    pub paper_units: f64,
}

/// Scores `methods` for every `k` over `windows` (serially, so decision times are not skewed by
/// other windows running alongside).
pub fn evaluate(
    split: &str,
    windows: &[Window],
    methods: &[Method],
    ks: &[usize],
    seed: u64,
    policy: Option<PolicyFn>,
) -> Result<Vec<Row>> {
    evaluate_with_progress(split, windows, methods, ks, seed, policy, &Progress::hidden())
}

/// [`evaluate`], counting one unit on `progress` per window scored (methods × ks × windows).
pub fn evaluate_with_progress(
    split: &str,
    windows: &[Window],
    methods: &[Method],
    ks: &[usize],
    seed: u64,
    policy: Option<PolicyFn>,
    progress: &Progress,
) -> Result<Vec<Row>> {
    let mut rows = Vec::new();
    for &method in methods {
        if method == Method::Sidql && policy.is_none() {
            continue;
        }
        for &k in ks {
            progress.set_message(format!("{split}: {} K={k}", method.label()));
            let (mut angle, mut cm, mut max_cm, mut secs, mut paper) = (0.0, 0.0, 0.0f64, 0.0, 0.0);
            for (i, w) in windows.iter().enumerate() {
                let t = Instant::now();
                let keys = select_keys(method, &w.rep, k, seed.wrapping_add(i as u64), policy)?;
                secs += t.elapsed().as_secs_f64();
                let e = w.rep.error(&keys);
                paper += measure::paper_units_error(&w.rep, &keys);
                angle += e.mean_angle;
                cm += e.mean_cm;
                max_cm = max_cm.max(e.max_cm);
                progress.inc(1);
            }
            let n = windows.len().max(1) as f64;
            rows.push(Row {
                split: split.to_string(),
                method,
                k,
                mean_angle_error: angle / n,
                mean_cm: cm / n,
                max_cm,
                decision_ms: secs * 1000.0 / n,
                windows: windows.len(),
                paper_units: paper / n,
            });
        }
    }
    Ok(rows)
}

/// The paper's Table 3 (mean angle error) for K = 5, 10, 15.
pub fn paper_value(method: Method, k: usize) -> Option<f64> {
    let col = match k {
        5 => 0,
        10 => 1,
        15 => 2,
        _ => return None,
    };
    let row: [f64; 3] = match method {
        Method::Rc => [0.1437, 0.0833, 0.0549],
        Method::Uc => [0.0945, 0.0490, 0.0328],
        Method::Greedy => [0.0536, 0.0311, 0.0200],
        Method::Sidql => [0.0844, 0.0443, 0.0297],
        Method::Optimal => return None,
    };
    Some(row[col])
}

/// The paper's decision time per 60-frame window at K = 5 (§5.4: "the Greedy method takes about
/// 0.9s …, while we can generate decisions within 0.004s"), in ms.
pub fn paper_decision_ms(method: Method) -> Option<f64> {
    match method {
        Method::Greedy => Some(900.0),
        Method::Sidql => Some(4.0),
        _ => None,
    }
}

/// The rows as CSV: `method,k,mean_angle_error,mean_cm,max_cm,decision_ms,split,windows,paper_mean_angle_error,paper_units_angle_error`.
pub fn to_csv(rows: &[Row]) -> String {
    report::rows_table(rows).to_csv()
}

#[cfg(test)]
mod tests {
    use super::*;
    use inbetween_core::procedural::gait_library;

    #[test]
    fn protocol_on_procedural_clips_orders_the_methods() {
        let p = Protocol { fps: 30.0, ..Protocol::paper() };
        let clips = gait_library(5, 2, 121, 30.0);
        let mut windows = Vec::new();
        for (i, c) in clips.into_iter().enumerate() {
            let clip = Clip { name: format!("c{i}"), source: "bvh", motion: c, cm_per_unit: 5.6444 };
            windows.extend(clip_windows(&clip, &p).unwrap());
        }
        assert_eq!(windows.len(), 4);
        assert_eq!(windows[0].rep.num_joints, 23);
        let progress = Progress::hidden();
        let rows = evaluate_with_progress("all", &windows, &Method::ALL, &[5, 10], 1, None, &progress).unwrap();
        assert_eq!(rows.len(), 8, "SIDQL without a model is skipped");
        assert_eq!(progress.position(), 4 * 4 * 2, "one unit per method, K and window");
        let get = |m: Method, k: usize| rows.iter().find(|r| r.method == m && r.k == k).unwrap().mean_angle_error;
        for k in [5, 10] {
            assert!(get(Method::Optimal, k) <= get(Method::Greedy, k) + 1e-12);
            assert!(get(Method::Optimal, k) <= get(Method::Uc, k) + 1e-12);
            assert!(get(Method::Optimal, k) <= get(Method::Rc, k) + 1e-12);
        }
        assert!(get(Method::Optimal, 10) < get(Method::Optimal, 5));
        let csv = to_csv(&rows);
        assert!(csv.starts_with(
            "method,k,mean_angle_error,mean_cm,max_cm,decision_ms,split,windows,paper_mean_angle_error,paper_units_angle_error\n"
        ));
        assert_eq!(csv.lines().count(), 9);
        let uc5 = csv.lines().find(|l| l.starts_with("uc,5,")).unwrap();
        assert!(uc5.contains(",all,4,0.0945,"), "{uc5}");
    }

    /// The committed policy against uniform keys on every 60-frame window of the corpus (the
    /// bench's protocol): never worse at K = 5, 10, 15.
    #[test]
    fn committed_policy_never_loses_to_uniform_keys_on_the_cmu_windows() {
        use crate::dqn::SidqlPolicy;
        inbetween_io::data::with_shared_data("SIDQL policy real-data test", |dir| {
            let corpus = crate::corpus::load(&dir, None).unwrap();
            let windows: Vec<_> =
                corpus.clips.iter().flat_map(|c| clip_windows(c, &Protocol::paper()).unwrap()).collect();
            assert!(windows.len() >= 100, "{} windows", windows.len());
            let policy = SidqlPolicy::committed().unwrap();
            let f = |rep: &SphericalMotion, k: usize| policy.select(rep, k);
            let rows = evaluate("all", &windows, &[Method::Uc, Method::Sidql], &[5, 10, 15], 0, Some(&f)).unwrap();
            for k in [5, 10, 15] {
                let get = |m: Method| rows.iter().find(|r| r.method == m && r.k == k).unwrap().mean_angle_error;
                assert!(
                    get(Method::Sidql) <= get(Method::Uc),
                    "K={k}: SIDQL {} vs UC {}",
                    get(Method::Sidql),
                    get(Method::Uc)
                );
            }
        });
    }

    #[test]
    fn sources_are_counted_by_name() {
        assert_eq!(describe_sources(&procedural_clips(3, 3)), "3 procedural");
    }
}
