//! Walking a route (§4.3): arc-length timing, eased start and stop, limited turn rate, and foot
//! locking that removes foot skate.

use inbetween_script::motion::locomotion::{heading_at, place_clip};
use inbetween_script::motion::{
    foot_skate, lock_feet, walk_route, walk_route_stats, LockParams, MotionLibrary, Rig, WalkParams,
};

fn arc_route() -> Vec<[f32; 2]> {
    (0..=40)
        .map(|i| {
            let a = i as f32 / 40.0 * 3.0;
            [1.0 + 2.0 * a.sin(), 1.0 + 2.0 - 2.0 * a.cos()]
        })
        .collect()
}

fn root_xz(m: &inbetween_core::clip::Clip, f: usize) -> [f64; 2] {
    let r = m.pose(f).translations[0];
    [r.x, r.z]
}

#[test]
fn straight_route_starts_and_stops_at_rest_and_arrives() {
    let lib = MotionLibrary::procedural(0);
    let route = [[1.0f32, 1.0], [1.0, 5.0]];
    let (m, st) = walk_route_stats(&route, &lib, &WalkParams::default());
    let n = m.num_frames();
    assert!((st.length - 4.0).abs() < 1e-6);
    let [x0, z0] = root_xz(&m, 0);
    let [x1, z1] = root_xz(&m, n - 1);
    assert!((x0 - 1.0).abs() < 0.05 && (z0 - 1.0).abs() < 0.05, "start {x0} {z0}");
    assert!((x1 - 1.0).abs() < 0.05 && (z1 - 5.0).abs() < 0.05, "end {x1} {z1}");
    let speed = |f: usize| {
        let (a, b) = (root_xz(&m, f), root_xz(&m, f + 1));
        ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt() * 30.0
    };
    let cycle_speed = {
        let c = &lib.cycle("walk").unwrap().clip;
        let (a, b) = (c.pose(0).translations[0], c.pose(c.num_frames() - 1).translations[0]);
        (b.z - a.z) / c.duration()
    };
    let top = (0..n - 1).map(speed).fold(0.0, f64::max);
    assert!(top > 0.8 * cycle_speed && top < 1.3 * cycle_speed, "top speed {top} vs cycle {cycle_speed}");
    // Eased: no jump to full speed at the start or from it at the end.
    for f in 0..12 {
        assert!(speed(f) < 0.6 * cycle_speed, "frame {f}: {}", speed(f));
    }
    for f in n - 10..n - 1 {
        assert!(speed(f) < 0.3 * cycle_speed, "frame {f}: {}", speed(f));
    }
    assert!(st.max_route_error < 0.1);
    // Faces along the route (+Z), within the cycle's pelvis yaw sway.
    assert!(heading_at(&m, n / 2).abs() < 0.25);
}

#[test]
fn foot_locking_removes_skate_on_a_curved_route() {
    let lib = MotionLibrary::procedural(0);
    let route = arc_route();
    let raw = walk_route(&route, &lib, &WalkParams { lock_feet: false, ..WalkParams::default() });
    let (locked, st) = walk_route_stats(&route, &lib, &WalkParams::default());
    let before = foot_skate(&raw).unwrap();
    let after = foot_skate(&locked).unwrap();
    println!("foot skate on a 6 m arc: {before:.2} cm/s before locking, {after:.2} cm/s after");
    assert!((st.skate_before - before).abs() < 1e-9 && (st.skate_after - after).abs() < 1e-9);
    assert!(before > 5.0, "the unlocked walk should skate on a curve ({before})");
    assert!(after < 0.35 * before, "locking must cut skate by two thirds: {before} -> {after}");
    // Locking keeps feet out of the floor and the root on the route.
    let rig = Rig::standard();
    let low = locked
        .globals()
        .iter()
        .map(|g| g.positions[rig.legs[0][2]].y.min(g.positions[rig.legs[1][2]].y))
        .fold(f64::INFINITY, f64::min);
    assert!(low > rig.ankle_height - 0.03, "ankle {low} below the floor");
    assert!(st.max_route_error < 0.1);
    // Locking is a post-process any clip on the rig can take.
    let again = lock_feet(&raw, &LockParams::default()).unwrap();
    assert_eq!(again, locked);
}

#[test]
fn corners_are_turned_at_a_limited_rate() {
    let lib = MotionLibrary::procedural(0);
    // An A*-style route: axis-aligned segments with a right-angle corner.
    let route = [[0.5f32, 0.5], [0.5, 3.0], [3.0, 3.0]];
    let p = WalkParams { max_turn_rate: 2.0, ..WalkParams::default() };
    let (m, st) = walk_route_stats(&route, &lib, &p);
    let n = m.num_frames();
    let [x1, z1] = root_xz(&m, n - 1);
    assert!((x1 - 3.0).abs() < 0.05 && (z1 - 3.0).abs() < 0.05);
    assert!(st.max_route_error < 0.05, "{}", st.max_route_error);
    // Heading ends along +X (π/2), and never changes faster than the limit plus the pelvis sway.
    assert!((heading_at(&m, n - 1) - std::f64::consts::FRAC_PI_2).abs() < 0.2);
    for f in 1..n {
        let d = inbetween_core::angle::wrap_angle(heading_at(&m, f) - heading_at(&m, f - 1));
        assert!(d.abs() < 2.0 / 30.0 + 0.05, "frame {f}: {d}");
    }
    println!("corner route: skate {:.2} -> {:.2} cm/s", st.skate_before, st.skate_after);
    assert!(st.skate_after < 0.5 * st.skate_before);
}

#[test]
fn final_heading_and_degenerate_routes() {
    let lib = MotionLibrary::procedural(0);
    let p = WalkParams { final_heading: Some(std::f64::consts::PI), ..WalkParams::default() };
    let m = walk_route(&[[0.0, 0.0], [0.0, 2.0]], &lib, &p);
    assert!((heading_at(&m, m.num_frames() - 1).abs() - std::f64::consts::PI).abs() < 0.2);
    // An empty library still walks (built-in cycle, rest pose as idle).
    let empty = MotionLibrary::default();
    let m = walk_route(&[[0.0, 0.0], [0.0, 2.0]], &empty, &WalkParams::default());
    let r = m.pose(m.num_frames() - 1).translations[0];
    assert!((r.z - 2.0).abs() < 0.1, "{r:?}");
    for route in [vec![], vec![[2.0f32, 2.0]], vec![[2.0, 2.0], [2.0, 2.0]]] {
        let m = walk_route(&route, &lib, &WalkParams::default());
        assert!(m.num_frames() > 0);
        let a = root_xz(&m, 0);
        let b = root_xz(&m, m.num_frames() - 1);
        assert!((a[0] - b[0]).abs() < 0.05 && (a[1] - b[1]).abs() < 0.05);
    }
}

#[test]
fn walking_is_deterministic_and_run_is_faster() {
    let lib = MotionLibrary::procedural(0);
    let route = arc_route();
    let a = walk_route(&route, &lib, &WalkParams::default());
    let b = walk_route(&route, &lib, &WalkParams::default());
    assert_eq!(a, b);
    let run = walk_route(&route, &lib, &WalkParams { verb: "run".into(), ..WalkParams::default() });
    assert!(run.num_frames() < a.num_frames());
    // A library clip can be placed in the world.
    let sit = &lib.retrieve("sit").unwrap().clip;
    let placed = place_clip(sit, [2.0, 3.0], 1.0).unwrap();
    let r = placed.pose(0).translations[0];
    let r0 = sit.pose(0).translations[0];
    assert!(
        (glam::DVec3::new(r.x - 2.0, 0.0, r.z - 3.0).length() - glam::DVec3::new(r0.x, 0.0, r0.z).length()).abs()
            < 1e-9
    );
    assert!((r.y - r0.y).abs() < 1e-12);
}

#[test]
fn walks_an_astar_route_around_an_obstacle() {
    use inbetween_script::layout::grid::{Grid, CELL};
    let mut grid = Grid::new(5.0, 5.0, CELL);
    grid.block_rect([2.5, 2.5], [0.8, 0.5], 0.0, 0.2);
    let route = grid.astar([0.6, 0.6], [4.4, 4.4]).expect("a route around the table");
    let lib = MotionLibrary::procedural(0);
    let (m, st) = walk_route_stats(&route, &lib, &WalkParams::default());
    println!(
        "A* route: {} points, {:.2} m, {} frames, skate {:.2} -> {:.2} cm/s",
        route.len(),
        st.length,
        st.frames,
        st.skate_before,
        st.skate_after
    );
    for f in 0..m.num_frames() {
        let [x, z] = root_xz(&m, f);
        assert!(grid.is_free_at([x as f32, z as f32]), "frame {f}: root at ({x:.2}, {z:.2}) is inside the obstacle");
    }
    let [x1, z1] = root_xz(&m, m.num_frames() - 1);
    assert!((x1 - 4.4).abs() < 0.05 && (z1 - 4.4).abs() < 0.05);
    assert!(st.skate_after < 0.5 * st.skate_before);
}

#[test]
fn a_foreign_skeleton_gives_an_error_naming_the_missing_joint_not_a_panic() {
    use inbetween_core::clip::Clip;
    use inbetween_core::Pose;
    use inbetween_script::animate::crowd::root_track;
    use inbetween_script::motion::locomotion::detect_contacts;
    use inbetween_script::motion::{blend_upper, reach_contacts, BlendParams, Contact, Limb};
    // The common rig without its left toe: every helper that needs the feet must say so.
    let rig = Rig::standard();
    let (sk, _) = rig.skeleton.filter(|_, j| j.name != "LeftToeBase");
    assert!(sk.find("LeftToeBase").is_none() && sk.find("LeftFoot").is_some());
    let mut pose = Pose::rest(&sk);
    pose.translations[0].y = 0.9;
    let m = Clip::from_poses(sk.clone(), 1.0 / 30.0, &[pose.clone(), pose]).unwrap();
    let contact =
        Contact { limb: Limb::RightArm, target: glam::DVec3::new(0.3, 1.0, 0.3), window: BlendParams::default() };
    let errors = [
        ("foot_skate", foot_skate(&m).err()),
        ("lock_feet", lock_feet(&m, &LockParams::default()).err()),
        ("detect_contacts", detect_contacts(&m, &LockParams::default()).err()),
        ("place_clip", place_clip(&m, [1.0, 1.0], 0.5).err()),
        ("blend_upper", blend_upper(&m, &m, &BlendParams::default()).err()),
        ("reach_contacts", reach_contacts(&m, &[contact]).err()),
        ("root_track", root_track(&m).err()),
    ];
    for (what, e) in errors {
        let msg = e.unwrap_or_else(|| panic!("{what} accepted a skeleton without LeftToeBase")).to_string();
        eprintln!("{what}: {msg}");
        // The missing joint is named by its role (core::roles), whatever the rig calls it.
        assert!(msg.contains("left_toe"), "{what}: {msg}");
    }
    // Two clips on different skeletons cannot be blended.
    let walk = walk_route(&[[0.0, 0.0], [1.0, 0.0]], &MotionLibrary::procedural(0), &WalkParams::default());
    let msg = blend_upper(&walk, &m, &BlendParams::default()).unwrap_err().to_string();
    assert!(msg.contains("one skeleton"), "{msg}");
}

#[test]
fn a_turn_on_the_spot_steps_instead_of_gliding() {
    // Walk 2 m along +z, then turn to face back: the feet step round instead of sliding about the
    // hips. Over the turn, an ankle on the floor (within 2 cm of its rest height) covers at most
    // 5 cm horizontally (it was about 0.3 m: the idle stance turned about the hips).
    let lib = MotionLibrary::procedural(0);
    let rig = Rig::standard();
    let route = [[0.0f32, 0.0], [0.0, 2.0]];
    let turned = WalkParams { final_heading: Some(std::f64::consts::PI), lock_feet: false, ..WalkParams::default() };
    let straight = WalkParams { lock_feet: false, ..WalkParams::default() };
    let m = walk_route(&route, &lib, &turned);
    let s = walk_route(&route, &lib, &straight);
    let g = m.globals();
    let turn_frames = m.num_frames() - s.num_frames();
    assert!(turn_frames > 10, "{turn_frames}");
    // The turn happens before the held end, which is as long in both.
    let hold = (WalkParams::default().hold_end * 30.0).round().max(1.0) as usize;
    let (a, b) = (s.num_frames() - hold, m.num_frames() - hold);
    // Per foot, the horizontal distance its ankle covers while on the floor over the turn.
    let mut glide = [0.0f64; 2];
    for f in a + 1..b {
        for (k, leg) in rig.legs.iter().enumerate() {
            let (p, q) = (g[f - 1].positions[leg[2]], g[f].positions[leg[2]]);
            if p.y <= rig.ankle_height + 0.02 && q.y <= rig.ankle_height + 0.02 {
                glide[k] += ((q.x - p.x).powi(2) + (q.z - p.z).powi(2)).sqrt();
            }
        }
    }
    eprintln!("turn of {turn_frames} frames: planted ankles glide {:.3} m and {:.3} m", glide[0], glide[1]);
    assert!(glide.iter().all(|&d| d <= 0.05), "planted feet glide {glide:?} m over the turn");
    assert!(heading_at(&m, m.num_frames() - 1).abs() > 3.0);
}
