//! The complete graph of §4.2: every pair of frames joined by the Euclidean distance of their
//! latent vectors (Eq. 7), and the plain pixel-distance graph used as a baseline for the ablations.

use image::RgbImage;
use rayon::prelude::*;

use super::input::frame_planes;
use super::loss::euclidean;

/// A complete graph on `n` frames: `dist[i · n + j]` is the edge weight `l_ij` (symmetric, zero
/// diagonal).
#[derive(Debug, Clone, PartialEq)]
pub struct Graph {
    pub n: usize,
    pub dist: Vec<f32>,
}

impl Graph {
    /// The graph of pairwise distances `d(i, j)` (computed once per unordered pair).
    pub fn from_fn(n: usize, d: impl Fn(usize, usize) -> f32 + Sync) -> Graph {
        let upper: Vec<Vec<f32>> = (0..n).into_par_iter().map(|i| (i + 1..n).map(|j| d(i, j)).collect()).collect();
        let mut dist = vec![0.0f32; n * n];
        for (i, row) in upper.iter().enumerate() {
            for (k, &v) in row.iter().enumerate() {
                let j = i + 1 + k;
                dist[i * n + j] = v;
                dist[j * n + i] = v;
            }
        }
        Graph { n, dist }
    }

    /// Edge weight between frames `i` and `j`.
    pub fn get(&self, i: usize, j: usize) -> f32 {
        self.dist[i * self.n + j]
    }

    /// Distances from frame `i` to every frame (its row).
    pub fn row(&self, i: usize) -> &[f32] {
        &self.dist[i * self.n..(i + 1) * self.n]
    }

    /// The other frames in order of distance from `i`, nearest first (ties by index).
    pub fn neighbours(&self, i: usize) -> Vec<usize> {
        let row = self.row(i);
        let mut order: Vec<usize> = (0..self.n).filter(|&j| j != i).collect();
        order.sort_by(|&a, &b| row[a].total_cmp(&row[b]).then(a.cmp(&b)));
        order
    }

    /// Share of frames whose nearest other frame lies within `±window` source frames.
    pub fn nearest_within(&self, window: usize) -> f64 {
        if self.n < 2 {
            return 0.0;
        }
        let hits =
            (0..self.n).filter(|&i| self.neighbours(i).first().is_some_and(|&j| j.abs_diff(i) <= window)).count();
        hits as f64 / self.n as f64
    }
}

/// Eq. 7: `l_ij = ‖R(x_i) − R(x_j)‖` for latent vectors `R(x_i)`.
pub fn graph_from_embeddings(e: &[Vec<f32>]) -> Graph {
    Graph::from_fn(e.len(), |i, j| euclidean(&e[i], &e[j]) as f32)
}

/// Baseline graph: Euclidean distance of the frames area-downscaled to `side × side` RGB in [0, 1]
/// (no learned metric; for the ablations).
pub fn pixel_graph(frames: &[RgbImage], side: u32) -> Graph {
    let planes: Vec<Vec<f32>> = frames.par_iter().map(|f| frame_planes(f, side as usize)).collect();
    graph_from_embeddings(&planes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn graph_is_symmetric_with_zero_diagonal() {
        let e = vec![vec![0.0, 0.0], vec![3.0, 4.0], vec![0.0, 1.0]];
        let g = graph_from_embeddings(&e);
        assert_eq!(g.n, 3);
        assert_eq!(g.dist.len(), 9);
        assert_eq!(g.get(0, 1), 5.0);
        assert_eq!(g.get(1, 0), 5.0);
        assert_eq!(g.get(0, 2), 1.0);
        assert!((0..3).all(|i| g.get(i, i) == 0.0));
        assert_eq!(g.neighbours(0), vec![2, 1]);
        // Nearest of 0 is 2 (|Δ| 2), of 1 is 2 (|Δ| 1), of 2 is 0 (|Δ| 2).
        assert_eq!(g.nearest_within(1), 1.0 / 3.0);
        assert_eq!(g.nearest_within(2), 1.0);
    }

    #[test]
    fn pixel_graph_measures_downscaled_rgb() {
        let black = RgbImage::new(8, 8);
        let white = RgbImage::from_pixel(8, 8, image::Rgb([255, 255, 255]));
        let g = pixel_graph(&[black.clone(), white, black], 2);
        // 2×2×3 = 12 values differing by 1 → √12.
        assert!((g.get(0, 1) - 12f32.sqrt()).abs() < 1e-6);
        assert_eq!(g.get(0, 2), 0.0);
    }
}
