//! The losses of §3.3.
//!
//! Generator: `L_G = L_rec + λ_dist·L_dist + λ_adv·L_adv` with
//! - `L_rec = mean |G − X|` over the whole window (the generator must also reproduce the frames it
//!   was given, §3.3);
//! - `L_dist = mean |d(G) − d(X)|` over the six key distances of [`crate::edit::distances`] (affine in
//!   the weights, `d(x) = b + x·W`, so `d(G) − d(X) = (G − X)·W`; after Berson et al. 2019);
//! - `L_adv = −mean D([X̃, d(X̃)])` on the recomposed animation `X̃ = X ⊙ (1 − M) + G ⊙ M`.
//!
//! Critic: hinge loss `mean relu(1 − D(real)) + mean relu(1 + D(fake))` plus WGAN-GP
//! `λ_gp · mean (‖∇ₓD(x̂)‖₂ − 1)²` at `x̂ = ε·real + (1 − ε)·fake`, `ε ~ U(0, 1)` per sample
//! (Gulrajani et al. 2017), where real is `[X, d(X)]` and fake `[X̃, d(X̃)]`. The input gradient is
//! written by hand ([`Critic::input_gradient_with`]), so one backward suffices.
//!
//! The λ values of the paper did not survive in our copy of it ("we set , , and"). Ours
//! ([`LossWeights::default`]): λ_dist = 1 (the distances are in blendshape units, like `L_rec`),
//! λ_adv = 0.01 (the adversarial term refines; reconstruction dominates, as in the inpainting works
//! the paper follows) and λ_gp = 10 (Gulrajani et al.'s value).

use burn::tensor::activation::relu;
use burn::tensor::{Device, Tensor, TensorData};
use inbetween_nn::burn;
use serde::{Deserialize, Serialize};

use crate::data::NUM_ARKIT;
use crate::edit::distances::{distance_bases, distance_matrix, NUM_DISTANCES};
use crate::model::critic::{Critic, CriticWeights};

/// The λs of §3.3 (ours; see the module docs).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct LossWeights {
    /// Weight of the key-distance loss.
    pub dist: f64,
    /// Weight of the generator's adversarial term.
    pub adv: f64,
    /// Weight of the critic's gradient penalty.
    pub gp: f64,
}

impl Default for LossWeights {
    fn default() -> Self {
        LossWeights { dist: 1.0, adv: 0.01, gp: 10.0 }
    }
}

/// The six key distances as tensors: `d(x) = b + x·W`, `W` `[52, 6]`.
#[derive(Clone, Debug)]
pub struct DistanceMap {
    /// `[52, 6]` coefficients.
    pub w: Tensor<2>,
    /// `[6]` constant terms.
    pub b: Tensor<1>,
}

impl DistanceMap {
    pub fn new(device: &Device) -> DistanceMap {
        DistanceMap {
            w: Tensor::from_data(TensorData::new(distance_matrix(), [NUM_ARKIT, NUM_DISTANCES]), device),
            b: Tensor::from_data(TensorData::new(distance_bases().to_vec(), [NUM_DISTANCES]), device),
        }
    }

    /// `[batch, frames, 6]` distances of `[batch, frames, 52]` weights.
    pub fn distances(&self, anim: Tensor<3>) -> Tensor<3> {
        self.linear_part(anim) + self.b.clone().reshape([1, 1, NUM_DISTANCES])
    }

    /// `x·W` without the constant terms (what a difference of distances needs).
    fn linear_part(&self, anim: Tensor<3>) -> Tensor<3> {
        let [batch, frames, _] = anim.dims();
        anim.reshape([batch * frames, NUM_ARKIT]).matmul(self.w.clone()).reshape([batch, frames, NUM_DISTANCES])
    }
}

/// The critic's input `[batch, 58, frames]` for an animation `[batch, frames, 52]`: the weights and
/// their six distances, channels first.
pub fn critic_input(anim: Tensor<3>, dist: &DistanceMap) -> Tensor<3> {
    let d = dist.distances(anim.clone());
    Tensor::cat(vec![anim, d], 2).swap_dims(1, 2)
}

/// `X ⊙ (1 − M) + G ⊙ M` (§3.3) for `[batch, frames, 52]` tensors, `mask` 1 where erased.
pub fn recompose(target: Tensor<3>, generated: Tensor<3>, mask: Tensor<3>) -> Tensor<3> {
    target.clone() + (generated - target) * mask
}

/// The masked reconstruction loss (§3.3): the mean `|G − X|` over the erased entries plus the mean
/// over the kept ones. The erased part is what the edit keeps; the kept part holds the output to the
/// input there, which the C1 join reads at the border frames ([`crate::edit::fill::correct`]).
pub fn reconstruction_loss(generated: Tensor<3>, target: Tensor<3>, mask: Tensor<3>) -> Tensor<1> {
    let err = (generated - target).abs();
    let kept = mask.ones_like() - mask.clone();
    let erased_mean = (err.clone() * mask.clone()).sum() / mask.sum().clamp_min(1.0);
    let kept_mean = (err * kept.clone()).sum() / kept.sum().clamp_min(1.0);
    erased_mean + kept_mean
}

/// `L_dist = mean |d(G) − d(X)|` over the frames with an erased entry.
pub fn distance_loss(generated: Tensor<3>, target: Tensor<3>, mask: Tensor<3>, dist: &DistanceMap) -> Tensor<1> {
    let frame_mask = mask.max_dim(2);
    let count = frame_mask.clone().sum().clamp_min(1.0).mul_scalar(NUM_DISTANCES as f64);
    (dist.linear_part(generated - target).abs() * frame_mask).sum() / count
}

/// The generator's loss and its terms (each `[1]`).
#[derive(Clone, Debug)]
pub struct GeneratorLoss {
    /// `L_rec + λ_dist·L_dist + λ_adv·L_adv`, differentiable.
    pub total: Tensor<1>,
    pub rec: Tensor<1>,
    pub dist: Tensor<1>,
    pub adv: Tensor<1>,
}

/// The generator's loss for `generated` (`[batch, frames, 52]`) against `target` with `mask`.
pub fn generator_loss(
    critic: &Critic,
    weights: &CriticWeights,
    generated: Tensor<3>,
    target: Tensor<3>,
    mask: Tensor<3>,
    dist: &DistanceMap,
    lambdas: &LossWeights,
) -> GeneratorLoss {
    let rec = reconstruction_loss(generated.clone(), target.clone(), mask.clone());
    let d = distance_loss(generated.clone(), target.clone(), mask.clone(), dist);
    let fake = critic_input(recompose(target, generated, mask), dist);
    let adv = critic.forward_with(weights, fake).mean().neg();
    let total = rec.clone() + d.clone().mul_scalar(lambdas.dist) + adv.clone().mul_scalar(lambdas.adv);
    GeneratorLoss { total, rec, dist: d, adv }
}

/// The critic's loss and its terms (each `[1]`).
#[derive(Clone, Debug)]
pub struct CriticLoss {
    /// `hinge + λ_gp·gp`, differentiable in the critic's weights.
    pub total: Tensor<1>,
    pub hinge: Tensor<1>,
    pub gp: Tensor<1>,
}

/// The critic's loss on critic inputs `real` and `fake` (`[batch, 58, frames]`, no gradient to the
/// generator: detach `fake`), with `epsilon` (`batch` values in [0, 1]) placing `x̂`.
pub fn critic_loss(
    critic: &Critic,
    weights: &CriticWeights,
    real: Tensor<3>,
    fake: Tensor<3>,
    epsilon: &[f32],
    lambdas: &LossWeights,
) -> CriticLoss {
    let [batch, _, _] = real.dims();
    assert_eq!(epsilon.len(), batch, "one ε per sample");
    let eps = Tensor::<3>::from_data(TensorData::new(epsilon.to_vec(), [batch, 1, 1]), &real.device());
    let x_hat = (real.clone() * eps.clone() + fake.clone() * (eps.neg() + 1.0)).detach();
    let d_real = critic.forward_with(weights, real);
    let d_fake = critic.forward_with(weights, fake);
    let hinge = relu(d_real.neg() + 1.0).mean() + relu(d_fake + 1.0).mean();
    let gp = critic.gradient_penalty_with(weights, x_hat);
    CriticLoss { total: hinge.clone() + gp.clone().mul_scalar(lambdas.gp), hinge, gp }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::edit::distances::distances;
    use crate::model::critic::CriticConfig;
    use inbetween_nn::backend;

    fn anim(batch: usize, frames: usize, phase: f32, device: &Device) -> (Vec<f32>, Tensor<3>) {
        let v: Vec<f32> =
            (0..batch * frames * NUM_ARKIT).map(|i| 0.5 + 0.45 * (i as f32 * 0.13 + phase).sin()).collect();
        (v.clone(), Tensor::from_data(TensorData::new(v, [batch, frames, NUM_ARKIT]), device))
    }

    fn scalar(t: Tensor<1>) -> f32 {
        t.into_scalar::<f32>()
    }

    #[test]
    fn train_losses_distances_match_the_per_frame_definition() {
        let device = backend::cpu();
        let (v, x) = anim(2, 3, 0.0, &device);
        let dist = DistanceMap::new(&device);
        let input = critic_input(x, &dist);
        assert_eq!(input.dims(), [2, NUM_ARKIT + NUM_DISTANCES, 3]);
        let got = input.into_data().try_to_vec::<f32>().unwrap();
        // Sample 1, frame 2: channel c at [1, c, 2].
        let frame = &v[(3 + 2) * NUM_ARKIT..(3 + 3) * NUM_ARKIT];
        let at = |c: usize| got[(NUM_ARKIT + NUM_DISTANCES) * 3 + c * 3 + 2];
        assert_eq!(at(17), frame[17]);
        for (k, d) in distances(frame).iter().enumerate() {
            assert!((at(NUM_ARKIT + k) - d).abs() < 1e-5, "distance {k}: {} vs {d}", at(NUM_ARKIT + k));
        }
    }

    fn half_mask(device: &Device) -> Tensor<3> {
        Tensor::cat(vec![Tensor::<3>::ones([2, 8, NUM_ARKIT], device), Tensor::zeros([2, 8, NUM_ARKIT], device)], 1)
    }

    #[test]
    fn train_losses_vanish_for_a_perfect_generator_and_recompose_keeps_the_input() {
        let device = backend::cpu();
        let (_, x) = anim(2, 16, 0.0, &device);
        let (_, g) = anim(2, 16, 1.0, &device);
        let dist = DistanceMap::new(&device);
        let zeros = Tensor::<3>::zeros([2, 16, NUM_ARKIT], &device);
        let all = zeros.ones_like();
        assert_eq!(scalar(reconstruction_loss(x.clone(), x.clone(), all.clone())), 0.0);
        assert!(scalar(distance_loss(x.clone(), x.clone(), all.clone(), &dist)).abs() < 1e-7);
        assert!(scalar(reconstruction_loss(g.clone(), x.clone(), all.clone())) > 0.1);
        assert!(scalar(distance_loss(g.clone(), x.clone(), all.clone(), &dist)) > 0.01);
        // Masked: the erased and the kept entries are averaged apart, then added.
        assert_eq!(scalar(distance_loss(g.clone(), x.clone(), zeros.clone(), &dist)), 0.0);
        let half = half_mask(&device);
        let part = |t: Tensor<3>, r: std::ops::Range<usize>| t.slice([0..2, r, 0..NUM_ARKIT]);
        let expected = scalar((part(g.clone(), 0..8) - part(x.clone(), 0..8)).abs().mean())
            + scalar((part(g.clone(), 8..16) - part(x.clone(), 8..16)).abs().mean());
        assert!((scalar(reconstruction_loss(g.clone(), x.clone(), half)) - expected).abs() < 1e-6);
        let erased_only = recompose(x.clone(), g.clone(), half_mask(&device));
        let e = scalar((part(erased_only.clone(), 0..8) - part(x.clone(), 0..8)).abs().mean());
        assert!((scalar(reconstruction_loss(erased_only, x.clone(), half_mask(&device))) - e).abs() < 1e-6);
        let kept = recompose(x.clone(), g.clone(), zeros.clone());
        assert_eq!(scalar(reconstruction_loss(kept, x.clone(), all.clone())), 0.0);
        let replaced = recompose(x.clone(), g.clone(), all);
        assert!(scalar(reconstruction_loss(replaced, g.clone(), zeros.ones_like())) < 1e-7);

        let critic = backend::seeded_module(&device, 3, |d| CriticConfig::new(16).init(d));
        let w = critic.weights();
        let lambdas = LossWeights::default();
        let gl = generator_loss(&critic, &w, g.clone(), x.clone(), zeros.ones_like(), &dist, &lambdas);
        let expected = scalar(gl.rec.clone()) + scalar(gl.dist.clone()) + 0.01 * scalar(gl.adv.clone());
        assert!((scalar(gl.total) - expected).abs() < 1e-5);
        let real = critic_input(x, &dist);
        let fake = critic_input(g, &dist);
        let cl = critic_loss(&critic, &w, real, fake, &[0.3, 0.8], &lambdas);
        let (hinge, gp) = (scalar(cl.hinge.clone()), scalar(cl.gp.clone()));
        assert!(hinge > 0.0 && gp >= 0.0, "hinge {hinge} gp {gp}");
        assert!((scalar(cl.total) - (hinge + 10.0 * gp)).abs() < 1e-4);
    }
}
