//! The demo story animated: continuous motion, characters end at their targets, the sitter's
//! pelvis on the seat, walking routes clear of objects, camera shots and poses.

use std::collections::HashMap;

use inbetween_core::fk::forward;
use inbetween_script::animate::{animate, camera_pose, AnimateConfig, Animation};
use inbetween_script::builtin_scripts;
use inbetween_script::catalogue::builtin::builtin;
use inbetween_script::compose::{compose, ComposeConfig, ComposeInput, Composition};
use inbetween_script::database::SceneDatabase;
use inbetween_script::layout::grid::blocks_walking;
use inbetween_script::motion::ik::PELVIS_ABOVE_SEAT;
use inbetween_script::motion::rig::Rig;
use inbetween_script::motion::MotionLibrary;
use inbetween_script::parse::parse_script;

fn demo() -> (Composition, Animation) {
    let cat = builtin();
    let db = SceneDatabase::builtin(&cat, 2, 7);
    let parsed = parse_script(builtin_scripts::DEMO, &cat);
    let comp = compose(
        &ComposeInput { parsed: &parsed, catalogue: &cat, database: &db, pins: &HashMap::new() },
        &ComposeConfig::default(),
    );
    let lib = MotionLibrary::procedural(0);
    let anim = animate(&comp, &cat, &lib, &AnimateConfig::default());
    (comp, anim)
}

#[test]
fn demo_characters_move_continuously_and_reach_their_targets() {
    let (_comp, anim) = demo();
    eprintln!("notes: {:?}", anim.notes);
    let names: Vec<&str> = anim.characters.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names, ["Eve", "Tom"]);
    for c in &anim.characters {
        let rig = Rig::of(c.clip.skeleton().clone());
        let poses = c.clip.poses();
        assert!(poses.len() > 60, "{}: {} frames", c.name, poses.len());
        for f in 1..poses.len() {
            let d = (poses[f].translations[rig.hips] - poses[f - 1].translations[rig.hips]).length();
            assert!(d < 0.06, "{}: root jumps {d:.3} m at frame {f}", c.name);
        }
        for s in &c.segments {
            eprintln!("{} {} {}..{} {:?} contacts {}", c.name, s.verb, s.start, s.end, s.target, s.contacts.len());
            assert!(s.start <= s.end && s.end <= poses.len());
        }
        // Every targeted segment ends near its target object.
        for s in c.segments.iter().filter(|s| s.object.is_some()) {
            let o = &anim.scene.objects[s.object.unwrap()];
            let r = poses[s.end - 1].translations[rig.hips];
            let [hx, hz] = o.half_extents_xz();
            let gap = ((r.x as f32 - o.position[0]).abs() - hx)
                .max(0.0)
                .hypot(((r.z as f32 - o.position[2]).abs() - hz).max(0.0));
            let limit = if o.support.is_some() { 1.2 } else { 0.8 };
            assert!(gap < limit, "{} {} ends {gap:.2} m from {}", c.name, s.verb, o.label);
        }
    }
}

#[test]
fn sitting_puts_the_pelvis_on_the_seat() {
    let (_comp, anim) = demo();
    let mut sat = 0;
    for c in &anim.characters {
        let rig = Rig::of(c.clip.skeleton().clone());
        for s in c.segments.iter().filter(|s| s.verb == "sit") {
            for jc in &s.contacts {
                let f = (jc.start + jc.end) / 2;
                let g = forward(&rig.skeleton, &c.clip.pose(f));
                let pelvis = (g.positions[rig.legs[0][0]] + g.positions[rig.legs[1][0]]) * 0.5;
                let seat_y = jc.point[1] as f64 - PELVIS_ABOVE_SEAT;
                let obj = &anim.scene.objects[s.object.unwrap()];
                eprintln!("{}: pelvis {:.3} seat {:.3} on {}", c.name, pelvis.y - PELVIS_ABOVE_SEAT, seat_y, obj.label);
                assert!(
                    (pelvis.y - PELVIS_ABOVE_SEAT - seat_y).abs() < 0.05,
                    "{}: pelvis {:.3} over seat {seat_y:.3}",
                    c.name,
                    pelvis.y
                );
                let h = ((pelvis.x - jc.point[0] as f64).powi(2) + (pelvis.z - jc.point[2] as f64).powi(2)).sqrt();
                assert!(h < 0.1, "{}: pelvis {h:.2} m off the seat", c.name);
                sat += 1;
            }
        }
    }
    assert_eq!(sat, 2, "Eve and Tom both sit");
}

#[test]
fn walking_roots_stay_out_of_floor_objects() {
    let (_comp, anim) = demo();
    for c in &anim.characters {
        let rig = Rig::of(c.clip.skeleton().clone());
        for s in c.segments.iter().filter(|s| s.verb == "walk") {
            for f in s.start..s.end {
                let r = c.clip.pose(f).translations[rig.hips];
                for (i, o) in anim.scene.objects.iter().enumerate() {
                    if o.support.is_some() || !blocks_walking(o) || s.touching.contains(&i) {
                        continue;
                    }
                    let l = inbetween_script::layout::geom::to_local(
                        [o.position[0], o.position[2]],
                        o.yaw,
                        [r.x as f32, r.z as f32],
                    );
                    let inside = l[0].abs() < o.size[0] / 2.0 && l[1].abs() < o.size[2] / 2.0;
                    assert!(!inside, "{} walks through {} at frame {f}", c.name, o.label);
                }
            }
        }
    }
}

#[test]
fn front_camera_frames_the_characters_from_inside_the_room() {
    let (_comp, anim) = demo();
    assert_eq!(anim.camera.len(), 1);
    assert_eq!(anim.camera[0].view, "front");
    assert_eq!((anim.camera[0].start, anim.camera[0].end), (0, anim.frames()));
    let room = &anim.scene.room;
    for f in (0..anim.frames()).step_by(17) {
        let c = camera_pose(&anim, f);
        let (eye, target, fov) = (c.eye, c.target, c.fovy_deg);
        assert!(
            eye[0] >= 0.0 && eye[0] <= room.width && eye[2] >= 0.0 && eye[2] <= room.depth && eye[1] <= room.height
        );
        // The first character's chest, or on the axis of a two-shot, which frames both heads in
        // the upper third (so it aims below them).
        assert!(target[1] > 0.3 && target[1] < 1.7, "target height {}", target[1]);
        assert!(eye[2] >= target[2] - 1e-3, "front camera looks towards -z");
        assert!(fov > 20.0 && fov < 90.0);
    }
}

#[test]
fn camera_commands_cut_at_the_next_action() {
    let cat = builtin();
    let db = SceneDatabase::builtin(&cat, 2, 7);
    let text = "In the office, a desk is near a bookshelf$\nA chair is next to the desk$\ncamera left\nEve walks to the desk.\ncamera top\nEve sits on the chair.\n";
    let parsed = parse_script(text, &cat);
    let comp = compose(
        &ComposeInput { parsed: &parsed, catalogue: &cat, database: &db, pins: &HashMap::new() },
        &ComposeConfig::default(),
    );
    let anim = animate(&comp, &cat, &MotionLibrary::procedural(0), &AnimateConfig::default());
    let views: Vec<&str> = anim.camera.iter().map(|s| s.view.as_str()).collect();
    assert_eq!(views, ["left", "top"], "{:?}", anim.camera);
    let eve = &anim.characters[0];
    let sit_start =
        eve.segments.iter().find(|s| s.target.as_deref() == Some("chair")).expect("walk to the chair").start;
    assert_eq!(anim.camera[1].start, sit_start);
    assert_eq!(anim.camera[0].end, sit_start);
    let c = camera_pose(&anim, 0);
    let (eye, target) = (c.eye, c.target);
    assert!(eye[0] < target[0], "the left camera stands at lower x");
    let c = camera_pose(&anim, anim.frames() - 1);
    let (eye, target) = (c.eye, c.target);
    assert!(eye[1] > target[1] + 0.8, "the top camera looks down");
}

#[test]
fn every_builtin_story_animates() {
    let cat = builtin();
    let db = SceneDatabase::builtin(&cat, 2, 7);
    let lib = MotionLibrary::procedural(0);
    for (name, text) in builtin_scripts::all() {
        let parsed = parse_script(text, &cat);
        let comp = compose(
            &ComposeInput { parsed: &parsed, catalogue: &cat, database: &db, pins: &HashMap::new() },
            &ComposeConfig::default(),
        );
        let anim = animate(&comp, &cat, &lib, &AnimateConfig::default());
        eprintln!(
            "{name}: {} characters, {} frames, camera {:?}, notes {:?}",
            anim.characters.len(),
            anim.frames(),
            anim.camera.iter().map(|s| &s.view).collect::<Vec<_>>(),
            anim.notes
        );
        assert!(!anim.camera.is_empty());
        for c in &anim.characters {
            let rig = Rig::of(c.clip.skeleton().clone());
            let poses = c.clip.poses();
            for f in 1..poses.len() {
                let d = (poses[f].translations[rig.hips] - poses[f - 1].translations[rig.hips]).length();
                assert!(d < 0.1, "{name} {}: root jumps {d:.3} m at frame {f}", c.name);
            }
        }
    }
}

/// Common verbs have motion (issue 27): "gets up" (the parser splits it into "get" and the
/// particle "up") stands up, and put, close, give and point reach; none falls back to standing.
#[test]
fn common_verbs_have_motion_instead_of_standing() {
    let cat = builtin();
    let db = SceneDatabase::builtin(&cat, 2, 7);
    let text = "In the office, a chair is near a desk, and a door is next to a window$\nA book is on the desk$\n\
                Tom sits on the chair. Tom gets up. Tom walks to the desk. Tom picks up the book. \
                Tom puts down the book. Tom opens the door. Tom closes the door. Tom points at the window. \
                Tom gives the book to Eve. Eve waves.\n";
    let parsed = parse_script(text, &cat);
    let comp = compose(
        &ComposeInput { parsed: &parsed, catalogue: &cat, database: &db, pins: &HashMap::new() },
        &ComposeConfig::default(),
    );
    let anim = animate(&comp, &cat, &MotionLibrary::procedural(0), &AnimateConfig::default());
    let fallbacks: Vec<&String> = anim.notes.iter().filter(|n| n.contains("standing instead")).collect();
    assert!(fallbacks.is_empty(), "{fallbacks:?}");
    let tom = anim.characters.iter().find(|c| c.name == "Tom").unwrap();
    let verbs: Vec<&str> = tom.segments.iter().map(|s| s.verb.as_str()).collect();
    assert!(verbs.contains(&"stand_up"), "{verbs:?}");
}
