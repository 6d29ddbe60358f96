//! Reconstruction from keyframes (Eq. 9–13): between consecutive keyframes, each joint's θ and φ
//! follow the cubic that matches value and angular velocity at both keys (Hermite form of Eq. 10,
//! sampled at the frame times of Eq. 11), and the root follows the same cubic in Cartesian
//! coordinates (Eq. 12–13). Positions are rebuilt down the hierarchy as parent + r·dir(θ, φ), so
//! every bone keeps its exact length by construction.

use crate::representation::{direction, SphericalMotion};
use glam::DVec3;
use inbetween_core::interp::{hermite, hermite_vec3};
use inbetween_core::KeyframeSet;

/// A reconstructed clip: angles joint-major like [`SphericalMotion`], positions frame-major.
#[derive(Clone, Debug)]
pub struct SphericalReconstruction {
    pub theta: Vec<f64>,
    pub phi: Vec<f64>,
    pub positions: Vec<DVec3>,
}

/// Reconstructs frame `f` of the segment between keys `a < b` (a ≤ f ≤ b): writes every joint's
/// θ, φ (`angles[2j]`, `angles[2j+1]`) and global position.
#[inline]
pub fn segment_frame(rep: &SphericalMotion, a: usize, b: usize, f: usize, angles: &mut [f64], positions: &mut [DVec3]) {
    let n = rep.num_frames;
    let h = (b - a) as f64 * rep.frame_time;
    let u = (f - a) as f64 / (b - a) as f64;
    positions[0] = hermite_vec3(rep.root_pos[a], rep.root_vel[a], rep.root_pos[b], rep.root_vel[b], h, u);
    for j in 1..rep.num_joints {
        let parent = rep.parents[j].expect("non-root joints have parents");
        if !rep.has_angles[j] {
            positions[j] = positions[parent];
            continue;
        }
        let (ia, ib) = (j * n + a, j * n + b);
        let theta = hermite(rep.theta[ia], rep.dtheta[ia], rep.theta[ib], rep.dtheta[ib], h, u);
        let phi = hermite(rep.phi[ia], rep.dphi[ia], rep.phi[ib], rep.dphi[ib], h, u);
        angles[2 * j] = theta;
        angles[2 * j + 1] = phi;
        positions[j] = positions[parent] + direction(theta, phi) * rep.bone_length[j];
    }
}

/// Reconstructs the whole clip from `keys` (Eq. 14: each section from its own two keys).
pub fn reconstruct_spherical(rep: &SphericalMotion, keys: &KeyframeSet) -> SphericalReconstruction {
    let (n, nj) = (rep.num_frames, rep.num_joints);
    let mut out =
        SphericalReconstruction { theta: rep.theta.clone(), phi: rep.phi.clone(), positions: rep.positions.clone() };
    let mut angles = vec![0.0; 2 * nj];
    let mut frame = vec![DVec3::ZERO; nj];
    for (a, b) in keys.segments() {
        for f in a..=b {
            segment_frame(rep, a, b, f, &mut angles, &mut frame);
            for j in 1..nj {
                if rep.has_angles[j] {
                    out.theta[j * n + f] = angles[2 * j];
                    out.phi[j * n + f] = angles[2 * j + 1];
                }
            }
            out.positions[f * nj..(f + 1) * nj].copy_from_slice(&frame);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::representation::JointFilter;
    use inbetween_core::procedural::{gait, GaitParams};

    fn walk() -> SphericalMotion {
        let mut p = GaitParams::run();
        p.frames = 60;
        SphericalMotion::from_motion(&JointFilter::paper().apply(&gait(&p))).unwrap()
    }

    #[test]
    fn bone_lengths_stay_exact() {
        let rep = walk();
        let keys = KeyframeSet::uniform(rep.num_frames, 4).unwrap();
        let rec = reconstruct_spherical(&rep, &keys);
        let nj = rep.num_joints;
        for f in 0..rep.num_frames {
            for j in 1..nj {
                let p = rep.parents[j].unwrap();
                let len = (rec.positions[f * nj + j] - rec.positions[f * nj + p]).length();
                assert!(
                    (len - rep.bone_length[j]).abs() < 1e-9,
                    "frame {f} joint {j}: {len} vs {}",
                    rep.bone_length[j]
                );
            }
        }
    }

    #[test]
    fn keyframes_are_reproduced_and_all_keys_is_lossless() {
        let rep = walk();
        let keys = KeyframeSet::new(vec![13, 31, 47], rep.num_frames).unwrap();
        let rec = reconstruct_spherical(&rep, &keys);
        let nj = rep.num_joints;
        for &k in keys.frames() {
            for j in 0..nj {
                assert!((rec.positions[k * nj + j] - rep.position(k, j)).length() < 1e-9);
            }
        }
        let all = KeyframeSet::new((0..rep.num_frames).collect(), rep.num_frames).unwrap();
        let rec = reconstruct_spherical(&rep, &all);
        assert!(rec.positions.iter().zip(&rep.positions).all(|(a, b)| (*a - *b).length() < 1e-9));
        // With few keys the in-betweens differ from the source (the test above is not vacuous).
        let sparse = reconstruct_spherical(&rep, &KeyframeSet::uniform(rep.num_frames, 3).unwrap());
        assert!(sparse.positions.iter().zip(&rep.positions).any(|(a, b)| (*a - *b).length() > 0.1));
    }

    #[test]
    fn cubic_root_motion_is_reproduced_exactly() {
        // A root on a cubic path with analytic velocities: Hermite interpolation is exact.
        let dt = 1.0 / 30.0;
        let path = |t: f64| DVec3::new(t * t * t - t, 2.0 * t * t, 3.0 * t);
        let vel = |t: f64| DVec3::new(3.0 * t * t - 1.0, 4.0 * t, 3.0);
        let global: Vec<Vec<DVec3>> = (0..20).map(|f| vec![path(f as f64 * dt)]).collect();
        let mut rep = SphericalMotion::from_positions(&[None], &global, dt);
        rep.root_vel = (0..20).map(|f| vel(f as f64 * dt)).collect();
        let rec = reconstruct_spherical(&rep, &KeyframeSet::new(vec![], 20).unwrap());
        for f in 0..20 {
            assert!((rec.positions[f] - path(f as f64 * dt)).length() < 1e-12);
        }
    }
}
