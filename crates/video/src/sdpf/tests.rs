//! Algorithm 1 on small hand-made graphs with known answers, the extras (shots, length, loop,
//! several), the scene-cut detector on a synthetic clip with a hard cut, and the metrics by hand.

use std::cell::Cell;
use std::f32::consts::{FRAC_PI_3, TAU};

use image::{Rgb, RgbImage};

use super::distill::Ctx;
use super::*;
use crate::metric::Graph;

/// Frames on a line: `e_ij = |i − j|`.
fn line_graph(n: usize) -> Graph {
    Graph::from_fn(n, |i, j| (i as f32 - j as f32).abs())
}

/// Frame 0 close (1) to every other frame, which are far (10) from each other.
fn star_graph(n: usize) -> Graph {
    Graph::from_fn(n, |i, j| if i == 0 || j == 0 { 1.0 } else { 10.0 })
}

/// Motion distances: `from_zero[k]` for 0 → k, 0 elsewhere; one floor for every frame.
fn motion_from_zero(from_zero: &[f32], floor: f32) -> MatrixMotion {
    let n = from_zero.len();
    let mut dist = vec![0.0; n * n];
    dist[..n].copy_from_slice(from_zero);
    MatrixMotion { n, dist, floor: vec![floor; n] }
}

fn step_from(
    graph: &Graph,
    motion: &MotionInfo,
    md: &dyn MotionDistance,
    p: &SdpfParams,
    from: usize,
    visited: &[usize],
) -> Transition {
    let ctx = Ctx::new(graph, motion, md, p);
    let mut v = vec![false; graph.n];
    visited.iter().chain([&from]).for_each(|&f| v[f] = true);
    ctx.step(from, &v)
}

fn no_repeats(frames: &[usize]) -> bool {
    let mut s = frames.to_vec();
    s.sort_unstable();
    s.dedup();
    s.len() == frames.len()
}

#[test]
fn eta_is_the_mean_of_the_off_diagonal_edges() {
    // 3 frames on a line: off-diagonal weights 1, 2, 1 (each twice) → 4/3 (not 8/3 = Σ/N).
    assert!((eta(&line_graph(3)) - 4.0 / 3.0).abs() < 1e-6);
    assert!(eta(&line_graph(1)).is_nan(), "one frame: no edge");
    let g = Graph { n: 2, dist: vec![0.0, f32::NAN, 2.0, 0.0] };
    assert_eq!(eta(&g), 2.0, "non-finite weights are skipped");
}

#[test]
fn s1_holds_the_unvisited_frames_strictly_below_eta() {
    let g = line_graph(9); // η = mean |i − j| over i ≠ j = 10/3
    let t = step_from(&g, &MotionInfo::none(), &NoMotion, &SdpfParams::paper_walk().paper_choice(), 4, &[3]);
    assert_eq!(t.s1, vec![1, 2, 5, 6, 7], "|4 − k| < 10/3, frames 3 and 4 visited");
    // Without motion differences every S1 frame survives, with equal probabilities (§5.1).
    assert_eq!(t.s2(), t.s1);
    assert!(t.probs.iter().all(|&(_, p)| (p - 0.2).abs() < 1e-6));
    assert!(t.candidates.iter().all(|c| c.edge < 10.0 / 3.0));
}

/// Six frames around frame 0, with LMS flags and tendencies chosen for C_d.
fn cd_scene() -> (Graph, MotionInfo) {
    let motion = MotionInfo {
        // 0: LMS heading 0 rad; 1: LMS 0.2 (kept); 2: LMS 3.0 (reversed, removed); 3: not LMS
        // (removed); 4: LMS −0.5 (29°, kept); 5: LMS 2π − 0.3 (17° once wrapped, kept).
        tendency: vec![Some(0.0), Some(0.2), Some(3.0), Some(0.0), Some(-0.5), Some(TAU - 0.3)],
        lms: vec![true, true, true, false, true, true],
        ..MotionInfo::none()
    };
    (star_graph(6), motion)
}

#[test]
fn cd_keeps_only_lms_candidates_heading_within_xi() {
    let (g, m) = cd_scene();
    let t = step_from(&g, &m, &NoMotion, &SdpfParams::paper_walk(), 0, &[]);
    assert_eq!(t.s1, vec![1, 2, 3, 4, 5]);
    assert_eq!(t.cd, CdState::Active { tendency: 0.0, xi: FRAC_PI_3 });
    assert_eq!(t.removed_cd, vec![2, 3]);
    assert_eq!(t.s2(), vec![1, 4, 5]);
    // An LMS candidate whose tendency is unknown or NaN cannot be checked: removed.
    let mut m2 = m.clone();
    m2.tendency[4] = Some(f32::NAN);
    m2.tendency[5] = None;
    assert_eq!(step_from(&g, &m2, &NoMotion, &SdpfParams::paper_walk(), 0, &[]).removed_cd, vec![2, 3, 4, 5]);
}

#[test]
fn cd_is_skipped_unless_both_sides_are_lms() {
    let (g, m) = cd_scene();
    let mut not_lms = m.clone();
    not_lms.lms[0] = false;
    let t = step_from(&g, &not_lms, &NoMotion, &SdpfParams::paper_walk(), 0, &[]);
    assert_eq!((t.cd, t.removed_cd.len(), t.s2().len()), (CdState::NotLms, 0, 5));
    let mut lone = m.clone();
    lone.lms = vec![true, false, false, false, false, false];
    let t = step_from(&g, &lone, &NoMotion, &SdpfParams::paper_walk(), 0, &[]);
    assert_eq!((t.cd, t.s2().len()), (CdState::NoLmsCandidate, 5));
    let off = SdpfParams { use_cd: false, ..SdpfParams::paper_walk() };
    let t = step_from(&g, &m, &NoMotion, &off, 0, &[]);
    assert_eq!((t.cd, t.s2().len()), (CdState::Disabled, 5));
    // NaN tendency on the current frame: no direction to compare, C_d skipped (no panic).
    let mut nan = m;
    nan.tendency[0] = Some(f32::NAN);
    assert_eq!(step_from(&g, &nan, &NoMotion, &SdpfParams::paper_walk(), 0, &[]).cd, CdState::NotLms);
}

#[test]
fn ct_keeps_the_candidates_at_most_the_mean_motion_distance_of_s1() {
    let g = star_graph(4);
    let md = motion_from_zero(&[0.0, 1.0, 2.0, 6.0], 100.0);
    let t = step_from(&g, &MotionInfo::none(), &md, &SdpfParams::paper_walk().paper_choice(), 0, &[]);
    assert_eq!(t.omega, Omega::Mean(3.0), "n1 = 3 ≥ 2: ω is the mean of 1, 2, 6");
    assert_eq!(t.removed_ct, vec![3], "the least smooth candidate goes (the floor is not used)");
    // Eq. 20: Ω ∝ exp(−distance), so frame 1 is e times as likely as frame 2.
    assert!((t.prob_of(1) / t.prob_of(2) - std::f32::consts::E).abs() < 1e-4);
    let off = SdpfParams { use_ct: false, ..SdpfParams::paper_walk() };
    let t = step_from(&g, &MotionInfo::none(), &md, &off, 0, &[]);
    assert_eq!((t.omega, t.s2()), (Omega::Off, vec![1, 2, 3]));
}

#[test]
fn the_default_choice_is_relative_to_omega_and_weighs_content() {
    // From 0 on a line of 6: S1 = {1, 2} (η = 7/3), edges 1 and 2 (ē = 1.5); motion distances 4
    // and 2 (ω = 3).
    let g = line_graph(6);
    let md = motion_from_zero(&[0.0, 4.0, 2.0, 0.0, 0.0, 0.0], 100.0);
    let p = SdpfParams { use_ct: false, ..SdpfParams::paper_walk() };
    let t = step_from(&g, &MotionInfo::none(), &md, &p, 0, &[]);
    assert_eq!(t.s2(), vec![1, 2]);
    // Ω_1/Ω_2 = exp(−((4 − 2)/ω + λ(1 − 2)/ē)/τ) with ω = 3, ē = 1.5, λ = 2, τ = 0.1.
    let expected = (-((4.0f32 - 2.0) / 3.0 + 2.0 * (1.0 - 2.0) / 1.5) / 0.1).exp();
    assert!((t.prob_of(1) / t.prob_of(2) / expected - 1.0).abs() < 1e-3, "{:?} vs {expected}", t.probs);
    // Scaling every motion distance leaves the relative choice unchanged.
    let md10 = MatrixMotion { dist: md.dist.iter().map(|d| d * 10.0).collect(), ..md.clone() };
    let t10 = step_from(&g, &MotionInfo::none(), &md10, &p, 0, &[]);
    assert!((t10.prob_of(1) - t.prob_of(1)).abs() < 1e-6);
    // Without the content term, the smoother motion (frame 2) wins.
    let motion_only = SdpfParams { content_weight: 0.0, ..p };
    let t = step_from(&g, &MotionInfo::none(), &md, &motion_only, 0, &[]);
    assert!(t.prob_of(2) > 0.99, "{:?}", t.probs);
}

#[test]
fn ct_uses_the_rotated_flow_floor_when_s1_has_one_frame_and_stops_early_on_an_empty_s2() {
    // From 0 only frame 1 is under η = (1 + 10 + 10) / 3 = 7.
    let g = Graph::from_fn(3, |i, j| if i.min(j) == 0 && i.max(j) == 1 { 1.0 } else { 10.0 });
    let rough = motion_from_zero(&[0.0, 2.0, 0.0], 1.5);
    let p = sdpf(&g, &MotionInfo::none(), &rough, 0, &SdpfParams::paper_walk()).unwrap();
    assert_eq!(p.frames, vec![0]);
    assert_eq!(p.stop, StopReason::EarlyStop);
    let t = &p.transitions[0];
    assert_eq!((t.s1.clone(), t.omega, t.removed_ct.clone(), t.chosen), (vec![1], Omega::Rotated(1.5), vec![1], None));
    // A candidate no farther than the floor passes; the next step has nothing under η and stops.
    let smooth = motion_from_zero(&[0.0, 1.0, 0.0], 1.5);
    let p = sdpf(&g, &MotionInfo::none(), &smooth, 0, &SdpfParams::paper_walk()).unwrap();
    assert_eq!((p.frames.clone(), p.stop), (vec![0, 1], StopReason::EarlyStop));
    assert!(p.transitions[1].s1.is_empty());
}

#[test]
fn s2_is_what_passes_both_constraints_and_each_verdict_is_recorded() {
    let (g, m) = cd_scene();
    // C_d removes 2 and 3 first; C_t judges 1, 4, 5: ω = (1 + 9 + 3) / 3 = 4.33.
    let md = motion_from_zero(&[0.0, 1.0, 1.0, 1.0, 9.0, 3.0], 0.0);
    let t = step_from(&g, &m, &md, &SdpfParams::paper_walk(), 0, &[]);
    assert_eq!(t.removed_cd, vec![2, 3]);
    assert_eq!(t.removed_ct, vec![4]);
    assert_eq!(t.s2(), vec![1, 5]);
    assert!((t.probs.iter().map(|p| p.1).sum::<f32>() - 1.0).abs() < 1e-6);
}

#[test]
fn degenerate_graphs_stop_without_panicking() {
    let one = sdpf(&line_graph(1), &MotionInfo::none(), &NoMotion, 0, &SdpfParams::paper_walk()).unwrap();
    assert_eq!((one.frames.clone(), one.stop), (vec![0], StopReason::AllVisited));
    // All distances equal: nothing is strictly under the mean, S1 is empty.
    let flat = Graph::from_fn(5, |_, _| 1.0);
    let p = sdpf(&flat, &MotionInfo::none(), &NoMotion, 2, &SdpfParams::paper_walk()).unwrap();
    assert_eq!((p.frames.clone(), p.stop), (vec![2], StopReason::EarlyStop));
    // NaN motion distances and tendencies everywhere: C_t cannot vouch for anyone, early stop.
    let nan_md = MatrixMotion { n: 6, dist: vec![f32::NAN; 36], floor: vec![f32::NAN; 6] };
    let nan_m = MotionInfo { tendency: vec![Some(f32::NAN); 6], lms: vec![true; 6], ..MotionInfo::none() };
    let p = sdpf(&line_graph(6), &nan_m, &nan_md, 0, &SdpfParams::paper_walk()).unwrap();
    assert_eq!(p.stop, StopReason::EarlyStop);
    // Without C_t the softmax over NaN distances is uniform and the walk goes on.
    let p =
        sdpf(&line_graph(6), &nan_m, &nan_md, 0, &SdpfParams { use_ct: false, ..SdpfParams::paper_walk() }).unwrap();
    assert!(p.len() > 1 && no_repeats(&p.frames));
}

#[test]
fn walks_never_revisit_and_only_take_s2_frames() {
    let g = line_graph(20);
    for seed in 0..10 {
        let p = sdpf(&g, &MotionInfo::none(), &NoMotion, 7, &SdpfParams { seed, ..SdpfParams::paper_walk() }).unwrap();
        assert_eq!(p.frames[0], 7);
        assert!(no_repeats(&p.frames), "{:?}", p.frames);
        for (t, w) in p.transitions.iter().zip(p.frames.windows(2)) {
            assert_eq!((t.from, t.chosen), (w[0], Some(w[1])));
            assert!(t.prob_of(w[1]) > 0.0 && g.get(w[0], w[1]) < p.eta);
        }
        assert_ne!(p.stop, StopReason::TargetLength);
    }
}

#[test]
fn the_seed_alone_decides_the_path() {
    let g = line_graph(20);
    let run = |seed| {
        sdpf(&g, &MotionInfo::none(), &NoMotion, 10, &SdpfParams { seed, ..SdpfParams::paper_walk() }.paper_choice())
            .unwrap()
    };
    assert_eq!(run(3), run(3));
    let mut distinct: Vec<Vec<usize>> = (0..8).map(|s| run(s).frames).collect();
    distinct.sort();
    distinct.dedup();
    assert!(distinct.len() >= 4, "8 seeds gave only {} paths", distinct.len());
}

/// Two shots of six frames; every pair at about the same distance, so shots are the only barrier.
fn two_shots() -> (Graph, MotionInfo) {
    let g = Graph::from_fn(12, |i, j| 1.0 - 0.01 * ((i + j) % 7) as f32);
    let m = MotionInfo::with_cuts(vec![], vec![], &(0..12).map(|i| i == 6).collect::<Vec<_>>());
    (g, m)
}

#[test]
fn walks_stay_in_their_shot_unless_cuts_are_allowed() {
    let (g, m) = two_shots();
    assert_eq!(m.shot, [vec![0; 6], vec![1; 6]].concat());
    for seed in 0..6 {
        let p = sdpf(&g, &m, &NoMotion, 2, &SdpfParams { seed, ..SdpfParams::paper_walk() }).unwrap();
        assert!(p.frames.iter().all(|&f| f < 6), "{:?}", p.frames);
        assert!(p.transitions.iter().all(|t| t.removed_cut.iter().all(|&f| f >= 6)));
    }
    let first = sdpf(&g, &m, &NoMotion, 2, &SdpfParams::paper_walk()).unwrap();
    assert!(!first.transitions[0].removed_cut.is_empty(), "frames of the other shot were under η");
    let across = sdpf(&g, &m, &NoMotion, 2, &SdpfParams { allow_cuts: true, ..SdpfParams::paper_walk() }).unwrap();
    assert!(across.transitions[0].s1.iter().any(|&f| f >= 6));
    assert!(across.transitions[0].removed_cut.is_empty());
}

#[test]
fn a_target_length_is_met_or_the_longest_attempt_kept() {
    let g = line_graph(12);
    for seed in 0..6 {
        let p = sdpf(
            &g,
            &MotionInfo::none(),
            &NoMotion,
            5,
            &SdpfParams { length: Some(6), seed, ..SdpfParams::paper_walk() },
        )
        .unwrap();
        assert_eq!((p.len(), p.stop), (6, StopReason::TargetLength));
        assert_eq!(p.transitions.len(), 5);
    }
    let one = sdpf(&g, &MotionInfo::none(), &NoMotion, 5, &SdpfParams { length: Some(1), ..SdpfParams::paper_walk() })
        .unwrap();
    assert_eq!((one.frames.clone(), one.transitions.len()), (vec![5], 0));
    // Unreachable target: every attempt runs and the longest walk comes back.
    let p = SdpfParams { length: Some(50), attempts: 5, ..SdpfParams::paper_walk() };
    let long = sdpf(&g, &MotionInfo::none(), &NoMotion, 5, &p).unwrap();
    let longest = (0..5)
        .map(|a| {
            let seed = if a == 0 { 0 } else { inbetween_core::seed::derive(0, a) };
            sdpf(&g, &MotionInfo::none(), &NoMotion, 5, &SdpfParams { seed, length: None, attempts: 1, ..p.clone() })
                .unwrap()
                .len()
        })
        .max()
        .unwrap();
    assert_eq!(long.len(), longest);
    assert_ne!(long.stop, StopReason::TargetLength);
}

#[test]
fn loop_closure_ends_on_a_frame_that_steps_back_to_the_start() {
    let g = line_graph(16);
    for seed in 0..4 {
        let p = sdpf(
            &g,
            &MotionInfo::none(),
            &NoMotion,
            8,
            &SdpfParams { loop_close: true, seed, ..SdpfParams::paper_walk() },
        )
        .unwrap();
        assert!(p.closes_loop && p.len() >= 3, "{:?}", p.frames);
        assert_eq!(p.stop, StopReason::LoopClosed);
        let closing = p.closing.as_ref().unwrap();
        assert_eq!((closing.from, closing.chosen), (*p.frames.last().unwrap(), Some(8)));
        assert!(closing.prob_of(8) > 0.0 && g.get(closing.from, 8) < p.eta);
        assert_eq!(p.transitions.len(), p.len() - 1);
    }
    // With a target length: a loop of exactly that many frames.
    let p = sdpf(
        &g,
        &MotionInfo::none(),
        &NoMotion,
        8,
        &SdpfParams { loop_close: true, length: Some(6), ..SdpfParams::paper_walk() },
    )
    .unwrap();
    assert_eq!((p.len(), p.closes_loop), (6, true));
}

#[test]
fn loop_closure_reports_failure_on_a_chain() {
    // 0 – 1 – 2 – 3: only neighbours are under η = 5.5, so no prefix of ≥ 3 frames can return to 0.
    let g = Graph::from_fn(4, |i, j| if i.abs_diff(j) == 1 { 1.0 } else { 10.0 });
    let p = sdpf(&g, &MotionInfo::none(), &NoMotion, 0, &SdpfParams { loop_close: true, ..SdpfParams::paper_walk() })
        .unwrap();
    assert_eq!(p.frames, vec![0, 1, 2, 3]);
    assert!(!p.closes_loop && p.closing.is_none());
    assert_eq!(p.stop, StopReason::AllVisited);
}

#[test]
fn several_sequences_are_distinct_and_the_first_is_sdpf() {
    let g = line_graph(14);
    let p = SdpfParams { seed: 9, ..SdpfParams::paper_walk() }.paper_choice();
    let paths = several(&g, &MotionInfo::none(), &NoMotion, 7, &p, 4).unwrap();
    assert_eq!(paths.len(), 4);
    for i in 0..paths.len() {
        assert_eq!(paths[i].frames[0], 7);
        for j in 0..i {
            assert_ne!(paths[i].frames, paths[j].frames);
        }
    }
    assert_eq!(paths[0], sdpf(&g, &MotionInfo::none(), &NoMotion, 7, &p).unwrap());
    // A chain has one path only: fewer than asked, no duplicates.
    let chain = Graph::from_fn(4, |i, j| if i.abs_diff(j) == 1 { 1.0 } else { 10.0 });
    assert_eq!(several(&chain, &MotionInfo::none(), &NoMotion, 0, &p, 3).unwrap().len(), 1);
}

/// Counts the pairs asked for, to check that a whole call asks for each pair once.
struct Counting {
    calls: Cell<usize>,
}

impl MotionDistance for Counting {
    fn distance(&self, c: usize, k: usize) -> f32 {
        self.calls.set(self.calls.get() + 1);
        (c as f32 - k as f32).abs() * 0.1
    }
    fn rotated_floor(&self, _c: usize) -> f32 {
        1.0
    }
}

#[test]
fn motion_distances_are_asked_once_per_pair() {
    let g = line_graph(16);
    let md = Counting { calls: Cell::new(0) };
    let p = SdpfParams { loop_close: true, length: Some(10), attempts: 8, ..SdpfParams::paper_walk() };
    let paths = several(&g, &MotionInfo::none(), &md, 8, &p, 3).unwrap();
    assert!(!paths.is_empty());
    assert!(md.calls.get() <= 16 * 15, "{} calls for 240 pairs", md.calls.get());
}

#[test]
fn bad_inputs_are_clear_errors() {
    let g = line_graph(12);
    let p = SdpfParams::paper_walk();
    let e = sdpf(&g, &MotionInfo::none(), &NoMotion, 12, &p).unwrap_err().to_string();
    assert!(e.contains("start frame 12") && e.contains("12 frames"), "{e}");
    let short = MotionInfo { lms: vec![false; 3], ..MotionInfo::none() };
    assert!(sdpf(&g, &short, &NoMotion, 0, &p).unwrap_err().to_string().contains("lms has 3 entries"));
    assert!(sdpf(&Graph { n: 3, dist: vec![0.0; 4] }, &MotionInfo::none(), &NoMotion, 0, &p).is_err());
    assert!(sdpf(&Graph { n: 0, dist: vec![] }, &MotionInfo::none(), &NoMotion, 0, &p).is_err());
    let hot = SdpfParams { temperature: 0.0, ..SdpfParams::paper_walk() };
    assert!(several(&g, &MotionInfo::none(), &NoMotion, 0, &hot, 2).is_err());
}

#[test]
fn softmax_is_eq_20_and_survives_non_finite_distances() {
    let p = softmax(&[0.0, 1.0], 1.0);
    assert!((p[0] / p[1] - std::f32::consts::E).abs() < 1e-4 && (p[0] + p[1] - 1.0).abs() < 1e-6);
    let p = softmax(&[1000.0, 1001.0], 1.0);
    assert!(p.iter().all(|x| x.is_finite()), "large distances must not underflow to 0/0");
    let p = softmax(&[0.0, 2.0], 2.0);
    assert!((p[0] / p[1] - std::f32::consts::E).abs() < 1e-4, "temperature 2 halves the gap");
    assert_eq!(softmax(&[1.0, f32::NAN], 1.0), vec![1.0, 0.0]);
    assert_eq!(softmax(&[f32::NAN, f32::INFINITY], 1.0), vec![0.5, 0.5]);
}

#[test]
fn explain_names_the_candidates_the_removals_and_the_choice() {
    let (g, m) = cd_scene();
    let md = motion_from_zero(&[0.0, 1.0, 1.0, 1.0, 9.0, 3.0], 0.0);
    let p = sdpf(&g, &m, &md, 0, &SdpfParams::paper_walk()).unwrap();
    let text = explain(&p);
    assert!(text.contains("from frame 0"), "{text}");
    assert!(text.contains("S1 (content, Eq. 8) = frames with e < η, n1 = 5"), "{text}");
    assert!(text.contains("T_c = 0°, keeps LMS frames within ξ = 60°; removed 2 3"), "{text}");
    assert!(text.contains("ω = 4.3333 (mean over what C_r and C_d left); removed 4"), "{text}");
    assert!(text.contains(&format!("chose {}", p.frames[1])), "{text}");
    assert!(text.contains("no candidate left"), "the star's leaves are far apart: {text}");
}

// --- reverse distillation C_r, lengths, cuts and loop backs (beyond the paper) ------------------

#[test]
fn cr_removes_steps_back_to_the_previous_frames_and_to_the_past() {
    // From 6 on a line of 12: η = 13/3, S1 = 2..=10 without 6.
    let g = line_graph(12);
    let t = step_from(&g, &MotionInfo::none(), &NoMotion, &SdpfParams::default(), 6, &[]);
    assert_eq!(t.s1, vec![2, 3, 4, 5, 7, 8, 9, 10]);
    assert_eq!(t.cr, CrState::Active);
    // 3, 4, 5 replay the source backwards; 2 is closer to 5 (the past) than to 7 (the future).
    assert_eq!(t.removed_cr, vec![2, 3, 4, 5]);
    assert!(t.s2().iter().all(|&k| k > 6), "{:?}", t.s2());
    // Removed frames need no motion distance (NaN), the others have one.
    assert!(t.candidates.iter().all(|c| c.motion.is_nan() == (c.frame < 6)));
    // Ablation: off. --allow-reverse acts on undirected shots only.
    let off = SdpfParams { use_cr: false, ..SdpfParams::default() };
    let t = step_from(&g, &MotionInfo::none(), &NoMotion, &off, 6, &[]);
    assert_eq!((t.cr, t.removed_cr.len()), (CrState::Disabled, 0));
    let allow = SdpfParams { allow_reverse: true, ..SdpfParams::default() };
    let undirected = MotionInfo { directed: vec![false], ..MotionInfo::none() };
    let t = step_from(&g, &undirected, &NoMotion, &allow, 6, &[]);
    assert_eq!((t.cr, t.removed_cr.len()), (CrState::AllowedUndirected, 0));
    let directed = MotionInfo { directed: vec![true], ..MotionInfo::none() };
    assert_eq!(step_from(&g, &directed, &NoMotion, &allow, 6, &[]).removed_cr, vec![2, 3, 4, 5]);
    // Without --allow-reverse an undirected shot keeps C_r too.
    assert_eq!(step_from(&g, &undirected, &NoMotion, &SdpfParams::default(), 6, &[]).removed_cr, vec![2, 3, 4, 5]);
}

#[test]
fn the_default_length_is_the_source_s_and_a_dead_end_loops_back_without_a_backward_step() {
    let g = line_graph(10);
    for seed in 0..8 {
        let p = sdpf(&g, &MotionInfo::none(), &NoMotion, 0, &SdpfParams { seed, ..SdpfParams::default() }).unwrap();
        assert_eq!((p.len(), p.stop), (10, StopReason::TargetLength), "{:?}", p.frames);
        assert_eq!(backward_steps(&p.frames, 3), 0, "{:?}", p.frames);
        let loops = p.loop_positions();
        if no_repeats(&p.frames) {
            assert!(loops.is_empty());
            assert!(p.frames.windows(2).all(|w| w[1] > w[0]), "{:?}", p.frames);
        } else {
            // A loop back, then the loop's frames repeat: every step except the loop back goes forward.
            assert_eq!(loops.len(), 1, "{:?}", p.frames);
            let StepKind::LoopBack { to, .. } = p.transitions.last().unwrap().kind else { panic!("no loop back") };
            assert_eq!(p.frames[loops[0]], p.frames[to]);
            assert!(p.transitions.len() - to >= super::distill::MIN_LOOP, "the loop has at least 4 frames");
        }
        let text = explain(&p);
        assert!(loops.is_empty() || text.contains("LOOP back to position"), "{text}");
    }
    // The paper's early stop ends at the first dead end, short of the source's length.
    let p =
        sdpf(&g, &MotionInfo::none(), &NoMotion, 0, &SdpfParams { stop_early: true, ..SdpfParams::default() }).unwrap();
    assert!(p.stop == StopReason::EarlyStop || p.len() == 10);
    assert!(p.frames.windows(2).all(|w| w[1] > w[0]));
}

#[test]
fn a_run_of_the_source_length_cuts_to_the_other_shot_at_a_dead_end() {
    // Two shots of six frames on one line: 0..6 and 6..12, the second a scene cut away.
    let g = line_graph(12);
    let m = MotionInfo::with_cuts(vec![], vec![], &(0..12).map(|i| i == 6).collect::<Vec<_>>());
    for seed in 0..6 {
        let p = sdpf(&g, &m, &NoMotion, 1, &SdpfParams { seed, ..SdpfParams::default() }).unwrap();
        assert_eq!(p.len(), 12, "{:?}", p.frames);
        let cuts = p.cut_positions();
        assert!(!cuts.is_empty(), "{:?}", p.frames);
        for &c in &cuts {
            assert_ne!(m.shot_of(p.frames[c - 1]), m.shot_of(p.frames[c]), "{:?} at {c}", p.frames);
        }
        assert!(p.frames.iter().any(|&f| f >= 6) && p.frames.iter().any(|&f| f < 6));
        assert_eq!(backward_steps(&p.frames, 3), 0, "{:?}", p.frames);
        assert!(explain(&p).contains("CUT to another shot"));
    }
}

#[test]
fn zero_lengths_are_refused_and_shots_are_judged_by_their_lms_share() {
    let e = sdpf(
        &line_graph(5),
        &MotionInfo::none(),
        &NoMotion,
        0,
        &SdpfParams { length: Some(0), ..SdpfParams::default() },
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("length of 0 frames"), "{e}");
    // Shot 0: 3 of 4 frames LMS (directed); shot 1: 1 of 4 (undirected).
    let lms = [true, true, true, false, false, true, false, false];
    let judged = judge_directed(&lms, &[0, 0, 0, 0, 1, 1, 1, 1]);
    assert_eq!(judged, vec![(true, 0.75), (false, 0.25)]);
    assert_eq!(judge_directed(&[], &[]), vec![(false, 0.0)]);
    assert_eq!(backward_positions(&[5, 4, 8, 5, 9, 1], 3), vec![1, 3]);
}

// --- scene cuts -------------------------------------------------------------------------------

/// 12 frames of a white square sliding over dark blue, then 8 of a green disc on orange.
fn clip_with_a_cut() -> Vec<RgbImage> {
    let square = |t: u32| {
        RgbImage::from_fn(48, 32, |x, y| {
            if (4 + 2 * t..12 + 2 * t).contains(&x) && (10..18).contains(&y) {
                Rgb([240, 240, 240])
            } else {
                Rgb([20, 30, 110])
            }
        })
    };
    let disc = |t: u32| {
        RgbImage::from_fn(48, 32, |x, y| {
            let (dx, dy) = (x as i32 - 10 - 2 * t as i32, y as i32 - 16);
            if dx * dx + dy * dy < 36 {
                Rgb([40, 200, 60])
            } else {
                Rgb([230, 140, 30])
            }
        })
    };
    (0..12).map(square).chain((0..8).map(disc)).collect()
}

#[test]
fn detect_cuts_finds_the_hard_cut_and_nothing_else() {
    let frames = clip_with_a_cut();
    let cuts = detect_cuts(&frames);
    let found: Vec<usize> = (0..cuts.len()).filter(|&i| cuts[i]).collect();
    assert_eq!(found, vec![12]);
    assert_eq!(detect_shots(&frames), [vec![0; 12], vec![1; 8]].concat());
    let scores = cut_scores(&frames, &CutParams::default());
    assert!(scores[12] > 0.5 && scores.iter().enumerate().all(|(i, &s)| i == 12 || s < 0.1), "{scores:?}");
}

#[test]
fn detect_cuts_on_tiny_or_odd_clips() {
    let frames = clip_with_a_cut();
    assert_eq!(detect_cuts(&frames[..1]), vec![false]);
    assert!(detect_cuts(&[]).is_empty());
    assert_eq!(detect_cuts(&frames[..12]), vec![false; 12], "motion alone is no cut");
    // Two frames across the cut: no neighbours to compare with, the absolute jump decides.
    assert_eq!(detect_cuts(&frames[11..13]), vec![false, true]);
    // Mixed sizes and an empty frame do not panic.
    let odd = vec![RgbImage::new(4, 4), RgbImage::new(0, 0), RgbImage::new(9, 3)];
    assert_eq!(detect_cuts(&odd).len(), 3);
}

// --- metrics ----------------------------------------------------------------------------------

fn solid(v: u8) -> RgbImage {
    RgbImage::from_pixel(8, 8, Rgb([v, v, v]))
}

#[test]
fn stability_md_is_the_mean_rms_difference_in_unit_range() {
    let frames = vec![solid(0), solid(51), solid(255)];
    assert!((stability_md(&frames, &[0, 1]) - 0.2).abs() < 1e-9);
    assert!((stability_md(&frames, &[0, 1, 2]) - 0.5).abs() < 1e-9, "(0.2 + 0.8) / 2");
    assert!((source_md(&frames) - 0.5).abs() < 1e-9);
    assert_eq!(stability_md(&frames, &[1]), 0.0);
    // RMS, not mean absolute: half the pixels black → white gives √0.5.
    let half = RgbImage::from_fn(8, 8, |x, _| if x < 4 { Rgb([255; 3]) } else { Rgb([0; 3]) });
    assert!((stability_md(&[solid(0), half], &[0, 1]) - 0.5f64.sqrt()).abs() < 1e-9);
    // Bad orders: NaN from the plain call, a clear error from the checked one.
    assert!(stability_md(&frames, &[0, 5]).is_nan());
    assert!(try_stability_md(&frames, &[0, 5]).unwrap_err().to_string().contains("frame 5"));
    let mixed = vec![solid(0), RgbImage::new(4, 4)];
    assert!(try_stability_md(&mixed, &[0, 1]).unwrap_err().to_string().contains("8x8"));
}

#[test]
fn delta_o_counts_the_source_transitions_kept() {
    assert_eq!(overlap_delta_o(&[0, 1, 2, 3, 4], 5), 1.0, "the source order");
    // 2, 3, 4: two source steps out of 2 (P = 1) and of the source's 4 (R = 0.5) → 2/3.
    let o = overlap(&[2, 3, 4], 5);
    assert_eq!((o.overlap, o.generated, o.source, o.precision, o.recall), (2, 2, 4, 1.0, 0.5));
    assert!((o.delta_o - 2.0 / 3.0).abs() < 1e-12);
    // 0 → 1 and 3 → 4 kept out of 4 steps each: P = R = 0.5.
    assert!((overlap_delta_o(&[0, 1, 3, 4, 2], 5) - 0.5).abs() < 1e-12);
    assert_eq!(overlap_delta_o(&[4, 3, 2, 1, 0], 5), 0.0, "backwards shares no source step");
    assert_eq!(overlap_delta_o(&[3], 5), 0.0);
    assert_eq!(overlap_delta_o(&[], 0), 0.0);
}

#[test]
fn a_cut_enters_the_other_shot_where_the_walk_can_go_on() {
    // Two shots: frames 0–4 and 5–9 on a line. From frame 2, frame 9 (the other shot's last frame)
    // is no closer than 5 in content, but only 5 has four unvisited frames after it in its shot;
    // frame 8 is the closest with one, frame 9 the closest with none.
    let g = Graph::from_fn(10, |i, j| {
        if i == j {
            0.0
        } else if (i == 2 && j == 9) || (i == 9 && j == 2) {
            0.5
        } else {
            (i as f32 - j as f32).abs()
        }
    });
    let motion = MotionInfo {
        tendency: vec![None; 10],
        lms: vec![false; 10],
        shot: [0; 5].into_iter().chain([1; 5]).collect(),
        directed: vec![false, false],
        ..MotionInfo::none()
    };
    let p = SdpfParams { use_cr: false, ..SdpfParams::default() };
    let ctx = Ctx::new(&g, &motion, &NoMotion, &p);
    let mut visited = vec![false; 10];
    visited[2] = true;
    assert_eq!(ctx.cut(2, &visited).map(|c| c.0), Some(5), "the frame with a way forward, not the closest (9)");
    // With 6 and 7 used, no frame of the other shot has four unvisited successors: one will do.
    visited[6] = true;
    visited[7] = true;
    assert_eq!(ctx.cut(2, &visited).map(|c| c.0), Some(8));
    // With 9 alone left, it is taken.
    visited[5] = true;
    visited[8] = true;
    assert_eq!(ctx.cut(2, &visited).map(|c| c.0), Some(9));
    // The walk with matched transitions cuts only into a stretch followed by MIN_LOOP unvisited
    // frames, entered at its first frame, and into a smaller one only when nothing else is left.
    let mut visited = vec![false; 10];
    visited[2] = true;
    visited[5] = true;
    assert_eq!(ctx.cut_into_stretch(2, &visited, super::distill::MIN_LOOP), None, "6..9 is 4 frames");
    visited[5] = false;
    assert_eq!(ctx.cut_into_stretch(2, &visited, super::distill::MIN_LOOP).map(|c| c.0), Some(5));
    visited[7] = true;
    assert_eq!(ctx.cut_into_stretch(2, &visited, super::distill::MIN_LOOP), None);
    // 9 is closer (0.5) but inside the stretch 8..9; of the heads 5 and 8, 5 is closer.
    assert_eq!(ctx.cut_into_stretch(2, &visited, 0).map(|c| c.0), Some(5));
}
