use super::*;
use image::RgbImage;

/// A motion distance from a table.
struct Table {
    n: usize,
    d: Vec<f32>,
    floor: f32,
}

impl MotionDistance for Table {
    fn distance(&self, c: usize, k: usize) -> f32 {
        self.d[c * self.n + k]
    }
    fn rotated_floor(&self, _: usize) -> f32 {
        self.floor
    }
}

fn line_graph(n: usize) -> Graph {
    Graph::from_fn(n, |i, j| (i as f32 - j as f32).abs())
}

fn still(n: usize) -> MotionInfo {
    MotionInfo { tendency: vec![None; n], lms: vec![false; n], shot: vec![0; n] }
}

fn flat_motion(n: usize) -> Table {
    Table { n, d: vec![1.0; n * n], floor: 1.0 }
}

#[test]
fn eta_is_the_mean_off_diagonal_weight() {
    // 3 frames on a line: off-diagonal weights 1, 2, 1 (twice each) → mean 4/3.
    assert!((eta(&line_graph(3)) - 4.0 / 3.0).abs() < 1e-6);
    assert_eq!(eta(&line_graph(1)), 0.0);
}

#[test]
fn s1_keeps_unvisited_frames_closer_than_eta() {
    let g = line_graph(9); // η = mean |i − j| = 10/3 for n = 9
    let m = still(9);
    let mut visited = vec![false; 9];
    visited[3] = true;
    let s1 = content_candidates(&g, &m, &visited, 4, eta(&g), false);
    assert_eq!(s1, vec![1, 2, 5, 6, 7]);
}

#[test]
fn cd_keeps_lms_candidates_in_the_current_direction_only() {
    let mut m = still(5);
    m.lms = vec![true, true, true, false, true];
    m.tendency = vec![Some(0.0), Some(0.2), Some(3.0), Some(0.0), Some(-0.5)];
    let (kept, removed) = directional(&m, 0, &[1, 2, 3, 4], std::f32::consts::FRAC_PI_3);
    assert_eq!(kept, vec![1, 4]);
    assert_eq!(removed, vec![2, 3]);
    // The current frame not in an LMS: C_d does not apply.
    let (kept, removed) = directional(&m, 3, &[1, 2], std::f32::consts::FRAC_PI_3);
    assert_eq!((kept, removed), (vec![1, 2], vec![]));
}

#[test]
fn ct_keeps_candidates_at_most_the_mean_or_the_rotated_floor() {
    let n = 4;
    let mut d = vec![0.0; n * n];
    d[1] = 1.0;
    d[2] = 2.0;
    d[3] = 6.0;
    let t = Table { n, d, floor: 1.5 };
    let (kept, removed, omega) = coherent(&t, 0, &[1, 2, 3], 3);
    assert_eq!(omega, 3.0);
    assert_eq!(kept, vec![(1, 1.0), (2, 2.0)]);
    assert_eq!(removed, vec![3]);
    // n1 < 2: the floor of Eq. 17.
    let (kept, _, omega) = coherent(&t, 0, &[2], 1);
    assert_eq!(omega, 1.5);
    assert!(kept.is_empty());
}

#[test]
fn softmax_favours_small_motion_distances() {
    let p = softmax_of_distances(&[0.0, 1.0]);
    assert!((p[0] + p[1] - 1.0).abs() < 1e-6);
    assert!((p[0] / p[1] - std::f32::consts::E).abs() < 1e-4);
}

#[test]
fn walks_never_revisit_are_seeded_and_stop_early() {
    let n = 12;
    let g = line_graph(n);
    let m = still(n);
    let md = flat_motion(n);
    let p = SdpfParams::default();
    let a = sdpf(&g, &m, &md, 5, &p).unwrap();
    assert_eq!(a.frames[0], 5);
    let mut seen = a.frames.clone();
    seen.sort();
    seen.dedup();
    assert_eq!(seen.len(), a.frames.len(), "no frame twice: {:?}", a.frames);
    assert_eq!(a, sdpf(&g, &m, &md, 5, &p).unwrap(), "same seed, same path");
    assert_eq!(a.stop, StopReason::NoCandidate);
    assert!(a.transitions.last().unwrap().chosen.is_none());
    let others: Vec<Vec<usize>> = (2..8).map(|s| sdpf(&g, &m, &md, 5, &SdpfParams { seed: s, ..p.clone() }).unwrap().frames).collect();
    assert!(others.iter().any(|o| *o != a.frames), "seeds change the path");
    // Every step goes to a frame closer than η to the current one.
    let e = eta(&g);
    assert!(a.frames.windows(2).all(|w| g.get(w[0], w[1]) < e));
}

#[test]
fn target_length_cuts_and_bad_starts() {
    let n = 12;
    let g = line_graph(n);
    let md = flat_motion(n);
    let p = SdpfParams { length: Some(4), ..SdpfParams::default() };
    let a = sdpf(&g, &still(n), &md, 0, &p).unwrap();
    assert_eq!((a.frames.len(), a.stop), (4, StopReason::Length));
    // Two shots: frames 0..6 and 6..12; the walk from 2 stays in the first.
    let mut m = still(n);
    m.shot = (0..n).map(|i| usize::from(i >= 6)).collect();
    let g2 = Graph::from_fn(n, |i, j| 1.0 - 0.01 * ((i + j) % 7) as f32);
    let w = sdpf(&g2, &m, &md, 2, &SdpfParams::default()).unwrap();
    assert!(w.frames.iter().all(|&f| f < 6), "{:?}", w.frames);
    let across = sdpf(&g2, &m, &md, 2, &SdpfParams { allow_cuts: true, ..SdpfParams::default() }).unwrap();
    assert!(across.transitions[0].s1.iter().any(|&f| f >= 6), "cuts allowed: the other shot is a candidate");
    assert!(sdpf(&g, &still(n), &md, 12, &p).unwrap_err().to_string().contains("start frame 12"));
    assert!(sdpf(&g, &still(3), &md, 0, &p).is_err());
}

#[test]
fn loop_closure_ends_next_to_the_start() {
    let n = 16;
    let g = line_graph(n);
    let md = flat_motion(n);
    let p = SdpfParams { loop_close: true, ..SdpfParams::default() };
    let w = sdpf(&g, &still(n), &md, 8, &p).unwrap();
    assert!(w.closes_loop);
    let last = *w.frames.last().unwrap();
    assert!(g.get(last, 8) < eta(&g), "{:?}", w.frames);
}

#[test]
fn several_sequences_are_distinct() {
    let n = 14;
    let g = line_graph(n);
    let md = flat_motion(n);
    let paths = several(&g, &still(n), &md, 7, &SdpfParams::default(), 4).unwrap();
    assert_eq!(paths.len(), 4);
    for i in 0..paths.len() {
        for j in 0..i {
            assert_ne!(paths[i].frames, paths[j].frames);
        }
    }
    let text = explain(&paths[0]);
    assert!(text.contains("S1 (content, Eq. 8)") && text.contains("chose frame"));
}

fn solid(v: [u8; 3]) -> RgbImage {
    RgbImage::from_pixel(8, 8, image::Rgb(v))
}

#[test]
fn metrics_match_hand_values() {
    let frames = vec![solid([0, 0, 0]), solid([51, 51, 51]), solid([255, 255, 255])];
    assert!((stability_md(&frames, &[0, 1]) - 0.2).abs() < 1e-9);
    assert!((stability_md(&frames, &[0, 1, 2]) - 0.5).abs() < 1e-9);
    assert_eq!(stability_md(&frames, &[1]), 0.0);
    assert_eq!(overlap_delta_o(&[0, 1, 2], 3), 1.0);
    assert_eq!(overlap_delta_o(&[2, 0, 1], 3), 2.0 * 0.5 * 0.5 / 1.0);
    assert_eq!(overlap_delta_o(&[2, 1, 0], 3), 0.0);
}

#[test]
fn shots_split_at_a_hard_cut_only() {
    // Horizontal gradients drifting a little per frame (some pixels change histogram bins), then a
    // different palette.
    let gradient = |f: &dyn Fn(u32) -> [u8; 3]| RgbImage::from_fn(8, 8, |x, _| image::Rgb(f(x)));
    let mut frames: Vec<RgbImage> = (0..10).map(|i| gradient(&|x| [(x * 30 + i * 3) as u8, 90, 140])).collect();
    frames.extend((0..6).map(|i| gradient(&|x| [230, (x * 30 + i * 3) as u8, 20])));
    let shots = detect_shots(&frames);
    assert_eq!(&shots[..10], &[0; 10]);
    assert_eq!(&shots[10..], &[1; 6]);
    assert_eq!(detect_shots(&frames[..10]), vec![0; 10]);
    assert!(detect_shots(&[]).is_empty());
}
