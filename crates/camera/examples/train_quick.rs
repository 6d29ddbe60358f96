//! The quick training run behind the committed weights, runnable without the CLI:
//! `cargo run -p inbetween-camera --example train_quick -- MINUTES OUT.bpk CHECKPOINT_DIR [ITERS_PER_EPOCH] [BATCH] [STATIC_START] [SCENES]`
//! (`CAMERA_MAX_GAP` overrides the longest generated gap; `CAMERA_LR` the learning rate; `CAMERA_EPOCHS` the epoch count; `CAMERA_LOSS_EPS` the loss's ε;
//! `CAMERA_LR_RESTART=1` restarts the decay schedule at the checkpoint's epoch, `CAMERA_LR_DECAY_FROM=N`
//! at epoch N; `CAMERA_OVERWRITE_COMMITTED=1` allows OUT in `crates/camera/weights/`.)
//! OUT defaults to `out/camera/camera.bpk`; its card (`.json`) holds the style codes.
//! (`inbetween camera train` is the full-featured front end.)

use inbetween_camera::train::{self, TrainConfig, TrainEvent};
use std::path::PathBuf;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let minutes: f64 = args.first().map_or(Ok(20.0), |s| s.parse())?;
    let out = args.get(1).map_or_else(inbetween_camera::weights::default_train_output, PathBuf::from);
    let overwrite_committed = std::env::var("CAMERA_OVERWRITE_COMMITTED").is_ok_and(|v| v == "1");
    inbetween_camera::weights::check_output(&out, overwrite_committed)?;
    let ckpt = PathBuf::from(args.get(2).map_or("out/camera-train", |s| s));
    let mut cfg = TrainConfig { time_limit_s: Some(minutes * 60.0), ..TrainConfig::default() };
    if let Some(i) = args.get(3) {
        cfg.iters_per_epoch = i.parse()?;
    }
    if let Some(b) = args.get(4) {
        cfg.batch = b.parse()?;
    }
    if let Some(p) = args.get(5) {
        cfg.static_start = p.parse()?;
    }
    if let Some(n) = args.get(6) {
        cfg.scenes = n.parse()?;
    }
    if let Ok(g) = std::env::var("CAMERA_MAX_GAP") {
        cfg.max_gap = g.parse()?;
    }
    if let Ok(e) = std::env::var("CAMERA_LOSS_EPS") {
        cfg.loss_smoothing = e.parse()?;
    }
    if let Ok(e) = std::env::var("CAMERA_EPOCHS") {
        cfg.epochs = e.parse()?;
    }
    if let Ok(lr) = std::env::var("CAMERA_LR") {
        cfg.lr = lr.parse()?;
    }
    if std::env::var("CAMERA_LR_RESTART").is_ok_and(|v| v == "1") {
        cfg.lr_decay_from = train::epochs_done(&ckpt)?;
    }
    if let Ok(e) = std::env::var("CAMERA_LR_DECAY_FROM") {
        cfg.lr_decay_from = e.parse()?;
    }
    let t0 = std::time::Instant::now();
    let mut report = |e: TrainEvent| match e {
        TrainEvent::Iteration { epoch, iter, loss } if iter % 10 == 0 => {
            println!("  epoch {} iter {iter} loss {loss:.4} ({:.1} s)", epoch + 1, t0.elapsed().as_secs_f64())
        }
        TrainEvent::Epoch { epoch, loss, lr, seconds } => {
            println!("epoch {:>3} loss {loss:.5} lr {lr:.2e} {seconds:.0} s", epoch + 1)
        }
        _ => {}
    };
    let (model, summary) = train::train(&cfg, Some(&ckpt), &mut report)?;
    if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)?;
    }
    inbetween_camera::weights::save(&model, &summary, &out, overwrite_committed)?;
    println!(
        "done: {} epochs, {} iterations, {:.1} min, final loss {:.4}",
        summary.epochs_done,
        summary.iterations,
        summary.seconds / 60.0,
        summary.final_loss
    );
    Ok(())
}
