//! The single-source shortest path-finding baseline (SSPF, §5 and Fig. 3(a)): from the start
//! frame, always step to the nearest unvisited frame of the graph. Deterministic (ties go to the
//! lower index); stays inside the current shot while that shot has unvisited frames, like SDPF.

use crate::metric::Graph;

/// The SSPF order from `start`, at most `length` frames. `shots[i]` is frame i's shot (pass all
/// zeros, or `None`, to ignore scene cuts).
pub fn sspf(graph: &Graph, start: usize, length: usize, shots: Option<&[usize]>) -> Vec<usize> {
    let n = graph.n;
    if start >= n || length == 0 {
        return Vec::new();
    }
    let shot = |i: usize| shots.map_or(0, |s| s[i]);
    let mut visited = vec![false; n];
    let mut order = vec![start];
    visited[start] = true;
    while order.len() < length.min(n) {
        let current = *order.last().expect("order starts non-empty");
        let nearest = |same_shot: bool| {
            (0..n)
                .filter(|&j| !visited[j] && (!same_shot || shot(j) == shot(current)))
                .min_by(|&a, &b| graph.get(current, a).total_cmp(&graph.get(current, b)).then(a.cmp(&b)))
        };
        let Some(next) = nearest(true).or_else(|| nearest(false)) else { break };
        visited[next] = true;
        order.push(next);
    }
    order
}

#[cfg(test)]
mod tests {
    use super::*;

    fn line_graph(n: usize) -> Graph {
        Graph::from_fn(n, |i, j| (i as f32 - j as f32).abs())
    }

    #[test]
    fn on_a_line_it_walks_to_the_nearer_neighbour_then_sweeps() {
        let g = line_graph(6);
        // From 2: 1 and 3 tie at distance 1, the lower index wins; then 0, then the far side.
        assert_eq!(sspf(&g, 2, 6, None), vec![2, 1, 0, 3, 4, 5]);
        assert_eq!(sspf(&g, 0, 3, None), vec![0, 1, 2]);
    }

    #[test]
    fn it_visits_each_frame_once_and_stops_at_the_length() {
        let g = Graph::from_fn(9, |i, j| ((i * 7 + j * 3) % 11) as f32 + if i == j { 0.0 } else { 1.0 });
        let order = sspf(&g, 4, 20, None);
        assert_eq!(order.len(), 9);
        let mut sorted = order.clone();
        sorted.sort();
        assert_eq!(sorted, (0..9).collect::<Vec<_>>());
        assert_eq!(sspf(&g, 4, 5, None).len(), 5);
        assert!(sspf(&g, 9, 5, None).is_empty());
    }

    #[test]
    fn it_finishes_the_current_shot_before_crossing_a_cut() {
        let g = line_graph(6);
        let shots = [0, 0, 0, 1, 1, 1];
        // From 2 the nearest is 3 (other shot) and 1 (same shot) at the same distance; the shot wins.
        assert_eq!(sspf(&g, 2, 6, Some(&shots)), vec![2, 1, 0, 3, 4, 5]);
        let shots = [1, 0, 0, 0, 1, 1];
        assert_eq!(sspf(&g, 2, 6, Some(&shots)), vec![2, 1, 3, 4, 5, 0]);
    }
}
