//! Two safeguards every fill goes through, whatever made it (issue 40; beyond the paper, whose §6
//! leaves joins and holds to the network):
//!
//! * [`join_borders`]: at the capture's own frame rate, each erased run of a channel is joined to the
//!   kept frames around it by an offset that fades out (inertialization): the first and last edited
//!   rows take the capture's own values there, so the step into the fill is the step the capture
//!   itself takes at that border, and the offset fades with a smoothstep (zero slope at both ends) so
//!   the fill's own motion carries on. The 25 fps model rate and its C1 join (`super::correct`) cannot
//!   guarantee this at 60 fps: a blink in a drawn segment, or a fast capture resampled to 25 fps,
//!   leaves a step of several 60 fps frames' worth at the border.
//! * [`limit_hold`] / [`limit_eye_holds`]: no eye channel stays above 0.5 inside a span for longer
//!   than the capture ever does outside the spans (a blink closes and opens within 0.1–0.5 s); a
//!   longer run is opened in its middle, keeping its closing and its opening. Applied at the model
//!   rate and again at the capture's rate after the join.

use inbetween_core::interp::smoothstep;

use crate::data::{ARKIT_NAMES, NUM_ARKIT};

use super::mask::Mask;
use super::Frame;

/// Seconds over which the border offset fades out (0.2 s: shorter than a blink's closing and
/// opening, long enough that the offset's own slope stays below the capture's usual step).
pub const JOIN_FADE_S: f64 = 0.2;

/// Join every run of `edited[i]` rows of `values` (one channel, the fill written in) to the rows
/// around it, whose values are the capture's (`orig`). See the module docs. `fade` is in rows.
pub fn join_borders(values: &mut [f32], orig: &[f32], edited: &[bool], fade: usize) {
    let n = values.len();
    let mut i = 0;
    while i < n {
        if !edited[i] {
            i += 1;
            continue;
        }
        let start = i;
        while i < n && edited[i] {
            i += 1;
        }
        let end = i;
        let len = end - start;
        // The offset fades over at most half the run, so the two borders' fades never add up.
        let k = fade.min(len.div_ceil(2)).max(1);
        if start > 0 {
            let d = orig[start] - values[start];
            for t in 0..k.min(len) {
                values[start + t] += d * (1.0 - smoothstep(t as f64 / k as f64) as f32);
            }
        }
        if end < n {
            let d = orig[end - 1] - values[end - 1];
            for t in 0..k.min(len) {
                values[end - 1 - t] += d * (1.0 - smoothstep(t as f64 / k as f64) as f32);
            }
        }
        for v in &mut values[start..end] {
            *v = v.clamp(0.0, 1.0);
        }
    }
}

/// Rows over which a cut hold fades to the open level (smoothstep), at the rate of the curve cut:
/// 0.1 s, as fast as a blink opens.
const REOPEN_S: f64 = 0.1;

/// Whether ARKit shape `c` is an eye channel (`Eye*`: blinks, gaze, squint, wide).
pub fn is_eye_channel(c: usize) -> bool {
    c < NUM_ARKIT && ARKIT_NAMES[c].starts_with("Eye")
}

/// Cut the holds above 0.5 of one eye channel's curve `values` (rows at `fps`): a run above 0.5 that
/// touches an `edited` row and is longer than the longest run of `orig` above 0.5 outside the edited
/// rows is brought down to the channel's open level (its median outside, at most 0.45) after as much
/// of the run as that longest run allows from each end, fading over [`REOPEN_S`]. Rows in `pinned`
/// (keys the user set above 0.5) keep their run whole. Only edited rows change. Returns the runs cut.
pub fn limit_hold(values: &mut [f32], orig: &[f32], edited: &[bool], pinned: &[bool], fps: f64) -> usize {
    let n = values.len();
    let fade = ((REOPEN_S * fps).round() as usize).max(1);
    let mut longest = 0;
    let mut run = 0;
    let mut outside = Vec::new();
    for i in 0..n {
        if !edited[i] {
            outside.push(orig[i]);
        }
        if !edited[i] && orig[i] > 0.5 {
            run += 1;
            longest = longest.max(run);
        } else {
            run = 0;
        }
    }
    outside.sort_by(f32::total_cmp);
    let open = outside.get(outside.len() / 2).copied().unwrap_or(0.0).min(0.45);
    let mut cut = 0;
    let mut i = 0;
    while i < n {
        if values[i] <= 0.5 {
            i += 1;
            continue;
        }
        let s = i;
        while i < n && values[i] > 0.5 {
            i += 1;
        }
        let e = i;
        if e - s <= longest || !(s..e).any(|r| edited[r]) || (s..e).any(|r| pinned[r]) {
            continue;
        }
        cut += 1;
        // Kept rows at each end: the unedited rows there, else half the longest hold, and no more
        // than the longest hold less the half of the fade spent above 0.5.
        let pre = (s..e).take_while(|r| !edited[*r]).count();
        let post = (s..e).rev().take_while(|r| !edited[*r]).count();
        let budget = longest.saturating_sub(fade / 2);
        let (k1, k2) = (pre.max((longest / 2).min(budget)), post.max((longest / 2).min(budget)));
        for r in s..e {
            if !edited[r] {
                continue;
            }
            let into = (r + 1 - s).saturating_sub(k1).min((e - r).saturating_sub(k2));
            if into == 0 {
                continue;
            }
            let w = smoothstep(into as f64 / fade as f64) as f32;
            let v = values[r];
            values[r] = v + (open.min(v) - v) * w;
        }
    }
    cut
}

/// [`limit_hold`] on every erased eye channel of a model-rate edit (`fps` = 25). Keys above 0.5
/// (`keys`) pin their runs; with `skip`, nothing is cut (a noisy take shows the performance's holds).
pub fn limit_eye_holds(after: &mut [Frame], before: &[Frame], mask: &Mask, keys: &[(usize, Frame)], fps: f64) -> usize {
    let n = after.len();
    let mut cut = 0;
    for c in (0..NUM_ARKIT).filter(|c| is_eye_channel(*c)) {
        let edited: Vec<bool> = (0..n).map(|f| mask.erased(f, c)).collect();
        if !edited.iter().any(|e| *e) {
            continue;
        }
        let mut pinned = vec![false; n];
        for (f, k) in keys {
            if *f < n && k[c] > 0.5 {
                pinned[*f] = true;
            }
        }
        let mut v: Vec<f32> = after.iter().map(|f| f[c]).collect();
        let o: Vec<f32> = before.iter().map(|f| f[c]).collect();
        cut += limit_hold(&mut v, &o, &edited, &pinned, fps);
        for (row, x) in after.iter_mut().zip(v) {
            row[c] = x;
        }
    }
    cut
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::arkit_index;

    #[test]
    fn a_border_step_becomes_the_captures_own_and_the_fill_carries_on() {
        let orig: Vec<f32> = (0..60).map(|i| 0.3 + 0.002 * i as f32).collect();
        let mut values = orig.clone();
        let edited: Vec<bool> = (0..60).map(|i| (20..40).contains(&i)).collect();
        for v in &mut values[20..40] {
            *v = 0.9;
        }
        join_borders(&mut values, &orig, &edited, 6);
        assert!((values[20] - orig[20]).abs() < 1e-6 && (values[39] - orig[39]).abs() < 1e-6);
        assert!((values[30] - 0.9).abs() < 1e-6, "the middle keeps the fill");
        for i in 1..60 {
            assert!((values[i] - values[i - 1]).abs() < 0.3, "row {i}: {}", values[i] - values[i - 1]);
        }
        assert_eq!(&values[..20], &orig[..20]);
    }

    #[test]
    fn an_eye_held_shut_opens_but_a_blink_stays_whole() {
        let blink = arkit_index("EyeBlinkLeft").unwrap();
        let mut before = vec![[0.1f32; NUM_ARKIT]; 200];
        for f in [30usize, 31, 32, 33, 150, 151, 152] {
            before[f][blink] = 0.9;
        }
        let mask = Mask::span(200, 60, 130);
        let mut after = before.clone();
        for f in after.iter_mut().take(125).skip(65) {
            f[blink] = 1.0;
        }
        for f in after.iter_mut().take(64).skip(61) {
            f[blink] = 0.8; // a blink of 3 frames inside: kept
        }
        let cut = limit_eye_holds(&mut after, &before, &mask, &[], 25.0);
        assert_eq!(cut, 1);
        // Every run above 0.5 in the span is at most the capture's longest (4 frames).
        let high: Vec<bool> = (60..130).map(|f| after[f][blink] > 0.5).collect();
        let longest = high.split(|h| !h).map(<[bool]>::len).max().unwrap_or(0);
        assert!(longest <= 4, "{high:?}");
        assert_eq!(after[62][blink], 0.8);
        let pin = vec![(90, after[90].map(|_| 0.9))];
        let mut held = before.clone();
        for f in held.iter_mut().take(125).skip(65) {
            f[blink] = 1.0;
        }
        assert_eq!(limit_eye_holds(&mut held, &before, &mask, &pin, 25.0), 0, "a key holds the eye shut");
        assert!(after[95][blink] < 0.2);
        for f in (0..60).chain(130..200) {
            assert_eq!(after[f], before[f]);
        }
    }
}
