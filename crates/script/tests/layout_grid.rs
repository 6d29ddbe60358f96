//! The occupancy grid: rasterised footprints, reachability, A* around a wall.

use inbetween_script::layout::grid::{Grid, CELL, WALKER_RADIUS};
use inbetween_script::scene::{Origin, PlacedObject, Room};

#[test]
fn astar_goes_round_a_wall_through_its_gap() {
    // 5 × 4 m, a wall across x = 2.5 from z = 0 to z = 3.2 (gap at the top).
    let mut g = Grid::new(5.0, 4.0, 0.1);
    g.block_rect([2.5, 1.6], [0.05, 1.6], 0.0, 0.0);
    let (from, to) = ([1.0, 1.0], [4.0, 1.0]);
    let path = g.astar(from, to).expect("a route through the gap");
    assert_eq!(path.first(), Some(&from));
    assert_eq!(path.last(), Some(&to));
    assert!(path.iter().any(|p| p[1] > 3.2), "goes round the wall's end");
    for p in &path {
        assert!(g.is_free_at(*p), "{p:?} is blocked");
    }
    for w in path.windows(2) {
        let step = ((w[1][0] - w[0][0]).powi(2) + (w[1][1] - w[0][1]).powi(2)).sqrt();
        assert!(step <= 0.25, "steps are single cells (ends snap to cell centres): {step}");
    }
    let len: f32 = path.windows(2).map(|w| ((w[1][0] - w[0][0]).powi(2) + (w[1][1] - w[0][1]).powi(2)).sqrt()).sum();
    // Straight-line detour via the gap is ≈ 2·√(1.5² + 2.25²) ≈ 5.4 m; A* on 8-connected cells is near it.
    assert!(len > 5.0 && len < 6.5, "length {len}");

    // Close the gap: no route, and the far side is not reachable.
    g.block_rect([2.5, 3.6], [0.05, 0.4], 0.0, 0.0);
    assert!(g.astar(from, to).is_none());
    let reached = g.reachable_from(g.cell_of(from).unwrap());
    let (i, j) = g.cell_of(to).unwrap();
    assert!(!reached[j * g.nx + i]);
    // Blocked or outside ends.
    assert!(g.astar([2.5, 1.0], to).is_none());
    assert!(g.astar([-1.0, 1.0], to).is_none());
    assert_eq!(g.astar(from, from), Some(vec![from, from]));
}

#[test]
fn objects_are_rasterised_grown_by_the_walker_radius() {
    let room = Room { name: "r".into(), width: 4.0, depth: 3.0, height: 2.5 };
    let o = PlacedObject {
        label: "box".into(),
        category: "box".into(),
        attributes: vec![],
        position: [2.0, 0.0, 1.5],
        yaw: std::f32::consts::FRAC_PI_4,
        size: [1.0, 1.0, 0.4],
        support: None,
        origin: Origin::Script { sentence: 0, node: 0 },
    };
    let g = Grid::from_objects(&room, std::slice::from_ref(&o), CELL, WALKER_RADIUS);
    assert_eq!((g.nx, g.nz), (40, 30));
    assert!(!g.is_free_at([2.0, 1.5]));
    // Along the box's turned width axis, 0.5 m + radius is blocked, 0.5 + radius + 0.15 free.
    let (c, s) = (std::f32::consts::FRAC_PI_4.cos(), std::f32::consts::FRAC_PI_4.sin());
    let at = |d: f32| [2.0 + d * c, 1.5 - d * s];
    assert!(!g.is_free_at(at(0.6)));
    assert!(g.is_free_at(at(0.85)));
    // Walls are grown too; a high object (a chandelier) does not block.
    assert!(!g.is_free_at([0.05, 1.5]) && g.is_free_at([0.35, 1.5]));
    let high = PlacedObject { position: [1.0, 2.0, 1.0], ..o };
    let g = Grid::from_objects(&room, &[high], CELL, WALKER_RADIUS);
    assert!(g.is_free_at([1.0, 1.0]));
    assert!(g.nearest_free([0.0, 0.0]).is_some());
}
