//! SIDQL selection (§4): a trained deep Q-network adds, one at a time, the frame with the highest
//! Q-value until `k` keys are chosen; beyond the paper, the keys are then checked against uniform
//! keys and refined ([`crate::dqn::Finish`]). Training lives in [`crate::dqn`].
//!
//! The policy keys windows of at most [`MAX_FRAMES`] frames (the paper's windows). [`sidql_long`]
//! keys a take of any length: windows of at most that length sharing their end frames, each
//! window's keys chosen by the policy, the keys beyond the windows' ends given one at a time to the
//! window whose error drops most; then, as for one window, checked against uniform keys.

pub use crate::dqn::SidqlPolicy;

use crate::dqn::env::MAX_FRAMES;
use crate::metrics::SegmentModel;
use crate::representation::SphericalMotion;
use crate::{MocapError, Result};
use inbetween_core::{KeyframeSet, Motion};
use std::collections::HashMap;

/// `k` keys for a window chosen by `policy`.
pub fn sidql(policy: &SidqlPolicy, rep: &SphericalMotion, k: usize) -> Result<KeyframeSet> {
    policy.select(rep, k)
}

/// `k` keys (first and last frame included) for a take of any length, `cm_per_unit` its length
/// unit. Up to [`MAX_FRAMES`] frames this is [`sidql`]. Longer takes are cut into the fewest
/// windows of at most [`MAX_FRAMES`] frames that share their end frames (all of them keys, so `k`
/// must cover them: an error says how many are needed); each window starts with its two end keys
/// and every further key goes to the window whose summed angle error (Eq. 18 times its frames)
/// drops most when the policy keys it with one more. The keys are then replaced by uniform keys
/// when those cost less over the whole take.
pub fn sidql_long(policy: &SidqlPolicy, motion: &Motion, cm_per_unit: f64, k: usize) -> Result<KeyframeSet> {
    crate::select::check_k(motion.num_frames(), k)?;
    SidqlLong::new(policy, motion, cm_per_unit)?.keys(k)
}

/// [`sidql_long`] for one take and many `k` (a studio's K slider): the windows' representations
/// are made once, and each window's keying by the policy with a given number of keys is kept, so
/// a K change only keys what it has not keyed before (the split of keys between windows for `k` is
/// the first steps of the split for any larger `k`). Same keys as [`sidql_long`].
pub struct SidqlLong<'p> {
    policy: &'p SidqlPolicy,
    n: usize,
    /// Window ends (shared between neighbours); one window spanning the take up to [`MAX_FRAMES`].
    ends: Vec<(usize, usize)>,
    reps: Vec<SphericalMotion>,
    whole: SphericalMotion,
    /// `(window, keys)` → (summed angle error, the policy's keys).
    keyed: HashMap<(usize, usize), (f64, KeyframeSet)>,
}

impl<'p> SidqlLong<'p> {
    /// Prepares `motion` (`cm_per_unit` its length unit) for keying by `policy`.
    pub fn new(policy: &'p SidqlPolicy, motion: &Motion, cm_per_unit: f64) -> Result<SidqlLong<'p>> {
        let n = motion.num_frames();
        let window_rep = |a: usize, b: usize| -> Result<SphericalMotion> {
            let m = motion.crop(a, b + 1).map_err(|e| MocapError::Invalid(e.to_string()))?;
            let mut rep = SphericalMotion::from_motion(&m)?;
            rep.cm_per_unit = cm_per_unit;
            Ok(rep)
        };
        let whole = window_rep(0, n.saturating_sub(1))?;
        let span = MAX_FRAMES - 1;
        let ends: Vec<(usize, usize)> = if n <= MAX_FRAMES {
            vec![(0, n.saturating_sub(1))]
        } else {
            (0..(n - 1).div_ceil(span)).map(|w| (w * span, ((w + 1) * span).min(n - 1))).collect()
        };
        let reps = if n <= MAX_FRAMES {
            vec![]
        } else {
            ends.iter().map(|&(a, b)| window_rep(a, b)).collect::<Result<_>>()?
        };
        Ok(SidqlLong { policy, n, ends, reps, whole, keyed: HashMap::new() })
    }

    /// Window `w` keyed by the policy with `kw` keys, and its summed angle error.
    fn keyed(&mut self, w: usize, kw: usize) -> Result<&(f64, KeyframeSet)> {
        if !self.keyed.contains_key(&(w, kw)) {
            let rep = &self.reps[w];
            let keys = sidql(self.policy, rep, kw.min(rep.num_frames))?;
            self.keyed.insert((w, kw), (rep.error(&keys).mean_angle * rep.num_frames as f64, keys));
        }
        Ok(&self.keyed[&(w, kw)])
    }

    /// The `k` keys of [`sidql_long`].
    pub fn keys(&mut self, k: usize) -> Result<KeyframeSet> {
        let n = self.n;
        crate::select::check_k(n, k)?;
        if n <= MAX_FRAMES {
            return sidql(self.policy, &self.whole, k);
        }
        let windows = self.ends.len();
        if k < windows + 1 {
            return Err(MocapError::Invalid(format!(
                "SIDQL keys windows of at most {MAX_FRAMES} frames: a {n}-frame take is {windows} windows whose {} end \
                 frames are all keys, so K must be at least {} (got {k}); use more keys, or uniform, greedy or optimal keys",
                windows + 1,
                windows + 1
            )));
        }
        // Keys per window; each further key to the window whose error drops most (ties: the earliest).
        let mut per: Vec<usize> = vec![2; windows];
        for _ in 0..k - (windows + 1) {
            let mut best: Option<(usize, f64)> = None;
            for (w, &kw) in per.iter().enumerate() {
                if kw >= self.reps[w].num_frames {
                    continue;
                }
                let gain = self.keyed(w, kw)?.0 - self.keyed(w, kw + 1)?.0;
                if best.is_none_or(|(_, g)| gain.total_cmp(&g).is_gt()) {
                    best = Some((w, gain));
                }
            }
            let Some((w, _)) = best else { break };
            per[w] += 1;
        }
        let mut keys: Vec<usize> = Vec::with_capacity(k);
        for (w, &kw) in per.iter().enumerate() {
            let a = self.ends[w].0;
            for &f in self.keyed(w, kw)?.1.frames() {
                if keys.last() != Some(&(a + f)) {
                    keys.push(a + f);
                }
            }
        }
        let mut scratch = self.whole.scratch();
        let whole = &self.whole;
        let mut total = |keys: &[usize]| -> f64 {
            keys.windows(2).map(|p| whole.segment_cost(p[0], p[1], &mut scratch).angle_sum).sum()
        };
        let uniform = KeyframeSet::uniform(n, k)?;
        if total(uniform.frames()) < total(&keys) {
            keys = uniform.frames().to_vec();
        }
        Ok(KeyframeSet::new(keys, n)?)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use inbetween_core::procedural::{gait, GaitParams, CM_PER_CMU_UNIT};

    /// `sidql_long` as it was before [`SidqlLong`] (verbatim): the reference it must match.
    fn reference(policy: &SidqlPolicy, motion: &Motion, cm_per_unit: f64, k: usize) -> Result<KeyframeSet> {
        let n = motion.num_frames();
        crate::select::check_k(n, k)?;
        let window_rep = |a: usize, b: usize| -> Result<SphericalMotion> {
            let m = motion.crop(a, b + 1).map_err(|e| MocapError::Invalid(e.to_string()))?;
            let mut rep = SphericalMotion::from_motion(&m)?;
            rep.cm_per_unit = cm_per_unit;
            Ok(rep)
        };
        if n <= MAX_FRAMES {
            return sidql(policy, &window_rep(0, n - 1)?, k);
        }
        let span = MAX_FRAMES - 1;
        let windows = (n - 1).div_ceil(span);
        let ends: Vec<(usize, usize)> = (0..windows).map(|w| (w * span, ((w + 1) * span).min(n - 1))).collect();
        if k < windows + 1 {
            return Err(MocapError::Invalid(format!(
                "SIDQL keys windows of at most {MAX_FRAMES} frames: a {n}-frame take is {windows} windows whose {} end \
                 frames are all keys, so K must be at least {} (got {k}); use more keys, or uniform, greedy or optimal keys",
                windows + 1,
                windows + 1
            )));
        }
        let reps: Vec<SphericalMotion> = ends.iter().map(|&(a, b)| window_rep(a, b)).collect::<Result<_>>()?;
        // Summed angle error of window `w` keyed with `kw` keys by the policy, and those keys.
        let keyed = |w: usize, kw: usize| -> Result<(f64, KeyframeSet)> {
            let rep = &reps[w];
            let keys = sidql(policy, rep, kw.min(rep.num_frames))?;
            Ok((rep.error(&keys).mean_angle * rep.num_frames as f64, keys))
        };
        let mut per: Vec<usize> = vec![2; windows];
        let mut now: Vec<(f64, KeyframeSet)> = (0..windows).map(|w| keyed(w, 2)).collect::<Result<_>>()?;
        let mut next: Vec<Option<(f64, KeyframeSet)>> =
            (0..windows).map(|w| (reps[w].num_frames > 2).then(|| keyed(w, 3)).transpose()).collect::<Result<_>>()?;
        for _ in 0..k - (windows + 1) {
            // The window whose error drops most with one more key (ties: the earliest).
            let best = (0..windows)
                .filter_map(|w| next[w].as_ref().map(|(e, _)| (w, now[w].0 - e)))
                .max_by(|a, b| a.1.total_cmp(&b.1).then(b.0.cmp(&a.0)));
            let Some((w, _)) = best else { break };
            per[w] += 1;
            now[w] = next[w].take().expect("the chosen window has a next keying");
            next[w] = (per[w] < reps[w].num_frames).then(|| keyed(w, per[w] + 1)).transpose()?;
        }
        let mut keys: Vec<usize> = Vec::with_capacity(k);
        for (w, (_, ks)) in now.iter().enumerate() {
            let a = ends[w].0;
            for &f in ks.frames() {
                // A window's first key is the previous window's last.
                if keys.last() != Some(&(a + f)) {
                    keys.push(a + f);
                }
            }
        }
        // As the window policy does (crate::dqn::Finish): never worse than uniform keys over the
        // whole take. (Each window's keys are already refined by the policy; refining across windows
        // over a 1000-frame take took about a second, too slow for an interactive K change.)
        let whole = window_rep(0, n - 1)?;
        let mut scratch = whole.scratch();
        let total = |keys: &[usize], scratch: &mut crate::metrics::Scratch| -> f64 {
            keys.windows(2).map(|p| whole.segment_cost(p[0], p[1], scratch).angle_sum).sum()
        };
        let uniform = KeyframeSet::uniform(n, k)?;
        if total(uniform.frames(), &mut scratch) < total(&keys, &mut scratch) {
            keys = uniform.frames().to_vec();
        }
        Ok(KeyframeSet::new(keys, n)?)
    }

    #[test]
    fn the_reusable_keyer_gives_the_keys_of_one_shot_keying_for_every_k() {
        let policy = SidqlPolicy::committed().unwrap();
        for frames in [50, 300] {
            let m = gait(&GaitParams { frames, ..GaitParams::walk() });
            let mut long = SidqlLong::new(&policy, &m, CM_PER_CMU_UNIT).unwrap();
            for k in [9, 6, 14, 30, 7] {
                assert_eq!(
                    long.keys(k).unwrap(),
                    reference(&policy, &m, CM_PER_CMU_UNIT, k).unwrap(),
                    "{frames} frames, K={k}"
                );
            }
            assert_eq!(long.keys(1).is_err(), reference(&policy, &m, CM_PER_CMU_UNIT, 1).is_err());
        }
    }

    #[test]
    fn a_long_take_gets_exactly_k_keys_and_a_short_one_the_window_policy_s() {
        let policy = SidqlPolicy::committed().unwrap();
        let m = gait(&GaitParams { frames: 300, ..GaitParams::walk() });
        // 300 frames: 5 windows of at most 64 frames, 6 end keys.
        let err = sidql_long(&policy, &m, CM_PER_CMU_UNIT, 5).unwrap_err().to_string();
        assert!(err.contains("K must be at least 6"), "{err}");
        for k in [6, 10, 17] {
            let keys = sidql_long(&policy, &m, CM_PER_CMU_UNIT, k).unwrap();
            assert_eq!(keys.frames().len(), k, "{:?}", keys.frames());
            assert_eq!(keys.frames()[0], 0);
            assert_eq!(*keys.frames().last().unwrap(), 299);
        }
        // Never worse than uniform keys; eleven more keys cost less.
        let mut rep = SphericalMotion::from_motion(&m).unwrap();
        rep.cm_per_unit = CM_PER_CMU_UNIT;
        let e = |k| rep.error(&sidql_long(&policy, &m, CM_PER_CMU_UNIT, k).unwrap()).mean_angle;
        for k in [6, 10, 17] {
            let uniform = rep.error(&KeyframeSet::uniform(300, k).unwrap()).mean_angle;
            assert!(e(k) <= uniform + 1e-12, "K={k}: {} > uniform {uniform}", e(k));
        }
        assert!(e(17) < e(6), "{} {}", e(6), e(17));
        // Up to 64 frames it is the window policy itself.
        let short = m.crop(0, 50).unwrap();
        let mut r = SphericalMotion::from_motion(&short).unwrap();
        r.cm_per_unit = CM_PER_CMU_UNIT;
        assert_eq!(sidql_long(&policy, &short, CM_PER_CMU_UNIT, 7).unwrap(), sidql(&policy, &r, 7).unwrap());
    }
}
