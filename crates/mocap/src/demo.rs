//! The mocap part of `inbetween demo`: on a procedural walk (no files needed), the optimal, uniform
//! and SIDQL keys and their errors, the keyframe codec at 1 cm, the rebuilt clip as BVH and an
//! overlay GIF of the original and its reconstruction.

use crate::codec::{self, Budget};
use crate::dqn::SidqlPolicy;
use crate::metrics::{ErrorMeasure, SegmentModel, SegmentTable};
use crate::representation::{JointFilter, SphericalMotion};
use crate::rotations::RotationMotion;
use crate::{MocapError, Result};
use inbetween_core::procedural::{gait, GaitParams};
use inbetween_core::Motion;
use inbetween_io::Progress;
use inbetween_render::StickOptions;
use std::path::Path;
use std::time::Instant;

/// The demo's procedural walk at `k`× its length (60·k frames at 30 fps; `mocap scale` runs it).
pub fn scaled_walk(k: usize) -> Motion {
    gait(&GaitParams { frames: 60 * k, ..GaitParams::walk() })
}

/// The demo's opening walk: a procedural walk jittered by `seed` (150 frames, turning), written
/// as `walk.bvh` with its preview `walk.gif` into `out` (which must exist); returns the line to print.
pub fn opening_walk(out: &Path, seed: u64) -> Result<String> {
    let walk = gait(&GaitParams { frames: 150, turn_rate: 0.35, ..GaitParams::walk().jittered(seed, 0.15) });
    let bvh = out.join("walk.bvh");
    inbetween_io::bvh::write_bvh(&bvh, &walk)?;
    let gif = out.join("walk.gif");
    let opts = StickOptions { title: Some(format!("procedural walk (seed {seed})")), ..Default::default() };
    inbetween_render::stick::render_motion_gif(&gif, &[&walk], &opts).map_err(|e| MocapError::Io {
        path: gif.display().to_string(),
        source: std::io::Error::other(e.to_string()),
    })?;
    Ok(format!(
        "walk: {} frames at {:.0} fps, {} joints -> {} and {}",
        walk.num_frames(),
        walk.fps(),
        walk.skeleton.len(),
        bvh.display(),
        gif.display()
    ))
}

/// The steps [`run`] counts on its progress bar.
pub const STEPS: u64 = 4;

/// Runs the demo, writes `mocap_walk.ibk`, `mocap_walk_reconstructed.bvh` and `mocap_overlay.gif`
/// into `out` (which must exist) and returns the lines to print. Counts [`STEPS`] steps on
/// `progress`.
pub fn run(out: &Path, progress: &Progress) -> Result<Vec<String>> {
    let t = Instant::now();
    let walk = scaled_walk(1);
    let paper = JointFilter::paper().apply(&walk);
    let rep = SphericalMotion::from_motion(&paper)?;
    let table = SegmentTable::full(&rep);
    let mut lines = vec![format!(
        "mocap: procedural walk, {} frames at {:.0} fps, {} joints (paper representation)",
        rep.num_frames,
        walk.fps(),
        rep.num_joints
    )];
    let sidql = SidqlPolicy::committed()?;
    for k in [5, 10] {
        lines.push(compare_selectors(&rep, &table, &sidql, k)?);
    }
    progress.inc(1);
    let c = codec::compress(&walk, Budget::MaxErrorCm(1.0), 15)?;
    lines.push(format!("  codec (31 joints, ≤ 1 cm): {}", codec_line(&walk, &c)));
    let ibk = out.join("mocap_walk.ibk");
    inbetween_io::write_atomic(&ibk, &c.bytes)
        .map_err(|source| MocapError::Io { path: ibk.display().to_string(), source })?;
    let rec = codec::decode(&c.bytes)?.reconstruct()?;
    let bvh = out.join("mocap_walk_reconstructed.bvh");
    inbetween_io::write_bvh(&bvh, &rec)?;
    progress.inc(1);
    let gif = out.join("mocap_overlay.gif");
    let opts = StickOptions {
        labels: vec!["original".into(), format!("from {} keys", c.keys.len())],
        title: Some(format!("mocap codec: {} keys, max {:.2} cm", c.keys.len(), c.decoded_max_cm)),
        max_frames: 60,
        ..StickOptions::default()
    };
    inbetween_render::render_motion_gif(&gif, &[&walk, &rec], &opts).map_err(|e| MocapError::Io {
        path: gif.display().to_string(),
        source: std::io::Error::other(e.to_string()),
    })?;
    progress.inc(1);
    // The rotation model is the one the codec uses; say how it compares to the spherical one.
    let rm = RotationMotion::from_motion(&paper)?;
    let k10 = crate::select::optimal(&table, 10, ErrorMeasure::Angle)?;
    lines.push(format!(
        "  K=10 on {} joints: rotation reconstruction mean {:.2} cm vs spherical {:.2} cm",
        rep.num_joints,
        rm.error(&k10).mean_cm,
        rep.error(&k10).mean_cm
    ));
    lines.push(format!(
        "  wrote {}, {}, {} ({:.1} s)",
        ibk.display(),
        bvh.display(),
        gif.display(),
        t.elapsed().as_secs_f64()
    ));
    progress.inc(1);
    Ok(lines)
}

/// One line: the optimal, uniform and SIDQL keys for `k` and their errors.
fn compare_selectors(rep: &SphericalMotion, table: &SegmentTable, sidql: &SidqlPolicy, k: usize) -> Result<String> {
    let opt = crate::select::optimal(table, k, ErrorMeasure::Angle)?;
    let uc = crate::select::uniform(rep.num_frames, k)?;
    let sq = sidql.select(rep, k)?;
    let (eo, eu, es) = (rep.error(&opt), rep.error(&uc), rep.error(&sq));
    Ok(format!(
        "  K={k:<2} optimal keys {:?}: angle err {:.4}, mean {:.2} cm, max {:.2} cm | uniform: {:.4}, {:.2} cm, {:.2} cm | SIDQL (committed policy): {:.4}, {:.2} cm, {:.2} cm",
        opt.frames(),
        eo.mean_angle,
        eo.mean_cm,
        eo.max_cm,
        eu.mean_angle,
        eu.mean_cm,
        eu.max_cm,
        es.mean_angle,
        es.mean_cm,
        es.max_cm
    ))
}

/// Size and error of a compressed clip in one line.
fn codec_line(m: &Motion, c: &codec::Compressed) -> String {
    let raw = codec::raw_bytes(m);
    format!(
        "{} frames, {} keys; {} bytes vs {} raw f32 bytes: ratio {:.1}x; decoded error mean {:.3} cm, max {:.3} cm; mean local rotation error {:.3} deg",
        m.num_frames(),
        c.keys.len(),
        c.bytes.len(),
        raw,
        raw as f64 / c.bytes.len() as f64,
        c.decoded_mean_cm,
        c.decoded_max_cm,
        c.planned.mean_angle.to_degrees()
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_opening_walk_is_seeded_and_written_with_its_preview() {
        let dir = tempfile::tempdir().unwrap();
        let line = opening_walk(dir.path(), 1).unwrap();
        assert!(line.starts_with("walk: 150 frames at 30 fps, 31 joints -> "), "{line}");
        let first = std::fs::read(dir.path().join("walk.bvh")).unwrap();
        assert!(std::fs::metadata(dir.path().join("walk.gif")).unwrap().len() > 1000);
        opening_walk(dir.path(), 2).unwrap();
        assert_ne!(std::fs::read(dir.path().join("walk.bvh")).unwrap(), first, "the seed changes the walk");
    }

    #[test]
    fn the_demo_writes_its_files_and_reports_every_selector() {
        let dir = tempfile::tempdir().unwrap();
        let progress = Progress::hidden();
        let lines = run(dir.path(), &progress).unwrap();
        assert_eq!(progress.position(), 4);
        assert!(lines[0].contains("60 frames at 30 fps, 23 joints"), "{}", lines[0]);
        assert!(lines.iter().any(|l| l.starts_with("  K=5 ") && l.contains("SIDQL")), "{lines:?}");
        assert!(lines.iter().any(|l| l.contains("codec (31 joints")), "{lines:?}");
        let bytes = std::fs::read(dir.path().join("mocap_walk.ibk")).unwrap();
        let decoded = codec::decode(&bytes).unwrap();
        assert_eq!(decoded.num_frames, 60);
        let bvh = inbetween_io::read_bvh(&dir.path().join("mocap_walk_reconstructed.bvh")).unwrap();
        assert_eq!(bvh.num_frames(), 60);
        let gif = std::fs::read(dir.path().join("mocap_overlay.gif")).unwrap();
        assert!(gif.starts_with(b"GIF89a"));
    }
}
