//! Tests of the whole metric on a toy clip: a square moving over a fixed gradient background.

use std::time::Instant;

use burn::tensor::{Tensor, TensorData};
use image::{Rgb, RgbImage};
use inbetween_io::Progress;
use inbetween_nn::backend;

use super::*;

/// `n` frames of `side × side`: a red square (side/4) moving right across the frame along a sine
/// in y, over a static gradient, drawn with fractional pixel coverage so that every frame differs
/// from the next even when the square moves less than a pixel.
pub(crate) fn moving_square(n: usize, side: u32) -> Vec<RgbImage> {
    let (s, size) = (side as f32, side as f32 / 4.0);
    (0..n)
        .map(|t| {
            let u = t as f32 / n.max(2) as f32;
            let x0 = 1.0 + u * (s - size - 2.0);
            let y0 = (s - size) / 2.0 * (1.0 + 0.8 * (u * 5.0).sin());
            RgbImage::from_fn(side, side, |x, y| {
                let overlap =
                    |p: u32, start: f32| ((p as f32 + 1.0).min(start + size) - (p as f32).max(start)).max(0.0);
                let cover = overlap(x, x0) * overlap(y, y0);
                let background = [(x * 255 / side) as f32 / 2.0, (y * 255 / side) as f32 / 2.0, 120.0];
                let square = [230.0, 40.0, 40.0];
                Rgb(std::array::from_fn(|c| (background[c] * (1.0 - cover) + square[c] * cover).round() as u8))
            })
        })
        .collect()
}

fn quick(steps: usize, seed: u64) -> TrainOptions {
    TrainOptions { steps, steps_per_epoch: 5, seed, local_window: 4, ..TrainOptions::default() }
}

/// Mean distance loss (Eq. 4–5) of labelled triplets under the given embeddings.
fn mean_loss(e: &[Vec<f32>], triplets: &[(Triplet, f32)]) -> f64 {
    let sum: f64 = triplets.iter().map(|&((a, p, n), z)| distance_loss_value(&e[a], &e[p], &e[n], z)).sum();
    sum / triplets.len() as f64
}

#[test]
fn output_shapes() {
    let cfg = RsfConfig::tiny();
    cfg.validate().unwrap();
    let device = backend::cpu();
    let net = backend::seeded_module(&device, 1, |d| cfg.init(d));
    let x = Tensor::<4>::from_data(TensorData::new(vec![0.5f32; 5 * 3 * 32 * 32], [5, 3, 32, 32]), &device);
    let xs = net.coarse_features(x.clone());
    let dims: Vec<[usize; 4]> = xs.iter().map(|t| t.dims()).collect();
    assert_eq!(dims, vec![[5, 4, 32, 32], [5, 8, 16, 16], [5, 8, 8, 8], [5, 16, 4, 4]]);
    assert_eq!(net.fine_features(xs).dims(), [5, 16, 2, 2]);
    assert_eq!(net.forward(x.clone()).dims(), [5, 16]);

    let plain_cfg = RsfConfig { use_rff: false, ..cfg.clone() };
    let plain = backend::seeded_module(&device, 1, |d| plain_cfg.init(d));
    assert!(plain.ncm.is_empty() && plain.c1r.is_empty());
    assert_eq!(plain.forward(x).dims(), [5, 16]);

    let embedder = Embedder::new(net, cfg);
    let frames = moving_square(3, 20); // any size: resized to 32×32
    let e = embedder.embed(&frames);
    assert_eq!((e.len(), e[0].len()), (3, 16));
    let pseudo = vec![vec![0.25f32; 10 * 6 * 3]; 2];
    let p = embedder.embed_pseudo(&pseudo, 10, 6).unwrap();
    assert_eq!((p.len(), p[1].len()), (2, 16));
    let err = embedder.embed_pseudo(&[vec![0.0; 5]], 10, 6).unwrap_err().to_string();
    assert!(err.contains("pseudo-image 0") && err.contains("180"), "{err}");
}

#[test]
fn bad_configs_and_clips_are_errors() {
    let err = RsfConfig { input_side: 40, ..RsfConfig::tiny() }.validate().unwrap_err().to_string();
    assert!(err.contains("input_side"), "{err}");
    let err = RsfConfig { pool_grid: 4, ..RsfConfig::tiny() }.validate().unwrap_err().to_string();
    assert!(err.contains("pool_grid"), "{err}");
    let err = TrainOptions { batch: 0, ..TrainOptions::default() }.validate().unwrap_err().to_string();
    assert!(err.contains("batch"), "{err}");
    let two = moving_square(2, 32);
    let err = train_rsfnet(&two, &RsfConfig::tiny(), &quick(5, 0), &Progress::hidden()).unwrap_err().to_string();
    assert!(err.contains("at least 3 frames"), "{err}");
    // A still shot (all frames equal) has no informative triplet: not trained, no NaN, no panic.
    let still = vec![moving_square(1, 32).remove(0); 5];
    let (embedder, summary) = train_rsfnet(&still, &RsfConfig::tiny(), &quick(5, 0), &Progress::hidden()).unwrap();
    assert!(!summary.trained && summary.loss_history.is_empty());
    assert_eq!(embedder.embed(&still).len(), 5);
}

#[test]
fn embedder_is_shareable_between_threads() {
    fn send_sync<T: Send + Sync>() {}
    send_sync::<Embedder>();
    send_sync::<Graph>();
}

#[test]
fn triplets_are_seeded_and_labelled_by_psnr() {
    let frames = moving_square(20, 32);
    let planes = clip_planes(&frames, 32);
    let opts = quick(5, 3);
    let sampler = TripletSampler::new(&planes, &opts);
    let draw = |seed| sampler.draw_many(&mut inbetween_core::seed::rng(seed), 64);
    let a = draw(9);
    assert_eq!(a, draw(9));
    assert_ne!(a, draw(10));
    assert_eq!(a.len(), 64);
    let labels = triplet_labels(&planes, &a.iter().map(|(t, _)| *t).collect::<Vec<_>>());
    for (((anchor, p, n), z), label) in a.iter().zip(labels) {
        assert!(anchor != p && anchor != n && p != n);
        assert_eq!(Some(*z), label);
    }
    // Local draws stay within the window.
    let local = TripletSampler::new(&planes, &TrainOptions { local_fraction: 1.0, ..opts });
    for ((anchor, p, n), _) in local.draw_many(&mut inbetween_core::seed::rng(1), 64) {
        assert!(anchor.abs_diff(p) <= 4 && anchor.abs_diff(n) <= 4);
    }
}

#[test]
fn early_stopping_keeps_the_best_validated_epoch() {
    let frames = moving_square(16, 32);
    let cfg = RsfConfig::tiny();
    // Patience 1 on a long budget: stops once an epoch fails to beat the best validation agreement.
    let opts = TrainOptions { patience: 1, ..quick(200, 4) };
    let (embedder, summary) = train_rsfnet(&frames, &cfg, &opts, &Progress::hidden()).unwrap();
    let epochs = summary.loss_history.len();
    assert_eq!(summary.val_agreement.len(), epochs);
    assert!(epochs < 40 && summary.steps == 5 * epochs, "{summary:?}");
    assert_eq!(summary.best_epoch + 2, epochs, "stopped one epoch after the best: {summary:?}");
    let best = summary.val_agreement[summary.best_epoch];
    assert!(summary.val_agreement.iter().all(|&a| a <= best));
    // The kept network is the best epoch's, and the run is reproducible.
    let (again, s2) = train_rsfnet(&frames, &cfg, &opts, &Progress::hidden()).unwrap();
    assert_eq!(embedder.embed(&frames), again.embed(&frames));
    assert_eq!(summary.val_agreement, s2.val_agreement);
    // Patience 0 trains the whole budget.
    let (_, full) =
        train_rsfnet(&frames, &cfg, &TrainOptions { patience: 0, ..quick(20, 4) }, &Progress::hidden()).unwrap();
    assert_eq!((full.steps, full.loss_history.len()), (20, 4));
}

#[test]
fn same_seed_gives_identical_embeddings() {
    let frames = moving_square(12, 32);
    let cfg = RsfConfig::tiny();
    let run = |seed| {
        let (embedder, summary) = train_rsfnet(&frames, &cfg, &quick(4, seed), &Progress::hidden()).unwrap();
        assert!(summary.trained && summary.steps == 5, "{summary:?}"); // rounded up to one epoch of 5
        embedder.embed(&frames)
    };
    let first = run(5);
    assert_eq!(first, run(5));
    assert_ne!(first, run(6));
}

#[test]
fn training_lowers_the_loss_and_ranks_neighbours_closer() {
    let frames = moving_square(24, 32);
    let cfg = RsfConfig::tiny();
    let started = Instant::now();
    let opts = quick(80, 11);
    let (trained, summary) = train_rsfnet(&frames, &cfg, &opts, &Progress::hidden()).unwrap();
    let secs = started.elapsed().as_secs_f64();
    let (untrained, none) =
        train_rsfnet(&frames, &cfg, &TrainOptions { use_distance_loss: false, ..opts.clone() }, &Progress::hidden())
            .unwrap();
    assert!(!none.trained && none.steps == 0);

    // Held-out triplets (a seed the training never drew from).
    let planes = clip_planes(&frames, cfg.input_side);
    let held = TripletSampler::new(&planes, &opts).draw_many(&mut inbetween_core::seed::rng(424242), 400);
    let (e_before, e_after) = (untrained.embed(&frames), trained.embed(&frames));
    let (loss_before, loss_after) = (mean_loss(&e_before, &held), mean_loss(&e_after, &held));
    let (agree_before, agree_after) = (agreement(&e_before, &held), agreement(&e_after, &held));
    let h = &summary.loss_history;
    let (g_before, g_after) = (graph_from_embeddings(&e_before), graph_from_embeddings(&e_after));
    let (nn_before, nn_after) = (g_before.nearest_within(3), g_after.nearest_within(3));
    // Chance that a random other frame is within ±3: about 6/23.
    let chance =
        (1..24).map(|i: usize| (0..24).filter(|&j| j != i && j.abs_diff(i) <= 3).count() as f64 / 23.0).sum::<f64>()
            / 23.0;
    println!(
        "80 steps in {secs:.1}s; epoch losses {:.3} → {:.3}; held-out loss {loss_before:.3} → {loss_after:.3}, \
         agreement {agree_before:.3} → {agree_after:.3} (summary {:.3} → {:.3}); nearest within ±3: {nn_before:.2} → {nn_after:.2} \
         (chance {chance:.2}); pixel graph {:.2}",
        h[0],
        h[h.len() - 1],
        summary.agreement_before,
        summary.agreement_after,
        pixel_graph(&frames, 32).nearest_within(3),
    );
    assert!(h[h.len() - 1] < h[0], "training loss did not fall: {h:?}");
    assert!(loss_after < loss_before, "held-out loss {loss_before} → {loss_after}");
    assert!(agree_after > 0.75 && agree_after > agree_before, "agreement {agree_before} → {agree_after}");
    assert!(nn_after >= 0.75 && nn_after > 2.0 * chance, "nearest neighbour within ±3 for {nn_after} of frames");
}

#[test]
fn cache_round_trip_and_corrupt_file_rebuild() {
    let dir = tempfile::tempdir().unwrap();
    let frames = moving_square(8, 32);
    let cfg = RsfConfig::tiny();
    let opts = quick(5, 2);
    let progress = Progress::hidden();
    let first = embeddings_cached(dir.path(), &frames, &cfg, &opts, &progress).unwrap();
    assert!(!first.from_cache && first.rejected_cache.is_none() && first.write_error.is_none());
    assert!(first.path.exists());
    assert_eq!(first.embeddings, first.embedder.embed(&frames));

    let again = embeddings_cached(dir.path(), &frames, &cfg, &opts, &progress).unwrap();
    assert!(again.from_cache);
    assert_eq!(again.key, first.key);
    assert_eq!(again.embeddings, first.embeddings);
    assert_eq!(again.summary, first.summary);
    // The loaded network is the trained one: same embeddings recomputed.
    assert_eq!(again.embedder.embed(&frames), first.embeddings);

    // Another seed or other pixels make another key.
    assert_ne!(embeddings_cached(dir.path(), &frames, &cfg, &quick(5, 3), &progress).unwrap().key, first.key);
    let mut changed = frames.clone();
    changed[3].put_pixel(0, 0, Rgb([255, 255, 255]));
    assert_ne!(cache_key(&clip_planes(&changed, 32), &cfg, &opts), first.key);

    // Corrupt files (garbage, truncated, a flipped header byte) are ignored and rebuilt.
    let good = std::fs::read(&first.path).unwrap();
    let mut flipped = good.clone();
    flipped[20] ^= 0x55;
    for bad in [b"garbage".to_vec(), good[..good.len() / 2].to_vec(), flipped] {
        std::fs::write(&first.path, &bad).unwrap();
        let rebuilt = embeddings_cached(dir.path(), &frames, &cfg, &opts, &progress).unwrap();
        assert!(!rebuilt.from_cache && rebuilt.rejected_cache.is_some());
        assert_eq!(rebuilt.embeddings, first.embeddings, "rebuilding is deterministic");
        assert!(
            embeddings_cached(dir.path(), &frames, &cfg, &opts, &progress).unwrap().from_cache,
            "the bad file was not replaced"
        );
    }
}

/// Training time of the default network on a 132-frame clip of 64×64 frames (run with `--ignored
/// --nocapture`).
#[test]
#[ignore]
fn timing_132_frames_at_64() {
    let frames = moving_square(132, 64);
    let cfg = RsfConfig::default();
    let opts = TrainOptions { seed: 1, ..TrainOptions::default() };
    let started = Instant::now();
    let (embedder, summary) = train_rsfnet(&frames, &cfg, &opts, &Progress::hidden()).unwrap();
    let train_s = started.elapsed().as_secs_f64();
    let t = Instant::now();
    let e = embedder.embed(&frames);
    let embed_s = t.elapsed().as_secs_f64();
    let g = graph_from_embeddings(&e);
    let h = &summary.loss_history;
    println!(
        "132 frames 64×64, {} steps × batch {}: train {train_s:.1}s, embed {embed_s:.2}s; loss {:.3} → {:.3}; agreement {:.3} → {:.3}; \
         nearest within ±3: {:.2} (pixel graph {:.2})",
        summary.steps,
        opts.batch,
        h[0],
        h[h.len() - 1],
        summary.agreement_before,
        summary.agreement_after,
        g.nearest_within(3),
        pixel_graph(&frames, 64).nearest_within(3),
    );
}

/// RSFNet against the plain pixel graph on the 24 real frames of `bbb_png_seq` (run with
/// `--ignored --nocapture`).
#[test]
#[ignore]
fn real_frames_bbb_png_seq() {
    inbetween_io::data::with_shared_data("video/bbb_png_seq", |dir| {
        let mut paths: Vec<_> =
            std::fs::read_dir(dir.join("video/bbb_png_seq")).unwrap().map(|e| e.unwrap().path()).collect();
        paths.sort();
        let frames: Vec<RgbImage> = paths.iter().map(|p| image::open(p).unwrap().to_rgb8()).collect();
        let cfg = RsfConfig::default();
        let opts = TrainOptions { seed: 1, ..TrainOptions::default() };
        let t = Instant::now();
        let (embedder, summary) = train_rsfnet(&frames, &cfg, &opts, &Progress::hidden()).unwrap();
        let g = graph_from_embeddings(&embedder.embed(&frames));
        let p = pixel_graph(&frames, 64);
        println!(
            "bbb_png_seq: {} frames, {} steps in {:.1}s; agreement {:.3} → {:.3}; nearest within ±1: RSFNet {:.2}, pixels {:.2}; ±3: {:.2}, {:.2}",
            frames.len(),
            summary.steps,
            t.elapsed().as_secs_f64(),
            summary.agreement_before,
            summary.agreement_after,
            g.nearest_within(1),
            p.nearest_within(1),
            g.nearest_within(3),
            p.nearest_within(3),
        );
    });
}
