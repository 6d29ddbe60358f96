//! `inbetween info` prints each joint role and how it was found (issue 42).

use inbetween_core::procedural::{gait, GaitParams};
use inbetween_core::roles::fixtures::{bare, chain, renamed, with_skeleton};
use inbetween_core::roles::Scheme;
use std::process::Command;

fn info(path: &std::path::Path, extra: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_inbetween")).arg("info").arg(path).args(extra).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8_lossy(&out.stdout).into_owned()
}

#[test]
fn info_prints_roles_by_name_by_shape_from_a_roles_file_or_why_none() {
    let dir = tempfile::tempdir().unwrap();
    let walk = gait(&GaitParams { frames: 10, ..GaitParams::walk() });
    let p = dir.path().join("walk.bvh");
    let mixamo = with_skeleton(&walk, renamed(&walk.skeleton, Scheme::Mixamo));
    std::fs::write(&p, inbetween_io::to_bvh_string(&mixamo)).unwrap();
    let text = info(&p, &[]);
    assert!(text.contains("roles:     21 of 21 (names read as Mixamo; confidence 1.00)"), "{text}");
    assert!(text.contains("left_upper_arm  mixamorig:LeftArm"), "{text}");
    assert!(text.contains("name (Mixamo)"), "{text}");

    let plain = with_skeleton(&walk, bare(&walk.skeleton));
    std::fs::write(&p, inbetween_io::to_bvh_string(&plain)).unwrap();
    let text = info(&p, &[]);
    assert!(text.contains("(no known names; confidence 0.90)"), "{text}");
    assert!(text.contains("shape, confidence 1.00") && text.contains("between the roles found"), "{text}");
    let roles = dir.path().join("roles.json");
    std::fs::write(&roles, r#"{"head": "j15"}"#).unwrap();
    let text = info(&p, &["--roles", roles.to_str().unwrap()]);
    assert!(text.lines().any(|l| l.contains("head") && l.contains("j15") && l.contains("roles file")), "{text}");

    let tail = inbetween_core::Motion::new(chain(), 1.0 / 30.0, vec![0.0; 2 * chain().num_channels()]).unwrap();
    std::fs::write(&p, inbetween_io::to_bvh_string(&tail)).unwrap();
    let text = info(&p, &[]);
    assert!(text.contains("roles:     none: not a humanoid skeleton") && text.contains("given as --roles"), "{text}");
}
