//! Animated outputs: the animated glTF re-parses with consistent buffers, one key per frame,
//! bounds on positions and key times, the skeleton's hierarchy and rest offsets, unit quaternions
//! and joint positions equal to core FK; BVH round-trips with its unit sidecar; the preview GIF
//! decodes with the expected frame count and size and shows the figure moving; the route plan has
//! the character's colour along the route.

use std::collections::HashMap;
use std::path::Path;

use glam::{DQuat, DVec3, Quat, Vec3};
use image::AnimationDecoder;
use inbetween_core::camera::AimedCamera;
use inbetween_core::clip::Clip;
use inbetween_core::fk::forward;
use inbetween_script::catalogue::builtin::builtin;
use inbetween_script::motion::{walk_route, MotionLibrary, WalkParams};
use inbetween_script::output::anim_gltf::{animation_frames, ANIMATION_NAME, CHARACTER_COLORS};
use inbetween_script::output::anim_preview::{plan_pixel, preview_frame_indices, preview_frames, root_route};
use inbetween_script::output::bvh_out::bvh_sidecar_path;
use inbetween_script::output::gltf::{base64_decode, parse_glb};
use inbetween_script::output::{
    animated_gltf_document, render_preview_gif, render_top_down_trails, write_animated_gltf, write_character_bvh,
    AnimPreviewOptions,
};
use inbetween_script::scene::{Room, Scene};
use serde_json::Value;

mod common;
use common::{accessor_floats, check_buffers, obj};

fn scene() -> Scene {
    Scene {
        room: Room { name: "office".into(), width: 5.0, depth: 4.0, height: 2.8 },
        objects: vec![
            obj("desk", "desk", [1.0, 0.0, 0.35], 0.0, [1.4, 0.75, 0.7]),
            obj("chair", "chair", [1.0, 0.0, 1.2], std::f32::consts::PI, [0.5, 0.9, 0.5]),
            obj("bed", "bed", [3.9, 0.0, 1.6], -std::f32::consts::FRAC_PI_2, [1.6, 0.5, 2.1]),
        ],
        camera: vec!["front".into()],
        weather: None,
    }
}

/// A straight walk across the room (procedural library, no shared data needed).
fn walk() -> Clip {
    walk_route(&[[0.6, 3.1], [4.4, 3.1]], &MotionLibrary::procedural(0), &WalkParams::default())
}

/// A camera in front of the room panning slowly with the frame.
fn camera(f: usize) -> AimedCamera {
    let x = 1.5 + 0.01 * f as f32;
    AimedCamera { eye: Vec3::new(x, 2.4, 8.5), target: Vec3::new(2.5, 0.8, 2.0), fovy_deg: 45.0 }
}

fn parents_by_node(doc: &Value) -> HashMap<usize, usize> {
    let mut parent = HashMap::new();
    for (i, n) in doc["nodes"].as_array().unwrap().iter().enumerate() {
        for c in n["children"].as_array().into_iter().flatten() {
            assert!(parent.insert(c.as_u64().unwrap() as usize, i).is_none(), "node with two parents");
        }
    }
    parent
}

/// Checks the animation against the motion; returns the number of key frames of the camera.
fn check_animation(doc: &Value, bin: &[u8], name: &str, m: &Clip, fps: f64) {
    check_buffers(doc, bin);
    let nodes = doc["nodes"].as_array().unwrap();
    let parent = parents_by_node(doc);
    let scene_roots: Vec<usize> =
        doc["scenes"][0]["nodes"].as_array().unwrap().iter().map(|v| v.as_u64().unwrap() as usize).collect();
    // The static scene is still there.
    assert!(nodes.iter().any(|n| n["name"] == "desk"));
    // Character: a scene root named `name` whose one child is the skeleton's root joint.
    let root = *scene_roots.iter().find(|&&r| nodes[r]["name"] == name).expect("character root node");
    let hips = nodes[root]["children"][0].as_u64().unwrap() as usize;
    let sk = m.skeleton();
    assert_eq!(nodes[hips]["name"], sk.joint(0).name.as_str());
    // Joint nodes: below the character root, named by joint, parented as in the skeleton, rest offsets.
    let under = |mut k: usize| {
        while let Some(&p) = parent.get(&k) {
            if p == root {
                return true;
            }
            k = p;
        }
        false
    };
    let mut joint_node = vec![usize::MAX; sk.len()];
    for (k, n) in nodes.iter().enumerate() {
        if let Some(j) = n["name"].as_str().and_then(|s| sk.find(s)) {
            if under(k) || k == hips {
                joint_node[j] = k;
            }
        }
    }
    for (j, joint) in sk.joints().iter().enumerate() {
        let k = joint_node[j];
        assert!(k != usize::MAX, "no node for joint {}", joint.name);
        if let Some(p) = joint.parent {
            assert_eq!(parent[&k], joint_node[p], "parent of {}", joint.name);
            let t: Vec<f64> = nodes[k]["translation"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
            assert!((DVec3::new(t[0], t[1], t[2]) - joint.offset).length() < 1e-5, "rest offset of {}", joint.name);
        }
    }
    // A visible body: mesh nodes under joint nodes.
    let bodies = nodes.iter().enumerate().filter(|(k, n)| n.get("mesh").is_some() && under(*k)).count();
    assert!(bodies >= 20, "{bodies} body boxes");

    let anims = doc["animations"].as_array().unwrap();
    assert_eq!(anims.len(), 1);
    let anim = &anims[0];
    assert_eq!(anim["name"], ANIMATION_NAME);
    let samplers = anim["samplers"].as_array().unwrap();
    let mut keyed: HashMap<(usize, String), Vec<f32>> = HashMap::new();
    for ch in anim["channels"].as_array().unwrap() {
        let s = &samplers[ch["sampler"].as_u64().unwrap() as usize];
        assert_eq!(s["interpolation"], "LINEAR");
        let input = s["input"].as_u64().unwrap() as usize;
        let output = s["output"].as_u64().unwrap() as usize;
        let ia = &doc["accessors"][input];
        assert!(ia["min"].is_array() && ia["max"].is_array(), "time accessor without bounds");
        let times = accessor_floats(doc, bin, input);
        assert_eq!(ia["min"][0].as_f64().unwrap() as f32, times[0]);
        assert_eq!(ia["max"][0].as_f64().unwrap() as f32, *times.last().unwrap());
        assert!(times.windows(2).all(|w| w[1] > w[0]), "times increase");
        assert_eq!(doc["accessors"][output]["count"], ia["count"]);
        if ch["target"]["path"] == "pointer" {
            continue;
        }
        let node = ch["target"]["node"].as_u64().unwrap() as usize;
        let path = ch["target"]["path"].as_str().unwrap().to_string();
        let vals = accessor_floats(doc, bin, output);
        if path == "rotation" {
            for q in vals.chunks(4) {
                let len = q.iter().map(|v| v * v).sum::<f32>().sqrt();
                assert!((len - 1.0).abs() < 1e-4, "quaternion length {len}");
            }
            for w in vals.chunks(4).collect::<Vec<_>>().windows(2) {
                let dot: f32 = (0..4).map(|k| w[0][k] * w[1][k]).sum();
                assert!(dot >= 0.0, "consecutive keys in opposite hemispheres");
            }
        }
        keyed.insert((node, path), vals);
    }
    // One key per frame on every joint's rotation and on the root's translation.
    let n = m.num_frames();
    for j in 0..sk.len() {
        assert_eq!(
            keyed[&(joint_node[j], "rotation".to_string())].len(),
            4 * n,
            "rotation keys of {}",
            sk.joint(j).name
        );
    }
    assert_eq!(keyed[&(hips, "translation".to_string())].len(), 3 * n);
    // FK through the keyed node transforms equals core FK (a foot, a hand, the head).
    for f in [0, n / 3, n - 1] {
        let g = forward(sk, &m.pose(f));
        for jn in ["LeftFoot", "RightHand", "Head"] {
            let j = sk.find(jn).unwrap();
            let mut chain = vec![j];
            while let Some(p) = sk.parent(*chain.last().unwrap()) {
                chain.push(p);
            }
            let (mut pos, mut rot) = (DVec3::ZERO, DQuat::IDENTITY);
            for &c in chain.iter().rev() {
                let k = joint_node[c];
                let t = match keyed.get(&(k, "translation".to_string())) {
                    Some(v) => DVec3::new(v[3 * f] as f64, v[3 * f + 1] as f64, v[3 * f + 2] as f64),
                    None => sk.joint(c).offset,
                };
                let q = &keyed[&(k, "rotation".to_string())][4 * f..4 * f + 4];
                pos += rot * t;
                rot = (rot * DQuat::from_xyzw(q[0] as f64, q[1] as f64, q[2] as f64, q[3] as f64)).normalize();
            }
            assert!((pos - g.positions[j]).length() < 1e-4, "{jn} at frame {f}: {pos} vs {}", g.positions[j]);
        }
    }
    // The camera: one key per story frame, looking from the eye at the target.
    let cam_node = *scene_roots.iter().find(|&&r| nodes[r].get("camera").is_some()).expect("camera node");
    let cam = &doc["cameras"][nodes[cam_node]["camera"].as_u64().unwrap() as usize];
    assert_eq!(cam["type"], "perspective");
    assert!((cam["perspective"]["yfov"].as_f64().unwrap() - 45f64.to_radians()).abs() < 1e-6);
    let frames = animation_frames(&[(name, m)], fps);
    let pos = &keyed[&(cam_node, "translation".to_string())];
    let rot = &keyed[&(cam_node, "rotation".to_string())];
    assert_eq!(pos.len(), 3 * frames);
    assert_eq!(rot.len(), 4 * frames);
    for f in [0, frames / 2, frames - 1] {
        let AimedCamera { eye, target, .. } = camera(f);
        assert_eq!(&pos[3 * f..3 * f + 3], &eye.to_array());
        let q = Quat::from_slice(&rot[4 * f..4 * f + 4]);
        let dir = (target - eye).normalize();
        assert!((q * Vec3::NEG_Z).dot(dir) > 0.9999, "camera looks at the target");
        assert!((q * Vec3::Y).y > 0.0, "camera upright");
    }
}

#[test]
fn animated_gltf_embedded_round_trips() {
    let m = walk();
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("story.gltf");
    write_animated_gltf(&p, &scene(), &builtin(), &[("walker", &m)], &camera, 30.0).unwrap();
    let doc: Value = serde_json::from_slice(&std::fs::read(&p).unwrap()).unwrap();
    let uri = doc["buffers"][0]["uri"].as_str().unwrap();
    let bin = base64_decode(uri.strip_prefix("data:application/octet-stream;base64,").unwrap()).unwrap();
    check_animation(&doc, &bin, "walker", &m, 30.0);
}

#[test]
fn animated_glb_round_trips_with_two_characters() {
    let a = walk();
    let b = walk_route(&[[4.4, 2.6], [0.6, 2.6]], &MotionLibrary::procedural(0), &WalkParams::default());
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("story.glb");
    write_animated_gltf(&p, &scene(), &builtin(), &[("ann", &a), ("bob", &b)], &camera, 30.0).unwrap();
    let glb = parse_glb(&std::fs::read(&p).unwrap()).unwrap();
    check_animation(&glb.json, &glb.bin, "ann", &a, 30.0);
    check_animation(&glb.json, &glb.bin, "bob", &b, 30.0);
    assert_eq!(
        glb.json["materials"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|m| m["name"].as_str().unwrap().ends_with(" body"))
            .count(),
        2
    );
}

#[test]
fn changing_field_of_view_steps_through_animation_pointer() {
    let m = walk();
    let lookup = |_: &str| None;
    let (doc, _, _) = animated_gltf_document(&scene(), &builtin(), &[("w", &m)], &camera, 30.0, &lookup).unwrap();
    assert!(doc.get("extensionsUsed").is_none(), "constant fov needs no extension");
    let cut = |f: usize| AimedCamera {
        eye: Vec3::new(2.5, 1.6, 3.9),
        target: Vec3::new(2.5, 1.0, 2.0),
        fovy_deg: if f < 30 { 50.0 } else { 70.0 },
    };
    let (doc, bin, _) = animated_gltf_document(&scene(), &builtin(), &[("w", &m)], &cut, 30.0, &lookup).unwrap();
    assert_eq!(doc["extensionsUsed"], serde_json::json!(["KHR_animation_pointer"]));
    assert!(doc.get("extensionsRequired").is_none());
    let anim = &doc["animations"][0];
    let ch = anim["channels"].as_array().unwrap().iter().find(|c| c["target"]["path"] == "pointer").unwrap();
    assert_eq!(ch["target"]["extensions"]["KHR_animation_pointer"]["pointer"], "/cameras/0/perspective/yfov");
    let s = &anim["samplers"][ch["sampler"].as_u64().unwrap() as usize];
    assert_eq!(s["interpolation"], "STEP");
    let v = accessor_floats(&doc, &bin, s["output"].as_u64().unwrap() as usize);
    assert_eq!(v.len(), animation_frames(&[("w", &m)], 30.0));
    assert!((v[0] - 50f32.to_radians()).abs() < 1e-6 && (v[40] - 70f32.to_radians()).abs() < 1e-6);
    assert!((doc["cameras"][0]["perspective"]["yfov"].as_f64().unwrap() - 50f64.to_radians()).abs() < 1e-6);
}

#[test]
fn animated_gltf_rejects_bad_input() {
    let m = walk();
    let lookup = |_: &str| None;
    assert!(animated_gltf_document(&scene(), &builtin(), &[("w", &m)], &camera, 0.0, &lookup).is_err());
    let bad_fov =
        |_: usize| AimedCamera { eye: Vec3::new(0.0, 1.0, 5.0), target: Vec3::new(0.0, 1.0, 0.0), fovy_deg: 0.0 };
    assert!(animated_gltf_document(&scene(), &builtin(), &[("w", &m)], &bad_fov, 30.0, &lookup).is_err());
    // A character without frames cannot be given: a clip has at least one.
    assert!(Clip::from_poses(m.skeleton().clone(), m.frame_time(), &[]).is_err());
    // No characters: the static scene plus a one-key camera.
    let (doc, _, _) = animated_gltf_document(&scene(), &builtin(), &[], &camera, 30.0, &lookup).unwrap();
    assert_eq!(doc["animations"][0]["channels"].as_array().unwrap().len(), 2);
}

#[test]
fn bvh_round_trips_within_1e6_with_unit_sidecar() {
    let m = walk();
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("walker.bvh");
    write_character_bvh(&p, &m).unwrap();
    let back = inbetween_io::bvh::read_bvh(&p).unwrap();
    assert_eq!(back.num_frames(), m.num_frames());
    assert!((back.frame_time - m.frame_time()).abs() < 1e-12);
    // Channels as written (the clip's poses in each joint's Euler order) and as read back.
    let m = m.to_motion().unwrap();
    assert_eq!(back.skeleton.len(), m.skeleton.len());
    for (j, joint) in m.skeleton.joints().iter().enumerate() {
        let k = back.skeleton.find(&joint.name).unwrap();
        let bj = back.skeleton.joint(k);
        assert_eq!(bj.channels, joint.channels);
        assert!((bj.offset - joint.offset).length() < 1e-6);
        let (s0, s1) = (m.skeleton.channel_start(j), back.skeleton.channel_start(k));
        for f in 0..m.num_frames() {
            for c in 0..joint.channels.len() {
                let (a, b) = (m.frame(f)[s0 + c], back.frame(f)[s1 + c]);
                assert!((a - b).abs() <= 1e-6, "{} channel {c} frame {f}: {a} vs {b}", joint.name);
            }
        }
    }
    let side = bvh_sidecar_path(&p);
    assert_eq!(side, dir.path().join("walker.bvh.json"));
    let meta: Value = serde_json::from_slice(&std::fs::read(&side).unwrap()).unwrap();
    assert_eq!(meta["unit"], "m");
    assert!((meta["fps"].as_f64().unwrap() - 30.0).abs() < 1e-9);
    assert_eq!(meta["frames"].as_u64().unwrap() as usize, m.num_frames());
}

fn decode_gif(path: &Path) -> Vec<image::RgbaImage> {
    let f = std::io::BufReader::new(std::fs::File::open(path).unwrap());
    let dec = image::codecs::gif::GifDecoder::new(f).unwrap();
    dec.into_frames().collect_frames().unwrap().into_iter().map(|f| f.into_buffer()).collect()
}

fn near(c: &[u8], target: [u8; 3], tol: i32) -> bool {
    (0..3).all(|k| (c[k] as i32 - target[k] as i32).abs() <= tol)
}

#[test]
fn preview_gif_decodes_with_expected_frames_and_motion() {
    let m = walk();
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("preview.gif");
    let opts = AnimPreviewOptions::default();
    render_preview_gif(&p, &scene(), &builtin(), &[("walker", &m)], &camera, 30.0, &opts).unwrap();
    let frames = decode_gif(&p);
    let (idx, gif_fps) = preview_frame_indices(&[("walker", &m)], 30.0, &opts);
    assert!((gif_fps - 10.0).abs() < 1e-9);
    assert_eq!(frames.len(), idx.len());
    assert_eq!(frames.len(), m.num_frames().div_ceil(3));
    assert!(frames.iter().all(|f| f.dimensions() == (480, 320)));
    // The figure is drawn (its colour shows) and moves: many pixels change between frames.
    let body = CHARACTER_COLORS[0];
    let count = |f: &image::RgbaImage| f.pixels().filter(|p| near(&p.0, body, 6)).count();
    let mid = frames.len() / 2;
    assert!(count(&frames[0]) > 30 && count(&frames[mid]) > 30, "{} {}", count(&frames[0]), count(&frames[mid]));
    let changed =
        frames[0].pixels().zip(frames[mid].pixels()).filter(|(a, b)| !near(&a.0, [b.0[0], b.0[1], b.0[2]], 10)).count();
    assert!(changed > 500, "{changed} pixels changed");
    // Where the figure was at frame 0 it is gone half-way (the title aside).
    let left: usize = frames[0].enumerate_pixels().filter(|(_, y, p)| *y > 30 && near(&p.0, body, 6)).count();
    let gone = frames[0]
        .enumerate_pixels()
        .filter(|(x, y, p)| *y > 30 && near(&p.0, body, 6) && !near(&frames[mid].get_pixel(*x, *y).0, body, 6))
        .count();
    assert!(gone * 2 > left, "{gone} of {left} figure pixels moved");
}

#[test]
fn preview_frames_respect_size_and_rate_caps() {
    let m = walk();
    let opts = AnimPreviewOptions {
        width: 2000,
        max_fps: 60.0,
        max_frames: 7,
        labels: false,
        ..AnimPreviewOptions::default()
    };
    let (frames, fps) = preview_frames(&scene(), &builtin(), &[("walker", &m)], &camera, 30.0, &opts).unwrap();
    assert!(frames.len() <= 7 && !frames.is_empty());
    assert!(fps <= 10.0);
    assert_eq!(frames[0].dimensions(), (480, 320));
    // A camera inside the room (floor partly behind it) still draws.
    let inside =
        |_: usize| AimedCamera { eye: Vec3::new(2.5, 1.6, 3.8), target: Vec3::new(2.5, 1.0, 0.0), fovy_deg: 60.0 };
    let (frames, _) = preview_frames(&scene(), &builtin(), &[("walker", &m)], &inside, 30.0, &opts).unwrap();
    assert!(frames[0].pixels().any(|p| p.0 == [236, 233, 226]), "floor visible");
    assert!(preview_frames(&scene(), &builtin(), &[("walker", &m)], &camera, -1.0, &opts).is_err());
}

#[test]
fn route_plan_has_the_character_colour_along_the_route() {
    let m = walk();
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("routes.png");
    render_top_down_trails(&p, &scene(), &builtin(), &[("walker", &m)]).unwrap();
    let img = image::open(&p).unwrap().to_rgb8();
    let route = root_route(&m);
    let color = CHARACTER_COLORS[0];
    let mut hits = 0;
    let samples: Vec<[f32; 2]> = (1..10).map(|k| route[k * route.len() / 10]).collect();
    for q in &samples {
        let (x, y) = plan_pixel(&scene(), *q);
        let found = (-2..=2).any(|dx: i32| {
            (-2..=2).any(|dy: i32| {
                let (px, py) = ((x as i32 + dx) as u32, (y as i32 + dy) as u32);
                near(&img.get_pixel(px, py).0, color, 12)
            })
        });
        hits += found as usize;
    }
    assert!(hits >= samples.len() - 1, "{hits} of {} route samples coloured", samples.len());
    // Off the route (the room's far corner) there is none of it.
    let (x, y) = plan_pixel(&scene(), [4.8, 0.2]);
    assert!(!near(&img.get_pixel(x as u32, y as u32).0, color, 12));
}

/// Sizes of the three outputs for a 10 s animation (printed; bounded so they stay small).
#[test]
fn ten_second_outputs_stay_small() {
    let lib = MotionLibrary::procedural(0);
    let route = [[0.6, 3.1], [4.4, 3.1]];
    let first = walk_route(&route, &lib, &WalkParams::default());
    let pad = (10.0 - first.duration()).max(0.0);
    let m = walk_route(&route, &lib, &WalkParams { hold_end: 0.3 + pad, ..WalkParams::default() });
    assert!((m.duration() - 10.0).abs() < 0.2, "{} s", m.duration());
    let tmp = tempfile::tempdir().unwrap();
    // ANIM_OUTPUT_DIR=… keeps the files for a look.
    let keep = std::env::var_os("ANIM_OUTPUT_DIR").map(std::path::PathBuf::from);
    let dir = keep.as_deref().unwrap_or(tmp.path());
    let chars = [("walker", &m)];
    let (sc, cat) = (scene(), builtin());
    write_animated_gltf(&dir.join("a.gltf"), &sc, &cat, &chars, &camera, 30.0).unwrap();
    write_animated_gltf(&dir.join("a.glb"), &sc, &cat, &chars, &camera, 30.0).unwrap();
    write_character_bvh(&dir.join("a.bvh"), &m).unwrap();
    render_preview_gif(&dir.join("a.gif"), &sc, &cat, &chars, &camera, 30.0, &AnimPreviewOptions::default()).unwrap();
    render_top_down_trails(&dir.join("a.png"), &sc, &cat, &chars).unwrap();
    if keep.is_some() {
        let (frames, _) = preview_frames(&sc, &cat, &chars, &camera, 30.0, &AnimPreviewOptions::default()).unwrap();
        for k in [0, frames.len() / 4, frames.len() / 2] {
            frames[k].save(dir.join(format!("frame{k}.png"))).unwrap();
        }
    }
    let size = |n: &str| std::fs::metadata(dir.join(n)).unwrap().len();
    for n in ["a.gltf", "a.glb", "a.bvh", "a.gif", "a.png"] {
        eprintln!("10 s, 1 character: {n} {} KiB", size(n) / 1024);
    }
    assert!(size("a.glb") < 2 << 20 && size("a.gltf") < 3 << 20);
    assert!(size("a.gif") < 4 << 20);
}
