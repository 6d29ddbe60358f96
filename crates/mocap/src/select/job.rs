//! `SelectJob`: keyframes for one clip by one of the engine's selectors, in ozz's job shape (the
//! inputs as fields with the engine's defaults, `validate`, then `run`), and a report with the key
//! frames, the key poses with their tangents (what a curve editor needs to reproduce the Hermite
//! segments between keys), the planned error of the spherical model (Eq. 15–18, 24) and the
//! measured position error of the rotation reconstruction, per frame. Front ends (the command
//! line, the studio, Python) parse their inputs into the job and show its report.

use crate::metrics::{ErrorMeasure, ReconstructionError, SegmentModel, SegmentTable};
use crate::prepared::PreparedClip;
use crate::rebuild::{rebuild, ReconstructReport};
use crate::rotations::{EulerKeys, EulerPlayback, KeyPose, RotationCurve, RotationMotion};
use crate::{MocapError, Result};
use inbetween_core::cancel::Cancel;
use inbetween_core::KeyframeSet;
use inbetween_io::Progress;
use serde::{Deserialize, Serialize};
use std::fmt;
use std::time::Instant;

/// The longest gap between two keys an error-bounded search considers by default, seconds (it
/// bounds the segment table; `mocap compress --max-gap-s` and the studio use it).
pub const DEFAULT_MAX_GAP_S: f64 = 0.5;

/// The frames of a gap of `seconds` at `frame_time` seconds per frame (at least one).
pub fn max_gap_frames(seconds: f64, frame_time: f64) -> usize {
    ((seconds / frame_time).round() as usize).max(1)
}

/// The keyframe selectors a job can run (the random baseline is left to the bench).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Selector {
    /// UC: `k` evenly spaced frames.
    Uniform,
    /// The paper's Greedy (§5.4): the frame that lowers the mean angle error most, one at a time.
    Greedy,
    /// The paper's deep Q-network (§4), the committed policy, windows of at most 64 frames.
    Sidql,
    /// The exact minimum of the mean angle error (Eq. 24) for `k` keys (beyond the paper).
    Optimal,
    /// The fewest keys keeping every joint of every frame within a bound (cm), ties broken by the
    /// mean angle error (beyond the paper).
    #[serde(alias = "bound")]
    ErrorBounded,
}

impl Selector {
    pub const ALL: [Selector; 5] =
        [Selector::Uniform, Selector::Greedy, Selector::Sidql, Selector::Optimal, Selector::ErrorBounded];

    /// The selector's name in files, flags and requests.
    pub fn name(self) -> &'static str {
        match self {
            Selector::Uniform => "uniform",
            Selector::Greedy => "greedy",
            Selector::Sidql => "sidql",
            Selector::Optimal => "optimal",
            Selector::ErrorBounded => "error_bounded",
        }
    }

    /// A selector by [`Selector::name`] (`bound` also names error-bounded).
    pub fn parse(s: &str) -> Result<Selector> {
        match s {
            "bound" | "error-bounded" => Ok(Selector::ErrorBounded),
            _ => Selector::ALL.into_iter().find(|m| m.name() == s).ok_or_else(|| {
                MocapError::Invalid(format!(
                    "method '{s}': expected uniform, greedy, sidql, optimal or error_bounded (bound)"
                ))
            }),
        }
    }

    /// Whether the selector takes a key count (all but error-bounded, which takes a bound).
    pub fn takes_k(self) -> bool {
        self != Selector::ErrorBounded
    }
}

impl std::str::FromStr for Selector {
    type Err = MocapError;
    fn from_str(s: &str) -> Result<Selector> {
        Selector::parse(s)
    }
}

/// Choose keys for one clip.
#[derive(Clone, Debug)]
pub struct SelectJob {
    pub method: Selector,
    /// Keys, counting the first and last frames (every method but error-bounded).
    pub k: Option<usize>,
    /// Largest position error of any joint in any frame, cm (error-bounded).
    pub bound_cm: Option<f64>,
    /// Largest local rotation error of any joint in any frame, degrees (error-bounded; with or
    /// without `bound_cm`).
    pub bound_deg: Option<f64>,
    /// Longest gap between two keys of an error-bounded search, seconds.
    pub max_gap_s: f64,
    /// How the reconstruction (and the error-bounded search's bound) evaluates rotations between
    /// keys: the engine's Hermite, or a DCC's quaternion or Euler Bezier curves.
    pub curve: RotationCurve,
    /// How Euler curves play each joint ([`RotationCurve::EulerBezier`]: orders, pre-rotations, the
    /// DCC's own angles); by default the skeleton's BVH channels.
    pub euler: Option<EulerPlayback>,
}

impl Default for SelectJob {
    fn default() -> SelectJob {
        SelectJob {
            method: Selector::Optimal,
            k: None,
            bound_cm: None,
            bound_deg: None,
            max_gap_s: DEFAULT_MAX_GAP_S,
            curve: RotationCurve::Hermite,
            euler: None,
        }
    }
}

/// The keys a job chose and how well they rebuild the clip.
#[derive(Clone, Debug, Serialize)]
pub struct SelectReport {
    pub method: Selector,
    /// The bounds of an error-bounded search, cm and degrees.
    pub bound_cm: Option<f64>,
    pub bound_deg: Option<f64>,
    /// Milliseconds the selection took (the reconstruction not included).
    pub select_ms: f64,
    /// The key poses in key order: local rotations with their body-frame angular velocities
    /// (rad/s) and translations with their velocities (file units/s), the tangents of the Hermite
    /// segments between keys.
    pub key_poses: Vec<KeyPose>,
    /// The keys' Euler angles and rates ([`RotationCurve::EulerBezier`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub key_euler: Option<EulerKeys>,
    /// The error the selectors minimise, on the spherical model (Eq. 17–18, 24).
    pub planned: ReconstructionError,
    /// The rebuilt clip (rotation reconstruction) and its measured position error.
    pub reconstruction: ReconstructReport,
}

impl SelectJob {
    /// Checks the inputs against a clip of `n` frames before any work.
    pub fn validate(&self, n: usize) -> Result<()> {
        let name = self.method.name();
        if self.method.takes_k() {
            let k = self.k.ok_or_else(|| MocapError::Invalid(format!("method '{name}' needs K")))?;
            super::check_k(n, k)?;
        } else {
            if self.bound_cm.is_none() && self.bound_deg.is_none() {
                return Err(MocapError::Invalid(format!("method '{name}' needs an error bound in cm (or degrees)")));
            }
            for (b, unit) in [(self.bound_cm, "cm"), (self.bound_deg, "degrees")] {
                match b {
                    Some(b) if !(b.is_finite() && b > 0.0) => {
                        return Err(MocapError::Invalid(format!(
                            "error bound {b} {unit}: expected a positive number of {unit}"
                        )))
                    }
                    _ => {}
                }
            }
            if n < 2 {
                return Err(MocapError::Invalid(format!("a clip of {n} frames has no segments")));
            }
        }
        crate::rotations::check_playback(self.curve, self.euler.as_ref())?;
        if !(self.max_gap_s.is_finite() && self.max_gap_s > 0.0) {
            return Err(MocapError::Invalid(format!(
                "max_gap_s {} s: expected a positive number of seconds",
                self.max_gap_s
            )));
        }
        Ok(())
    }

    /// Chooses keys for `clip`, then rebuilds it from them. `progress` hears two phases,
    /// `choosing keys` (in thousandths, for the optimal search) and `reconstructing`.
    pub fn run(&self, clip: &PreparedClip, cancel: &Cancel, progress: &Progress) -> Result<SelectReport> {
        self.validate(clip.num_frames())?;
        let t = Instant::now();
        let rotations = clip.rotations.played(self.curve, self.euler.as_ref())?;
        let keys = self.keys(clip, &rotations, cancel, progress)?;
        let select_ms = t.elapsed().as_secs_f64() * 1000.0;
        cancel.check()?;
        // The planned error beside the reconstruction (rayon's pool).
        let (planned, reconstruction) = rayon::join(
            || clip.rep.error(&keys),
            || rebuild(clip, &rotations, keys.clone(), self.curve, cancel, progress),
        );
        let reconstruction = reconstruction?;
        let key_poses = rotations.key_poses(&keys);
        let key_euler = rotations.key_euler(&keys);
        Ok(SelectReport {
            method: self.method,
            bound_cm: self.bound_cm,
            bound_deg: self.bound_deg,
            select_ms,
            key_poses,
            key_euler,
            planned,
            reconstruction,
        })
    }

    /// The keys; an error-bounded search measures along the job's curve on `rotations` (the clip's,
    /// with its Euler keys for [`RotationCurve::EulerBezier`]).
    fn keys(
        &self,
        clip: &PreparedClip,
        rotations: &RotationMotion,
        cancel: &Cancel,
        progress: &Progress,
    ) -> Result<KeyframeSet> {
        let n = clip.num_frames();
        let k = self.k.unwrap_or(2);
        progress.phase(1000, "choosing keys");
        let keys = match self.method {
            Selector::Uniform => super::uniform(n, k)?,
            Selector::Greedy => {
                clip.greedy().get_or_insert_with(|| super::GreedyOrder::angle(&clip.rep)).keys(k, cancel)?
            }
            Selector::Optimal => {
                progress.phase(1000, "choosing keys (exact optimum)");
                let mut report = |f: f64| progress.set_position((f.clamp(0.0, 1.0) * 1000.0) as u64);
                match clip.optimal_memo() {
                    Some(mut memo) => {
                        let memo = memo.as_mut().expect("made by optimal_memo");
                        super::optimal_spherical_memo(&clip.rep, k, ErrorMeasure::Angle, cancel, memo, &mut report)?.0
                    }
                    None => super::optimal_spherical_cancellable(&clip.rep, k, ErrorMeasure::Angle, cancel)?.0,
                }
            }
            // Windows of at most 64 frames on a longer take (the policy's range), each window's
            // keyings kept with the clip for the next K.
            Selector::Sidql => clip.sidql()?.as_mut().expect("made by sidql()").keys(k)?,
            // The bound holds on the rebuilt clip: segments are measured along the job's curve
            // (the reconstruction the report gives, or a DCC's playback), not on the spherical
            // model the other selectors plan with.
            Selector::ErrorBounded => {
                // Infeasible segments are stored at an infinite cm: a finite stand-in when only degrees bound.
                let b = self.bound_cm.unwrap_or(f64::MAX);
                let max_gap = max_gap_frames(self.max_gap_s, clip.motion.frame_time).min(n - 1);
                let model = rotations.along(self.curve, self.bound_deg.map(f64::to_radians));
                let table = SegmentTable::bounded(&model, max_gap, b);
                cancel.check()?;
                super::error_bounded(&table, b, ErrorMeasure::Angle)?
            }
        };
        progress.set_position(1000);
        Ok(keys)
    }
}

impl SelectReport {
    pub fn keys(&self) -> &KeyframeSet {
        &self.reconstruction.keys
    }

    /// The method and key count in words (`optimal K=10`, `fewest keys under 1 cm: K=7`).
    pub fn label(&self) -> String {
        let k = self.keys().len();
        match self.method {
            Selector::Uniform => format!("uniform K={k}"),
            Selector::Greedy => format!("greedy K={k}"),
            Selector::Sidql => format!("SIDQL K={k}"),
            Selector::Optimal => format!("optimal K={k}"),
            Selector::ErrorBounded => match (self.bound_cm, self.bound_deg) {
                (Some(cm), Some(deg)) => format!("fewest keys under {cm} cm and {deg}°: K={k}"),
                (None, Some(deg)) => format!("fewest keys under {deg}°: K={k}"),
                (cm, _) => format!("fewest keys under {} cm: K={k}", cm.unwrap_or(f64::NAN)),
            },
        }
    }
}

impl fmt::Display for SelectReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "{}: keys {:?}", self.label(), self.keys().frames())?;
        writeln!(
            f,
            "planned (spherical model): mean angle {:.3} deg, mean {:.3} cm, max {:.3} cm",
            self.planned.mean_angle.to_degrees(),
            self.planned.mean_cm,
            self.planned.max_cm
        )?;
        write!(f, "rebuilt (rotations): {}; selection {:.2} ms", self.reconstruction.error, self.select_ms)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ReconstructJob;
    use inbetween_core::procedural::{gait, GaitParams};

    fn walk(frames: usize) -> PreparedClip {
        PreparedClip::inferred(gait(&GaitParams { frames, ..GaitParams::walk() })).unwrap()
    }

    fn run(clip: &PreparedClip, job: SelectJob) -> SelectReport {
        job.run(clip, &Cancel::new(), &Progress::hidden()).unwrap()
    }

    #[test]
    fn every_selector_keeps_the_ends_and_matches_the_selector_it_wraps() {
        let clip = walk(90);
        let n = clip.num_frames();
        for method in [Selector::Uniform, Selector::Greedy, Selector::Sidql, Selector::Optimal] {
            let r = run(&clip, SelectJob { method, k: Some(8), ..SelectJob::default() });
            let f = r.keys().frames();
            assert_eq!((f.len(), f[0], f[7]), (8, 0, n - 1), "{method:?}");
            assert_eq!(r.key_poses.len(), 8);
            assert_eq!(r.reconstruction.error.per_frame_cm.len(), n);
            // Key frames rebuild exactly; the in-betweens of 8 keys on a walk do not.
            assert!(f.iter().all(|&k| r.reconstruction.error.per_frame_cm[k] < 1e-6), "{method:?}");
            assert!(r.reconstruction.error.max_cm > 0.01, "{method:?}: {}", r.reconstruction.error);
        }
        let job = |method| SelectJob { method, k: Some(8), ..SelectJob::default() };
        let g = crate::select::greedy(&clip.rep, 8, ErrorMeasure::Angle).unwrap();
        assert_eq!(run(&clip, job(Selector::Greedy)).keys(), &g);
        let o = crate::select::optimal_spherical(&clip.rep, 8, ErrorMeasure::Angle).unwrap();
        let r = run(&clip, job(Selector::Optimal));
        assert_eq!(r.keys(), &o);
        // The exact optimum is never worse than greedy on its objective.
        assert!(r.planned.mean_angle <= run(&clip, job(Selector::Greedy)).planned.mean_angle + 1e-12);
        // A second K on the same clip reuses what the first learnt and agrees with a fresh clip.
        let again = run(&clip, SelectJob { k: Some(12), ..job(Selector::Optimal) });
        let fresh = run(&walk(90), SelectJob { k: Some(12), ..job(Selector::Optimal) });
        assert_eq!(again.keys(), fresh.keys());
    }

    #[test]
    fn error_bounded_keeps_the_rebuilt_error_under_its_bound_with_fewer_keys_for_a_looser_one() {
        let clip = walk(120);
        let job = |b| SelectJob { method: Selector::ErrorBounded, bound_cm: Some(b), ..SelectJob::default() };
        let tight = run(&clip, job(0.5));
        let loose = run(&clip, job(3.0));
        let measured = |r: &SelectReport| r.reconstruction.error.max_cm;
        assert!(measured(&tight) <= 0.5 + 1e-9 && measured(&loose) <= 3.0 + 1e-9);
        assert!(loose.keys().len() < tight.keys().len(), "{} vs {}", loose.keys().len(), tight.keys().len());
        assert!(tight.label().starts_with("fewest keys under 0.5 cm: K="));
        let json = serde_json::to_value(&tight).unwrap();
        assert_eq!(json["method"], "error_bounded");
        assert_eq!(json["reconstruction"]["keys"]["frames"].as_array().unwrap().len(), tight.keys().len());
        assert_eq!(json["key_poses"].as_array().unwrap().len(), tight.keys().len());
        // The job's reconstruction is ReconstructJob's on the same keys.
        let rebuilt = ReconstructJob { keys: tight.keys().frames().to_vec(), ..ReconstructJob::default() }
            .run(&clip, &Cancel::new(), &Progress::hidden())
            .unwrap();
        assert_eq!(rebuilt.error, tight.reconstruction.error);
    }

    #[test]
    fn an_angle_bound_holds_on_every_joint_alone_or_beside_a_length_bound() {
        let clip = walk(120);
        let deg = |cm: Option<f64>, deg: f64| SelectJob {
            method: Selector::ErrorBounded,
            bound_cm: cm,
            bound_deg: Some(deg),
            curve: RotationCurve::QuaternionBezier,
            ..SelectJob::default()
        };
        for job in [deg(None, 2.0), deg(Some(1.0), 2.0)] {
            let r = run(&clip, job.clone());
            let poses = &r.reconstruction.poses;
            let mut worst = 0.0f64;
            for (f, pose) in poses.iter().enumerate() {
                for (j, q) in pose.rotations.iter().enumerate() {
                    if clip.motion.skeleton.joint(j).rotation_order().is_some() {
                        let a = inbetween_core::rotation::angle_between(*q, clip.rotations.frames[f].rotations[j]);
                        worst = worst.max(a.to_degrees());
                    }
                }
            }
            assert!(worst <= 2.0 + 1e-6, "{worst}°");
            if job.bound_cm.is_some() {
                assert!(r.reconstruction.error.max_cm <= 1.0 + 1e-9);
                assert!(r.label().contains("1 cm and 2°"), "{}", r.label());
            }
        }
        let loose = run(&clip, deg(None, 20.0));
        assert!(loose.keys().len() < run(&clip, deg(None, 2.0)).keys().len());
    }

    #[test]
    fn bad_inputs_are_refused_with_what_was_expected() {
        let clip = walk(30);
        let err = |job: SelectJob| job.run(&clip, &Cancel::new(), &Progress::hidden()).unwrap_err().to_string();
        assert!(err(SelectJob { method: Selector::Uniform, ..SelectJob::default() }).contains("needs K"));
        assert!(err(SelectJob { k: Some(31), ..SelectJob::default() }).contains("do not fit a clip of 30 frames"));
        let bound = |b| SelectJob { method: Selector::ErrorBounded, bound_cm: Some(b), ..SelectJob::default() };
        assert!(err(bound(-1.0)).contains("expected a positive number of cm"));
        assert!(err(SelectJob { max_gap_s: 0.0, ..bound(1.0) }).contains("max_gap_s"));
        assert!(err(SelectJob { bound_deg: Some(f64::NAN), ..bound(1.0) }).contains("positive number of degrees"));
        assert_eq!(Selector::parse("bound").unwrap(), Selector::ErrorBounded);
        assert!(Selector::parse("magic").unwrap_err().to_string().contains("expected uniform, greedy"));
        let cancel = Cancel::new();
        cancel.cancel();
        let job = SelectJob { method: Selector::Greedy, k: Some(10), ..SelectJob::default() };
        assert!(matches!(job.run(&clip, &cancel, &Progress::hidden()), Err(MocapError::Cancelled(_))));
    }

    #[test]
    fn progress_hears_the_selection_then_the_reconstruction() {
        let clip = walk(60);
        let seen = std::sync::Arc::new(std::sync::Mutex::new(Vec::new()));
        let log = seen.clone();
        let progress =
            Progress::observed(move |stage, pos, len| log.lock().unwrap().push((stage.to_string(), pos, len)));
        SelectJob { k: Some(6), ..SelectJob::default() }.run(&clip, &Cancel::new(), &progress).unwrap();
        let seen = seen.lock().unwrap();
        let stages: Vec<&str> = seen.iter().map(|s| s.0.as_str()).collect();
        assert!(stages.contains(&"choosing keys (exact optimum)"), "{stages:?}");
        assert_eq!(seen.last().unwrap(), &("reconstructing".to_string(), 2, 2));
    }
}
