//! The built-in procedural template actions (§3.2 "template actions"), so that every verb the
//! paper's figures use animates without any captured data. All clips are on the metre-scaled
//! standard skeleton ([`super::rig`]), 30 fps, standing at the origin facing +Z.

use super::ik::{seated_pose, solve_limb, Limb};
use super::rig::{clip, hip_height, local_from_global, Rig, FPS, M_PER_CMU};
use glam::{DQuat, DVec3};
use inbetween_core::clip::Clip;
use inbetween_core::fk::forward;
use inbetween_core::motion::interpolate_pose;
use inbetween_core::procedural::{gait, GaitParams};
use inbetween_core::units::scale_motion;
use inbetween_core::Pose;
use rand::Rng;
use std::f64::consts::{PI, TAU};

/// Gait cycles per second of the procedural walk (core's relaxed walk takes 0.9; a slightly
/// quicker cadence with shorter steps keeps the pelvis of our shorter-legged rig high).
pub const WALK_CYCLE_HZ: f64 = 1.0;

/// Seat height (metres) of the procedural sitting clips.
pub const SEAT_HEIGHT: f64 = 0.45;

/// Seat contact point of the procedural sitting clips, relative to where the character stood.
pub fn seat_point() -> DVec3 {
    DVec3::new(0.0, SEAT_HEIGHT, -0.38)
}

use inbetween_core::interp::smoothstep as smooth;

/// Amplitude jitter from the seed (±5 %), so libraries built with different seeds differ slightly.
struct Jitter<R: Rng>(R);

impl<R: Rng> Jitter<R> {
    fn k(&mut self) -> f64 {
        1.0 + self.0.random_range(-0.05..=0.05)
    }
}

/// A gait cycle clip (exactly `cycles` periods, 30 fps) in metres; cycle frequency chosen so one
/// period is a whole number of frames. The torso and arms come from core's parametric gait; the
/// legs are re-solved with two-bone IK so each foot is planted for `duty` of the cycle (no skate
/// on a straight line) and lifted `lift` metres in swing; the pelvis height follows the reach of
/// the legs.
pub fn gait_cycle(mut p: GaitParams, cycles: usize, duty: f64, lift: f64) -> Clip {
    let period = (FPS / p.cycle_hz).round();
    let stride = p.speed / p.cycle_hz;
    p.cycle_hz = FPS / period;
    p.speed = stride * p.cycle_hz;
    p.fps = FPS;
    p.frames = period as usize * cycles;
    let base = scale_motion(&gait(&p), M_PER_CMU);
    // `gait` builds core's standard skeleton, which scaled to metres is the common rig's.
    let rig = Rig::standard();
    debug_assert!(rig.skeleton == base.skeleton);
    let speed = p.speed * M_PER_CMU;
    let stride = speed / p.cycle_hz;
    let n = base.num_frames();
    let s = &rig.skeleton;
    let leg = (s.joint(rig.legs[0][1]).offset.length() + s.joint(rig.legs[0][2]).offset.length()) * 0.985;
    let hip_x = s.joint(rig.legs[0][0]).offset.x.abs();
    // Foot targets relative to the progression point, per frame and foot: ankle and pitch.
    let roll = FootRoll::of(&rig);
    let targets: Vec<[(DVec3, f64); 2]> = (0..n)
        .map(|f| {
            let t = f as f64 / FPS;
            let centre = speed * t;
            [0.0, 0.5].map(|off| {
                let ph = (t * p.cycle_hz - 0.25 + off).rem_euclid(1.0);
                let side = if off == 0.0 { 1.0 } else { -1.0 };
                let (a, pitch) = roll.at(ph, duty, stride, lift);
                (DVec3::new(side * hip_x, a.y, centre + a.z), pitch)
            })
        })
        .collect();
    let mut poses = base.poses();
    // Highest pelvis each frame that lets both legs reach, then a periodic min-and-average filter.
    let need: Vec<f64> = (0..n)
        .map(|f| {
            let g = forward(s, &poses[f]);
            let mut y = poses[f].translations[rig.hips].y;
            for (k, &(t, _)) in targets[f].iter().enumerate() {
                let hip = g.positions[rig.legs[k][0]];
                let r = DVec3::new(t.x - hip.x, 0.0, t.z - hip.z).length().min(leg * 0.999);
                let max_hip = t.y + (leg * leg - r * r).sqrt();
                y = y.min(poses[f].translations[rig.hips].y - (hip.y - max_hip).max(0.0));
            }
            y
        })
        .collect();
    let w = 2i64;
    let at = |v: &[f64], i: i64| v[i.rem_euclid(n as i64) as usize];
    let low: Vec<f64> =
        (0..n as i64).map(|i| (-w..=w).map(|d| at(&need, i + d)).fold(f64::INFINITY, f64::min)).collect();
    for (f, pose) in poses.iter_mut().enumerate() {
        pose.translations[rig.hips].y = (-w..=w).map(|d| at(&low, f as i64 + d)).sum::<f64>() / (2 * w + 1) as f64;
        for (k, limb) in [Limb::LeftLeg, Limb::RightLeg].into_iter().enumerate() {
            let (target, pitch) = targets[f][k];
            solve_limb(&rig, pose, limb, target, None);
            let [_, knee, foot, toe] = rig.legs[k];
            let knee_global = forward(s, pose).rotations[knee];
            pose.rotations[foot] = local_from_global(knee_global, DQuat::from_rotation_x(pitch));
            // Toes stay on the floor while the heel rolls over them.
            pose.rotations[toe] = DQuat::from_rotation_x(-pitch.max(0.0));
        }
    }
    clip(&rig, &poses)
}

/// A foot rolling over the floor through one gait cycle (heel strike, flat, heel off over the
/// toes, swing), in the frame of the progression point, facing +Z. Rolling over the toes lets
/// the ankle rise and come forward at the end of the stance, so the pelvis stays high.
struct FootRoll {
    /// Toe base relative to the ankle at rest (metres).
    toe: DVec3,
    /// Heel point relative to the ankle at rest.
    heel: DVec3,
    ankle_height: f64,
}

impl FootRoll {
    /// Pitch at heel strike (toes up), radians.
    const HEEL_STRIKE: f64 = -0.15;
    /// Pitch at toe off (heel up), radians.
    const TOE_OFF: f64 = 0.6;
    /// Fraction of the stance rolling onto the flat foot, and the fraction where the heel lifts.
    const FLAT_FROM: f64 = 0.12;
    const HEEL_OFF: f64 = 0.5;
    /// The stance lies this fraction of its length behind the hips (a foot lands closer in
    /// front of the body than it leaves behind it).
    const BACK: f64 = 0.1;

    fn of(rig: &Rig) -> FootRoll {
        let g = forward(&rig.skeleton, &rig.standing());
        let [_, _, foot, toe] = rig.legs[0];
        let toe = g.positions[toe] - g.positions[foot];
        FootRoll {
            toe: DVec3::new(0.0, toe.y, toe.z),
            heel: DVec3::new(0.0, -rig.ankle_height, -super::ik::HEEL_BACK),
            ankle_height: rig.ankle_height,
        }
    }

    /// Ankle (x = 0) and pitch (about +X; positive lifts the heel) at stance phase `s` ∈ [0, 1]
    /// of a foot whose flat ankle would be at `z` (y = rest ankle height).
    fn stance(&self, s: f64, z: f64) -> (DVec3, f64) {
        let a = DVec3::new(0.0, self.ankle_height, z);
        let (pivot, pitch) = if s < Self::FLAT_FROM {
            (a + self.heel, Self::HEEL_STRIKE * (1.0 - smooth(s / Self::FLAT_FROM)))
        } else if s > Self::HEEL_OFF {
            (a + self.toe, Self::TOE_OFF * smooth((s - Self::HEEL_OFF) / (1.0 - Self::HEEL_OFF)))
        } else {
            (a, 0.0)
        };
        (pivot + DQuat::from_rotation_x(pitch) * (a - pivot), pitch)
    }

    /// Ankle (x = 0, z relative to the progression point) and pitch at cycle phase `ph` ∈ [0, 1)
    /// of a foot planted for `duty` of a cycle of `stride` metres, lifted `lift` in swing.
    fn at(&self, ph: f64, duty: f64, stride: f64, lift: f64) -> (DVec3, f64) {
        let front = stride * duty * (0.5 - Self::BACK);
        if ph < duty {
            return self.stance(ph / duty, front - stride * ph);
        }
        let u = (ph - duty) / (1.0 - duty);
        let (from, p0) = self.stance(1.0, front - stride * duty);
        let (to, p1) = self.stance(0.0, front);
        let w = smooth(u);
        let a = from.lerp(to, w) + DVec3::Y * lift * (PI * u).sin();
        (a, p0 + (p1 - p0) * w)
    }
}

fn build(rig: &Rig, frames: usize, mut f: impl FnMut(f64, &mut Pose)) -> Clip {
    let poses: Vec<Pose> = (0..frames)
        .map(|i| {
            let mut p = rig.standing();
            f(i as f64 / FPS, &mut p);
            p
        })
        .collect();
    clip(rig, &poses)
}

fn breathe(rig: &Rig, p: &mut Pose, t: f64, amp: f64) {
    let b = (TAU * 0.25 * t).sin();
    p.rotations[rig.spine1] = DQuat::from_rotation_x(0.015 * amp * b);
    p.rotations[rig.neck] = DQuat::from_rotation_x(-0.01 * amp * b);
    for (s, arm) in [1.0, -1.0].into_iter().zip(rig.arms) {
        p.rotations[arm[1]] = DQuat::from_rotation_z(s * 0.08) * DQuat::from_rotation_x(-0.03 * amp * b);
        p.rotations[arm[2]] = DQuat::from_rotation_x(-0.15);
    }
}

/// Standing idle: breathing and a slight weight shift.
fn idle(rig: &Rig, k: f64) -> Clip {
    build(rig, 90, |t, p| {
        breathe(rig, p, t, k);
        p.translations[rig.hips].x += 0.01 * k * (TAU * t / 3.0).sin();
    })
}

/// Puts the hand of `limb` at a point given in the body frame (metres, relative to the feet
/// centre at the floor, +Z forward), bending the elbow back.
fn hand_to(rig: &Rig, p: &mut Pose, limb: Limb, body: DVec3) {
    let root = p.translations[rig.hips];
    let target = DVec3::new(root.x, 0.0, root.z) + p.rotations[rig.hips] * body;
    let side = if limb == Limb::LeftArm { 1.0 } else { -1.0 };
    let g = forward(&rig.skeleton, p);
    let shoulder = g.positions[limb.chain(rig)[0]];
    let pole = shoulder + DVec3::new(0.6 * side, -0.8, -0.6);
    solve_limb(rig, p, limb, target, Some(pole));
}

fn head_point(rig: &Rig) -> DVec3 {
    let g = forward(&rig.skeleton, &rig.standing());
    g.positions[rig.head] + DVec3::Y * 0.05
}

/// Linear blend of a pose towards another by `w`.
fn mix(a: &Pose, b: &Pose, w: f64) -> Pose {
    interpolate_pose(a, b, w)
}

/// All procedural clips: (name, tags, clip). The first tag is the primary (canonical) one.
pub fn clips(seed: u64) -> Vec<(String, Vec<String>, Clip)> {
    let rig = Rig::standard();
    let mut jit = Jitter(inbetween_core::seed::rng(seed));
    let mut out: Vec<(String, Vec<String>, Clip)> = Vec::new();
    let mut add = |name: &str, tags: &[&str], m: Clip| {
        out.push((name.to_string(), tags.iter().map(|s| s.to_string()).collect(), m))
    };

    let mut walk = GaitParams::walk();
    walk.speed *= jit.k();
    walk.cycle_hz = WALK_CYCLE_HZ;
    add("procedural walk cycle", &["walk", "cycle", "loop", "locomotion"], gait_cycle(walk, 2, 0.6, 0.08));
    let mut run = GaitParams::run();
    run.speed *= jit.k();
    add("procedural run cycle", &["run", "cycle", "loop", "locomotion"], gait_cycle(run, 2, 0.4, 0.12));
    let k = jit.k();
    add("procedural idle", &["stand", "idle", "loop"], idle(&rig, k));

    // Sitting: seat under the pelvis, a little behind where the character stood.
    let seat = seat_point();
    let seated = seated_pose(&rig, seat, 0.0);
    let standing = rig.standing();
    let ankles_of = |p: &Pose| -> Vec<DVec3> {
        let g = forward(&rig.skeleton, p);
        rig.legs.iter().map(|l| g.positions[l[2]]).collect()
    };
    let (ankles0, ankles1) = (ankles_of(&standing), ankles_of(&seated));
    let transition = |w: f64| {
        // Lean forward mid-way, keep the feet planted with leg IK.
        let mut p = mix(&standing, &seated, smooth(w));
        let lean = 0.45 * (PI * w).sin();
        p.rotations[rig.lower_back] = DQuat::from_rotation_x(lean) * p.rotations[rig.lower_back];
        for (k, leg) in [Limb::LeftLeg, Limb::RightLeg].into_iter().enumerate() {
            solve_limb(&rig, &mut p, leg, ankles0[k].lerp(ankles1[k], smooth(w)), None);
        }
        for arm in rig.arms {
            p.rotations[arm[1]] = DQuat::from_rotation_x(-0.5 * (PI * w).sin()) * p.rotations[arm[1]];
        }
        p
    };
    let n = 45;
    let down: Vec<Pose> = (0..n).map(|i| transition(i as f64 / (n - 1) as f64)).collect();
    let up: Vec<Pose> = down.iter().rev().cloned().collect();
    add("procedural sit down", &["sit_down", "sit", "transition"], clip(&rig, &down));
    let k = jit.k();
    let sit_loop: Vec<Pose> = (0..90)
        .map(|i| {
            let mut p = seated.clone();
            let t = i as f64 / FPS;
            p.rotations[rig.spine1] = DQuat::from_rotation_x(0.02 * k * (TAU * 0.25 * t).sin());
            for (arm, s) in rig.arms.iter().zip([1.0, -1.0]) {
                // Hands resting on the thighs.
                p.rotations[arm[1]] = DQuat::from_rotation_z(0.15 * s) * DQuat::from_rotation_x(-0.35);
                p.rotations[arm[2]] = DQuat::from_rotation_x(-0.9);
            }
            p
        })
        .collect();
    add("procedural sit", &["sit", "loop", "seated"], clip(&rig, &sit_loop));
    add("procedural stand up", &["stand_up", "stand", "transition"], clip(&rig, &up));

    let head = head_point(&rig);
    let k = jit.k();
    add(
        "procedural reach",
        &["reach", "arm"],
        build(&rig, 45, |t, p| {
            breathe(&rig, p, t, 1.0);
            let w = (PI * t / (44.0 / FPS)).sin().powi(2);
            let rest = DVec3::new(-0.2, 0.85, 0.05);
            let far = DVec3::new(-0.2, 1.25, 0.62 * k);
            hand_to(&rig, p, Limb::RightArm, rest.lerp(far, w));
        }),
    );
    add(
        "procedural wave",
        &["wave", "arm", "loop"],
        build(&rig, 60, |t, p| {
            breathe(&rig, p, t, 1.0);
            let x = -0.35 + 0.1 * k * (TAU * 1.5 * t).sin();
            hand_to(&rig, p, Limb::RightArm, DVec3::new(x, head.y + 0.15, 0.1));
        }),
    );
    let k = jit.k();
    add(
        "procedural punch",
        &["punch", "arm", "loop"],
        build(&rig, 40, |t, p| {
            let ph = (t * FPS / 40.0).fract();
            let jab = (PI * (ph / 0.5).min(1.0)).sin().max(0.0).powf(0.6);
            p.rotations[rig.spine1] = DQuat::from_rotation_y(0.25 * jab);
            for leg in rig.legs {
                p.rotations[leg[0]] = DQuat::from_rotation_x(-0.12);
                p.rotations[leg[1]] = DQuat::from_rotation_x(0.24);
                p.rotations[leg[2]] = DQuat::from_rotation_x(-0.12);
            }
            let h = p.translations[rig.hips];
            p.translations[rig.hips] = DVec3::new(h.x, hip_height() - 0.006, h.z);
            let guard_r = DVec3::new(-0.12, 1.35, 0.22);
            let hit = DVec3::new(-0.08, 1.4, 0.62 * k);
            hand_to(&rig, p, Limb::RightArm, guard_r.lerp(hit, jab));
            hand_to(&rig, p, Limb::LeftArm, DVec3::new(0.12, 1.4, 0.25));
        }),
    );
    let k = jit.k();
    add(
        "procedural type",
        &["type", "arm", "loop", "table"],
        build(&rig, 60, |t, p| {
            breathe(&rig, p, t, 0.5);
            for (limb, s, ph) in [(Limb::LeftArm, 1.0, 0.0), (Limb::RightArm, -1.0, 1.3)] {
                let tap = 0.012 * k * ((TAU * 3.0 * t + ph).sin()).max(0.0);
                hand_to(&rig, p, limb, DVec3::new(0.17 * s, 0.95 + tap, 0.42));
            }
        }),
    );
    add(
        "procedural call",
        &["call", "arm", "loop", "head"],
        build(&rig, 60, |t, p| {
            breathe(&rig, p, t, 1.0);
            p.rotations[rig.neck] = DQuat::from_rotation_z(0.12 * (TAU * 0.3 * t).sin());
            hand_to(&rig, p, Limb::RightArm, DVec3::new(-0.1, head.y - 0.05, head.z + 0.02));
        }),
    );
    add(
        "procedural drink",
        &["drink", "arm", "loop", "head"],
        build(&rig, 60, |t, p| {
            breathe(&rig, p, t, 1.0);
            let w = (PI * t / 2.0).sin().powi(2);
            let low = DVec3::new(-0.2, 1.0, 0.25);
            let mouth = DVec3::new(-0.02, head.y - 0.1, head.z + 0.1);
            hand_to(&rig, p, Limb::RightArm, low.lerp(mouth, w));
            p.rotations[rig.neck] = DQuat::from_rotation_x(-0.25 * w);
        }),
    );
    let k = jit.k();
    add(
        "procedural look",
        &["look", "head", "loop"],
        build(&rig, 90, |t, p| {
            breathe(&rig, p, t, 1.0);
            p.rotations[rig.neck] =
                DQuat::from_rotation_y(0.35 * k * (TAU * t / 3.0).sin()) * DQuat::from_rotation_x(0.08);
        }),
    );
    add(
        "procedural think",
        &["think", "head", "loop"],
        build(&rig, 90, |t, p| {
            breathe(&rig, p, t, 1.0);
            p.rotations[rig.neck] =
                DQuat::from_rotation_z(0.18 * k) * DQuat::from_rotation_x(0.12 + 0.03 * (TAU * t / 3.0).sin());
            hand_to(&rig, p, Limb::RightArm, DVec3::new(-0.02, head.y - 0.16, head.z + 0.12));
            hand_to(&rig, p, Limb::LeftArm, DVec3::new(0.05, 1.1, 0.16));
        }),
    );
    let k = jit.k();
    add(
        "procedural write",
        &["write", "arm", "loop", "board"],
        build(&rig, 90, |t, p| {
            breathe(&rig, p, t, 1.0);
            let a = TAU * t / 1.5;
            let target = DVec3::new(-0.15 + 0.12 * k * a.sin(), 1.45 + 0.06 * (2.0 * a).sin(), 0.5);
            hand_to(&rig, p, Limb::RightArm, target);
        }),
    );
    add(
        "procedural hammer",
        &["hammer", "arm", "loop", "table"],
        build(&rig, 30, |t, p| {
            breathe(&rig, p, t, 1.0);
            let ph = (t * FPS / 30.0).fract();
            let up = (PI * ph).sin();
            p.rotations[rig.lower_back] = DQuat::from_rotation_x(0.15);
            hand_to(&rig, p, Limb::RightArm, DVec3::new(-0.18, 0.95 + 0.3 * up, 0.4 - 0.08 * up));
            hand_to(&rig, p, Limb::LeftArm, DVec3::new(0.1, 0.92, 0.42));
        }),
    );
    out
}
