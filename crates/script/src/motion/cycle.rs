//! Walk cycles cut from captured walks (§4.3's locomotion takes its cycle "from the library"):
//! one gait cycle (two steps) of a retargeted CMU walk, turned to walk along +Z, with the loop
//! seam closed, so [`super::walk_route`] can loop captured steps instead of the procedural cycle.
//!
//! The cycle is the window `[start, start + period)` whose last frame best matches its first in
//! body pose (every joint's local rotation, the hips with their heading removed, and the hips'
//! height) among windows of 0.8–1.6 s that travel in a near-straight line at walking speed.

use super::rig::{heading_of, wrap, yaw, Rig, FPS};
use glam::{DQuat, DVec3};
use inbetween_core::clip::Clip;
use inbetween_core::Pose;

/// Shortest and longest gait cycle considered, seconds (people walk at about 1 s per cycle).
const PERIOD_SECONDS: (f64, f64) = (0.8, 1.6);
/// Slowest walk a cycle may show, m/s.
const MIN_SPEED: f64 = 0.5;
/// Largest heading change over one cycle, degrees.
const MAX_TURN_DEG: f64 = 20.0;
/// Smallest ratio of straight-line to travelled distance over a cycle.
const MIN_STRAIGHTNESS: f64 = 0.9;
/// Largest seam mismatch accepted, radians summed over joints (≈ 2° per joint on the common rig).
const MAX_SEAM: f64 = 1.2;

/// Where a cycle was found in a clip and how well it loops.
#[derive(Clone, Debug, PartialEq)]
pub struct CycleCut {
    pub start: usize,
    /// Frames in one cycle.
    pub period: usize,
    /// Pose mismatch between the cycle's first frame and the frame after its last, radians summed
    /// over joints (before the seam is closed).
    pub seam: f64,
    /// Heading change over the cycle, degrees.
    pub turn_deg: f64,
    /// Walking speed, m/s.
    pub speed: f64,
}

fn horizontal(v: DVec3) -> DVec3 {
    DVec3::new(v.x, 0.0, v.z)
}

/// Pose mismatch of two frames: local rotation angles of every joint but the hips, plus the hips'
/// rotation with its heading removed and 1 rad per 10 cm of hips height difference.
fn seam_distance(rig: &Rig, a: &Pose, b: &Pose) -> f64 {
    let mut d = 0.0;
    for j in 0..a.rotations.len() {
        let (qa, qb) = if j == rig.hips {
            (yaw(-heading_of(a.rotations[j])) * a.rotations[j], yaw(-heading_of(b.rotations[j])) * b.rotations[j])
        } else {
            (a.rotations[j], b.rotations[j])
        };
        d += qa.angle_between(qb);
    }
    d + (a.translations[rig.hips].y - b.translations[rig.hips].y).abs() * 10.0
}

/// The best-looping gait cycle of a walk clip on the common rig, or None when no window walks
/// straight enough, fast enough and loops closely enough.
pub fn find_cycle(m: &Clip, rig: &Rig) -> Option<CycleCut> {
    let poses = m.poses();
    let n = poses.len();
    let fps = m.fps();
    let (lo, hi) = ((PERIOD_SECONDS.0 * fps).round() as usize, (PERIOD_SECONDS.1 * fps).round() as usize);
    let root: Vec<DVec3> = poses.iter().map(|p| horizontal(p.translations[rig.hips])).collect();
    let heading: Vec<f64> = poses.iter().map(|p| heading_of(p.rotations[rig.hips])).collect();
    // Travelled distance up to each frame.
    let mut travelled = vec![0.0; n];
    for f in 1..n {
        travelled[f] = travelled[f - 1] + (root[f] - root[f - 1]).length();
    }
    let mut best: Option<CycleCut> = None;
    for period in lo..=hi {
        for start in 0..n.saturating_sub(period) {
            let end = start + period;
            let straight = (root[end] - root[start]).length();
            let path = travelled[end] - travelled[start];
            let seconds = period as f64 / fps;
            let turn = wrap(heading[end] - heading[start]).abs().to_degrees();
            if straight / seconds < MIN_SPEED || straight < MIN_STRAIGHTNESS * path || turn > MAX_TURN_DEG {
                continue;
            }
            let seam = seam_distance(rig, &poses[start], &poses[end]);
            if seam <= MAX_SEAM && best.as_ref().is_none_or(|b| seam < b.seam) {
                best = Some(CycleCut { start, period, seam, turn_deg: turn, speed: straight / seconds });
            }
        }
    }
    best
}

/// The cycle's frames as a loopable clip: travelling along +Z from the origin, the seam mismatch
/// of every joint spread evenly over the cycle (so frame `period` would equal frame 0 again,
/// heading drift included), resampled to the common rig's frame rate.
pub fn cut_cycle(m: &Clip, rig: &Rig, cut: &CycleCut) -> Clip {
    let poses = m.poses();
    let (s, e) = (cut.start, cut.start + cut.period);
    let travel = horizontal(poses[e].translations[rig.hips] - poses[s].translations[rig.hips]);
    let turn = yaw(-travel.x.atan2(travel.z));
    let origin = horizontal(poses[s].translations[rig.hips]);
    let oriented = |p: &Pose| {
        let mut p = p.clone();
        p.translations[rig.hips] = turn * (p.translations[rig.hips] - origin);
        p.rotations[rig.hips] = (turn * p.rotations[rig.hips]).normalize();
        p
    };
    let first = oriented(&poses[s]);
    let after = oriented(&poses[e]);
    // Per-joint seam error, removed progressively: corrected(f) = slerp(I, error⁻¹, f / period) · q(f).
    let errors: Vec<DQuat> =
        first.rotations.iter().zip(&after.rotations).map(|(a, b)| (*b * a.inverse()).normalize()).collect();
    let dy = after.translations[rig.hips].y - first.translations[rig.hips].y;
    let mut out: Vec<Pose> = (s..e)
        .map(|f| {
            let w = (f - s) as f64 / cut.period as f64;
            let mut p = oriented(&poses[f]);
            for (q, err) in p.rotations.iter_mut().zip(&errors) {
                *q = (DQuat::IDENTITY.slerp(err.inverse(), w) * *q).normalize();
            }
            p.translations[rig.hips].y -= dy * w;
            p
        })
        .collect();
    if (m.frame_time() - 1.0 / FPS).abs() > 1e-9 {
        out = resample_loop(&out, m.frame_time(), travel.length());
    }
    Clip::from_poses(m.skeleton().clone(), 1.0 / FPS, &out).expect("poses come from the same skeleton")
}

/// A looping cycle sampled at another frame time, resampled to [`FPS`] (the root's forward
/// travel of `stride` metres per loop continues across the seam).
fn resample_loop(poses: &[Pose], frame_time: f64, stride: f64) -> Vec<Pose> {
    let n = poses.len();
    let duration = n as f64 * frame_time;
    let frames = (duration * FPS).round().max(1.0) as usize;
    (0..frames)
        .map(|k| {
            let x = k as f64 / frames as f64 * n as f64;
            let f0 = (x.floor() as usize).min(n - 1);
            let w = x - f0 as f64;
            if f0 + 1 < n {
                inbetween_core::motion::interpolate_pose(&poses[f0], &poses[f0 + 1], w)
            } else {
                let mut next = poses[0].clone();
                for t in next.translations.iter_mut().take(1) {
                    *t += DVec3::Z * stride;
                }
                inbetween_core::motion::interpolate_pose(&poses[f0], &next, w)
            }
        })
        .collect()
}

/// [`find_cycle`] then [`cut_cycle`].
pub fn extract_cycle(m: &Clip, rig: &Rig) -> Option<(Clip, CycleCut)> {
    if m.skeleton() != &rig.skeleton {
        return None;
    }
    let cut = find_cycle(m, rig)?;
    Some((cut_cycle(m, rig, &cut), cut))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::motion::locomotion::foot_skate;

    /// A procedural walk cycle repeated several times, turned and shifted like a capture.
    fn captured_walk(rig: &Rig, turn: f64, loops: usize) -> (Clip, usize) {
        let lib = crate::motion::MotionLibrary::procedural(0);
        let cyc = lib.cycle("walk").expect("procedural walk cycle").clip.clone();
        let one = cyc.poses();
        let n = one.len();
        let stride = one[n - 1].translations[rig.hips].z - one[0].translations[rig.hips].z;
        let stride = stride * n as f64 / (n - 1) as f64;
        let mut poses = Vec::new();
        for l in 0..loops {
            for p in &one {
                let mut p = p.clone();
                p.translations[rig.hips].z += stride * l as f64;
                p.translations[rig.hips] = yaw(turn) * p.translations[rig.hips] + DVec3::new(3.0, 0.0, -2.0);
                p.rotations[rig.hips] = (yaw(turn) * p.rotations[rig.hips]).normalize();
                poses.push(p);
            }
        }
        (Clip::from_poses(cyc.skeleton().clone(), 1.0 / FPS, &poses).unwrap(), n)
    }

    #[test]
    fn finds_the_period_of_a_repeated_cycle_and_turns_it_to_plus_z() {
        let rig = Rig::standard();
        let (walk, n) = captured_walk(&rig, 1.1, 4);
        let (cycle, cut) = extract_cycle(&walk, &rig).expect("a cycle");
        // The clip holds whole gait cycles: the one found divides it.
        assert_eq!(n % cut.period, 0, "{cut:?} in {n} frames");
        assert!(cut.seam < 1e-6, "{cut:?}");
        let p = cycle.poses();
        let travel = p[p.len() - 1].translations[rig.hips] - p[0].translations[rig.hips];
        assert!(travel.z > 0.3 && travel.x.abs() < 0.02 * travel.z, "{travel:?}");
        assert!(p[0].translations[rig.hips].x.abs() < 1e-9 && p[0].translations[rig.hips].z.abs() < 1e-9);
        assert!(foot_skate(&cycle).unwrap().is_finite());
    }

    #[test]
    fn closes_the_seam_of_a_drifting_cycle() {
        let rig = Rig::standard();
        let (walk, _) = captured_walk(&rig, 0.0, 3);
        // Drift the spine and the hips' height a little over the clip, as a capture would.
        let mut poses = walk.poses();
        let total = poses.len() as f64;
        for (f, p) in poses.iter_mut().enumerate() {
            let w = f as f64 / total;
            p.rotations[rig.spine1] = (DQuat::from_rotation_x(0.2 * w) * p.rotations[rig.spine1]).normalize();
            p.translations[rig.hips].y += 0.03 * w;
        }
        let walk = Clip::from_poses(walk.skeleton().clone(), 1.0 / FPS, &poses).unwrap();
        let (cycle, cut) = extract_cycle(&walk, &rig).expect("a cycle");
        assert!(cut.seam > 0.01, "the drift makes a seam: {cut:?}");
        // Closed seam: looping from the last frame back to the first changes the spine and the
        // hips' height no more than one step of the drift-free walk does (the drift per cycle,
        // 0.2 rad / 3 and 1 cm, is gone).
        let c = cycle.poses();
        let (clean, _) = captured_walk(&rig, 0.0, 1);
        let o = clean.poses();
        let step = |a: &Pose, b: &Pose| {
            (
                a.rotations[rig.spine1].angle_between(b.rotations[rig.spine1]),
                (a.translations[rig.hips].y - b.translations[rig.hips].y).abs(),
            )
        };
        let (max_turn, max_rise) =
            o.windows(2).map(|w| step(&w[0], &w[1])).fold((0.0f64, 0.0f64), |m, s| (m.0.max(s.0), m.1.max(s.1)));
        let (turn, rise) = step(&c[c.len() - 1], &c[0]);
        assert!(turn <= max_turn + 0.01, "spine {turn} vs {max_turn}");
        assert!(rise <= max_rise + 0.002, "hips {rise} vs {max_rise}");
    }

    #[test]
    fn standing_still_has_no_cycle() {
        let rig = Rig::standard();
        let stand = vec![rig.standing(); 90];
        let m = Clip::from_poses(rig.skeleton.clone(), 1.0 / FPS, &stand).unwrap();
        assert!(find_cycle(&m, &rig).is_none());
    }
}
