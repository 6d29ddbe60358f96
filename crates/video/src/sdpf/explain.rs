//! `--explain`: each transition of a path in words — its candidates, what each constraint
//! removed and why, the softmax probabilities and the choice.

use std::fmt::Write as _;

use super::types::{Candidate, CdState, CrState, Omega, SdpfPath, StepKind, StopReason, Transition};

/// A readable account of `path`, one block per transition (plus the loop-closing step).
pub fn explain(path: &SdpfPath) -> String {
    let mut s = String::new();
    let list: Vec<String> = path.frames.iter().map(|f| f.to_string()).collect();
    let start = path.frames.first().map_or_else(|| "?".to_string(), |f| f.to_string());
    let _ = writeln!(
        s,
        "SDPF path of {} frames from frame {start} (seed {}, attempt {}): {}",
        path.len(),
        path.seed,
        path.attempt,
        list.join(" ")
    );
    let _ = writeln!(s, "η (Eq. 8, mean edge weight) = {:.4}; stop: {}", path.eta, stop_words(path.stop));
    for (i, t) in path.transitions.iter().enumerate() {
        let _ = writeln!(s, "step {}: {}", i + 1, head(t));
        body(&mut s, t);
    }
    if let Some(StepKind::LoopBack { to, .. }) = path.transitions.last().map(|t| t.kind) {
        let body = path.transitions.len() - to;
        let _ = writeln!(s, "then the loop of {body} frames (positions {to}..) repeats up to {} frames", path.len());
    }
    if let Some(t) = &path.closing {
        let _ = writeln!(s, "loop closure: {}", head(t));
        body(&mut s, t);
    }
    s
}

/// One transition in words (its head line and its candidates, what each constraint removed, the
/// probabilities and the choice): the block [`explain`] prints for that step. The studio shows it
/// when the pointer rests on the step.
pub fn explain_step(t: &Transition) -> String {
    let mut s = head(t);
    s.push('\n');
    body(&mut s, t);
    s
}

fn stop_words(stop: StopReason) -> &'static str {
    match stop {
        StopReason::TargetLength => "target length reached",
        StopReason::EarlyStop => "early stop, no candidate left (S2 empty, §5.2.3)",
        StopReason::AllVisited => "every frame used",
        StopReason::LoopClosed => "cut where the last frame returns to the start (loop closure)",
        StopReason::DeadEnd => "dead end: no candidate left, no other shot to cut to and no loop back possible",
    }
}

fn head(t: &Transition) -> String {
    let how = match t.kind {
        StepKind::Distilled => String::new(),
        StepKind::Cut { edge } => format!(" CUT to another shot (S2 empty; its closest unvisited frame, e {edge:.3})"),
        StepKind::LoopBack { to, edge } => {
            format!(" LOOP back to position {to} (S2 empty, no other shot left; the closest frame of the path, e {edge:.3})")
        }
        StepKind::JumpCut { cost } => format!(
            " JUMP CUT inside the shot (S2 empty, no matched way to its frames not yet shown; {cost:.2} source steps)"
        ),
        StepKind::Replay => " REPLAY (S2 empty: the next source frame, already shown)".to_string(),
        StepKind::Transition { cost, loop_frames } => {
            let opens = if loop_frames > 0 { format!(", opens a loop of {loop_frames} frames") } else { String::new() };
            format!(" TRANSITION (S2 empty: the frames before it match those around frame {} in content and direction, cost {cost:.2} source steps{opens})", t.from)
        }
    };
    match t.chosen {
        Some(k) => format!("frame {} → {k}{how}", t.from),
        None => format!("frame {} → (none)", t.from),
    }
}

fn body(s: &mut String, t: &Transition) {
    let s1: Vec<String> = t.candidates.iter().map(candidate).collect();
    let _ = writeln!(s, "  S1 (content, Eq. 8) = frames with e < η, n1 = {}: {}", t.s1.len(), none_if_empty(&s1));
    if !t.removed_cut.is_empty() {
        let _ = writeln!(s, "  left out, another shot (scene cut): {}", frames(&t.removed_cut));
    }
    let _ = writeln!(s, "  C_r (reverse, beyond the paper): {}", cr_words(t));
    let _ = writeln!(s, "  C_d (Eq. 12): {}", cd_words(t));
    let _ = writeln!(s, "  C_t (Eq. 16-17): {}", ct_words(t));
    if !t.removed_cap.is_empty() {
        let _ =
            writeln!(s, "  step cap (farther than the source's own steps allow): removed {}", frames(&t.removed_cap));
    }
    let s2: Vec<String> = t.probs.iter().map(|(f, p)| format!("{f} p={p:.3}")).collect();
    let _ = writeln!(s, "  S2 with softmax probabilities (Eq. 20): {}", none_if_empty(&s2));
    match (t.chosen, t.kind) {
        (Some(k), StepKind::Distilled) => {
            let _ = writeln!(s, "  chose {k}");
        }
        (Some(k), StepKind::Cut { .. }) => {
            let _ = writeln!(s, "  no candidate left: cut to {k}");
        }
        (Some(k), StepKind::LoopBack { .. }) => {
            let _ = writeln!(s, "  no candidate left and no other shot: loop back to {k}");
        }
        (Some(k), StepKind::JumpCut { .. }) => {
            let _ = writeln!(s, "  no candidate and no matched way left: jump cut to {k}");
        }
        (Some(k), StepKind::Replay) => {
            let _ = writeln!(s, "  no candidate left: play on to {k}");
        }
        (Some(k), StepKind::Transition { .. }) => {
            let _ = writeln!(s, "  no candidate left: matched transition to {k}");
        }
        (None, _) => {
            let _ = writeln!(s, "  no candidate left: stop");
        }
    }
}

fn candidate(c: &Candidate) -> String {
    let t = c.tendency.map_or_else(|| "-".to_string(), |t| format!("{:.0}°", t.to_degrees()));
    let m = if c.motion.is_nan() { "-".to_string() } else { format!("{:.3}", c.motion) };
    format!("{} (e {:.3}, motion {m}, T {t}{})", c.frame, c.edge, if c.lms { ", LMS" } else { "" })
}

fn cr_words(t: &Transition) -> String {
    match t.cr {
        CrState::Disabled => "off".into(),
        CrState::AllowedUndirected => "skipped, the shot's motion is judged undirected (`allow_reverse`)".into(),
        CrState::Active => format!(
            "removes steps that play the motion backwards (replays of the previous source frames, or frames closer to frame {}'s past than to its future); removed {}",
            t.from,
            none_if_empty_frames(&t.removed_cr)
        ),
    }
}

fn cd_words(t: &Transition) -> String {
    match t.cd {
        CdState::Disabled => "off".into(),
        CdState::NotLms => format!("skipped, frame {} is not an LMS frame", t.from),
        CdState::NoLmsCandidate => "skipped, no LMS frame in S1".into(),
        CdState::Active { tendency, xi } => format!(
            "T_c = {:.0}°, keeps LMS frames within ξ = {:.0}°; removed {}",
            tendency.to_degrees(),
            xi.to_degrees(),
            none_if_empty_frames(&t.removed_cd)
        ),
    }
}

fn ct_words(t: &Transition) -> String {
    match t.omega {
        Omega::Off if t.s1.is_empty() => "nothing to check".into(),
        Omega::Off => "off".into(),
        Omega::Mean(w) => {
            format!(
                "keeps motion ≤ ω = {w:.4} (mean over what C_r and C_d left); removed {}",
                none_if_empty_frames(&t.removed_ct)
            )
        }
        Omega::Rotated(w) => {
            format!(
                "keeps motion ≤ ω = {w:.4} (FC against its ±90° rotations, n1 < 2); removed {}",
                none_if_empty_frames(&t.removed_ct)
            )
        }
    }
}

fn frames(f: &[usize]) -> String {
    f.iter().map(|x| x.to_string()).collect::<Vec<_>>().join(" ")
}

fn none_if_empty_frames(f: &[usize]) -> String {
    if f.is_empty() {
        "none".into()
    } else {
        frames(f)
    }
}

fn none_if_empty(items: &[String]) -> String {
    if items.is_empty() {
        "none".into()
    } else {
        items.join(", ")
    }
}
