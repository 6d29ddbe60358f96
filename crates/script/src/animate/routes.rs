//! Walks as the characters make them: the [`route`] on a character's grid, how the crowd repair
//! changes a walk ([`WalkChoice`]: wait, then a route), what was built ([`WalkInfo`]) and the
//! [`WalkCache`] of walks already made, as the optimiser re-animates many nearly equal scenes.

use std::collections::HashMap;

use inbetween_core::clip::Clip;

use crate::layout::grid::Grid;
use crate::motion::{walk_route, MotionLibrary, WalkParams};

/// How one walk of a timeline is made: wait `wait` frames in place first, then follow `route`
/// (None: the A* route on the character's grid).
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct WalkChoice {
    pub wait: usize,
    pub route: Option<Vec<[f32; 2]>>,
}

/// One walk as built: frames `[wait_start, walk_start)` wait, `[walk_start, end)` walk.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct WalkInfo {
    pub wait_start: usize,
    pub walk_start: usize,
    pub end: usize,
    /// The route walked (its first point is where the character stood).
    pub route: Vec<[f32; 2]>,
    pub params: WalkParams,
}

/// Walks already generated, by route and parameters (a disturbed scene often leaves a route as
/// it was).
#[derive(Default)]
pub(crate) struct WalkCache {
    walks: HashMap<Vec<u64>, Clip>,
}

impl WalkCache {
    pub fn walk(&mut self, route: &[[f32; 2]], lib: &MotionLibrary, p: &WalkParams) -> Clip {
        let mut key: Vec<u64> = route.iter().map(|q| ((q[0].to_bits() as u64) << 32) | q[1].to_bits() as u64).collect();
        key.push(p.speed.unwrap_or(-1.0).to_bits());
        key.push(p.initial_heading.unwrap_or(9.0).to_bits());
        key.push(p.final_heading.unwrap_or(9.0).to_bits());
        key.push(p.verb.bytes().fold(0u64, |h, b| h.wrapping_mul(131).wrapping_add(b as u64)));
        key.push(p.lock_feet as u64);
        if let Some(m) = self.walks.get(&key) {
            return m.clone();
        }
        let m = walk_route(route, lib, p);
        self.walks.insert(key, m.clone());
        m
    }
}

/// A walking route on `grid` from `from` to `to`: when an end lies on a blocked cell (next to a
/// seat, just stood up) the route goes through the nearest free cell.
pub(crate) fn route(grid: &Grid, from: [f32; 2], to: [f32; 2]) -> Option<Vec<[f32; 2]>> {
    let free = |p: [f32; 2]| if grid.is_free_at(p) { Some(p) } else { grid.nearest_free(p).map(|c| grid.center(c)) };
    let (s, g) = (free(from)?, free(to)?);
    let mut path = grid.astar(s, g)?;
    if s != from {
        path.insert(0, from);
    }
    if g != to {
        path.push(to);
    }
    Some(path)
}
