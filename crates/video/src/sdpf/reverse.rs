//! Direction of motion (beyond the paper): whether a shot's motion is directed, so that playing it
//! backwards shows, and how many steps of an order play the source backwards.

use super::types::MotionInfo;

/// A shot is judged directed when at least this share of its frames are LMS frames (Eq. 11): its
/// motion keeps one direction over four frames or more most of the time, as people, vehicles and
/// camera moves do. Water, fire and flicker change direction from frame to frame (or have none).
pub const DIRECTED_LMS_SHARE: f32 = 0.5;

/// Per shot: the share of its frames that are LMS frames, and whether that makes it directed
/// ([`DIRECTED_LMS_SHARE`]). `shot` as in [`MotionInfo::shot`] (empty: one shot of `lms.len()`
/// frames).
pub fn judge_directed(lms: &[bool], shot: &[usize]) -> Vec<(bool, f32)> {
    let shots = shot.iter().max().map_or(1, |m| m + 1);
    let mut count = vec![(0usize, 0usize); shots];
    for (i, &l) in lms.iter().enumerate() {
        let s = shot.get(i).copied().unwrap_or(0);
        count[s].0 += 1;
        count[s].1 += usize::from(l);
    }
    count
        .into_iter()
        .map(|(n, l)| {
            let share = if n == 0 { 0.0 } else { l as f32 / n as f32 };
            (share >= DIRECTED_LMS_SHARE, share)
        })
        .collect()
}

/// Whether the step `a → b` goes back to one of the `window` source frames before `a` (the issue's
/// "backward step": i → i − 1, i − 2, i − 3 with `window` = 3), which replays the source backwards.
pub fn is_backward_step(a: usize, b: usize, window: usize) -> bool {
    b < a && a - b <= window
}

/// Positions `i` of `order` whose step `order[i − 1] → order[i]` is a backward step.
pub fn backward_positions(order: &[usize], window: usize) -> Vec<usize> {
    (1..order.len()).filter(|&i| is_backward_step(order[i - 1], order[i], window)).collect()
}

/// The number of backward steps of `order` ([`is_backward_step`]).
pub fn backward_steps(order: &[usize], window: usize) -> usize {
    backward_positions(order, window).len()
}

/// Steps of `order` between two LMS frames (Eq. 11) whose tendencies differ by more than `xi`:
/// the direction flips that C_d (Eq. 12) exists to prevent. Loop backs and cuts count too (the
/// caller may leave them out).
pub fn direction_flips(order: &[usize], info: &MotionInfo, xi: f32) -> usize {
    order
        .windows(2)
        .filter(|w| {
            let (c, k) = (w[0], w[1]);
            match (info.tendency_of(c), info.tendency_of(k)) {
                (Some(tc), Some(tk)) => info.is_lms(c) && info.is_lms(k) && crate::motion::angle_between(tc, tk) > xi,
                _ => false,
            }
        })
        .count()
}

/// One line per shot saying how its motion was judged and what C_r does there, for `--explain`.
pub fn direction_words(info: &MotionInfo, judged: &[(bool, f32)], allow_reverse: bool, use_cr: bool) -> String {
    let mut out = String::new();
    for (s, &(directed, share)) in judged.iter().enumerate() {
        let frames = if info.shot.is_empty() { info.lms.len() } else { info.shot.iter().filter(|&&x| x == s).count() };
        let verdict = if directed { "directed" } else { "undirected (water, fire, flicker or no steady motion)" };
        let rule = if !use_cr {
            "reverse distillation C_r is off: steps that play it backwards are allowed"
        } else if directed {
            "steps that play it backwards are removed (C_r)"
        } else if allow_reverse {
            "steps that play it backwards are allowed (`allow_reverse`)"
        } else {
            "steps that play it backwards are still removed (C_r; `allow_reverse` would allow them here)"
        };
        out.push_str(&format!(
            "shot {s} ({frames} frames): motion judged {verdict}, {:.0} % LMS frames (directed from {:.0} %); {rule}\n",
            share * 100.0,
            DIRECTED_LMS_SHARE * 100.0
        ));
    }
    out
}
