//! An occupancy grid over the room floor (metres, square cells) with footprints rasterised and
//! grown by a walker's radius, so "free" means a person can stand there. Layout uses its BFS to
//! keep every object's front reachable; part 2 uses [`Grid::astar`] for walking routes.

use std::cmp::Ordering;
use std::collections::{BinaryHeap, VecDeque};

use crate::scene::{PlacedObject, Room};

use super::geom;

/// Cell size layout uses, metres.
pub const CELL: f32 = 0.1;
/// Half the width of a walking person, metres: obstacles and walls are grown by this much.
pub const WALKER_RADIUS: f32 = 0.2;
/// Objects whose base is higher than this do not block walking (chandeliers, high shelves).
pub const HEADROOM: f32 = 1.9;
/// Objects whose top is lower than this are walked over (rugs, mats).
pub const FLAT: f32 = 0.05;

/// Whether an object is in a walker's way: neither hanging above head height nor flat.
pub fn blocks_walking(o: &PlacedObject) -> bool {
    o.position[1] < HEADROOM && o.top() >= FLAT
}

/// A grid of square cells covering x ∈ [0, width], z ∈ [0, depth]; cell (i, j) spans
/// x ∈ [i·cell, (i+1)·cell], z ∈ [j·cell, (j+1)·cell].
#[derive(Debug, Clone, PartialEq)]
pub struct Grid {
    pub cell: f32,
    pub nx: usize,
    pub nz: usize,
    blocked: Vec<bool>,
}

/// A cell index (i along x, j along z).
pub type Cell = (usize, usize);

impl Grid {
    /// An empty grid over a `width` × `depth` m floor with `cell`-metre cells (at least one cell).
    pub fn new(width: f32, depth: f32, cell: f32) -> Grid {
        let cell = if cell.is_finite() && cell > 1e-3 { cell } else { CELL };
        let n = |len: f32| ((len.max(0.0) / cell).ceil() as usize).clamp(1, 4096);
        let (nx, nz) = (n(width), n(depth));
        Grid { cell, nx, nz, blocked: vec![false; nx * nz] }
    }

    /// The room's floor with walls grown by `radius` (a walker's centre stays that far from walls)
    /// and every object in the way ([`blocks_walking`]) rasterised, grown by `radius`.
    pub fn from_objects(room: &Room, objects: &[PlacedObject], cell: f32, radius: f32) -> Grid {
        let mut g = Grid::new(room.width, room.depth, cell);
        g.block_walls(room.width, room.depth, radius);
        for o in objects.iter().filter(|o| blocks_walking(o)) {
            g.block_object(o, radius);
        }
        g
    }

    /// Centre of a cell, world (x, z).
    pub fn center(&self, (i, j): Cell) -> [f32; 2] {
        [(i as f32 + 0.5) * self.cell, (j as f32 + 0.5) * self.cell]
    }

    /// The cell holding world point (x, z), or None outside the grid.
    pub fn cell_of(&self, p: [f32; 2]) -> Option<Cell> {
        if !(p[0].is_finite() && p[1].is_finite()) || p[0] < 0.0 || p[1] < 0.0 {
            return None;
        }
        let (i, j) = ((p[0] / self.cell) as usize, (p[1] / self.cell) as usize);
        (i < self.nx && j < self.nz).then_some((i, j))
    }

    pub fn is_blocked(&self, (i, j): Cell) -> bool {
        self.blocked[j * self.nx + i]
    }

    pub fn set_blocked(&mut self, (i, j): Cell, blocked: bool) {
        self.blocked[j * self.nx + i] = blocked;
    }

    /// Whether a world point lies on a free cell.
    pub fn is_free_at(&self, p: [f32; 2]) -> bool {
        self.cell_of(p).is_some_and(|c| !self.is_blocked(c))
    }

    /// Blocks cells whose centre lies within `margin` of a wall of a `width` × `depth` room.
    pub fn block_walls(&mut self, width: f32, depth: f32, margin: f32) {
        for j in 0..self.nz {
            for i in 0..self.nx {
                let [x, z] = self.center((i, j));
                if x < margin || z < margin || x > width - margin || z > depth - margin {
                    self.set_blocked((i, j), true);
                }
            }
        }
    }

    /// Blocks cells whose centre lies within `grow` of the oriented rectangle at `center` with
    /// half extents `half` (its own width, depth) turned by `yaw`.
    pub fn block_rect(&mut self, center: [f32; 2], half: [f32; 2], yaw: f32, grow: f32) {
        let (s, c) = yaw.sin_cos();
        let ext = [half[0] * c.abs() + half[1] * s.abs() + grow, half[0] * s.abs() + half[1] * c.abs() + grow];
        let lo = |v: f32| ((v / self.cell).floor().max(0.0)) as usize;
        let (i0, j0) = (lo(center[0] - ext[0]), lo(center[1] - ext[1]));
        let i1 = (((center[0] + ext[0]) / self.cell).ceil().max(0.0) as usize).min(self.nx);
        let j1 = (((center[1] + ext[1]) / self.cell).ceil().max(0.0) as usize).min(self.nz);
        for j in j0..j1 {
            for i in i0..i1 {
                let l = geom::to_local(center, yaw, self.center((i, j)));
                let dx = (l[0].abs() - half[0]).max(0.0);
                let dz = (l[1].abs() - half[1]).max(0.0);
                if dx * dx + dz * dz < grow * grow || (dx == 0.0 && dz == 0.0) {
                    self.set_blocked((i, j), true);
                }
            }
        }
    }

    /// Blocks an object's footprint grown by `grow`.
    pub fn block_object(&mut self, o: &PlacedObject, grow: f32) {
        self.block_rect(geom::center(o), [o.size[0] / 2.0, o.size[2] / 2.0], o.yaw, grow);
    }

    /// The free cell nearest to `p` (by centre distance), or None when every cell is blocked.
    pub fn nearest_free(&self, p: [f32; 2]) -> Option<Cell> {
        let mut best: Option<(f32, Cell)> = None;
        for j in 0..self.nz {
            for i in 0..self.nx {
                if self.is_blocked((i, j)) {
                    continue;
                }
                let c = self.center((i, j));
                let d = (c[0] - p[0]).powi(2) + (c[1] - p[1]).powi(2);
                if best.is_none_or(|(b, _)| d < b) {
                    best = Some((d, (i, j)));
                }
            }
        }
        best.map(|(_, c)| c)
    }

    /// Neighbours a walker can step to: 8-connected, diagonals only when both side cells are free
    /// (no cutting corners), with the step length in cells.
    fn neighbours(&self, (i, j): Cell) -> impl Iterator<Item = (Cell, f32)> + '_ {
        const STEPS: [(i64, i64); 8] = [(1, 0), (-1, 0), (0, 1), (0, -1), (1, 1), (1, -1), (-1, 1), (-1, -1)];
        STEPS.iter().filter_map(move |&(di, dj)| {
            let (ni, nj) = (i as i64 + di, j as i64 + dj);
            if ni < 0 || nj < 0 || ni >= self.nx as i64 || nj >= self.nz as i64 {
                return None;
            }
            let n = (ni as usize, nj as usize);
            if self.is_blocked(n) {
                return None;
            }
            if di != 0 && dj != 0 && (self.is_blocked((ni as usize, j)) || self.is_blocked((i, nj as usize))) {
                return None;
            }
            Some((n, if di != 0 && dj != 0 { std::f32::consts::SQRT_2 } else { 1.0 }))
        })
    }

    /// Breadth-first flood from `start`: `reached[j * nx + i]` for every cell. A blocked start
    /// reaches nothing.
    pub fn reachable_from(&self, start: Cell) -> Vec<bool> {
        let mut seen = vec![false; self.nx * self.nz];
        if start.0 >= self.nx || start.1 >= self.nz || self.is_blocked(start) {
            return seen;
        }
        let mut queue = VecDeque::from([start]);
        seen[start.1 * self.nx + start.0] = true;
        while let Some(c) = queue.pop_front() {
            for (n, _) in self.neighbours(c) {
                let k = n.1 * self.nx + n.0;
                if !seen[k] {
                    seen[k] = true;
                    queue.push_back(n);
                }
            }
        }
        seen
    }

    /// Shortest walking route from `from` to `to` (world x, z) over free cells, 8-connected
    /// without cutting corners: `from`, the centres of the cells between, then `to`. None when
    /// either end is outside or blocked, or no route exists.
    pub fn astar(&self, from: [f32; 2], to: [f32; 2]) -> Option<Vec<[f32; 2]>> {
        let (s, g) = (self.cell_of(from)?, self.cell_of(to)?);
        if self.is_blocked(s) || self.is_blocked(g) {
            return None;
        }
        let idx = |c: Cell| c.1 * self.nx + c.0;
        let h = |c: Cell| {
            let (dx, dz) = ((c.0 as f32 - g.0 as f32).abs(), (c.1 as f32 - g.1 as f32).abs());
            dx.max(dz) + (std::f32::consts::SQRT_2 - 1.0) * dx.min(dz)
        };
        let mut cost = vec![f32::INFINITY; self.nx * self.nz];
        let mut came = vec![usize::MAX; self.nx * self.nz];
        let mut open = BinaryHeap::new();
        cost[idx(s)] = 0.0;
        open.push(Open { f: h(s), g: 0.0, cell: s });
        while let Some(Open { g: gc, cell, .. }) = open.pop() {
            if cell == g {
                break;
            }
            if gc > cost[idx(cell)] {
                continue;
            }
            for (n, step) in self.neighbours(cell) {
                let ng = gc + step;
                if ng < cost[idx(n)] {
                    cost[idx(n)] = ng;
                    came[idx(n)] = idx(cell);
                    open.push(Open { f: ng + h(n), g: ng, cell: n });
                }
            }
        }
        if !cost[idx(g)].is_finite() {
            return None;
        }
        let mut cells = vec![idx(g)];
        while let Some(&k) = cells.last() {
            if k == idx(s) {
                break;
            }
            cells.push(came[k]);
        }
        cells.reverse();
        let mut path = vec![from];
        let inner = cells.len().saturating_sub(1);
        path.extend(cells[1.min(inner)..inner].iter().map(|&k| self.center((k % self.nx, k / self.nx))));
        path.push(to);
        Some(path)
    }
}

/// An open-list entry, ordered so the max-heap pops the lowest f (ties: highest g, deeper first).
#[derive(Debug, Clone, Copy)]
struct Open {
    f: f32,
    g: f32,
    cell: Cell,
}

impl PartialEq for Open {
    fn eq(&self, o: &Self) -> bool {
        self.cmp(o) == Ordering::Equal
    }
}
impl Eq for Open {}
impl PartialOrd for Open {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Open {
    fn cmp(&self, o: &Self) -> Ordering {
        o.f.total_cmp(&self.f).then(self.g.total_cmp(&o.g)).then(o.cell.cmp(&self.cell))
    }
}
