//! Two-bone IK against forward kinematics, and hips placement for sitting (§4.2, §4.3).

use glam::DVec3;
use inbetween_core::fk::forward;
use inbetween_script::motion::ik::{seated_pose, PELVIS_ABOVE_SEAT};
use inbetween_script::motion::{place_hips, solve_limb, two_bone, Limb, Rig};
use rand::Rng;

#[test]
fn reachable_targets_are_met_exactly() {
    let rig = Rig::standard();
    let mut rng = inbetween_core::seed::rng(11);
    for limb in [Limb::LeftArm, Limb::RightArm, Limb::LeftLeg, Limb::RightLeg] {
        let [a, b, c] = limb.chain(&rig);
        for _ in 0..50 {
            let mut pose = rig.standing();
            let g = forward(&rig.skeleton, &pose);
            let (l1, l2) = ((g.positions[b] - g.positions[a]).length(), (g.positions[c] - g.positions[b]).length());
            let dir = DVec3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0))
                .normalize();
            let dist = rng.random_range((l1 - l2).abs() + 0.02..l1 + l2 - 0.01);
            let target = g.positions[a] + dir * dist;
            let err = solve_limb(&rig, &mut pose, limb, target, None);
            let h = forward(&rig.skeleton, &pose);
            assert!(err < 1e-9, "{limb:?}: {err}");
            assert!(
                (h.positions[c] - target).length() < 1e-9,
                "{limb:?}: FK misses by {}",
                (h.positions[c] - target).length()
            );
            // The root of the chain did not move, bone lengths are kept, the end kept its orientation.
            assert!((h.positions[a] - g.positions[a]).length() < 1e-12);
            assert!(((h.positions[b] - h.positions[a]).length() - l1).abs() < 1e-9);
            assert!(inbetween_core::rotation::angle_between(h.rotations[c], g.rotations[c]) < 1e-9);
        }
    }
}

#[test]
fn unreachable_targets_are_clamped_along_the_line() {
    let rig = Rig::standard();
    let mut pose = rig.standing();
    let [a, b, c] = Limb::RightArm.chain(&rig);
    let g = forward(&rig.skeleton, &pose);
    let reach = (g.positions[b] - g.positions[a]).length() + (g.positions[c] - g.positions[b]).length();
    let target = g.positions[a] + DVec3::new(0.0, 0.3, 3.0);
    let err = solve_limb(&rig, &mut pose, Limb::RightArm, target, None);
    let h = forward(&rig.skeleton, &pose);
    let hand = h.positions[c];
    assert!(((hand - h.positions[a]).length() - reach).abs() < 1e-9);
    assert!((err - ((target - g.positions[a]).length() - reach)).abs() < 1e-9);
    let along = (target - g.positions[a]).normalize();
    assert!(((hand - h.positions[a]).normalize() - along).length() < 1e-9);
}

#[test]
fn pole_vector_chooses_the_bend_side() {
    let root = DVec3::ZERO;
    let mid = DVec3::new(0.0, -0.4, 0.0);
    let end = DVec3::new(0.0, -0.8, 0.0);
    let target = DVec3::new(0.0, -0.6, 0.0);
    for side in [1.0, -1.0] {
        let s = two_bone(root, mid, end, target, DVec3::new(0.0, -0.3, side));
        assert!(!s.clamped);
        assert!(s.mid.z * side > 0.1, "{s:?}");
        assert!((s.end - target).length() < 1e-12);
        assert!(((s.mid - root).length() - 0.4).abs() < 1e-12);
        assert!(((s.end - s.mid).length() - 0.4).abs() < 1e-12);
    }
    // Too close: clamped to the inner shell.
    let s =
        two_bone(root, DVec3::new(0.0, -0.5, 0.0), DVec3::new(0.0, -0.8, 0.0), DVec3::new(0.0, -0.1, 0.0), DVec3::Z);
    assert!(s.clamped);
    assert!((s.end.length() - 0.2).abs() < 1e-12);
}

#[test]
fn hips_meet_the_seat_and_feet_stay_on_the_floor() {
    let rig = Rig::standard();
    for (seat, heading) in
        [(DVec3::new(2.0, 0.45, 1.0), 0.0), (DVec3::new(-1.0, 0.5, 3.0), 1.3), (DVec3::new(0.0, 0.40, 0.0), -2.0)]
    {
        let pose = seated_pose(&rig, seat, heading);
        let g = forward(&rig.skeleton, &pose);
        let pelvis = (g.positions[rig.legs[0][0]] + g.positions[rig.legs[1][0]]) * 0.5;
        assert!((pelvis - (seat + DVec3::Y * PELVIS_ABOVE_SEAT)).length() < 1e-9, "{pelvis:?}");
        for leg in rig.legs {
            assert!((g.positions[leg[2]].y - rig.ankle_height).abs() < 1e-6, "ankle at {}", g.positions[leg[2]].y);
            // Knees in front of the pelvis (thighs forward along the heading).
            let fwd = DVec3::new(heading.sin(), 0.0, heading.cos());
            assert!((g.positions[leg[1]] - pelvis).dot(fwd) > 0.25);
        }
    }
    // Placing a standing pose's hips lower bends the legs and keeps the feet where they were.
    let mut pose = rig.standing();
    let err = place_hips(&rig, &mut pose, DVec3::new(0.0, 0.6, 0.0), true);
    assert!(err < 1e-9);
}
