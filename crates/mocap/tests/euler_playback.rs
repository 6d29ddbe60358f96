//! Keys chosen for Euler playback hold their bound on what a DCC plays from Euler Bezier F-curves.
//! The oracle here is the DCC's side, written apart from the engine: each channel's cubic Bezier
//! (the values and handles of `dcc::bezier_keys`) evaluated by solving x(s) = frame, the three
//! angles composed into a matrix axis by axis (`pre · R_a(E_a) · R_b(E_b) · R_c(E_c)`), quaternion
//! channels normalised, and forward kinematics with matrices against the source's joint positions.

use glam::{DMat3, DQuat, DVec3};
use inbetween_core::cancel::Cancel;
use inbetween_core::procedural::{gait, GaitParams};
use inbetween_core::rotation::{Axis, EulerOrder};
use inbetween_io::data::with_shared_data;
use inbetween_io::Progress;
use inbetween_mocap::dcc::{bezier_keys, BezierKeys};
use inbetween_mocap::rotations::{EulerPlayback, RotationCurve};
use inbetween_mocap::{PreparedClip, SelectJob, SelectReport, Selector};

/// A cubic Bezier through `(x[i], y[i])` at `frame`: bisection on x(s), then y(s).
fn bezier_at(x: [f64; 4], y: [f64; 4], frame: f64) -> f64 {
    let at = |c: [f64; 4], s: f64| {
        // de Casteljau
        let l1 = [c[0] + (c[1] - c[0]) * s, c[1] + (c[2] - c[1]) * s, c[2] + (c[3] - c[2]) * s];
        let l2 = [l1[0] + (l1[1] - l1[0]) * s, l1[1] + (l1[2] - l1[1]) * s];
        l2[0] + (l2[1] - l2[0]) * s
    };
    let (mut lo, mut hi) = (0.0, 1.0);
    for _ in 0..80 {
        let mid = 0.5 * (lo + hi);
        if at(x, mid) < frame {
            lo = mid
        } else {
            hi = mid
        }
    }
    at(y, 0.5 * (lo + hi))
}

fn axis_matrix(axis: Axis, angle: f64) -> DMat3 {
    match axis {
        Axis::X => DMat3::from_rotation_x(angle),
        Axis::Y => DMat3::from_rotation_y(angle),
        Axis::Z => DMat3::from_rotation_z(angle),
    }
}

/// The largest joint position error (cm) of the clip a DCC plays from `bz`, every frame.
fn dcc_max_cm(clip: &PreparedClip, playback: &EulerPlayback, bz: &BezierKeys) -> f64 {
    let sk = &clip.motion.skeleton;
    let nj = sk.len();
    let src = &clip.rotations;
    let mut worst = 0.0f64;
    for s in 0..bz.frames.len() - 1 {
        let (fa, fb) = (bz.frames[s], bz.frames[s + 1]);
        let x = [fa as f64, bz.right_frames[s], bz.left_frames[s + 1], fb as f64];
        let curve = |a: &[f64; 3], ar: &[f64; 3], bl: &[f64; 3], b: &[f64; 3], i: usize, f: usize| {
            bezier_at(x, [a[i], ar[i], bl[i], b[i]], f as f64)
        };
        for f in fa..=fb {
            let mut rot = vec![DMat3::IDENTITY; nj];
            let mut pos = vec![DVec3::ZERO; nj];
            for j in 0..nj {
                let local = match playback.orders[j] {
                    Some(order) => {
                        let (a, b) = (&bz.euler[s][j], &bz.euler[s + 1][j]);
                        let xyz: Vec<f64> =
                            (0..3).map(|i| curve(&a.value, &a.right, &b.left, &b.value, i, f)).collect();
                        let r =
                            order.axes().iter().fold(DMat3::IDENTITY, |m, &ax| m * axis_matrix(ax, xyz[ax.index()]));
                        DMat3::from_quat(playback.pre[j]) * r
                    }
                    None => {
                        let (a, b) = (&bz.rotations[s][j], &bz.rotations[s + 1][j]);
                        let q: Vec<f64> = (0..4)
                            .map(|i| bezier_at(x, [a.value[i], a.right[i], b.left[i], b.value[i]], f as f64))
                            .collect();
                        DMat3::from_quat(DQuat::from_xyzw(q[0], q[1], q[2], q[3]).normalize())
                    }
                };
                let (a, b) = (&bz.translations[s][j], &bz.translations[s + 1][j]);
                let t = DVec3::new(
                    curve(&a.value, &a.right, &b.left, &b.value, 0, f),
                    curve(&a.value, &a.right, &b.left, &b.value, 1, f),
                    curve(&a.value, &a.right, &b.left, &b.value, 2, f),
                );
                match sk.parent(j) {
                    None => (pos[j], rot[j]) = (t, local),
                    Some(p) => (pos[j], rot[j]) = (pos[p] + rot[p] * t, rot[p] * local),
                }
                let d = pos[j].distance(src.positions[f * nj + j]) * src.cm_per_unit;
                worst = worst.max(d);
            }
        }
    }
    worst
}

fn select(clip: &PreparedClip, curve: RotationCurve, euler: Option<EulerPlayback>, cm: f64) -> SelectReport {
    let job = SelectJob { method: Selector::ErrorBounded, bound_cm: Some(cm), curve, euler, ..SelectJob::default() };
    job.run(clip, &Cancel::new(), &Progress::hidden()).unwrap()
}

fn handles(clip: &PreparedClip, r: &SelectReport) -> BezierKeys {
    bezier_keys(r.keys().frames(), &r.key_poses, r.key_euler.as_ref(), clip.motion.frame_time).unwrap()
}

/// A seeded playback unlike the clip's own: every joint a different order and a pre-rotation, a
/// few joints on quaternion curves (as Blender's rest frames and mixed rotation modes give).
fn odd_playback(nj: usize) -> EulerPlayback {
    let mut rng = inbetween_core::seed::rng(45);
    use rand::Rng;
    EulerPlayback {
        orders: (0..nj).map(|j| (j % 7 != 3).then(|| EulerOrder::ALL[rng.random_range(0..6)])).collect(),
        pre: (0..nj)
            .map(|_| {
                let axis =
                    DVec3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
                DQuat::from_axis_angle(axis.normalize(), rng.random_range(-3.0..3.0))
            })
            .collect(),
        reference: None,
    }
}

#[test]
fn keys_chosen_for_euler_curves_hold_the_bound_on_a_dccs_euler_bezier_playback() {
    let clip = PreparedClip::inferred(gait(&GaitParams { frames: 120, ..GaitParams::walk() })).unwrap();
    let nj = clip.motion.skeleton.len();
    for playback in [EulerPlayback::of_skeleton(&clip.motion.skeleton), odd_playback(nj)] {
        let r = select(&clip, RotationCurve::EulerBezier, Some(playback.clone()), 1.0);
        assert!(r.reconstruction.error.max_cm <= 1.0 + 1e-9, "{}", r.reconstruction.error);
        let dcc = dcc_max_cm(&clip, &playback, &handles(&clip, &r));
        assert!(dcc <= 1.0 + 1e-6, "a DCC plays {dcc} cm (engine {} cm)", r.reconstruction.error.max_cm);
        // The engine's figure is the DCC's, to rounding.
        assert!((dcc - r.reconstruction.error.max_cm).abs() < 1e-6, "{dcc} vs {}", r.reconstruction.error.max_cm);
        let q = select(&clip, RotationCurve::QuaternionBezier, None, 1.0);
        println!("walk: euler {} keys, quaternion {} keys", r.keys().len(), q.keys().len());
    }
}

#[test]
fn euler_playback_refuses_bad_inputs_with_what_was_expected() {
    let clip = PreparedClip::inferred(gait(&GaitParams { frames: 30, ..GaitParams::walk() })).unwrap();
    let err = |curve, euler| {
        let job =
            SelectJob { method: Selector::ErrorBounded, bound_cm: Some(1.0), curve, euler, ..SelectJob::default() };
        job.run(&clip, &Cancel::new(), &Progress::hidden()).unwrap_err().to_string()
    };
    let mut p = EulerPlayback::of_skeleton(&clip.motion.skeleton);
    assert!(err(RotationCurve::QuaternionBezier, Some(p.clone())).contains("needs curve 'euler_bezier'"));
    p.pre.pop();
    assert!(err(RotationCurve::EulerBezier, Some(p.clone())).contains("expected one per joint"));
    p.pre.push(DQuat::from_xyzw(0.0, 0.0, 0.0, 2.0));
    assert!(err(RotationCurve::EulerBezier, Some(p.clone())).contains("not a unit quaternion"));
    p.pre = vec![DQuat::IDENTITY; clip.motion.skeleton.len()];
    p.reference = Some(vec![DVec3::ZERO; 3]);
    assert!(err(RotationCurve::EulerBezier, Some(p)).contains("one per frame and joint"));
}

/// A CMU take (skipped without the corpus) at 1 cm, played by a DCC from the BVH's own Euler
/// channels: within 1 cm on every frame; key counts of the three curves printed.
#[test]
fn a_cmu_take_played_from_euler_curves_stays_within_1_cm() {
    with_shared_data("Euler playback real-data test", |dir| {
        let corpus = inbetween_mocap::corpus::load(&dir, None).unwrap();
        let last = corpus.clips.len() - 1;
        let (clip, unit) = (&corpus.clips[last], &corpus.units[last]);
        // Four seconds keep it short on two cores.
        let n = clip.motion.num_frames().min((4.0 / clip.motion.frame_time) as usize);
        let prepared = PreparedClip::new(clip.motion.crop(0, n).unwrap(), unit.clone()).unwrap();
        let sk = &prepared.motion.skeleton;
        let nj = sk.len();
        let mut line = format!("{}: {n} frames at 1 cm", clip.name);
        for playback in [EulerPlayback::of_skeleton(sk), odd_playback(nj)] {
            let r = select(&prepared, RotationCurve::EulerBezier, Some(playback.clone()), 1.0);
            let dcc = dcc_max_cm(&prepared, &playback, &handles(&prepared, &r));
            assert!(dcc <= 1.0 + 1e-6, "{}: a DCC plays {dcc} cm", clip.name);
            line += &format!("; euler_bezier {} keys (DCC max {dcc:.3} cm)", r.keys().len());
        }
        for curve in [RotationCurve::QuaternionBezier, RotationCurve::Hermite] {
            let r = select(&prepared, curve, None, 1.0);
            line += &format!("; {} {} keys", curve.name(), r.keys().len());
            if curve == RotationCurve::QuaternionBezier {
                // Those keys played from the BVH's Euler curves (what a DCC did before).
                let playback = EulerPlayback::of_skeleton(sk);
                let played = inbetween_mocap::ReconstructJob {
                    keys: r.keys().frames().to_vec(),
                    curve: RotationCurve::EulerBezier,
                    euler: Some(playback.clone()),
                }
                .run(&prepared, &Cancel::new(), &Progress::hidden())
                .unwrap();
                let euler = prepared.rotations.with_euler(&playback).unwrap();
                let bz = bezier_keys(
                    r.keys().frames(),
                    &r.key_poses,
                    euler.key_euler(r.keys()).as_ref(),
                    prepared.motion.frame_time,
                )
                .unwrap();
                let dcc = dcc_max_cm(&prepared, &playback, &bz);
                assert!((dcc - played.error.max_cm).abs() < 1e-6, "{dcc} vs {}", played.error.max_cm);
                line += &format!(" (played from Euler curves: max {dcc:.3} cm)");
            }
        }
        println!("{line}");
    });
}
