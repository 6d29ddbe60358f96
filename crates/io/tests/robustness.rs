//! Property tests: no input makes the readers panic, and generated clips round-trip through BVH.

use glam::DVec3;
use inbetween_core::procedural::{gait, GaitParams};
use inbetween_core::{positions_clip, Channel, EulerOrder, Joint, Motion, Skeleton};
use inbetween_io::asf::parse_asf_amc;
use inbetween_io::bvh::{parse_bvh, to_bvh_string};
use proptest::prelude::*;

const ASF: &str = ":units\n angle deg\n:root\n order TX TY TZ RX RY RZ\n axis XYZ\n position 0 0 0\n orientation 0 0 0\n:bonedata\n begin\n  name a\n  direction 0 1 0\n  length 2\n  axis 0 0 30 XYZ\n  dof rx rz\n  limits (-90 90)\n   (-90 90)\n end\n begin\n  name b\n  direction 1 0 0\n  length 1\n  axis 10 0 0 ZYX\n  dof ry\n end\n:hierarchy\n begin\n  root a\n  a b\n end\n";
const AMC: &str = ":FULLY-SPECIFIED\r\n:DEGREES\r\n1\r\nroot 0 1 2 3 4 5\r\na 10 20\r\nb 30\r\n2\r\nroot 0 1 2 3 4 5\r\na 10 20\r\nb 30\r\n";

fn small_bvh() -> String {
    to_bvh_string(&gait(&GaitParams::walk()).crop(0, 3).unwrap())
}

/// Applies byte-level edits (replace, delete, duplicate) at positions chosen by the strategy.
fn mutate(text: &str, edits: &[(usize, u8, u8)]) -> Vec<u8> {
    let mut bytes = text.as_bytes().to_vec();
    for &(pos, kind, byte) in edits {
        if bytes.is_empty() {
            break;
        }
        let p = pos % bytes.len();
        match kind % 3 {
            0 => bytes[p] = byte,
            1 => {
                let end = (p + 1 + byte as usize % 16).min(bytes.len());
                bytes.drain(p..end);
            }
            _ => {
                let end = (p + 1 + byte as usize % 16).min(bytes.len());
                let chunk = bytes[p..end].to_vec();
                bytes.splice(p..p, chunk);
            }
        }
    }
    bytes
}

/// A random skeleton in depth-first order (each joint's parent is the previous joint or one of its
/// ancestors) with every channel layout BVH allows.
fn skeleton_strategy() -> impl Strategy<Value = Skeleton> {
    let joint =
        (any::<prop::sample::Index>(), 0usize..7, 0usize..6, prop::array::uniform3(-50.0f64..50.0), any::<bool>());
    prop::collection::vec(joint, 1..8).prop_map(|specs| {
        let mut joints: Vec<Joint> = Vec::new();
        let mut path: Vec<usize> = Vec::new(); // the chain from the root to the previous joint
        for (i, (pick, layout, order, offset, end)) in specs.into_iter().enumerate() {
            let parent = if i == 0 { None } else { Some(path[pick.index(path.len())]) };
            if let Some(p) = parent {
                let keep = path.iter().position(|&x| x == p).unwrap() + 1;
                path.truncate(keep);
            }
            path.push(i);
            let rot = Channel::rotations(EulerOrder::ALL[order]).to_vec();
            let pos = Channel::POSITION_XYZ.to_vec();
            let channels = match layout {
                0 => Vec::new(),
                1 => rot,
                2 => [pos, rot].concat(),
                3 => [rot, pos].concat(),
                4 => pos,
                5 => vec![Channel::Zposition, rot[0], Channel::Xposition, rot[1], rot[2], Channel::Yposition],
                _ => rot,
            };
            joints.push(Joint {
                name: format!("j{i}_{layout}"),
                parent,
                offset: DVec3::from(offset),
                channels,
                end_site: end.then_some(DVec3::new(0.0, 1.0, 0.5)),
            });
        }
        Skeleton::new(joints).unwrap()
    })
}

fn motion_strategy() -> impl Strategy<Value = Motion> {
    (skeleton_strategy(), 0usize..5, 1u32..240).prop_flat_map(|(s, frames, fps)| {
        let n = s.num_channels() * frames;
        prop::collection::vec(-400.0f64..400.0, n..=n)
            .prop_map(move |data| Motion::new(s.clone(), 1.0 / fps as f64, data).unwrap())
    })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, rng_seed: proptest::test_runner::RngSeed::Fixed(inbetween_core::seed::PROPTEST_SEED), ..ProptestConfig::default() })]

    #[test]
    fn arbitrary_bytes_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..512)) {
        let text = String::from_utf8_lossy(&bytes);
        let _ = parse_bvh(&text, "fuzz.bvh");
        let _ = parse_asf_amc(&text, AMC, "fuzz.asf", "t.amc");
        let _ = parse_asf_amc(ASF, &text, "t.asf", "fuzz.amc");
    }

    #[test]
    fn mutated_valid_files_never_panic(edits in prop::collection::vec((any::<usize>(), any::<u8>(), any::<u8>()), 1..6)) {
        let bvh = small_bvh();
        let _ = parse_bvh(&String::from_utf8_lossy(&mutate(&bvh, &edits)), "m.bvh");
        let _ = parse_asf_amc(&String::from_utf8_lossy(&mutate(ASF, &edits)), AMC, "m.asf", "t.amc");
        let _ = parse_asf_amc(ASF, &String::from_utf8_lossy(&mutate(AMC, &edits)), "t.asf", "m.amc");
    }

    #[test]
    fn generated_motions_round_trip_through_bvh(m in motion_strategy()) {
        let back = parse_bvh(&to_bvh_string(&m), "gen.bvh").unwrap();
        prop_assert_eq!(back.skeleton.len(), m.skeleton.len());
        for (a, b) in back.skeleton.joints().iter().zip(m.skeleton.joints()) {
            prop_assert_eq!(&a.name, &b.name);
            prop_assert_eq!(a.parent, b.parent);
            prop_assert_eq!(&a.channels, &b.channels);
            prop_assert!((a.offset - b.offset).abs().max_element() <= 5e-7);
            prop_assert_eq!(a.end_site.is_some(), b.end_site.is_some());
        }
        prop_assert_eq!(back.num_frames(), m.num_frames());
        prop_assert!((back.frame_time - m.frame_time).abs() <= 1e-15);
        for (a, b) in back.data().iter().zip(m.data()) {
            prop_assert!((a - b).abs() <= 5.0001e-7, "{} vs {}", a, b);
        }
    }
}

#[test]
fn valid_fixtures_parse() {
    assert_eq!(parse_bvh(&small_bvh(), "w.bvh").unwrap().num_frames(), 3);
    assert_eq!(parse_asf_amc(ASF, AMC, "t.asf", "t.amc").unwrap().num_frames(), 2);
}

#[test]
fn non_depth_first_skeletons_are_reordered_but_move_the_same() {
    let rot = Channel::rotations(EulerOrder::Zyx).to_vec();
    let j = |name: &str, parent: Option<usize>, x: f64| Joint {
        name: name.into(),
        parent,
        offset: DVec3::new(x, 1.0, 0.0),
        channels: rot.clone(),
        end_site: None,
    };
    // Breadth-first: root, a, b, a_child.
    let s = Skeleton::new(vec![
        j("root", None, 0.0),
        j("a", Some(0), 1.0),
        j("b", Some(0), -1.0),
        j("a_child", Some(1), 2.0),
    ])
    .unwrap();
    let data: Vec<f64> = (0..24).map(|i| i as f64 * 7.0 - 60.0).collect();
    let m = Motion::new(s, 0.04, data).unwrap();
    let back = parse_bvh(&to_bvh_string(&m), "w.bvh").unwrap();
    let names: Vec<&str> = back.skeleton.joints().iter().map(|j| j.name.as_str()).collect();
    assert_eq!(names, ["root", "a", "a_child", "b"]);
    let (pa, pb) = (positions_clip(&m), positions_clip(&back));
    for (fa, fb) in pa.iter().zip(&pb) {
        for (i, joint) in m.skeleton.joints().iter().enumerate() {
            let k = back.skeleton.find(&joint.name).unwrap();
            assert!((fa[i] - fb[k]).length() < 1e-5);
        }
    }
}
