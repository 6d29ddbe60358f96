//! Diagnostics of a trained model against trivial baselines on the training-loss scale:
//! `cargo run -p inbetween-camera --example diagnose -- [WEIGHTS.bpk|committed] [SEED] [SCENES] [GAP]`.
//! Per behaviour: mean per-step ‖Δx^c‖₂ of the network (mapped H from the 5 real frames, z from a
//! window of the same sequence), of Toric lerp to the key, and of holding the start pose; plus the
//! spread of the per-step ground-truth change and how much z changes the output.

use inbetween_camera::dataset::{Dataset, BEHAVIOURS, DOWNSAMPLE};
use inbetween_camera::infer::{cam_distance as err, Cam, FastModel, Rollout};
use inbetween_camera::model::{MAP_FRAMES, STYLE_STEPS};
use rand::{Rng, SeedableRng};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let model = match args.first() {
        Some(p) if p != "committed" => FastModel::load(std::path::Path::new(p))?,
        _ => FastModel::committed()?,
    };
    let seed: u64 = args.get(1).map_or(Ok(1), |s| s.parse())?;
    let scenes: usize = args.get(2).map_or(Ok(12), |s| s.parse())?;
    let gap: usize = args.get(3).map_or(Ok(40), |s| s.parse())?;
    let data = Dataset::generate(seed, scenes, inbetween_camera::dataset::SCENE_FRAMES);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
    // [net, lerp, hold, net with other z, net last-step miss, gt per-step motion]
    let mut acc = [[0.0f64; 6]; 4];
    let mut n = [0usize; 4];
    let mut zs: Vec<Vec<f32>> = vec![];
    for s in &data.sequences {
        let (c, x) = s.encoded(DOWNSAMPLE);
        zs.push(model.extract_style(&c[..STYLE_STEPS], &x[..STYLE_STEPS]));
    }
    for (si, s) in data.sequences.iter().enumerate() {
        let (c, x) = s.encoded(DOWNSAMPLE);
        for _ in 0..3 {
            let w0 = rng.random_range(0..=x.len() - STYLE_STEPS);
            let z = model.extract_style(&c[w0..w0 + STYLE_STEPS], &x[w0..w0 + STYLE_STEPS]);
            let other = &zs[(si + 1 + rng.random_range(0..zs.len() - 1)) % zs.len()];
            let s0 = rng.random_range(0..=x.len() - MAP_FRAMES - gap);
            let last = s0 + MAP_FRAMES - 1;
            let kf = last + gap;
            let frames: [Cam; MAP_FRAMES] = std::array::from_fn(|i| x[s0 + i]);
            // Steps 1..=gap after `last`, the key at the end; drop the start.
            let run = |zz: &[f32]| {
                Rollout::mapped(&model, zz, &frames).through_keys(&c[last..=kf], &[(gap, x[kf])])[1..].to_vec()
            };
            let net = run(&z);
            let alt = run(other);
            let b = s.behaviour.index();
            let mut e = [0.0f64; 6];
            for k in 0..gap {
                let t = last + 1 + k;
                let f = (k + 1) as f32 / gap as f32;
                let lerp: Cam = std::array::from_fn(|j| x[last][j] + (x[kf][j] - x[last][j]) * f);
                e[0] += err(&net[k], &x[t]);
                e[1] += err(&lerp, &x[t]);
                e[2] += err(&x[last], &x[t]);
                e[3] += err(&net[k], &alt[k]);
                e[5] += err(&x[t], &x[t - 1]);
            }
            for v in e.iter_mut() {
                *v /= gap as f64;
            }
            e[4] = err(&net[gap - 1], &x[kf]);
            for j in 0..6 {
                acc[b][j] += e[j];
            }
            n[b] += 1;
        }
    }
    println!("gap {gap} steps; per-step mean ‖Δx^c‖ (training-loss scale is rec + key)");
    println!(
        "{:>9} {:>7} {:>7} {:>7} {:>9} {:>8} {:>8}",
        "behaviour", "net", "lerp", "hold", "z-effect", "key-miss", "gt-step"
    );
    let mut tot = [0.0; 6];
    for b in BEHAVIOURS {
        let i = b.index();
        let m: Vec<f64> = acc[i].iter().map(|v| v / n[i] as f64).collect();
        for j in 0..6 {
            tot[j] += m[j] / 4.0;
        }
        println!("{:>9} {:>7.3} {:>7.3} {:>7.3} {:>9.3} {:>8.3} {:>8.3}", b.name(), m[0], m[1], m[2], m[3], m[4], m[5]);
    }
    println!(
        "{:>9} {:>7.3} {:>7.3} {:>7.3} {:>9.3} {:>8.3} {:>8.3}",
        "average", tot[0], tot[1], tot[2], tot[3], tot[4], tot[5]
    );
    let zstd: Vec<f64> = (0..zs[0].len())
        .map(|d| {
            let m = zs.iter().map(|z| z[d] as f64).sum::<f64>() / zs.len() as f64;
            (zs.iter().map(|z| (z[d] as f64 - m).powi(2)).sum::<f64>() / zs.len() as f64).sqrt()
        })
        .collect();
    println!("z std per dim {zstd:.3?}");
    Ok(())
}
