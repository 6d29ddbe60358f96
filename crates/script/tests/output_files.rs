//! Outputs: JSON round-trips, glTF re-parses with consistent buffers and accessors (boxes and
//! merged Kenney models), previews decode at the expected size with objects drawn.

use std::path::PathBuf;

use inbetween_script::catalogue::builtin::builtin;
use inbetween_script::output::gltf::{base64, base64_decode, gltf_document, parse_glb};
use inbetween_script::output::{
    perspective, read_json, top_down, write_gltf, write_gltf_with_models, write_json, write_previews, VIEWS,
};
use inbetween_script::scene::{Room, Scene};
use serde_json::Value;

mod common;
use common::{check_buffers, obj};

fn scene() -> Scene {
    let mut lamp = obj("lamp", "lamp", [1.2, 0.75, 0.4], 0.0, [0.2, 0.45, 0.2]);
    lamp.support = Some(0);
    Scene {
        room: Room { name: "office".into(), width: 5.0, depth: 4.0, height: 2.8 },
        objects: vec![
            obj("desk", "desk", [1.0, 0.0, 0.35], 0.0, [1.4, 0.75, 0.7]),
            obj("chair", "chair", [1.0, 0.0, 1.2], std::f32::consts::PI, [0.5, 0.9, 0.5]),
            lamp,
            obj("bed", "bed", [3.9, 0.0, 2.0], -std::f32::consts::FRAC_PI_2, [1.6, 0.5, 2.1]),
            obj("painting", "oilpainting", [2.5, 1.15, 0.025], 0.0, [0.9, 0.7, 0.05]),
        ],
        camera: vec!["front".into()],
        weather: None,
    }
}

#[test]
fn json_round_trips_and_says_what_holds_each_object_up() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("sub/scene.json");
    write_json(&p, &scene(), &builtin()).unwrap();
    assert_eq!(read_json(&p).unwrap(), scene());
    let v: serde_json::Value = serde_json::from_slice(&std::fs::read(&p).unwrap()).unwrap();
    let mounts: Vec<(&str, &str)> = v["objects"]
        .as_array()
        .unwrap()
        .iter()
        .map(|o| (o["label"].as_str().unwrap(), o["mount"].as_str().unwrap()))
        .collect();
    let scene = scene();
    for (o, (label, mount)) in scene.objects.iter().zip(&mounts) {
        let want = match (o.support, o.category.as_str()) {
            (Some(_), _) => "on",
            (None, "oilpainting") => "wall",
            _ => "floor",
        };
        assert_eq!((*label, *mount), (o.label.as_str(), want));
    }
}

#[test]
fn base64_round_trips() {
    assert_eq!(base64(b"Man"), "TWFu");
    assert_eq!(base64(b"M"), "TQ==");
    for n in 0..20 {
        let v: Vec<u8> = (0..n).map(|k| (k * 37 + 5) as u8).collect();
        assert_eq!(base64_decode(&base64(&v)).unwrap(), v);
    }
}

/// Checks a document against its buffer ([`check_buffers`]) and its nodes/meshes/materials
/// indices. Returns the node names.
fn validate(doc: &Value, bin: &[u8]) -> Vec<String> {
    assert_eq!(doc["asset"]["version"], "2.0");
    check_buffers(doc, bin);
    let accessors = doc["accessors"].as_array().unwrap();
    let (nmesh, nmat) = (doc["meshes"].as_array().unwrap().len(), doc["materials"].as_array().unwrap().len());
    for m in doc["meshes"].as_array().unwrap() {
        for p in m["primitives"].as_array().unwrap() {
            for v in p["attributes"].as_object().unwrap().values() {
                assert!((v.as_u64().unwrap() as usize) < accessors.len());
            }
            assert!((p["material"].as_u64().unwrap() as usize) < nmat);
        }
    }
    let nodes = doc["nodes"].as_array().unwrap();
    for n in nodes {
        if let Some(m) = n.get("mesh") {
            assert!((m.as_u64().unwrap() as usize) < nmesh);
        }
        for c in n.get("children").and_then(Value::as_array).into_iter().flatten() {
            assert!((c.as_u64().unwrap() as usize) < nodes.len());
        }
    }
    nodes.iter().filter_map(|n| n["name"].as_str().map(String::from)).collect()
}

#[test]
fn gltf_and_glb_reparse_with_a_node_per_object() {
    let dir = tempfile::tempdir().unwrap();
    let cat = builtin();
    let s = scene();
    let p = dir.path().join("scene.gltf");
    write_gltf(&p, &s, &cat).unwrap();
    let doc: Value = serde_json::from_slice(&std::fs::read(&p).unwrap()).unwrap();
    let uri = doc["buffers"][0]["uri"].as_str().unwrap();
    let bin = base64_decode(uri.strip_prefix("data:application/octet-stream;base64,").unwrap()).unwrap();
    let names = validate(&doc, &bin);
    for o in &s.objects {
        assert!(names.contains(&o.label), "no node '{}'", o.label);
    }
    let chair = doc["nodes"].as_array().unwrap().iter().find(|n| n["name"] == "chair").unwrap();
    let t: Vec<f64> = chair["translation"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
    assert!((t[0] - 1.0).abs() < 1e-6 && t[1].abs() < 1e-6 && (t[2] - 1.2).abs() < 1e-6, "{t:?}");
    let q = chair["rotation"].as_array().unwrap();
    assert!((q[1].as_f64().unwrap() - 1.0).abs() < 1e-6, "half a turn about y: {q:?}");
    // One box mesh per category, coloured by the catalogue; the chair as a seat and a backrest, the
    // bed (no backrest above its seat) as one box.
    assert_eq!(doc["meshes"].as_array().unwrap().len(), 1 + 5);
    for part in ["chair seat", "chair back", "bed box", "desk box"] {
        assert!(names.iter().any(|n| n == part), "no node '{part}' in {names:?}");
    }

    let p = dir.path().join("scene.glb");
    write_gltf(&p, &s, &cat).unwrap();
    let glb = parse_glb(&std::fs::read(&p).unwrap()).unwrap();
    assert!(glb.json["buffers"][0].get("uri").is_none());
    validate(&glb.json, &glb.bin[..glb.json["buffers"][0]["byteLength"].as_u64().unwrap() as usize]);
}

fn kenney_dir() -> Option<PathBuf> {
    let d = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/assets/kenney_furniture");
    d.join("desk.glb").is_file().then_some(d)
}

#[test]
fn kenney_models_are_merged_and_fitted_when_present() {
    let Some(dir) = kenney_dir() else {
        eprintln!("Kenney furniture not present; skipped");
        return;
    };
    let path = dir.join("desk.glb");
    let model = |c: &str| {
        (c == "desk" || c == "bed").then(|| if c == "desk" { path.clone() } else { dir.join("bedSingle.glb") })
    };
    let (doc, bin, notes) = gltf_document(&scene(), &builtin(), &model);
    assert!(notes.is_empty(), "{notes:?}");
    validate(&doc, &bin);
    assert!(doc["extensionsUsed"].as_array().unwrap().iter().any(|e| e == "KHR_materials_unlit"));
    let nodes = doc["nodes"].as_array().unwrap();
    let desk_model = nodes.iter().find(|n| n["name"] == "desk model").expect("model node");
    let sc: Vec<f64> = desk_model["scale"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
    // desk.glb spans ≈ 0.73 m in x; fitted to the 1.4 m desk.
    assert!(sc[0] > 1.5 && sc[0] < 2.5, "{sc:?}");
    // Writing with a models folder uses the catalogue's model stems (none in the built-in one: boxes).
    let out = tempfile::tempdir().unwrap();
    let notes = write_gltf_with_models(&out.path().join("m.glb"), &scene(), &builtin(), Some(&dir)).unwrap();
    assert!(notes.is_empty());
    // The Kenney catalogue gives model paths: write_gltf merges them on its own.
    let kcat = inbetween_script::catalogue::kenney::with_models(builtin(), &dir).unwrap();
    if kcat.model_path("desk").is_some() {
        let p = out.path().join("k.glb");
        write_gltf(&p, &scene(), &kcat).unwrap();
        let glb = parse_glb(&std::fs::read(&p).unwrap()).unwrap();
        let names = validate(&glb.json, &glb.bin[..glb.json["buffers"][0]["byteLength"].as_u64().unwrap() as usize]);
        assert!(names.iter().any(|n| n == "desk model"), "{names:?}");
    }
    // A broken model falls back to a box with a note.
    let bad = out.path().join("bad.glb");
    std::fs::write(&bad, b"not a glb").unwrap();
    let (doc, bin, notes) = gltf_document(&scene(), &builtin(), &|c: &str| (c == "desk").then(|| bad.clone()));
    assert_eq!(notes.len(), 1, "{notes:?}");
    assert!(notes[0].contains("desk"));
    validate(&doc, &bin);
}

fn differs(img: &image::RgbImage, x: u32, y: u32, bg: [u8; 3]) -> bool {
    img.get_pixel(x, y).0 != bg
}

#[test]
fn top_down_draws_objects_where_they_are() {
    let cat = builtin();
    let s = scene();
    let img = top_down(&s, &cat);
    // 5 × 4 m at 135 px/m (540 / 4), margins 60 + 60 wide, 50 + 80 high.
    let scale = (720.0f32 / 5.0).min(540.0 / 4.0);
    assert_eq!(img.width(), (5.0 * scale + 120.0).ceil() as u32);
    assert_eq!(img.height(), (4.0 * scale + 130.0).ceil() as u32);
    let px = |x: f32, z: f32| ((60.0 + x * scale) as u32, (50.0 + z * scale) as u32);
    // The bed's colour inside its footprint, off its label.
    let (bx, by) = px(3.9, 2.7);
    assert_eq!(img.get_pixel(bx, by).0, cat.get("bed").unwrap().color);
    // Empty floor elsewhere is floor coloured, the margin white.
    let (fx, fy) = px(2.5, 3.0);
    assert!(!differs(&img, fx, fy + 3, [236, 233, 226]) || !differs(&img, fx + 3, fy + 3, [236, 233, 226]));
    assert_eq!(img.get_pixel(5, img.height() / 2).0, [255, 255, 255]);
    // The scale bar below the room.
    let bar_y = (50.0 + 4.0 * scale + 45.0) as u32;
    assert_eq!(img.get_pixel(60 + 20, bar_y).0, [40, 40, 40]);
}

#[test]
fn perspective_views_render_the_scene() {
    let cat = builtin();
    let s = scene();
    let empty = Scene { objects: vec![], ..s.clone() };
    for view in VIEWS {
        let img = perspective(&s, &cat, view);
        assert_eq!((img.width(), img.height()), (960, 640));
        let blank = perspective(&empty, &cat, view);
        let changed = img.pixels().zip(blank.pixels()).filter(|(a, b)| a != b).count();
        assert!(changed > 2000, "{view}: objects changed only {changed} pixels");
    }
    // Unknown views fall back to the front.
    assert_eq!(perspective(&s, &cat, "close"), perspective(&s, &cat, "front"));
}

#[test]
fn previews_are_written_as_pngs() {
    let dir = tempfile::tempdir().unwrap();
    let files = write_previews(dir.path(), &scene(), &builtin(), "left").unwrap();
    assert_eq!(files, vec![dir.path().join("top.png"), dir.path().join("view.png")]);
    let top = image::open(&files[0]).unwrap().to_rgb8();
    assert_eq!(top, top_down(&scene(), &builtin()));
    let view = image::open(&files[1]).unwrap().to_rgb8();
    assert_eq!((view.width(), view.height()), (960, 640));
}

/// Seats with a backrest are drawn as a seat at the seat contact's height and a back along their
/// rear edge: a character seated at any of their seat contacts (the engine's seated pose, §4.3) has
/// no point of a leg inside either box, as it had inside the one box as tall as the back. Stools,
/// benches and beds (no backrest above the seat) stay one box.
#[test]
fn a_seated_character_s_legs_rest_on_the_seat_not_inside_it() {
    use glam::DVec3;
    use inbetween_core::fk::forward;
    use inbetween_script::catalogue::ContactKind;
    use inbetween_script::motion::ik::seated_pose;
    use inbetween_script::motion::Rig;
    use inbetween_script::output::{placed_box, placeholder_boxes};

    let (cat, rig) = (builtin(), Rig::standard());
    for name in ["chair", "officechair", "armchair", "sofa", "stool", "bench", "bed"] {
        let c = cat.get(name).unwrap();
        let o = obj(name, name, [0.0, 0.0, 0.0], 0.0, c.size);
        let boxes = placeholder_boxes(&o, &cat);
        let parts: Vec<&str> = boxes.iter().map(|b| b.part).collect();
        let backed = matches!(name, "chair" | "officechair" | "armchair" | "sofa");
        assert_eq!(parts, if backed { vec!["seat", "back"] } else { vec!["box"] }, "{name}");
        if !backed {
            continue;
        }
        let inside = |p: DVec3| {
            boxes.iter().map(|b| placed_box(&o, b)).any(|b| {
                let [w, h, d] = b.size.map(f64::from);
                let c = DVec3::new(b.position[0] as f64, b.position[1] as f64, b.position[2] as f64);
                (p.x - c.x).abs() < w / 2.0 - 1e-3
                    && (p.z - c.z).abs() < d / 2.0 - 1e-3
                    && p.y > c.y
                    && p.y < c.y + h - 1e-3
            })
        };
        let mut points = Vec::new();
        for seat in c.contacts.iter().filter(|p| p.kind == ContactKind::Seat) {
            let s = seat.local.map(f64::from);
            let g = forward(&rig.skeleton, &seated_pose(&rig, DVec3::new(s[0], s[1], s[2]), 0.0));
            for leg in rig.legs {
                for (a, b) in [(leg[0], leg[1]), (leg[1], leg[2])] {
                    points.extend((0..=20).map(|k| g.positions[a].lerp(g.positions[b], k as f64 / 20.0)));
                }
            }
        }
        for p in &points {
            assert!(!inside(*p), "{name}: a leg passes through the placeholder at {p:?}");
        }
        // The one box as tall as the back (the placeholder before) held the thighs.
        let [w, h, d] = c.size.map(f64::from);
        assert!(points.iter().any(|p| p.x.abs() < w / 2.0 && p.z.abs() < d / 2.0 && p.y < h), "{name}");
    }
}
