//! The distance loss of §4.1 (Eq. 4–6) and its triplets.
//!
//! `ξ = γ(‖r_a − r_n‖₂ − ‖r_a − r_p‖₂)` (Eq. 5, γ the sigmoid) and
//! `L_d = −z log ξ − (1 − z) log(1 − ξ)` (Eq. 4 with its sign written out: the binary cross-entropy
//! of ξ against z).
//!
//! # Which way z points
//! Eq. 6 as printed sets `z = 1` when `d_p(x_a, x_n) > d_p(x_a, x_p)` with `d_p` the PSNR, i.e. when
//! the *negative* is the more similar frame. With z = 1, Eq. 4 reduces to `−log ξ`, which is
//! minimised by making `‖r_a − r_n‖` large and `‖r_a − r_p‖` small: it pulls `a` towards `p`, as the
//! paper says Eq. 4 does. The two statements contradict each other; we follow the stated intent:
//! **z = 1 when p is the more similar frame (higher PSNR with the anchor), z = 0 when n is**, so the
//! embedding always moves the anchor towards the frame that looks more like it. Ties (equal PSNR,
//! e.g. duplicate frames) carry no information and are not used.
//!
//! Since `−log γ(x) = softplus(−x)` and `−log(1 − γ(x)) = softplus(x)`, the loss is computed as
//! `softplus(x) − z·x` with `x = ‖r_a − r_n‖ − ‖r_a − r_p‖`, which does not overflow.

use burn::tensor::activation::softplus;
use burn::tensor::Tensor;

use super::input::{psnr, Planes};

/// Added under the square root of the distances so their gradient is finite at zero.
pub const DISTANCE_EPS: f32 = 1e-8;

/// Euclidean distance per row of two `[batch, latent]` tensors (`[batch]`).
fn row_distance(a: Tensor<2>, b: Tensor<2>) -> Tensor<1> {
    (a - b).square().sum_dim(1).add_scalar(DISTANCE_EPS).sqrt().flatten(0, 1)
}

/// Mean distance loss (Eq. 4–5) of a batch of triplets: embeddings `[batch, latent]` of the
/// anchors, positives and negatives, labels `z` (`[batch]`, 1 or 0, Eq. 6 as read above).
/// Returns a `[1]` tensor.
pub fn distance_loss(ra: Tensor<2>, rp: Tensor<2>, rn: Tensor<2>, z: Tensor<1>) -> Tensor<1> {
    let x = row_distance(ra.clone(), rn) - row_distance(ra, rp);
    (softplus(x.clone(), 1.0) - x * z).mean()
}

/// The same loss for one triplet of plain vectors, in f64 (for evaluation and checks).
pub fn distance_loss_value(ra: &[f32], rp: &[f32], rn: &[f32], z: f32) -> f64 {
    let x = euclidean(ra, rn) - euclidean(ra, rp);
    let xi = 1.0 / (1.0 + (-x).exp());
    let z = f64::from(z);
    -z * xi.ln() - (1.0 - z) * (1.0 - xi).ln()
}

/// Euclidean distance of two vectors, in f64.
pub fn euclidean(a: &[f32], b: &[f32]) -> f64 {
    a.iter().zip(b).map(|(x, y)| f64::from(x - y).powi(2)).sum::<f64>().sqrt()
}

/// Eq. 6 from the two PSNRs: `Some(1.0)` when the positive is the more similar frame
/// (`psnr_ap > psnr_an`), `Some(0.0)` when the negative is, `None` on a tie.
pub fn triplet_label(psnr_ap: f64, psnr_an: f64) -> Option<f32> {
    if psnr_ap > psnr_an {
        Some(1.0)
    } else if psnr_ap < psnr_an {
        Some(0.0)
    } else {
        None
    }
}

/// A triplet of frame indices (anchor, positive, negative).
pub type Triplet = (usize, usize, usize);

/// Eq. 6 for each triplet of frames, on the images RSFNet sees (`planes`, see
/// [`super::input::frame_planes`]); `None` for ties.
pub fn triplet_labels(planes: &[Planes], triplets: &[Triplet]) -> Vec<Option<f32>> {
    triplets
        .iter()
        .map(|&(a, p, n)| triplet_label(psnr(&planes[a], &planes[p]), psnr(&planes[a], &planes[n])))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use burn::tensor::TensorData;
    use inbetween_nn::backend;

    fn t2(rows: &[[f32; 2]]) -> Tensor<2> {
        let v: Vec<f32> = rows.iter().flatten().copied().collect();
        Tensor::from_data(TensorData::new(v, [rows.len(), 2]), &backend::cpu())
    }

    #[test]
    fn loss_matches_a_hand_computation() {
        // Triplet 1: |a−n| = 5 (3-4-5), |a−p| = 1 → x = 4, z = 1: L = −ln σ(4) = ln(1 + e^−4).
        // Triplet 2: |a−n| = 0, |a−p| = 2 → x = −2, z = 0: L = −ln(1 − σ(−2)) = ln(1 + e^−2).
        let ra = t2(&[[0.0, 0.0], [1.0, 1.0]]);
        let rp = t2(&[[1.0, 0.0], [1.0, 3.0]]);
        let rn = t2(&[[3.0, 4.0], [1.0, 1.0]]);
        let z = Tensor::from_data(TensorData::new(vec![1.0f32, 0.0], [2]), &backend::cpu());
        let got = f64::from(distance_loss(ra, rp, rn, z).into_scalar::<f32>());
        let expected = ((1.0 + (-4.0f64).exp()).ln() + (1.0 + (-2.0f64).exp()).ln()) / 2.0;
        assert!((got - expected).abs() < 1e-5, "{got} vs {expected}");
        // The f64 version agrees triplet by triplet.
        let one = distance_loss_value(&[0.0, 0.0], &[1.0, 0.0], &[3.0, 4.0], 1.0);
        assert!((one - (1.0 + (-4.0f64).exp()).ln()).abs() < 1e-12);
        // A wrong label costs more than the right one.
        assert!(distance_loss_value(&[0.0, 0.0], &[1.0, 0.0], &[3.0, 4.0], 0.0) > 4.0);
    }

    #[test]
    fn labels_follow_psnr() {
        assert_eq!(triplet_label(30.0, 20.0), Some(1.0));
        assert_eq!(triplet_label(20.0, 30.0), Some(0.0));
        assert_eq!(triplet_label(25.0, 25.0), None);
        // Frame 1 differs from the anchor 0 by 0.1 everywhere, frame 2 by 0.5: 1 is more similar.
        let planes = vec![vec![0.0f32; 12], vec![0.1; 12], vec![0.5; 12]];
        assert_eq!(triplet_labels(&planes, &[(0, 1, 2), (0, 2, 1), (0, 1, 1)]), vec![Some(1.0), Some(0.0), None]);
    }
}
