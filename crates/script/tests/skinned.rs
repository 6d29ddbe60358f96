//! Skinned Kenney characters: a generated Kenney-like GLB (seven box parts in Kenney's node layout,
//! an embedded 4 × 4 texture) is read at rest, retargeted onto the common rig and exported as a
//! skinned glTF; the document re-parses from GLB bytes with valid skin, joint and weight data,
//! and the skin math applied to the document's own buffers puts every vertex on its bind placement
//! at a bind-pose frame and carries it rigidly with its joint on later frames. The real
//! `character-a.glb` … run the same way when ../shared/data is present.

use std::path::{Path, PathBuf};

use glam::{DQuat, DVec3, Mat4, Quat, Vec3};
use inbetween_core::camera::AimedCamera;
use inbetween_core::clip::Clip;
use inbetween_core::fk::forward;
use inbetween_core::Pose;
use inbetween_script::catalogue::builtin::builtin;
use inbetween_script::motion::kenney::{read_character, KenneyCharacter};
use inbetween_script::motion::rig::{clip, Rig};
use inbetween_script::output::gltf::{glb_bytes, parse_glb};
use inbetween_script::output::skinned::{
    bind_body, bind_pose, character_file, first_character_dir, joint_matrices, render_skinned_frame, skin_positions,
    skinned_gltf_document, SkinnedBody, SkinnedCast, BLOCKY_DIR,
};
use inbetween_script::scene::{Room, Scene};
use serde_json::{json, Value};

mod common;
use common::{accessor_bytes, accessor_floats};

/// Positions, normals, uvs and u8 indices of a mesh.
type MeshData = (Vec<[f32; 3]>, Vec<[f32; 3]>, Vec<[f32; 2]>, Vec<u8>);

/// A part of the fixture: name, translation, box min, box max, uniform scale, child of the torso.
type PartSpec = (&'static str, [f32; 3], [f32; 3], [f32; 3], f32, bool);

/// A box mesh (24 vertices with flat normals and per-face uvs, 36 u8 indices) from `lo` to `hi`.
fn box_mesh(lo: [f32; 3], hi: [f32; 3]) -> MeshData {
    let (mut p, mut n, mut uv, mut idx) = (vec![], vec![], vec![], vec![]);
    for axis in 0..3 {
        for side in [0usize, 1] {
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            let base = p.len() as u8;
            for (a, b) in [(0, 0), (1, 0), (1, 1), (0, 1)] {
                let mut q = [0.0; 3];
                q[axis] = if side == 1 { hi[axis] } else { lo[axis] };
                q[u] = if a == 1 { hi[u] } else { lo[u] };
                q[v] = if b == 1 { hi[v] } else { lo[v] };
                p.push(q);
                let mut nn = [0.0; 3];
                nn[axis] = if side == 1 { 1.0 } else { -1.0 };
                n.push(nn);
                uv.push([0.25 * (axis as f32 + a as f32 * 0.5), 0.5 * (side as f32 + b as f32 * 0.5)]);
            }
            // Counter-clockwise seen from outside.
            let quad: [u8; 6] = if side == 1 { [0, 1, 2, 0, 2, 3] } else { [0, 2, 1, 0, 3, 2] };
            idx.extend(quad.iter().map(|k| base + k));
        }
    }
    (p, n, uv, idx)
}

/// A Kenney-like GLB: the blocky characters' node layout, sizes and transforms (Kenney units: legs
/// 1 long from the hip pivot, torso 0.9, arms hanging 1.0 from the shoulder pivot, a head mesh at
/// 10× scaled by 0.1), one material with an embedded PNG texture.
fn kenney_like_glb(with_torso: bool) -> Vec<u8> {
    let parts: Vec<PartSpec> = vec![
        ("leg-left", [0.2, 1.0, 0.0], [-0.2, -1.0, -0.2], [0.2, 0.0, 0.2], 1.0, false),
        ("leg-right", [-0.2, 1.0, 0.0], [-0.2, -1.0, -0.2], [0.2, 0.0, 0.2], 1.0, false),
        ("torso", [0.0, 0.7, 0.0], [-0.4, 0.3, -0.3], [0.4, 1.2, 0.3], 1.0, false),
        ("arm-left", [0.4, 1.1, -0.1], [0.0, -1.0, -0.2], [0.4, 0.1, 0.2], 1.0, true),
        ("arm-right", [-0.4, 1.1, -0.1], [-0.4, -1.0, -0.2], [0.0, 0.1, 0.2], 1.0, true),
        ("head", [0.0, 1.2, 0.0], [-4.0, 0.0, -4.0], [4.0, 8.0, 4.0], 0.1, true),
    ];
    let parts: Vec<_> = parts.into_iter().filter(|p| with_torso || p.0 != "torso").collect();
    let mut bin: Vec<u8> = Vec::new();
    let mut views = vec![];
    let mut accessors = vec![];
    let mut meshes = vec![];
    let mut view = |bin: &mut Vec<u8>, bytes: &[u8]| {
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        views.push(json!({"buffer": 0, "byteOffset": bin.len(), "byteLength": bytes.len()}));
        bin.extend_from_slice(bytes);
        views.len() - 1
    };
    let mut nodes = vec![json!({"name": "character-x", "children": [1]}), json!({"name": "root", "children": []})];
    let mut index_of = std::collections::HashMap::new();
    for (name, t, lo, hi, s, on_torso) in &parts {
        let (p, n, uv, idx) = box_mesh(*lo, *hi);
        let f = |v: &[f32]| v.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<u8>>();
        let a0 = accessors.len();
        let vp = view(&mut bin, &f(&p.concat()));
        accessors.push(
            json!({"bufferView": vp, "componentType": 5126, "count": p.len(), "type": "VEC3", "min": lo, "max": hi}),
        );
        let vn = view(&mut bin, &f(&n.concat()));
        accessors.push(json!({"bufferView": vn, "componentType": 5126, "count": n.len(), "type": "VEC3"}));
        let vu = view(&mut bin, &f(&uv.concat()));
        accessors.push(json!({"bufferView": vu, "componentType": 5126, "count": uv.len(), "type": "VEC2"}));
        let vi = view(&mut bin, &idx);
        accessors.push(json!({"bufferView": vi, "componentType": 5121, "count": idx.len(), "type": "SCALAR"}));
        meshes.push(json!({"name": name, "primitives": [{"attributes": {"POSITION": a0, "NORMAL": a0 + 1, "TEXCOORD_0": a0 + 2}, "indices": a0 + 3, "material": 0}]}));
        let node = nodes.len();
        nodes.push(json!({"name": name, "mesh": meshes.len() - 1, "translation": t, "scale": [s, s, s]}));
        index_of.insert(*name, node);
        let parent = if *on_torso { index_of.get("torso").copied().unwrap_or(1) } else { 1 };
        if !nodes[parent]["children"].is_array() {
            nodes[parent]["children"] = json!([]);
        }
        nodes[parent]["children"].as_array_mut().unwrap().push(json!(node));
    }
    let tex = image::RgbImage::from_fn(4, 4, |x, y| image::Rgb([60 * x as u8, 60 * y as u8, 200]));
    let png = inbetween_render::png_bytes(&tex).unwrap();
    let vimg = view(&mut bin, &png);
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let doc = json!({
        "asset": {"version": "2.0", "generator": "test"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": nodes,
        "meshes": meshes,
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": bin.len()}],
        "materials": [{"name": "texture-x", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
        "textures": [{"source": 0, "sampler": 0}],
        "samplers": [{"minFilter": 9729}],
        "images": [{"bufferView": vimg, "mimeType": "image/png"}],
    });
    glb_bytes(&doc, &bin)
}

fn fixture(dir: &Path, with_torso: bool) -> PathBuf {
    let path = dir.join(if with_torso { "character-a.glb" } else { "no-torso.glb" });
    std::fs::write(&path, kenney_like_glb(with_torso)).unwrap();
    path
}

fn room() -> Scene {
    Scene {
        room: Room { name: "studio".into(), width: 4.0, depth: 4.0, height: 2.8 },
        objects: vec![],
        camera: vec![],
        weather: None,
    }
}

fn camera(_: usize) -> AimedCamera {
    AimedCamera { eye: Vec3::new(2.0, 1.4, 6.0), target: Vec3::new(2.0, 0.9, 2.0), fovy_deg: 40.0 }
}

/// Frame 0 the bind pose at (2, y, 2); then the left knee bends to 90°, the right arm drops to the
/// side and the body walks 0.5 m along +z and turns 90° about +Y.
fn test_motion(rig: &Rig) -> Clip {
    let (bind, _) = bind_pose(&rig.skeleton);
    let frames = 6;
    let poses: Vec<Pose> = (0..frames)
        .map(|f| {
            let s = f as f64 / (frames - 1) as f64;
            let mut p = bind.clone();
            p.translations[rig.hips] += DVec3::new(2.0, 0.0, 2.0 + 0.5 * s);
            p.rotations[rig.hips] = DQuat::from_rotation_y(s * std::f64::consts::FRAC_PI_2);
            p.rotations[rig.legs[0][1]] = DQuat::from_rotation_x(s * std::f64::consts::FRAC_PI_2);
            p.rotations[rig.arms[1][1]] = DQuat::from_rotation_z(-s * 1.3);
            p
        })
        .collect();
    clip(rig, &poses)
}

// ---------- reading back our own document ----------

/// World matrices of every node at animation key `k` (channels sampled at that key; nodes without
/// channels keep their own TRS).
fn node_worlds(doc: &Value, bin: &[u8], k: usize) -> Vec<Mat4> {
    let nodes = doc["nodes"].as_array().unwrap();
    let mut trs: Vec<(Vec3, Quat)> = nodes
        .iter()
        .map(|n| {
            let t = n["translation"].as_array().map_or(Vec3::ZERO, |a| {
                Vec3::new(a[0].as_f64().unwrap() as f32, a[1].as_f64().unwrap() as f32, a[2].as_f64().unwrap() as f32)
            });
            let r = n["rotation"].as_array().map_or(Quat::IDENTITY, |a| {
                Quat::from_xyzw(
                    a[0].as_f64().unwrap() as f32,
                    a[1].as_f64().unwrap() as f32,
                    a[2].as_f64().unwrap() as f32,
                    a[3].as_f64().unwrap() as f32,
                )
            });
            (t, r)
        })
        .collect();
    let anim = &doc["animations"][0];
    for ch in anim["channels"].as_array().unwrap() {
        let Some(node) = ch["target"]["node"].as_u64() else { continue };
        let s = &anim["samplers"][ch["sampler"].as_u64().unwrap() as usize];
        let out = accessor_floats(doc, bin, s["output"].as_u64().unwrap() as usize);
        match ch["target"]["path"].as_str().unwrap() {
            "translation" if out.len() >= 3 * (k + 1) => {
                trs[node as usize].0 = Vec3::from_slice(&out[3 * k..3 * k + 3])
            }
            "rotation" if out.len() >= 4 * (k + 1) => trs[node as usize].1 = Quat::from_slice(&out[4 * k..4 * k + 4]),
            _ => {}
        }
    }
    let mut parent = vec![None; nodes.len()];
    for (i, n) in nodes.iter().enumerate() {
        for c in n["children"].as_array().into_iter().flatten() {
            parent[c.as_u64().unwrap() as usize] = Some(i);
        }
    }
    let local = |i: usize| Mat4::from_rotation_translation(trs[i].1, trs[i].0);
    (0..nodes.len())
        .map(|mut i| {
            let mut m = local(i);
            while let Some(p) = parent[i] {
                m = local(p) * m;
                i = p;
            }
            m
        })
        .collect()
}

/// Skinned positions of the document's first skinned mesh at key `k`, computed from the document's
/// own accessors (POSITION, JOINTS_0, WEIGHTS_0, inverse bind matrices) and node hierarchy.
fn doc_skinned(doc: &Value, bin: &[u8], k: usize) -> Vec<Vec3> {
    let node = doc["nodes"].as_array().unwrap().iter().find(|n| n.get("skin").is_some()).unwrap();
    let skin = &doc["skins"][node["skin"].as_u64().unwrap() as usize];
    let prim = &doc["meshes"][node["mesh"].as_u64().unwrap() as usize]["primitives"][0];
    let pos = accessor_floats(doc, bin, prim["attributes"]["POSITION"].as_u64().unwrap() as usize);
    let w = accessor_floats(doc, bin, prim["attributes"]["WEIGHTS_0"].as_u64().unwrap() as usize);
    let j = accessor_bytes(doc, bin, prim["attributes"]["JOINTS_0"].as_u64().unwrap() as usize);
    let ibm = accessor_floats(doc, bin, skin["inverseBindMatrices"].as_u64().unwrap() as usize);
    let joints: Vec<usize> = skin["joints"].as_array().unwrap().iter().map(|x| x.as_u64().unwrap() as usize).collect();
    let worlds = node_worlds(doc, bin, k);
    let mats: Vec<Mat4> =
        joints.iter().enumerate().map(|(i, &n)| worlds[n] * Mat4::from_cols_slice(&ibm[16 * i..16 * i + 16])).collect();
    (0..pos.len() / 3)
        .map(|v| {
            let p = Vec3::from_slice(&pos[3 * v..3 * v + 3]);
            (0..4).map(|c| mats[j[4 * v + c] as usize].transform_point3(p) * w[4 * v + c]).sum()
        })
        .collect()
}

// ---------- tests ----------

#[test]
fn reads_kenney_parts_at_rest_with_their_texture() {
    let dir = tempfile::tempdir().unwrap();
    let ch = read_character(&fixture(dir.path(), true)).unwrap();
    let names: Vec<&str> = ch.parts.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(names, ["arm-left", "arm-right", "head", "leg-left", "leg-right", "torso"]);
    let bounds = |name: &str| {
        let p = ch.part(name).unwrap();
        let lo = p.positions.iter().fold(Vec3::splat(f32::MAX), |a, q| a.min(Vec3::from(*q)));
        let hi = p.positions.iter().fold(Vec3::splat(f32::MIN), |a, q| a.max(Vec3::from(*q)));
        (lo, hi)
    };
    // Node transforms applied: legs from the floor to the hips, the head (0.1 × its 10× mesh) on
    // the torso at 1.9, the arms under the torso node.
    let (lo, hi) = bounds("leg-left");
    assert!(
        lo.abs_diff_eq(Vec3::new(0.0, 0.0, -0.2), 1e-5) && hi.abs_diff_eq(Vec3::new(0.4, 1.0, 0.2), 1e-5),
        "{lo} {hi}"
    );
    let (lo, hi) = bounds("head");
    assert!(
        lo.abs_diff_eq(Vec3::new(-0.4, 1.9, -0.4), 1e-5) && hi.abs_diff_eq(Vec3::new(0.4, 2.7, 0.4), 1e-5),
        "{lo} {hi}"
    );
    let (lo, hi) = bounds("arm-left");
    assert!(
        lo.abs_diff_eq(Vec3::new(0.4, 0.8, -0.3), 1e-5) && hi.abs_diff_eq(Vec3::new(0.8, 1.9, 0.1), 1e-5),
        "{lo} {hi}"
    );
    // Normals stay unit length under the head's 0.1 scale.
    assert!(ch.part("head").unwrap().normals.iter().all(|n| (Vec3::from(*n).length() - 1.0).abs() < 1e-5));
    let img = ch.image.as_ref().unwrap();
    assert_eq!(img.mime, "image/png");
    assert_eq!(image::load_from_memory(&img.bytes).unwrap().width(), 4);
}

#[test]
fn bad_character_files_are_errors_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let rig = Rig::standard();
    let no_torso = fixture(dir.path(), false);
    fixture(dir.path(), true);
    let e = bind_body(&read_character(&no_torso).unwrap(), &rig.skeleton).unwrap_err().to_string();
    assert!(e.contains("no-torso.glb") && e.contains("torso"), "{e}");
    let cut = dir.path().join("cut.glb");
    std::fs::write(&cut, &kenney_like_glb(true)[..200]).unwrap();
    let e = read_character(&cut).unwrap_err().to_string();
    assert!(e.contains("cut.glb"), "{e}");
    let missing = Path::new("/tmp/no-such-data-xyz");
    let e = first_character_dir(&[missing.join(BLOCKY_DIR)]).unwrap_err().to_string();
    assert!(e.contains("/tmp/no-such-data-xyz/assets/kenney_blocky_characters"), "{e}");
    assert_eq!(first_character_dir(&[missing.to_path_buf(), dir.path().to_path_buf()]).unwrap(), dir.path());
    assert_eq!(character_file(dir.path(), 7), dir.path().join("character-c.glb"));
}

/// Checks of a body bound to the standard rig in bind space.
fn check_bind(ch: &KenneyCharacter, body: &SkinnedBody, rig: &Rig) {
    let sk = &rig.skeleton;
    assert_eq!(body.bind.len(), sk.len());
    assert_eq!(body.positions.len(), body.joints.len());
    assert!(body.indices.iter().all(|&i| (i as usize) < body.positions.len()));
    let (_, g) = bind_pose(sk);
    let lowest = body.positions.iter().map(|p| p.y).fold(f32::MAX, f32::min);
    assert!(lowest.abs() < 1e-4, "feet on the floor: lowest vertex at {lowest}");
    let neck = g.positions[rig.neck].y as f32;
    assert!(body.height() > neck, "head above the neck: {} vs {neck}", body.height());
    let knee = g.positions[rig.legs[0][1]].y as f32;
    let shoulder = g.positions[rig.arms[0][1]];
    for (p, &j) in body.positions.iter().zip(&body.joints) {
        let j = j as usize;
        // Thighs above the knee, shins below it; the left forearm on the left (+x).
        if j == rig.legs[0][0] {
            assert!(p.y >= knee - 1e-4 && p.x >= -1e-5, "{p}");
        }
        if j == rig.legs[0][1] {
            assert!(p.y <= knee + 1e-4, "{p}");
        }
        if j == rig.arms[0][2] {
            assert!(p.x > 0.0 && (p.y as f64) < shoulder.y, "{p}");
        }
    }
    for part in ["torso", "head", "leg-left", "leg-right", "arm-left", "arm-right"] {
        assert!(ch.part(part).is_some(), "{part}");
    }
    for j in [
        rig.legs[0][0],
        rig.legs[0][1],
        rig.legs[0][2],
        rig.arms[1][1],
        rig.arms[1][2],
        rig.arms[1][3],
        rig.lower_back,
        rig.spine1,
        rig.head,
    ] {
        assert!(body.joints.iter().any(|&x| x as usize == j), "no vertex bound to {}", sk.joint(j).name);
    }
}

/// Document invariants (glTF 2.0 rules our readers and Blender rely on) plus the skin math on the
/// document's own data.
fn check_document(doc: &Value, bin: &[u8], body: &SkinnedBody, m: &Clip) {
    let sk = m.skeleton();
    assert_eq!(doc["buffers"][0]["byteLength"].as_u64().unwrap() as usize, bin.len());
    // Views lie in the buffer, 4-byte aligned, and cover all of it but the alignment padding:
    // nothing was written only to be dropped (the bone boxes are never built for a skinned body).
    let mut covered = 0;
    for v in doc["bufferViews"].as_array().unwrap() {
        let (off, len) = (v["byteOffset"].as_u64().unwrap() as usize, v["byteLength"].as_u64().unwrap() as usize);
        assert!(off % 4 == 0 && off + len <= bin.len(), "{v}");
        covered += len.next_multiple_of(4);
    }
    assert_eq!(covered, bin.len(), "bytes no view uses");
    let mesh_names: Vec<&str> = doc["meshes"].as_array().unwrap().iter().filter_map(|m| m["name"].as_str()).collect();
    assert!(mesh_names.iter().all(|n| !n.ends_with(" bone")), "no bone box mesh: {mesh_names:?}");
    let sizes = |a: &Value| {
        let c = match a["componentType"].as_u64().unwrap() {
            5121 => 1,
            5123 => 2,
            _ => 4,
        };
        let n = match a["type"].as_str().unwrap() {
            "SCALAR" => 1,
            "VEC2" => 2,
            "VEC3" => 3,
            "VEC4" => 4,
            _ => 16,
        };
        c * n * a["count"].as_u64().unwrap() as usize
    };
    for a in doc["accessors"].as_array().unwrap() {
        let v = &doc["bufferViews"][a["bufferView"].as_u64().unwrap() as usize];
        assert!(sizes(a) <= v["byteLength"].as_u64().unwrap() as usize, "{a}");
    }
    let nodes = doc["nodes"].as_array().unwrap();
    assert!(nodes.iter().all(|n| !n["name"].as_str().unwrap_or("").ends_with(" bone")), "no bone boxes");
    for n in nodes {
        for key in ["mesh", "skin", "camera"] {
            if let Some(i) = n[key].as_u64() {
                let arr = match key {
                    "mesh" => "meshes",
                    "skin" => "skins",
                    _ => "cameras",
                };
                assert!((i as usize) < doc[arr].as_array().unwrap().len(), "{key} {i}");
            }
        }
    }
    for mesh in doc["meshes"].as_array().unwrap() {
        for p in mesh["primitives"].as_array().unwrap() {
            assert!(p["material"].as_u64().unwrap() < doc["materials"].as_array().unwrap().len() as u64);
        }
    }
    let skins = doc["skins"].as_array().unwrap();
    assert_eq!(skins.len(), 1);
    let joints: Vec<usize> =
        skins[0]["joints"].as_array().unwrap().iter().map(|x| x.as_u64().unwrap() as usize).collect();
    assert_eq!(joints.len(), sk.len());
    for (j, &n) in joints.iter().enumerate() {
        assert_eq!(nodes[n]["name"].as_str().unwrap(), sk.joint(j).name);
    }
    assert_eq!(skins[0]["skeleton"].as_u64().unwrap() as usize, joints[0]);
    let ibm = &doc["accessors"][skins[0]["inverseBindMatrices"].as_u64().unwrap() as usize];
    assert_eq!((ibm["type"].as_str().unwrap(), ibm["count"].as_u64().unwrap() as usize), ("MAT4", sk.len()));
    let node = nodes.iter().find(|n| n.get("skin").is_some()).unwrap();
    let prim = &doc["meshes"][node["mesh"].as_u64().unwrap() as usize]["primitives"][0];
    let attr = &prim["attributes"];
    let jacc = &doc["accessors"][attr["JOINTS_0"].as_u64().unwrap() as usize];
    assert_eq!((jacc["componentType"].as_u64().unwrap(), jacc["type"].as_str().unwrap()), (5121, "VEC4"));
    let w = accessor_floats(doc, bin, attr["WEIGHTS_0"].as_u64().unwrap() as usize);
    assert!(w.chunks(4).all(|q| (q.iter().sum::<f32>() - 1.0).abs() < 1e-6 && q.iter().all(|x| *x >= 0.0)));
    let pacc = &doc["accessors"][attr["POSITION"].as_u64().unwrap() as usize];
    let pos = accessor_floats(doc, bin, attr["POSITION"].as_u64().unwrap() as usize);
    for k in 0..3 {
        let lo = pos.iter().skip(k).step_by(3).copied().fold(f32::MAX, f32::min);
        let hi = pos.iter().skip(k).step_by(3).copied().fold(f32::MIN, f32::max);
        assert_eq!((pacc["min"][k].as_f64().unwrap() as f32, pacc["max"][k].as_f64().unwrap() as f32), (lo, hi));
    }
    let image = &doc["images"].as_array().unwrap()[0];
    assert!(image["bufferView"].is_u64() && image["mimeType"] == "image/png");

    // The skin math on the document's own buffers and hierarchy.
    let (bind, _) = bind_pose(sk);
    let offset = m.pose(0).translations[0] - bind.translations[0];
    let skinned0 = doc_skinned(doc, bin, 0);
    for (s, p) in skinned0.iter().zip(&body.positions) {
        assert!(s.abs_diff_eq(*p + offset.as_vec3(), 1e-4), "frame 0 = bind placement: {s} vs {p}");
    }
    for f in 1..m.num_frames() {
        let g = forward(sk, &m.pose(f));
        let skinned = doc_skinned(doc, bin, f);
        // The same as the Rust skin function on core FK …
        let expected = skin_positions(body, &joint_matrices(&g));
        for (a, b) in skinned.iter().zip(&expected) {
            assert!(a.abs_diff_eq(*b, 1e-4), "frame {f}: {a} vs {b}");
        }
        // … and rigid with the joint: the vertex in its joint's frame is where it was at bind.
        let g0 = forward(sk, &m.pose(0));
        for (v, &j) in body.joints.iter().enumerate().step_by(7) {
            let j = j as usize;
            let local_now = g.rotations[j].inverse() * (skinned[v].as_dvec3() - g.positions[j]);
            let local_bind = g0.rotations[j].inverse() * (skinned0[v].as_dvec3() - g0.positions[j]);
            assert!(local_now.abs_diff_eq(local_bind, 1e-4), "frame {f} vertex {v}: {local_now} vs {local_bind}");
        }
    }
}

#[test]
fn fixture_character_skins_onto_the_rig_and_follows_its_joints() {
    let dir = tempfile::tempdir().unwrap();
    let ch = read_character(&fixture(dir.path(), true)).unwrap();
    let rig = Rig::standard();
    let body = bind_body(&ch, &rig.skeleton).unwrap();
    check_bind(&ch, &body, &rig);
    let m = test_motion(&rig);
    let cat = builtin();
    let (doc, bin, _) = skinned_gltf_document(
        &SkinnedCast {
            scene: &room(),
            cat: &cat,
            characters: &[("Eve", &m)],
            bodies: &[Some(&body)],
            camera: &camera,
            fps: 30.0,
        },
        &|_| None,
    )
    .unwrap();
    // Through GLB bytes and back.
    let glb = parse_glb(&glb_bytes(&doc, &bin)).unwrap();
    check_document(&glb.json, &glb.bin, &body, &m);
    // The bent knee lifts the left shin: its lowest vertex rises from the floor to about knee height.
    let last = doc_skinned(&glb.json, &glb.bin, m.num_frames() - 1);
    let knee = forward(&rig.skeleton, &m.pose(m.num_frames() - 1)).positions[rig.legs[0][1]].y as f32;
    let shin_low = body
        .joints
        .iter()
        .zip(&last)
        .filter(|(j, _)| **j as usize == rig.legs[0][1])
        .map(|(_, p)| p.y)
        .fold(f32::MAX, f32::min);
    assert!(shin_low > knee - 0.15, "shin horizontal: lowest {shin_low} vs knee {knee}");
    // A preview frame shows the character's texture colours where the body is.
    let refs = [Some(&body)];
    let img = render_skinned_frame(
        &SkinnedCast {
            scene: &room(),
            cat: &cat,
            characters: &[("Eve", &m)],
            bodies: &refs,
            camera: &camera,
            fps: 30.0,
        },
        0,
        (160, 120),
    );
    let blueish = img.pixels().filter(|p| p.0[2] > 120 && p.0[0] < 200 && p.0[2] > p.0[1].saturating_add(20)).count();
    assert!(blueish > 50, "textured body pixels: {blueish}");
}

#[test]
fn characters_without_a_body_keep_the_stick_figure() {
    let dir = tempfile::tempdir().unwrap();
    let ch = read_character(&fixture(dir.path(), true)).unwrap();
    let rig = Rig::standard();
    let body = bind_body(&ch, &rig.skeleton).unwrap();
    let m = test_motion(&rig);
    let chars = [("Eve", &m), ("Bob", &m)];
    let (doc, _, _) = skinned_gltf_document(
        &SkinnedCast {
            scene: &room(),
            cat: &builtin(),
            characters: &chars,
            bodies: &[None, Some(&body)],
            camera: &camera,
            fps: 30.0,
        },
        &|_| None,
    )
    .unwrap();
    let nodes = doc["nodes"].as_array().unwrap();
    let bones = nodes.iter().filter(|n| n["name"].as_str().unwrap_or("").ends_with(" bone")).count();
    assert!(bones > 10, "Eve's bone boxes stay: {bones}");
    assert_eq!(doc["skins"].as_array().unwrap().len(), 1);
    let skinned = nodes.iter().find(|n| n.get("skin").is_some()).unwrap();
    assert_eq!(skinned["name"], "Bob body");
    let e = skinned_gltf_document(
        &SkinnedCast {
            scene: &room(),
            cat: &builtin(),
            characters: &chars,
            bodies: &[Some(&body)],
            camera: &camera,
            fps: 30.0,
        },
        &|_| None,
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("1 bodies for 2 characters"), "{e}");
}

#[test]
fn real_kenney_characters_skin_onto_the_rig() {
    inbetween_io::data::with_shared_data("Kenney blocky characters", |data| {
        let dir = data.join(BLOCKY_DIR);
        let rig = Rig::standard();
        let m = test_motion(&rig);
        for i in 0..6 {
            let file = character_file(&dir, i);
            let ch = read_character(&file).unwrap();
            let body = bind_body(&ch, &rig.skeleton).unwrap();
            check_bind(&ch, &body, &rig);
            let img = image::load_from_memory(&body.image.as_ref().unwrap().bytes).unwrap();
            assert_eq!((img.width(), img.height()), (1024, 1024));
            let h = body.height();
            assert!((1.3..1.8).contains(&h), "{}: {h} m", file.display());
            println!(
                "{}: {} vertices, {} triangles, {h:.3} m",
                file.display(),
                body.positions.len(),
                body.indices.len() / 3
            );
            if i == 0 {
                let (doc, bin, _) = skinned_gltf_document(
                    &SkinnedCast {
                        scene: &room(),
                        cat: &builtin(),
                        characters: &[("Eve", &m)],
                        bodies: &[Some(&body)],
                        camera: &camera,
                        fps: 30.0,
                    },
                    &|_| None,
                )
                .unwrap();
                let glb = parse_glb(&glb_bytes(&doc, &bin)).unwrap();
                check_document(&glb.json, &glb.bin, &body, &m);
            }
        }
    });
}
