//! Upper-body action on lower-body locomotion (§4.2), and contact IK (§4.3).

use glam::DVec3;
use inbetween_core::fk::forward;
use inbetween_core::rotation::angle_between;
use inbetween_script::motion::locomotion::place_clip;
use inbetween_script::motion::{
    blend_upper, reach_contacts, walk_route, BlendParams, Contact, Limb, MotionLibrary, Rig, WalkParams,
};

#[test]
fn blend_keeps_lower_body_from_locomotion_and_upper_body_from_action() {
    let lib = MotionLibrary::procedural(0);
    let rig = Rig::standard();
    let mask = rig.upper_body_mask();
    let walk = walk_route(&[[0.0, 0.0], [0.0, 4.0]], &lib, &WalkParams::default());
    let action = &lib.retrieve("call").unwrap().clip;
    let params = BlendParams { start: 20, end: Some(80), blend_in: 6, blend_out: 6, looping: true, action_offset: 0 };
    let out = blend_upper(&walk, action, &params).unwrap();
    assert_eq!(out.num_frames(), walk.num_frames());
    for f in 0..out.num_frames() {
        let (o, w) = (out.pose(f), walk.pose(f));
        for (j, &upper) in mask.iter().enumerate() {
            if !upper {
                assert!(angle_between(o.rotations[j], w.rotations[j]) < 1e-6, "frame {f} joint {j} lower body changed");
                assert!((o.translations[j] - w.translations[j]).length() < 1e-9);
            }
        }
        let weight = params.weight(f, out.num_frames());
        if weight == 0.0 {
            assert!((0..rig.skeleton.len()).all(|j| angle_between(o.rotations[j], w.rotations[j]) < 1e-6), "frame {f}");
        }
        if weight >= 1.0 {
            let a = action.pose(params.action_frame(f, action.num_frames()));
            for (j, &upper) in mask.iter().enumerate() {
                if upper && j != rig.lower_back {
                    assert!(
                        angle_between(o.rotations[j], a.rotations[j]) < 1e-6,
                        "frame {f} joint {j} not from the action"
                    );
                }
            }
        }
    }
    // With the action at full weight the right hand is up at the head (calling), not swinging low.
    let g = forward(out.skeleton(), &out.pose(50));
    let hand = g.positions[rig.arms[1][3]];
    let head = g.positions[rig.head];
    assert!((hand - head).length() < 0.25, "hand {hand:?} head {head:?}");
}

#[test]
fn action_window_loops_or_holds() {
    let p = BlendParams { start: 10, end: Some(30), blend_in: 4, blend_out: 4, looping: true, action_offset: 0 };
    assert_eq!(p.weight(5, 100), 0.0);
    assert!(p.weight(10, 100) > 0.0 && p.weight(10, 100) < 1.0);
    assert_eq!(p.weight(20, 100), 1.0);
    assert_eq!(p.weight(30, 100), 0.0);
    assert_eq!(p.action_frame(10, 7), 0);
    assert_eq!(p.action_frame(17, 7), 0);
    let hold = BlendParams { looping: false, ..p };
    assert_eq!(hold.action_frame(25, 7), 6);
}

#[test]
fn seated_typing_meets_the_keyboard() {
    let lib = MotionLibrary::procedural(0);
    let rig = Rig::standard();
    // Sit on a chair at (2, 1) facing +X, type on a keyboard 0.38 m in front at desk height.
    let sit = place_clip(&lib.retrieve("sit").unwrap().clip, [2.0, 1.0], std::f64::consts::FRAC_PI_2).unwrap();
    let typing = &lib.retrieve("type").unwrap().clip;
    let blended = blend_upper(&sit, typing, &BlendParams::default()).unwrap();
    let g0 = forward(blended.skeleton(), &blended.pose(0));
    let pelvis = g0.positions[rig.hips];
    let keys = [DVec3::new(pelvis.x + 0.38, 0.72, pelvis.z + 0.12), DVec3::new(pelvis.x + 0.38, 0.72, pelvis.z - 0.12)];
    let window = BlendParams { start: 0, end: None, blend_in: 1, blend_out: 0, ..BlendParams::default() };
    let contacts = [
        Contact { limb: Limb::LeftArm, target: keys[1], window: window.clone() },
        Contact { limb: Limb::RightArm, target: keys[0], window },
    ];
    let (out, worst) = reach_contacts(&blended, &contacts).unwrap();
    assert!(worst < 1e-6, "hands miss the keyboard by {worst}");
    for f in [0, 20, 45, out.num_frames() - 1] {
        let g = forward(out.skeleton(), &out.pose(f));
        assert!((g.positions[rig.arms[0][3]] - keys[1]).length() < 1e-6);
        assert!((g.positions[rig.arms[1][3]] - keys[0]).length() < 1e-6);
        // The seated lower body is untouched.
        assert!(
            (g.positions[rig.legs[0][2]] - forward(sit.skeleton(), &sit.pose(f)).positions[rig.legs[0][2]]).length()
                < 1e-9
        );
    }
}
