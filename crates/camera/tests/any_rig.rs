//! Camera generation from two takes on any rig (issue 42): the procedural walk and run, and real CMU
//! and Character Creator takes, renamed to every naming scheme and to bare names (roles by shape),
//! give the same scene as the original names, and a camera track through it.

use inbetween_camera::dataset::{scene_from_motions, scene_from_motions_with, Behaviour, Scene};
use inbetween_camera::infer::{example_keys, GenerateJob};
use inbetween_camera::weights::committed;
use inbetween_core::procedural::{gait, GaitParams};
use inbetween_core::roles::fixtures::{bare, renamed, reordered, with_skeleton};
use inbetween_core::roles::{RoleOverrides, Scheme};
use inbetween_core::Motion;

/// Every rig a pair of takes is tried on: each scheme, bare names, bare names right side first.
fn variants(m: &Motion) -> Vec<(String, Motion)> {
    let mut out: Vec<(String, Motion)> =
        Scheme::ALL.iter().map(|s| (format!("{s:?}"), with_skeleton(m, renamed(&m.skeleton, *s)))).collect();
    out.push(("bare".into(), with_skeleton(m, bare(&m.skeleton))));
    let r = reordered(m);
    out.push(("bare, right side first".into(), with_skeleton(&r, bare(&r.skeleton))));
    out
}

fn same_scene(a: &Scene, b: &Scene, what: &str) {
    for (ca, cb) in a.characters.iter().zip(&b.characters) {
        for (f, (x, y)) in ca.root.iter().zip(&cb.root).enumerate() {
            assert!(x.distance(*y) < 1e-9, "{what}: root at frame {f}: {x} vs {y}");
        }
        for (x, y) in ca.shoulder_l.iter().zip(&cb.shoulder_l).chain(ca.shoulder_r.iter().zip(&cb.shoulder_r)) {
            assert!(x.distance(*y) < 1e-9, "{what}: shoulder {x} vs {y}");
        }
    }
}

/// Generates an orbit track over `scene` and checks it hits its keys.
fn camera_over(scene: &Scene, what: &str) {
    let w = committed().unwrap();
    let last = scene.num_frames() - 1;
    let keys = example_keys(scene, &[0, last / 2, last]);
    let style = w.style(Behaviour::Orbit).unwrap();
    let track = GenerateJob::new(&w.model, scene, &keys, &style).run().unwrap_or_else(|e| panic!("{what}: {e}"));
    assert_eq!(track.frames.len(), scene.num_frames(), "{what}");
    assert!(track.max_corrected_residual < 1e-3, "{what}: keys missed by {}", track.max_corrected_residual);
}

fn check_pair(a: &Motion, b: &Motion, label: &str) {
    let (reference, _) = scene_from_motions(&[("a", a), ("b", b)]).unwrap();
    let (va, vb) = (variants(a), variants(b));
    for ((name, ma), (_, mb)) in va.iter().zip(&vb) {
        let what = format!("{label} as {name}");
        let (scene, notes) = scene_from_motions(&[("a", ma), ("b", mb)]).unwrap_or_else(|e| panic!("{what}: {e}"));
        same_scene(&reference, &scene, &what);
        let by = if name.starts_with("bare") { "by shape" } else { "by name" };
        assert!(notes.lines[0].contains(by), "{what}: {:?}", notes.lines);
        camera_over(&scene, &what);
    }
}

#[test]
fn two_procedural_takes_on_every_rig_give_the_same_scene_and_a_camera() {
    let a = gait(&GaitParams { frames: 60, ..GaitParams::walk() });
    let b = gait(&GaitParams { frames: 60, ..GaitParams::run() });
    check_pair(&a, &b, "procedural walk + run");
}

#[test]
fn a_roles_file_reads_a_rig_neither_names_nor_shape_settle() {
    // No toes and bare names: the shape still reads it (facing +Z assumed) and says so.
    let a = gait(&GaitParams { frames: 30, ..GaitParams::walk() });
    let toeless = a.filter_joints(|_, j| !j.name.contains("Toe"));
    let s = bare(&toeless.skeleton);
    let m = with_skeleton(&toeless, s.clone());
    let (scene, _) = scene_from_motions(&[("a", &m), ("b", &m)]).unwrap();
    // A roles file swapping the arms (clavicle to hand) swaps the shoulders in the scene.
    use inbetween_core::roles::{Role, Side};
    let mut o = RoleOverrides::default();
    let named = |n: &str| s.joint(toeless.skeleton.find(n).unwrap()).name.clone();
    for (side, other) in [(Side::Left, "Right"), (Side::Right, "Left")] {
        for (role, part) in [
            (Role::Clavicle(side), "Shoulder"),
            (Role::UpperArm(side), "Arm"),
            (Role::Forearm(side), "ForeArm"),
            (Role::Hand(side), "Hand"),
        ] {
            o.joints.insert(role, named(&format!("{other}{part}")));
        }
    }
    let (swapped, notes) = scene_from_motions_with(&[("a", &m), ("b", &m)], &o).unwrap();
    assert!(notes.lines[0].contains("roles file"), "{:?}", notes.lines);
    assert!(swapped.characters[0].shoulder_l[0].distance(scene.characters[0].shoulder_r[0]) < 1e-9);
}

#[test]
fn real_takes_on_every_rig_give_the_same_scene_and_a_camera() {
    inbetween_io::data::with_shared_data("mocap/cmu (cgspeed, iclone_cc)", |data| {
        let cmu = data.join("mocap/cmu");
        let load = |p: &str, frames: usize| {
            let m = inbetween_io::load_motion(&cmu.join(p)).unwrap();
            m.crop(1, frames.min(m.num_frames())).unwrap()
        };
        // Two cgspeed releases (MotionBuilder names; the 3ds Max release's own names).
        check_pair(&load("cgspeed/01_01.bvh", 240), &load("cgspeed/131_01.bvh", 240), "CMU 01_01 + 131_01");
        // Character Creator: 100 and 101 joints with twist, share and finger bones.
        let (a, b) = (load("iclone_cc/002_01.bvh", 120), load("iclone_cc/001_08.bvh", 120));
        let (reference, notes) = scene_from_motions(&[("a", &a), ("b", &b)]).unwrap();
        assert!(notes.lines.iter().all(|l| l.contains("CC_Base_L_Upperarm")), "{:?}", notes.lines);
        let bare_a = with_skeleton(&a, bare(&a.skeleton));
        let bare_b = with_skeleton(&b, bare(&b.skeleton));
        let (scene, _) = scene_from_motions(&[("a", &bare_a), ("b", &bare_b)]).unwrap();
        same_scene(&reference, &scene, "Character Creator with bare names");
        camera_over(&scene, "Character Creator with bare names");
    });
}
