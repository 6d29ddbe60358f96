//! ASF/AMC reader on small hand-written files with known answers.

use glam::DVec3;
use inbetween_core::{forward, EulerOrder};
use inbetween_io::asf::parse_asf_amc;
use inbetween_io::{load_motion, IoError};

/// Root plus a two-bone arm along +X; bone `a` has its axis frame turned 90° about Z.
const ASF: &str = "# test skeleton\n:version 1.10\n:name T\n:units\n  mass 1.0\n  length 0.45\n  angle deg\n:documentation\n  hand written\n:root\n   order TX TY TZ RX RY RZ\n   axis XYZ\n   position 0 0 0\n   orientation 0 0 0\n:bonedata\n  begin\n     id 1\n     name a\n     direction 1 0 0\n     length 2\n     axis 0 0 90  XYZ\n    dof rx\n    limits (-180.0 180.0)\n  end\n  begin\n     id 2\n     name b\n     direction 1 0 0\n     length 1\n     axis 0 0 0 XYZ\n    dof rx ry rz\n    limits (-10.0 10.0)\n           (-inf inf)\n           (-20 20)\n  end\n:hierarchy\n  begin\n    root a\n    a b\n  end\n";

const AMC: &str = "#!OML:ASF t.asf\n# comment\n:FULLY-SPECIFIED\n:DEGREES\n1\nroot 1 2 3 0 0 0\na 90\nb 0 0 0\n2\nroot 1 2 3 0 0 0\nb 0 0 90\na 0\n";

fn err(asf: &str, amc: &str) -> String {
    match parse_asf_amc(asf, amc, "t.asf", "t.amc") {
        Ok(_) => panic!("expected an error"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn bone_axis_frame_conjugates_the_dof_rotation() {
    let m = parse_asf_amc(ASF, AMC, "t.asf", "t.amc").unwrap();
    let s = &m.skeleton;
    assert_eq!(s.len(), 3);
    assert_eq!(s.joint(1).name, "a");
    assert_eq!(s.joint(1).offset, DVec3::ZERO, "bones below the root start at the root");
    assert_eq!(s.joint(2).offset, DVec3::new(2.0, 0.0, 0.0), "b sits at the tip of a");
    assert_eq!(s.joint(2).end_site, Some(DVec3::new(1.0, 0.0, 0.0)));
    assert_eq!(s.joint(0).rotation_order(), Some(EulerOrder::Zyx));
    assert_eq!(m.num_channels(), 12);
    assert_eq!(m.num_frames(), 2);

    // Frame 1: rx = 90° about a's local x, which C = Rz(90°) maps to world +Y, so the arm swings
    // from +X to -Z.
    let g = forward(s, &m.pose(0));
    assert!((g.positions[0] - DVec3::new(1.0, 2.0, 3.0)).length() < 1e-12);
    assert!((g.positions[2] - DVec3::new(1.0, 2.0, 1.0)).length() < 1e-9, "{:?}", g.positions[2]);
    // Frame 2 (bones listed in another order): b turns 90° about Z, its tip points up.
    let g = forward(s, &m.pose(1));
    let tip = g.end_site(s, 2).unwrap();
    assert!((tip - DVec3::new(3.0, 3.0, 3.0)).length() < 1e-9, "{tip:?}");
}

#[test]
fn crlf_radians_and_root_order_are_honoured() {
    let base = parse_asf_amc(ASF, AMC, "t.asf", "t.amc").unwrap();
    let crlf = parse_asf_amc(&ASF.replace('\n', "\r\n"), &AMC.replace('\n', "\r\n"), "t.asf", "t.amc").unwrap();
    assert_eq!(crlf, base);
    let rad_amc = AMC
        .replace(":DEGREES", ":RADIANS")
        .replace("a 90", &format!("a {}", std::f64::consts::FRAC_PI_2))
        .replace("b 0 0 90", &format!("b 0 0 {}", std::f64::consts::FRAC_PI_2));
    let rad = parse_asf_amc(ASF, &rad_amc, "t.asf", "t.amc").unwrap();
    let worst = rad.data().iter().zip(base.data()).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    assert!(worst < 1e-9, "{worst}");
    // Root values listed rotations first.
    let swapped = ASF.replace("order TX TY TZ RX RY RZ", "order RX RY RZ TX TY TZ");
    let m = parse_asf_amc(&swapped, &AMC.replace("root 1 2 3 0 0 0", "root 0 0 0 1 2 3"), "t.asf", "t.amc").unwrap();
    assert_eq!(&m.frame(0)[..3], &[1.0, 2.0, 3.0]);
}

#[test]
fn errors_name_file_line_and_expectation() {
    let e = err(ASF, &AMC.replace("a 90\n", ""));
    assert!(e.starts_with("t.amc:5:") && e.contains("no values for 'a'"), "{e}");
    let e = err(ASF, &AMC.replace("b 0 0 0", "b 0 0"));
    assert!(e.starts_with("t.amc:8:") && e.contains("3 values for 'b'"), "{e}");
    let e = err(ASF, &AMC.replace("b 0 0 0", "b 0 0 x"));
    assert!(e.starts_with("t.amc:8:") && e.contains("'x'"), "{e}");
    let e = err(ASF, &AMC.replace("b 0 0 0", "c 0 0 0"));
    assert!(e.starts_with("t.amc:8:") && e.contains("bone named in the ASF"), "{e}");
    let e = err(ASF, &AMC.replace("\n2\n", "\n3\n"));
    assert!(e.starts_with("t.amc:9:") && e.contains("frame number 2"), "{e}");
    let e = err(ASF, &AMC.replace("a 0\n", "a 0\na 1\n"));
    assert!(e.starts_with("t.amc:13:") && e.contains("twice"), "{e}");
    let e = err(&ASF.replace("0 0 90  XYZ", "0 0 90  XYQ"), AMC);
    assert!(e.starts_with("t.asf:21:") && e.contains("axis order"), "{e}");
    let e = err(&ASF.replace("    a b\n", "    a c\n"), AMC);
    assert!(e.starts_with("t.asf:39:") && e.contains("'c'"), "{e}");
    let e = err(&ASF.replace("    a b\n", ""), AMC);
    assert!(e.starts_with("t.asf:25:") && e.contains("not connected"), "{e}");
    let e = err(&ASF.replace("dof rx ry rz", "dof rx ry"), AMC);
    assert!(e.contains("2 dof but 3 limits"), "{e}");
    let e = err(&ASF.replace("dof rx\n", "dof rx l\n"), AMC);
    assert!(e.starts_with("t.asf:22:") && e.contains("'l'"), "{e}");
    let e = err(&ASF.replace("  end\n:hierarchy", ":hierarchy"), AMC);
    assert!(e.contains("'end' closing the bone"), "{e}");
    for cut in 0..ASF.len() {
        let _ = parse_asf_amc(&ASF[..cut], AMC, "t.asf", "t.amc");
    }
    for cut in 0..AMC.len() {
        let _ = parse_asf_amc(ASF, &AMC[..cut], "t.asf", "t.amc");
    }
}

#[test]
fn load_motion_finds_the_skeleton_beside_the_amc() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("07.asf"), ASF).unwrap();
    std::fs::write(dir.path().join("07_03.amc"), AMC).unwrap();
    assert_eq!(load_motion(&dir.path().join("07_03.amc")).unwrap().num_frames(), 2);
    std::fs::write(dir.path().join("walk.asf"), ASF).unwrap();
    std::fs::write(dir.path().join("walk.amc"), AMC).unwrap();
    assert_eq!(load_motion(&dir.path().join("walk.amc")).unwrap().num_frames(), 2);
    std::fs::write(dir.path().join("lonely_1.amc"), AMC).unwrap();
    let e = load_motion(&dir.path().join("lonely_1.amc")).unwrap_err();
    assert!(matches!(e, IoError::MissingAsf { .. }));
    assert!(e.to_string().contains("lonely.asf") && e.to_string().contains("lonely_1.asf"), "{e}");
}
