//! The paper's protocol (§5.1–5.4) and the benchmark table: clips resampled to 30 fps, cut into
//! 60-frame windows on the 23 major joints, split 80/20 by clip, and every selector scored for
//! K = 5, 10, 15 with the mean angle error (Eq. 24), the mean and max position error in cm and the
//! decision time per window.

pub use crate::corpus::Clip;
use crate::error::{Objective, SegmentModel, SegmentTable};
use crate::representation::{JointFilter, SphericalMotion};
use crate::select;
use crate::{MocapError, Result};
use inbetween_core::{KeyframeSet, Motion};
use rand::seq::SliceRandom;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use std::time::Instant;

/// The protocol's knobs; [`Protocol::paper`] gives §5.2's values.
#[derive(Clone, Debug)]
pub struct Protocol {
    pub fps: f64,
    pub window: usize,
    pub stride: usize,
    pub filter: JointFilter,
    /// Drop the first frame of every clip (the cgspeed T-pose).
    pub skip_first_frame: bool,
    pub train_fraction: f64,
    pub seed: u64,
}

impl Protocol {
    pub fn paper() -> Protocol {
        Protocol {
            fps: 30.0,
            window: 60,
            stride: 60,
            filter: JointFilter::paper(),
            skip_first_frame: true,
            train_fraction: 0.8,
            seed: 0,
        }
    }
}

/// One 60-frame window of a clip, in the paper's representation.
#[derive(Clone, Debug)]
pub struct Window {
    pub clip: String,
    pub start: usize,
    pub rep: SphericalMotion,
    /// The window as a clip (filtered joints, 30 fps), for the rotation reconstruction.
    pub motion: Motion,
}

/// Resamples, filters and windows one clip.
pub fn clip_windows(clip: &Clip, p: &Protocol) -> Result<Vec<Window>> {
    let (name, motion) = (&clip.name, &clip.motion);
    let m = if p.skip_first_frame && motion.num_frames() > 1 {
        motion.crop(1, motion.num_frames())?
    } else {
        motion.clone()
    };
    let m = p.filter.apply(&m.resample(p.fps)?);
    let mut out = Vec::new();
    let stride = p.stride.max(1);
    for (i, w) in m.windows(p.window, stride).into_iter().enumerate() {
        let mut rep = SphericalMotion::from_motion(&w)?;
        rep.cm_per_unit = clip.cm_per_unit;
        out.push(Window { clip: name.to_string(), start: i * stride, rep, motion: w });
    }
    Ok(out)
}

/// Splits clip names 80/20 (seeded shuffle; at least one clip on each side when there are two).
pub fn split_clips(names: &[String], p: &Protocol) -> (Vec<String>, Vec<String>) {
    let mut v = names.to_vec();
    v.sort();
    v.shuffle(&mut ChaCha8Rng::seed_from_u64(p.seed));
    let mut n_train = (v.len() as f64 * p.train_fraction).round() as usize;
    if v.len() >= 2 {
        n_train = n_train.clamp(1, v.len() - 1);
    }
    let test = v.split_off(n_train.min(v.len()));
    (v, test)
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

    pub fn name(self) -> &'static str {
        match self {
            Method::Rc => "rc",
            Method::Uc => "uc",
            Method::Greedy => "greedy",
            Method::Sidql => "sidql",
            Method::Optimal => "optimal",
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
        Method::Greedy => select::greedy(rep, k, Objective::Angle),
        Method::Optimal => select::optimal(&SegmentTable::full_serial(rep), k, Objective::Angle),
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
    let mut rows = Vec::new();
    for &method in methods {
        if method == Method::Sidql && policy.is_none() {
            continue;
        }
        for &k in ks {
            let (mut angle, mut cm, mut max_cm, mut secs) = (0.0, 0.0, 0.0f64, 0.0);
            for (i, w) in windows.iter().enumerate() {
                let t = Instant::now();
                let keys = select_keys(method, &w.rep, k, seed.wrapping_add(i as u64), policy)?;
                secs += t.elapsed().as_secs_f64();
                let e = w.rep.error(&keys);
                angle += e.mean_angle;
                cm += e.mean_cm;
                max_cm = max_cm.max(e.max_cm);
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
            });
        }
    }
    Ok(rows)
}

/// The paper's Table 3 (mean angle error) for K = 5, 10, 15, for the README comparison.
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

/// The table as CSV: `split,method,k,mean_angle_error,mean_cm,max_cm,decision_ms,windows,paper_mean_angle_error`.
pub fn to_csv(rows: &[Row]) -> String {
    let mut s =
        String::from("method,k,mean_angle_error,mean_cm,max_cm,decision_ms,split,windows,paper_mean_angle_error\n");
    for r in rows {
        let paper = paper_value(r.method, r.k).map(|v| format!("{v}")).unwrap_or_default();
        s.push_str(&format!(
            "{},{},{:.6},{:.4},{:.4},{:.4},{},{},{}\n",
            r.method.name(),
            r.k,
            r.mean_angle_error,
            r.mean_cm,
            r.max_cm,
            r.decision_ms,
            r.split,
            r.windows,
            paper
        ));
    }
    s
}

/// The table as aligned text.
pub fn to_table(rows: &[Row]) -> String {
    let mut s = format!(
        "{:<6} {:<8} {:>3} {:>10} {:>8} {:>9} {:>9} {:>12} {:>8}\n",
        "split", "method", "K", "angle_err", "paper", "mean_cm", "max_cm", "decision_ms", "windows"
    );
    for r in rows {
        let paper = paper_value(r.method, r.k).map(|v| format!("{v:.4}")).unwrap_or_else(|| "-".into());
        s.push_str(&format!(
            "{:<6} {:<8} {:>3} {:>10.4} {:>8} {:>9.3} {:>9.3} {:>12.3} {:>8}\n",
            r.split,
            r.method.name(),
            r.k,
            r.mean_angle_error,
            paper,
            r.mean_cm,
            r.max_cm,
            r.decision_ms,
            r.windows
        ));
    }
    s
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
        let rows = evaluate("all", &windows, &Method::ALL, &[5, 10], 1, None).unwrap();
        assert_eq!(rows.len(), 8, "SIDQL without a model is skipped");
        let get = |m: Method, k: usize| rows.iter().find(|r| r.method == m && r.k == k).unwrap().mean_angle_error;
        for k in [5, 10] {
            assert!(get(Method::Optimal, k) <= get(Method::Greedy, k) + 1e-12);
            assert!(get(Method::Optimal, k) <= get(Method::Uc, k) + 1e-12);
            assert!(get(Method::Optimal, k) <= get(Method::Rc, k) + 1e-12);
        }
        assert!(get(Method::Optimal, 10) < get(Method::Optimal, 5));
        let csv = to_csv(&rows);
        assert!(csv.starts_with("method,k,mean_angle_error,mean_cm,max_cm,decision_ms"));
        assert_eq!(csv.lines().count(), 9);
    }

    #[test]
    fn split_is_by_clip_and_seeded() {
        let names: Vec<String> = (0..10).map(|i| format!("clip{i}")).collect();
        let (train, test) = split_clips(&names, &Protocol::paper());
        assert_eq!((train.len(), test.len()), (8, 2));
        assert!(test.iter().all(|t| !train.contains(t)));
        assert_eq!(split_clips(&names, &Protocol::paper()), (train, test));
        let four: Vec<String> = (0..4).map(|i| format!("c{i}")).collect();
        let (tr, te) = split_clips(&four, &Protocol::paper());
        assert_eq!((tr.len(), te.len()), (3, 1));
    }
}
