//! `inbetween info` and `inbetween convert` on a generated walk.

use inbetween_core::procedural::{gait, GaitParams};
use std::process::Command;

fn inbetween(args: &[&str]) -> (bool, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_inbetween")).args(args).env("RUST_BACKTRACE", "0").output().unwrap();
    let text = format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    (out.status.success(), text)
}

#[test]
fn convert_crops_and_resamples_and_info_reports_it() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("walk.bvh");
    let output = dir.path().join("out.bvh");
    let walk = gait(&GaitParams { frames: 120, fps: 60.0, ..GaitParams::walk() });
    inbetween_io::write_bvh(&input, &walk).unwrap();

    let (ok, text) = inbetween(&["convert", input.to_str().unwrap(), "-o", output.to_str().unwrap(), "--start", "10", "--end", "70", "--fps", "30"]);
    assert!(ok, "{text}");
    assert!(text.contains("30 frames at 30.000 fps"), "{text}");

    let (ok, text) = inbetween(&["info", output.to_str().unwrap()]);
    assert!(ok, "{text}");
    assert!(text.contains("joints:    31") && text.contains("frames:    30") && text.contains("duration:  0.967 s"), "{text}");
    assert!(text.contains("Hips  offset") && text.contains("Xposition Yposition Zposition Zrotation Yrotation Xrotation"), "{text}");

    let (ok, text) = inbetween(&["info", dir.path().join("missing.bvh").to_str().unwrap()]);
    assert!(!ok && text.contains("missing.bvh"), "{text}");
    std::fs::write(&input, "HIERARCHY\nROOT a\n{\nOFFSET 0 0\n}\n").unwrap();
    let (ok, text) = inbetween(&["convert", input.to_str().unwrap(), "-o", output.to_str().unwrap()]);
    assert!(!ok && text.contains("walk.bvh:5: expected OFFSET z"), "{text}");
}
