//! BVH reader/writer behaviour on small hand-written and generated files.

use inbetween_core::procedural::{gait, standard_skeleton, GaitParams};
use inbetween_core::{Channel, EulerOrder, Motion};
use inbetween_io::bvh::{parse_bvh, to_bvh_string, write_bvh};
use inbetween_io::{load_motion, IoError};

const TWO_JOINTS: &str = "HIERARCHY\nROOT Hips\n{\n\tOFFSET 0 0 0\n\tCHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation\n\tJOINT Chest\n\t{\n\t\tOFFSET 0 2.5 0\n\t\tCHANNELS 3 Zrotation Xrotation Yrotation\n\t\tEnd Site\n\t\t{\n\t\t\tOFFSET 0 1 0\n\t\t}\n\t}\n}\nMOTION\nFrames: 2\nFrame Time: 0.0333333\n1 2 3 10 20 30 40 50 60\n-1 -2 -3 0 0 0 1.5 -2.5 90\n";

fn err(text: &str) -> String {
    match parse_bvh(text, "t.bvh") {
        Ok(_) => panic!("expected an error for {text:?}"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn reads_channels_offsets_end_sites_and_values() {
    let m = parse_bvh(TWO_JOINTS, "t.bvh").unwrap();
    let s = &m.skeleton;
    assert_eq!(s.len(), 2);
    assert_eq!(s.joint(1).name, "Chest");
    assert_eq!(s.joint(1).parent, Some(0));
    assert_eq!(s.joint(1).offset.y, 2.5);
    assert_eq!(s.joint(1).end_site.unwrap().y, 1.0);
    assert_eq!(s.joint(1).rotation_order(), Some(EulerOrder::Zxy));
    assert_eq!(m.num_frames(), 2);
    assert_eq!(m.num_channels(), 9);
    assert!((m.frame_time - 0.0333333).abs() < 1e-12);
    assert_eq!(m.frame(1), &[-1.0, -2.0, -3.0, 0.0, 0.0, 0.0, 1.5, -2.5, 90.0]);
}

#[test]
fn crlf_mixed_line_ends_tabs_and_spaces_read_the_same() {
    let base = parse_bvh(TWO_JOINTS, "t.bvh").unwrap();
    let crlf = TWO_JOINTS.replace('\n', "\r\n");
    assert_eq!(parse_bvh(&crlf, "t.bvh").unwrap(), base);
    let mixed: String = TWO_JOINTS
        .split('\n')
        .enumerate()
        .map(|(i, l)| if i % 2 == 0 { format!("{l}\r\n") } else { format!("{l}\n") })
        .collect();
    assert_eq!(parse_bvh(&mixed, "t.bvh").unwrap(), base);
    let spaced = TWO_JOINTS.replace('\t', "   ").replace(' ', " \t  ");
    assert_eq!(parse_bvh(&spaced, "t.bvh").unwrap(), base);
}

#[test]
fn rotations_before_positions_and_six_channel_children() {
    let text = "HIERARCHY\nROOT r\n{\nOFFSET 0 0 0\nCHANNELS 6 Yrotation Xrotation Zrotation Xposition Yposition Zposition\nJOINT c {\nOFFSET 1 0 0\nCHANNELS 6 Xposition Yposition Zposition Xrotation Yrotation Zrotation\nJOINT leaf\n{\nOFFSET 0 1 0\nCHANNELS 0\n}\n}\n}\nMOTION\nFrames: 1\nFrame Time: 0.01\n90 0 0 5 6 7 1 2 3 0 0 0\n";
    let m = parse_bvh(text, "t.bvh").unwrap();
    assert_eq!(m.skeleton.joint(0).rotation_order(), Some(EulerOrder::Yxz));
    assert_eq!(m.skeleton.joint(1).channels.len(), 6);
    assert!(m.skeleton.joint(2).channels.is_empty());
    let pose = m.pose(0);
    assert_eq!(pose.translations[0], glam::DVec3::new(5.0, 6.0, 7.0));
    assert_eq!(pose.translations[1], glam::DVec3::new(1.0, 2.0, 3.0));
    // The written file reads back to the same clip.
    assert_eq!(parse_bvh(&to_bvh_string(&m), "w.bvh").unwrap(), m);
}

#[test]
fn errors_name_file_line_and_expectation() {
    let e = err(&TWO_JOINTS.replace("Frames: 2", "Frames: 3"));
    assert!(e.starts_with("t.bvh:") && e.contains("3 frames"), "{e}");
    let e = err(&TWO_JOINTS.replace("Frames: 2", "Frames: 1"));
    assert!(e.starts_with("t.bvh:20:") && e.contains("end of file after 1 frames"), "{e}");
    let e = err(&TWO_JOINTS.replace("40 50 60", "40 50"));
    assert!(e.starts_with("t.bvh:19:") && e.contains("9 values"), "{e}");
    let e = err(&TWO_JOINTS.replace("40 50 60", "40 50 60 70"));
    assert!(e.starts_with("t.bvh:19:") && e.contains("9 values"), "{e}");
    let e = err(&TWO_JOINTS.replace("1.5 -2.5", "1.5 abc"));
    assert!(e.starts_with("t.bvh:20:") && e.contains("Chest Xrotation") && e.contains("'abc'"), "{e}");
    let e = err(&TWO_JOINTS.replace("1.5 -2.5", "1.5 nan"));
    assert!(e.contains("finite number"), "{e}");
    let e = err(&TWO_JOINTS.replace("Zrotation Xrotation Yrotation", "Zrotation Xrotation Wrotation"));
    assert!(e.starts_with("t.bvh:9:") && e.contains("channel name"), "{e}");
    let e = err(&TWO_JOINTS.replace("Frame Time: 0.0333333", "Frame Time: 0"));
    assert!(e.starts_with("t.bvh:18:") && e.contains("positive frame time"), "{e}");
    let e = err(&TWO_JOINTS.replace("JOINT Chest", "JOINT Hips"));
    assert!(e.starts_with("t.bvh:6:") && e.contains("appears twice"), "{e}");
    let e = err(&TWO_JOINTS.replace("OFFSET 0 2.5 0", "OFFSET 0 2.5"));
    assert!(e.starts_with("t.bvh:9:") && e.contains("OFFSET z"), "{e}");
    let e = err(&TWO_JOINTS.replace("CHANNELS 3 Zrotation Xrotation Yrotation", "CHANNELS 2 Zrotation Xrotation"));
    assert!(e.contains("rotation channels"), "{e}");
}

#[test]
fn tiny_truncated_and_huge_inputs_fail_cleanly() {
    for text in ["", "HIER", "\u{feff}", "HIERARCHY\nROOT", "HIERARCHY\nROOT a\n{\nOFFSET 0 0"] {
        assert!(parse_bvh(text, "t.bvh").is_err());
    }
    for cut in 0..TWO_JOINTS.len() - 1 {
        let _ = parse_bvh(&TWO_JOINTS[..cut], "t.bvh");
    }
    // A declared frame count far beyond the data must not be allocated up front.
    let e = err(&TWO_JOINTS.replace("Frames: 2", "Frames: 18446744073709551615"));
    assert!(e.contains("18446744073709551615 frames"), "{e}");
    let e = err(&TWO_JOINTS.replace("Frames: 2", "Frames: 99999999999999999999999"));
    assert!(e.contains("frame count"), "{e}");
    // Deep nesting is handled without recursion.
    let mut deep = String::from("HIERARCHY\nROOT j0\n{\nCHANNELS 3 Xrotation Yrotation Zrotation\n");
    for i in 1..20_000 {
        deep.push_str(&format!("JOINT j{i}\n{{\nOFFSET 0 1 0\n"));
    }
    assert!(parse_bvh(&deep, "deep.bvh").unwrap_err().to_string().contains("end of file"));
}

#[test]
fn generated_gait_round_trips_within_print_precision() {
    let m = gait(&GaitParams::walk());
    assert_eq!(m.skeleton, standard_skeleton());
    let back = parse_bvh(&to_bvh_string(&m), "w.bvh").unwrap();
    assert_eq!(back.skeleton.joints().len(), m.skeleton.len());
    for (a, b) in back.skeleton.joints().iter().zip(m.skeleton.joints()) {
        assert_eq!(a.name, b.name);
        assert_eq!(a.parent, b.parent);
        assert_eq!(a.channels, b.channels);
        assert!((a.offset - b.offset).abs().max_element() <= 5e-7);
    }
    assert_eq!(back.num_frames(), m.num_frames());
    assert!((back.frame_time - m.frame_time).abs() < 1e-15);
    let worst = back.data().iter().zip(m.data()).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    assert!(worst <= 5.0001e-7, "worst value difference {worst}");
}

#[test]
fn write_and_load_through_files() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("walk.bvh");
    let m = gait(&GaitParams::walk()).crop(0, 10).unwrap();
    write_bvh(&path, &m).unwrap();
    let back = load_motion(&path).unwrap();
    assert_eq!(back.num_frames(), 10);
    assert_eq!(back.skeleton.joint(0).channels[..3], Channel::POSITION_XYZ);
    let missing = load_motion(&dir.path().join("nope.bvh")).unwrap_err();
    assert!(matches!(missing, IoError::Io { .. }) && missing.to_string().contains("nope.bvh"));
    assert!(matches!(load_motion(&dir.path().join("x.txt")), Err(IoError::UnknownFormat { .. })));
    std::fs::write(dir.path().join("bad.bvh"), b"HIERARCHY\nROOT \xff\n").unwrap();
    let e = load_motion(&dir.path().join("bad.bvh")).unwrap_err().to_string();
    assert!(e.contains("bad.bvh:2:") && e.contains("UTF-8"), "{e}");
}

#[test]
fn motion_new_is_what_the_reader_builds() {
    // The reader produces exactly the values of the file, in file order.
    let m = parse_bvh(TWO_JOINTS, "t.bvh").unwrap();
    let again = Motion::new(m.skeleton.clone(), m.frame_time, m.data().to_vec()).unwrap();
    assert_eq!(again, m);
}

#[test]
fn bom_lowercase_keywords_spaced_names_and_inline_braces() {
    let text = "\u{feff}hierarchy\nroot Root Bone {\n  offset 0 0 0\n  channels 3 xrotation yrotation zrotation\n  end site {\n    offset 0 1 0\n  }\n}\nmotion\nframes: 1\nframe time: 0.5\n1 2 3\n";
    let m = parse_bvh(text, "t.bvh").unwrap();
    assert_eq!(m.skeleton.joint(0).name, "Root Bone");
    assert_eq!(m.skeleton.joint(0).end_site, Some(glam::DVec3::Y));
    assert_eq!(m.frame(0), &[1.0, 2.0, 3.0]);
    assert_eq!(parse_bvh(&to_bvh_string(&m), "w.bvh").unwrap(), m);
}
