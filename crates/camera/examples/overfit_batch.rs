//! Can the model overfit one fixed batch? `cargo run -p inbetween-camera --example overfit_batch -- [STEPS] [GAP] [LR] [BEHAVIOUR]`
//! Prints L, L_rec, L_K every 20 steps and, for scale, the Toric-lerp loss on the same batches
//! (smoothed like the training loss). Environment: `RESAMPLE` draws fresh windows every step
//! (generalisation instead of memorising one batch), `TF` teacher-forces the previous pose (and
//! prints the loss of the straight-line base alone), `NOARRIVAL` trains the plain residual,
//! `SCENES` / `BATCH` size the data.

use burn::optim::{AdamConfig, GradientsParams, ModuleOptimizer};
use inbetween_camera::dataset::{Behaviour, Dataset};
use inbetween_camera::model::ModelConfig;
use inbetween_camera::train::{batch_loss, sample_batch, TrainData, LOSS_SMOOTHING};
use rand::SeedableRng;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let steps: usize = args.first().map_or(200, |s| s.parse().unwrap());
    let gap: usize = args.get(1).map_or(20, |s| s.parse().unwrap());
    let lr: f64 = args.get(2).map_or(1e-3, |s| s.parse().unwrap());
    let beh = args.get(3).and_then(|s| Behaviour::parse(s));
    let device = inbetween_nn::backend::cpu_autodiff();
    inbetween_nn::backend::seed(&device, 3);
    let cfg = ModelConfig { arrival_base: std::env::var("NOARRIVAL").is_err(), ..ModelConfig::default() };
    let scenes: usize = std::env::var("SCENES").map_or(4, |s| s.parse().unwrap());
    let data = TrainData::from_dataset(&Dataset::generate(1, scenes, 1500));
    let which: Vec<usize> = (0..data.len())
        .filter(|&i| beh.is_none_or(|b| data.behaviours[i] == b))
        .take(std::env::var("BATCH").map_or(16, |s| s.parse().unwrap()))
        .collect();
    let mut model = cfg.init(&device);
    let mut optim: ModuleOptimizer = AdamConfig::new().init();
    let t0 = std::time::Instant::now();
    let resample = std::env::var("RESAMPLE").is_ok();
    let (mut avg_net, mut avg_lerp) = (0.0f32, 0.0f32);
    for it in 0..steps {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(if resample { 100 + it as u64 } else { 9 });
        let batch = sample_batch(&data, &cfg, &which, gap, 0.0, &mut rng, &device);
        {
            // lerp loss on the same batch
            let start = batch.start_camera.clone().into_data().try_to_vec::<f32>().unwrap();
            let key = batch.key.clone().into_data().try_to_vec::<f32>().unwrap();
            let mut tot = 0.0;
            for (k, t) in batch.targets.iter().enumerate() {
                let tv = t.clone().into_data().try_to_vec::<f32>().unwrap();
                let f = (k + 1) as f32 / gap as f32;
                let mut s = 0.0;
                for b in 0..which.len() {
                    let e: f32 = (0..6)
                        .map(|j| {
                            let l = start[b * 6 + j] + (key[b * 14 + j] - start[b * 6 + j]) * f;
                            (l - tv[b * 6 + j]).powi(2)
                        })
                        .sum();
                    s += (e + 0.0025).sqrt() - 0.05;
                }
                tot += s / which.len() as f32;
            }
            avg_lerp += tot / gap as f32;
        }
        let (loss, rec, lk) = if std::env::var("TF").is_ok() {
            tf_loss(&model, batch)
        } else {
            batch_loss(&model, batch, LOSS_SMOOTHING)
        };
        let v = [loss.clone(), rec, lk].map(|t| t.into_scalar::<f32>());
        avg_net += v[1];
        let grads = GradientsParams::from_grads(loss.backward(), &model);
        model = optim.step(lr, model, grads);
        if it % 20 == 0 || it + 1 == steps {
            let n = if it == 0 { 1.0 } else { 20.0 };
            println!(
                "{it:>4} L {:.4} rec {:.4} K {:.4} | mean rec {:.4} vs lerp {:.4} ({:.0} s)",
                v[0],
                v[1],
                v[2],
                avg_net / n,
                avg_lerp / n,
                t0.elapsed().as_secs_f64()
            );
            avg_net = 0.0;
            BASE.with(|b| {
                println!("      TF base (no network) mean {:.4}", *b.borrow() / (n * gap as f32));
                *b.borrow_mut() = 0.0;
            });
            avg_lerp = 0.0;
        }
    }
}

/// Teacher-forced variant of `batch_loss`: every step reads the ground-truth previous pose.
fn tf_loss(
    model: &inbetween_camera::model::CameraModel,
    batch: inbetween_camera::train::Batch,
) -> (burn::tensor::Tensor<1>, burn::tensor::Tensor<1>, burn::tensor::Tensor<1>) {
    use burn::tensor::Tensor;
    use inbetween_camera::model::generator::StepInput;
    let z = model.extractor.forward(&batch.style_steps);
    let mut state = model.mapping.forward(z.clone(), batch.map_frames);
    let mut prev = batch.start_camera;
    let mut rec = vec![];
    let mut lk = None;
    for (((ch, tta), arrival), target) in
        batch.characters.into_iter().zip(batch.tta).zip(batch.arrival).zip(batch.targets)
    {
        let base = prev.clone() + (batch.key.clone().narrow(1, 0, 6) - prev.clone()) * arrival.clone();
        let eb: f32 = (base - target.clone())
            .powf_scalar(2.0)
            .sum_dim(1)
            .add_scalar(0.0025)
            .sqrt()
            .sub_scalar(0.05)
            .mean()
            .into_scalar();
        BASE.with(|b| *b.borrow_mut() += eb);
        let input =
            StepInput { style: z.clone(), prev_camera: prev, character: ch, key: batch.key.clone(), tta, arrival };
        let (cam, next) = model.generator.step(input, Some(state));
        state = next;
        let e = (cam - target.clone()).powf_scalar(2.0).sum_dim(1).add_scalar(0.0025).sqrt().sub_scalar(0.05).mean();
        rec.push(e.clone());
        lk = Some(e);
        prev = target;
    }
    let r: Tensor<1> = Tensor::cat(rec, 0).mean();
    let k = lk.unwrap();
    (r.clone() + k.clone(), r, k)
}

thread_local! { static BASE: std::cell::RefCell<f32> = const { std::cell::RefCell::new(0.0) }; }
