//! The frames of a new order, optionally cross-faded at costly transitions (issue 41's `--blend N`,
//! after Schödl et al. 2000, "Video Textures", §5: "cross-fading … the transition", where the
//! frames on both sides of a jump are mixed so the change is spread over several frames).
//!
//! A jump `c → j` inside a shot whose residual `D(c, j)` (M_D's RMS difference, Eq. 21) is above
//! the shot's own step (the median `D(i, i + 1)` over the shot) is blended over `N` frames:
//! - **after the jump**, when the source goes on after `c` for `N` frames in the shot and the
//!   order plays `j, j + 1, …` for `N` frames: frame `p + t` (t = 0..N−1, `p` the jump's position)
//!   becomes `α_t · F[c + 1 + t] + (1 − α_t) · F[j + t]`, `α_t = (N − t) / (N + 1)`: the old
//!   stream fades out while the new one fades in;
//! - else **before it**, when the order played `c − N + 1 … c` and the source has `N` frames before
//!   `j` in the shot: frame `p − 1 − t` becomes `(1 − β_t) · F[c − t] + β_t · F[j − 1 − t]`,
//!   `β_t = (N − t) / (N + 1)`;
//! - else the jump stays a cut. Cuts between shots are never blended, and no frame is blended twice
//!   (the earlier jump keeps it).

use image::RgbImage;

use crate::frames::Clip;
use crate::sdpf::frame_rms;

/// Where and how to cross-fade the orders of one clip.
#[derive(Clone, Debug)]
pub struct Blend<'a> {
    /// Frames per cross-fade; 0: none.
    pub frames: usize,
    clip: &'a Clip,
    /// Shot of every frame.
    shot: Vec<usize>,
    /// Per shot: the median RMS difference of its adjacent frames (the source's own step), the
    /// residual above which a jump is blended.
    step: Vec<f64>,
}

/// One planned cross-fade: the positions it rewrites and, per position, the two source frames and
/// the weight of the first.
type Fade = Vec<(usize, usize, usize, f32)>;

impl<'a> Blend<'a> {
    /// The cross-fades of `clip` (whose frames lie in the shots `shot`) over `frames` frames.
    pub fn new(clip: &'a Clip, shot: &[usize], frames: usize) -> Blend<'a> {
        let n = clip.len();
        let shot_of = |i: usize| shot.get(i).copied().unwrap_or(0);
        let shots = shot.iter().max().map_or(1, |m| m + 1);
        let step = (0..if frames > 0 { shots } else { 0 })
            .map(|s| {
                let mut v: Vec<f64> = (1..n)
                    .filter(|&i| shot_of(i) == s && shot_of(i - 1) == s)
                    .filter_map(|i| frame_rms(&clip.frames[i - 1], &clip.frames[i], i - 1, i).ok())
                    .collect();
                v.sort_by(f64::total_cmp);
                v.get(v.len() / 2).copied().unwrap_or(0.0)
            })
            .collect();
        Blend { frames, clip, shot: (0..n).map(shot_of).collect(), step }
    }

    /// Whether the step `c → j` is blended: a jump inside a shot above the shot's own step.
    fn costly(&self, c: usize, j: usize) -> bool {
        if j == c + 1 || self.shot[c] != self.shot[j] {
            return false;
        }
        let d = frame_rms(&self.clip.frames[c], &self.clip.frames[j], c, j).unwrap_or(0.0);
        d > self.step[self.shot[c]]
    }

    /// The cross-fades of `order`.
    fn fades(&self, order: &[usize]) -> Vec<Fade> {
        let (n, big_n) = (self.shot.len(), self.frames);
        if big_n == 0 {
            return Vec::new();
        }
        let mut taken = vec![false; order.len()];
        let mut out = Vec::new();
        for p in 1..order.len() {
            let (c, j) = (order[p - 1], order[p]);
            if !self.costly(c, j) {
                continue;
            }
            let s = self.shot[c];
            let in_shot = |f: usize| f < n && self.shot[f] == s;
            let after = (0..big_n).all(|t| {
                p + t < order.len() && !taken[p + t] && order[p + t] == j + t && in_shot(c + 1 + t) && in_shot(j + t)
            });
            let before = !after
                && p >= big_n
                && j >= big_n
                && (0..big_n).all(|t| !taken[p - 1 - t] && order[p - 1 - t] + t == c && in_shot(j - 1 - t));
            let w = |t: usize| (big_n - t) as f32 / (big_n + 1) as f32;
            let fade: Fade = if after {
                (0..big_n).map(|t| (p + t, c + 1 + t, j + t, w(t))).collect()
            } else if before {
                (0..big_n).map(|t| (p - 1 - t, c - t, j - 1 - t, 1.0 - w(t))).collect()
            } else {
                continue;
            };
            for &(q, ..) in &fade {
                taken[q] = true;
            }
            out.push(fade);
        }
        out
    }

    /// Positions of `order` whose frame is a cross-fade.
    pub fn positions(&self, order: &[usize]) -> Vec<usize> {
        let mut v: Vec<usize> = self.fades(order).into_iter().flatten().map(|f| f.0).collect();
        v.sort_unstable();
        v
    }
}

/// `a · x + (1 − a) · y` per channel, rounded.
fn mix(x: &RgbImage, y: &RgbImage, a: f32) -> RgbImage {
    let mut out = x.clone();
    for (o, (&p, &q)) in out.iter_mut().zip(x.iter().zip(y.iter())) {
        *o = (a * f32::from(p) + (1.0 - a) * f32::from(q)).round().clamp(0.0, 255.0) as u8;
    }
    out
}

/// A clip of `order`'s frames of `blend`'s clip at the source rate, cross-faded where `blend` says
/// (with 0 frames: [`reorder`](crate::pipeline::reorder)'s clip).
pub fn render(order: &[usize], blend: &Blend) -> Clip {
    let clip = blend.clip;
    let mut frames: Vec<RgbImage> = order.iter().map(|&f| clip.frames[f].clone()).collect();
    for fade in blend.fades(order) {
        for (q, x, y, a) in fade {
            frames[q] = mix(&clip.frames[x], &clip.frames[y], a);
        }
    }
    Clip { frames, fps: clip.fps, source: format!("{} resequenced", clip.source) }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A clip whose frame f is a flat grey of value 10·f: D(a, b) ∝ |a − b|.
    fn ramp(n: usize) -> Clip {
        let frames = (0..n).map(|f| RgbImage::from_pixel(4, 4, image::Rgb([(10 * f) as u8; 3]))).collect();
        Clip { frames, fps: 25.0, source: "ramp".into() }
    }

    #[test]
    fn no_blend_is_the_plain_order() {
        let clip = ramp(20);
        let order = [0, 1, 2, 10, 11, 12];
        let r = render(&order, &Blend::new(&clip, &[0; 20], 0));
        assert!(r.frames.iter().zip(order).all(|(f, o)| *f == clip.frames[o]));
    }

    #[test]
    fn a_costly_jump_fades_over_n_frames_after_it() {
        let clip = ramp(20);
        let blend = Blend::new(&clip, &[0; 20], 2);
        // 2 → 10 is 8 steps: costly. After it the source goes on (3, 4) and the order plays 10, 11.
        let order = [0, 1, 2, 10, 11, 12, 13];
        assert_eq!(blend.positions(&order), vec![3, 4]);
        let r = render(&order, &blend);
        // Position 3: 2/3 of frame 3 and 1/3 of frame 10: 10·(2·3 + 10)/3 = 53.3 → 53.
        assert_eq!(r.frames[3].get_pixel(0, 0)[0], 53);
        // Position 4: 1/3 of frame 4, 2/3 of frame 11: 10·(4 + 22)/3 = 86.7 → 87.
        assert_eq!(r.frames[4].get_pixel(0, 0)[0], 87);
        assert_eq!(r.frames[5], clip.frames[12]);
        // The blended order moves in smaller steps than the jump: M_D's largest step shrinks.
        let steps =
            |c: &Clip| c.frames.windows(2).map(|w| frame_rms(&w[0], &w[1], 0, 1).unwrap()).fold(0.0f64, f64::max);
        let plain = render(&order, &Blend::new(&clip, &[0; 20], 0));
        assert!(steps(&r) < steps(&plain), "{} vs {}", steps(&r), steps(&plain));
    }

    #[test]
    fn at_the_shots_end_it_fades_before_the_jump_and_never_across_shots() {
        let clip = ramp(20);
        let blend = Blend::new(&clip, &[0; 20], 2);
        // 19 is the last frame: nothing follows it, so the fade goes before: 17, 18, 19 → 5.
        let order = [16, 17, 18, 19, 5, 6];
        assert_eq!(blend.positions(&order), vec![2, 3]);
        // Two shots: 9 → 15 crosses the cut at 10 and stays a cut.
        let shots: Vec<usize> = (0..20).map(|f| usize::from(f >= 10)).collect();
        let blend = Blend::new(&clip, &shots, 2);
        assert!(blend.positions(&[7, 8, 9, 15, 16, 17]).is_empty());
        // A step like the source's own is never blended.
        assert!(blend.positions(&[0, 1, 2, 3]).is_empty());
    }
}
