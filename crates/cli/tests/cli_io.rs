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

    let (ok, text) = inbetween(&[
        "convert",
        input.to_str().unwrap(),
        "-o",
        output.to_str().unwrap(),
        "--start",
        "10",
        "--end",
        "70",
        "--fps",
        "30",
    ]);
    assert!(ok, "{text}");
    assert!(text.contains("30 frames at 30.000 fps"), "{text}");

    let (ok, text) = inbetween(&["info", output.to_str().unwrap()]);
    assert!(ok, "{text}");
    assert!(
        text.contains("joints:    31") && text.contains("frames:    30") && text.contains("duration:  0.967 s"),
        "{text}"
    );
    assert!(
        text.contains("Hips  offset") && text.contains("Xposition Yposition Zposition Zrotation Yrotation Xrotation"),
        "{text}"
    );

    assert!(text.contains("unit:      CMU units (5.6444 cm) (rest-pose height 26.7 units ≈ 151 cm"), "{text}");
    assert!(text.contains("rest pose: 26.70 units = 150.7 cm"), "{text}");

    let (ok, text) = inbetween(&["info", dir.path().join("missing.bvh").to_str().unwrap()]);
    assert!(!ok && text.contains("missing.bvh"), "{text}");
    std::fs::write(&input, "HIERARCHY\nROOT a\n{\nOFFSET 0 0\n}\n").unwrap();
    let (ok, text) = inbetween(&["convert", input.to_str().unwrap(), "-o", output.to_str().unwrap()]);
    assert!(!ok && text.contains("walk.bvh:5: expected OFFSET z"), "{text}");
}

#[test]
fn amc_input_is_converted_with_its_asf() {
    let dir = tempfile::tempdir().unwrap();
    let asf = ":units\n angle deg\n:root\n order TX TY TZ RX RY RZ\n axis XYZ\n position 0 0 0\n orientation 0 0 0\n:bonedata\n begin\n  name a\n  direction 0 1 0\n  length 2\n  axis 0 0 0 XYZ\n  dof rx\n end\n:hierarchy\n begin\n  root a\n end\n";
    let amc = ":FULLY-SPECIFIED\r\n:DEGREES\r\n1\r\nroot 0 1 2 0 0 0\r\na 10\r\n2\r\nroot 0 1 2 0 0 0\r\na 20\r\n";
    std::fs::write(dir.path().join("skel.asf"), asf).unwrap();
    std::fs::write(dir.path().join("05_01.amc"), amc).unwrap();
    let input = dir.path().join("05_01.amc");
    let (ok, text) = inbetween(&["info", input.to_str().unwrap()]);
    assert!(!ok && text.contains("05.asf"), "no ASF beside it: {text}");
    let output = dir.path().join("o.bvh");
    let asf_path = dir.path().join("skel.asf");
    let (ok, text) = inbetween(&[
        "convert",
        input.to_str().unwrap(),
        "--asf",
        asf_path.to_str().unwrap(),
        "-o",
        output.to_str().unwrap(),
    ]);
    assert!(ok, "{text}");
    assert!(text.contains("2 joints, 9 channels, 2 frames at 120.000 fps"), "{text}");
    let m = inbetween_io::load_motion(&output).unwrap();
    assert!((m.frame(1)[8] - 20.0).abs() < 1e-6, "a's Xrotation: {:?}", m.frame(1));
}

/// `info` says which length unit it reads a file in and why; a centimetre rig is recognised, and
/// `--unit` overrides (a bad one is refused with the accepted values).
#[test]
fn info_infers_the_length_unit_and_accepts_an_override() {
    let dir = tempfile::tempdir().unwrap();
    let cm = dir.path().join("cm.bvh");
    let walk = gait(&GaitParams { frames: 10, ..GaitParams::walk() });
    inbetween_io::write_bvh(&cm, &inbetween_core::units::scale_motion(&walk, 5.6444)).unwrap();
    let (ok, text) = inbetween(&["info", cm.to_str().unwrap()]);
    assert!(ok, "{text}");
    assert!(text.contains("unit:      cm (rest-pose height 151 units ≈ 151 cm in cm"), "{text}");
    let (ok, text) = inbetween(&["info", cm.to_str().unwrap(), "--unit", "in"]);
    assert!(ok && text.contains("unit:      inches (given with --unit)"), "{text}");
    assert!(text.contains("rest pose: 150.71 units = 382.8 cm"), "{text}");
    let (ok, text) = inbetween(&["info", cm.to_str().unwrap(), "--unit", "0"]);
    assert!(!ok && text.contains("'0' is not a length unit"), "{text}");
}
