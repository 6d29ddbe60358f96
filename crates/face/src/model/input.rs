//! The generator's input, frame by frame (§3.1): the incomplete animation `X ⊙ (1 − M)`, the mask `M`,
//! a noise vector `z`, and for a guided network the constraint matrix `C` and its mask `M_C`.
//!
//! Layout of one frame (`input_dim(kind)` floats):
//!
//! | offset | width | content |
//! |---|---|---|
//! | 0 | 52 | ARKit weights; where erased, the linear prior (see below) |
//! | 52 | 52 | mask, 1 where erased (per channel: our extension for group edits; the paper erases whole frames) |
//! | 104 | [`NOISE_DIM`] | standard normal noise (§3.1) |
//! | 104 + NOISE_DIM | `kind.dim()` | constraint `C`, zero outside erased frames |
//! | … | 1 if guided | constraint mask `M_C` |
//!
//! **Linear prior (a difference on purpose).** The paper feeds zeros where the animation is erased
//! and lets the network produce every output value. We feed, in those entries, the linear
//! interpolation of the kept values around the gap (and, for the keyframe network, of the keys
//! inside it: [`crate::edit::fill::interpolate`]), and the generator outputs a correction of that
//! prior ([`super::generator`]). The input carries exactly the same information (the prior is a
//! function of the kept values and the keys), but a network that has not learnt anything yet
//! already gives the linear baseline, and training only has to learn what linear misses: with the
//! few CPU hours we train for, the zero-filled layout stayed near a constant output.
//!
//! Training (batched tensors) and the plain-Rust runtime both build their input here, so the two
//! cannot drift apart.

use rand::Rng;

use crate::data::NUM_ARKIT;
use crate::edit::fill::{interpolate, Interp};
use crate::edit::{Constraint, ConstraintKind, Frame, Mask};

/// Noise features per frame. The paper does not give the size; 8 is ours.
pub const NOISE_DIM: usize = 8;

/// Offset of the mask channels.
pub const MASK_OFFSET: usize = NUM_ARKIT;
/// Offset of the noise.
pub const NOISE_OFFSET: usize = 2 * NUM_ARKIT;
/// Offset of the constraint features.
pub const CONSTRAINT_OFFSET: usize = NOISE_OFFSET + NOISE_DIM;

/// Input features per frame for a network of `kind`.
pub fn input_dim(kind: ConstraintKind) -> usize {
    let c = kind.dim();
    CONSTRAINT_OFFSET + c + usize::from(c > 0)
}

/// Standard normal noise for `frames` frames (`frames × NOISE_DIM`).
pub fn noise(rng: &mut impl Rng, frames: usize) -> Vec<f32> {
    (0..frames * NOISE_DIM).map(|_| inbetween_core::seed::normal(rng) as f32).collect()
}

/// The input of one clip, frame-major (`frames × input_dim(constraint.kind())`), written into `out`
/// (cleared first). `noise` holds `frames × NOISE_DIM` values.
pub fn assemble_into(anim: &[Frame], mask: &Mask, constraint: &Constraint, noise: &[f32], out: &mut Vec<f32>) {
    let frames = anim.len();
    assert_eq!(mask.frames(), frames, "mask and animation lengths differ");
    assert_eq!(noise.len(), frames * NOISE_DIM, "noise length");
    let kind = constraint.kind();
    let (dim, d_in) = (kind.dim(), input_dim(kind));
    let (c, mc) = constraint.features(mask);
    let keys: &[(usize, Frame)] = match constraint {
        Constraint::Keyframes(k) => k,
        _ => &[],
    };
    let prior = interpolate(anim, mask, keys, Interp::Linear);
    out.clear();
    out.resize(frames * d_in, 0.0);
    for f in 0..frames {
        let row = &mut out[f * d_in..(f + 1) * d_in];
        for (ch, erased) in mask.frame(f).iter().enumerate() {
            row[ch] = prior[f][ch];
            if *erased {
                row[MASK_OFFSET + ch] = 1.0;
            }
        }
        row[NOISE_OFFSET..CONSTRAINT_OFFSET].copy_from_slice(&noise[f * NOISE_DIM..(f + 1) * NOISE_DIM]);
        if dim > 0 {
            row[CONSTRAINT_OFFSET..CONSTRAINT_OFFSET + dim].copy_from_slice(&c[f * dim..(f + 1) * dim]);
            row[CONSTRAINT_OFFSET + dim] = mc[f];
        }
    }
}

/// [`assemble_into`] into a new vector.
pub fn assemble(anim: &[Frame], mask: &Mask, constraint: &Constraint, noise: &[f32]) -> Vec<f32> {
    let mut out = Vec::new();
    assemble_into(anim, mask, constraint, noise, &mut out);
    out
}

/// The recomposed animation `X ⊙ (1 − M) + G ⊙ M` (§3.3): generated values only where erased.
pub fn recompose(anim: &[Frame], mask: &Mask, generated: &[Frame]) -> Vec<Frame> {
    anim.iter()
        .zip(generated)
        .enumerate()
        .map(|(f, (x, g))| {
            let mut out = *x;
            for (c, erased) in mask.frame(f).iter().enumerate() {
                if *erased {
                    out[c] = g[c];
                }
            }
            out
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::edit::Segment;
    use crate::visemes::{Viseme, NUM_VISEMES};
    use inbetween_core::seed::rng;

    #[test]
    fn layout_matches_the_documented_offsets() {
        assert_eq!(input_dim(ConstraintKind::None), 112);
        assert_eq!(input_dim(ConstraintKind::Keyframes), 112 + 53);
        assert_eq!(input_dim(ConstraintKind::Visemes), 112 + NUM_VISEMES + 1);
        let anim: Vec<Frame> = (0..6).map(|f| [f as f32 / 10.0; NUM_ARKIT]).collect();
        let mask = Mask::from_segments(6, &[Segment { start: 2, end: 4 }], &[true; NUM_ARKIT]);
        let z = noise(&mut rng(1), 6);
        let c = Constraint::Visemes(vec![Viseme::FV; 6]);
        let x = assemble(&anim, &mask, &c, &z);
        let d = input_dim(ConstraintKind::Visemes);
        assert_eq!(x.len(), 6 * d);
        assert_eq!(x[d], 0.1); // frame 1 kept
        assert!((x[2 * d] - 0.2).abs() < 1e-6, "frame 2 erased: the linear prior between frames 1 and 4");
        assert_eq!(x[2 * d + MASK_OFFSET + 5], 1.0);
        assert_eq!(x[d + MASK_OFFSET], 0.0);
        assert_eq!(x[3 * d + NOISE_OFFSET], z[3 * NOISE_DIM]);
        assert_eq!(x[3 * d + CONSTRAINT_OFFSET + Viseme::FV.index()], 1.0);
        assert_eq!(x[3 * d + d - 1], 1.0);
        assert_eq!(x[5 * d + d - 1], 0.0);
    }

    #[test]
    fn the_prior_reads_only_kept_values_and_keys() {
        let anim: Vec<Frame> = (0..10).map(|f| [(f as f32 * 0.7).sin().abs(); NUM_ARKIT]).collect();
        let mask = Mask::from_segments(10, &[Segment { start: 2, end: 8 }], &[true; NUM_ARKIT]);
        let z = noise(&mut rng(1), 10);
        let mut other = anim.clone();
        other[2..8].iter_mut().for_each(|f| *f = [0.9; NUM_ARKIT]);
        let d = input_dim(ConstraintKind::None);
        assert_eq!(assemble(&anim, &mask, &Constraint::None, &z), assemble(&other, &mask, &Constraint::None, &z));
        let keys = Constraint::Keyframes(vec![(5, [0.75; NUM_ARKIT])]);
        let dk = input_dim(ConstraintKind::Keyframes);
        let x = assemble(&anim, &mask, &keys, &z);
        assert_eq!(x[5 * dk + 3], 0.75, "the keyframe prior passes through the key");
        let unguided = assemble(&anim, &mask, &Constraint::None, &z);
        assert_ne!(unguided[5 * d + 3], 0.75);
    }

    #[test]
    fn recomposition_keeps_the_input_outside_the_mask() {
        let anim = vec![[0.1; NUM_ARKIT]; 4];
        let gen = vec![[0.9; NUM_ARKIT]; 4];
        let mut ch = [false; NUM_ARKIT];
        ch[17] = true;
        let mask = Mask::from_segments(4, &[Segment { start: 1, end: 3 }], &ch);
        let r = recompose(&anim, &mask, &gen);
        assert_eq!(r[1][17], 0.9);
        assert_eq!(r[1][16], 0.1);
        assert_eq!(r[0][17], 0.1);
    }
}
