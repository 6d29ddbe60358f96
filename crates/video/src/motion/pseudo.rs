//! Pseudo-images of PMSM (§5.2.2, Eq. 13–14) and the rotated flows A₁, A₂ of Eq. 17.
//!
//! Reading chosen where the paper is ambiguous:
//! - Eq. 13 writes M = max(FC, FK) right after normalising both flows by Eq. 9, so M is the
//!   element-wise maximum of the two *normalised magnitudes* (a 2-D vector has no max).
//! - E is counted "in each normalised optical flow", so each flow gets its own threshold: μ starts
//!   at μ₀ (½) and is halved while fewer than `min_count` of that flow's normalised magnitudes
//!   exceed μ (N_e < min_count). The paper's "e_k, the largest element of E" cannot be meant
//!   literally (M ≥ max E would keep only the few fastest pixels, defeating the N_e guarantee);
//!   the final μ, the bound every element of E exceeds, is used as the threshold on M instead.
//! - Pixel (i, j) of X_c is (x/2‖F‖ + ½, y/2‖F‖ + ½, 1) with F = FC_ij when M_ij ≥ μ_c, otherwise
//!   (½, ½, 0); likewise X_k with FK and μ_k. A significant pixel whose own vector is zero (M came
//!   from the other flow) gets (½, ½, 1): no direction, but marked as part of the motion.

use super::tendency::normalized_magnitude;
use super::Flow;

/// μ₀ of Eq. 14's threshold search.
pub const MU0: f32 = 0.5;

/// Halvings of μ before giving up (2⁻³² · μ₀ is below any meaningful normalised magnitude).
const MAX_HALVINGS: usize = 32;

/// Eq. 13–14: the pseudo-images X_c (of `fc`) and X_k (of `fk`), each H×W×3, channels last,
/// values in [0, 1]. `fk` on a different grid is sampled at the nearest position of `fc`'s grid
/// (Eq. 9 and 14 only use directions and relative magnitudes, so no rescaling is needed).
pub fn pseudo_images(fc: &Flow, fk: &Flow, mu0: f32, min_count: usize) -> (Vec<f32>, Vec<f32>) {
    let fk = fk.resampled_nearest(fc.width, fc.height);
    let (nc, nk) = (normalized_magnitude(fc), normalized_magnitude(&fk));
    let m: Vec<f32> = nc.iter().zip(&nk).map(|(a, b)| a.max(*b)).collect();
    let (mu_c, mu_k) = (threshold(&nc, mu0, min_count), threshold(&nk, mu0, min_count));
    (render(fc, &m, mu_c), render(&fk, &m, mu_k))
}

/// The threshold of Eq. 14: μ, starting at `mu0` and halved while fewer than `min_count`
/// elements of `norm` exceed it. A non-positive or non-finite `mu0` means [`MU0`].
pub fn threshold(norm: &[f32], mu0: f32, min_count: usize) -> f32 {
    let mut mu = if mu0.is_finite() && mu0 > 0.0 { mu0 } else { MU0 };
    for _ in 0..MAX_HALVINGS {
        if norm.iter().filter(|&&v| v > mu).count() >= min_count {
            break;
        }
        mu *= 0.5;
    }
    mu
}

/// Eq. 14 for one flow, given the shared map M and this flow's threshold.
fn render(flow: &Flow, m: &[f32], mu: f32) -> Vec<f32> {
    let mut out = Vec::with_capacity(flow.uv.len() * 3);
    for (v, &mv) in flow.uv.iter().zip(m) {
        if mv >= mu {
            let len = (v[0] * v[0] + v[1] * v[1]).sqrt();
            let (ux, uy) = if len > 0.0 && len.is_finite() { (v[0] / len, v[1] / len) } else { (0.0, 0.0) };
            out.extend_from_slice(&[0.5 * ux + 0.5, 0.5 * uy + 0.5, 1.0]);
        } else {
            out.extend_from_slice(&[0.5, 0.5, 0.0]);
        }
    }
    out
}

/// Every flow vector turned by `angle` radians, in place (the field's layout is unchanged):
/// A₁ = `rotate_flow(fc, π/2)` and A₂ = `rotate_flow(fc, −π/2)` of Eq. 17, the reference "a 90°
/// change of every motion" that bounds C_t when S₁ has fewer than two candidates. In image
/// coordinates (y down) a positive angle turns clockwise on screen: (1, 0) → (0, 1).
pub fn rotate_flow(flow: &Flow, angle: f32) -> Flow {
    let (s, c) = angle.sin_cos();
    let uv = flow.uv.iter().map(|v| [c * v[0] - s * v[1], s * v[0] + c * v[1]]).collect();
    Flow { width: flow.width, height: flow.height, uv }
}
