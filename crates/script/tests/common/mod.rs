//! Fixtures and glTF read-back helpers shared by the output and story tests (each test binary uses
//! a part).
#![allow(dead_code)]

use inbetween_script::jobs::{RunJob, SceneJob};
use inbetween_script::scene::{Origin, PlacedObject};
use serde_json::Value;

/// A story job as `inbetween script run` makes it (seed 1, procedural motions, small GIF) writing
/// into `out`.
pub fn run_job(out: &std::path::Path, optimize: bool) -> RunJob {
    RunJob {
        scene: SceneJob {
            out_dir: out.to_path_buf(),
            seed: 1,
            view: None,
            models: None,
            config: Default::default(),
            semantic: None,
            limits: Default::default(),
        },
        optimize,
        shared_motions: false,
        gif_width: 120,
        cancel: Default::default(),
        progress: inbetween_io::Progress::hidden(),
    }
}

/// An object placed by the script's first sentence, with no attributes and no support.
pub fn obj(label: &str, category: &str, position: [f32; 3], yaw: f32, size: [f32; 3]) -> PlacedObject {
    PlacedObject {
        label: label.into(),
        category: category.into(),
        attributes: vec![],
        position,
        yaw,
        size,
        support: None,
        origin: Origin::Script { sentence: 0, node: 0 },
    }
}

/// Components per element of a glTF accessor type.
pub fn components(accessor: &Value) -> u64 {
    match accessor["type"].as_str().unwrap() {
        "SCALAR" => 1,
        "VEC2" => 2,
        "VEC3" => 3,
        "VEC4" => 4,
        "MAT4" => 16,
        t => panic!("type {t}"),
    }
}

/// Byte offset of an accessor's first element in the binary buffer.
fn accessor_start(doc: &Value, a: &Value) -> usize {
    let v = &doc["bufferViews"][a["bufferView"].as_u64().unwrap() as usize];
    v["byteOffset"].as_u64().unwrap_or(0) as usize + a["byteOffset"].as_u64().unwrap_or(0) as usize
}

/// The float values of accessor `acc`, element-major (tightly packed views, as we write them).
pub fn accessor_floats(doc: &Value, bin: &[u8], acc: usize) -> Vec<f32> {
    let a = &doc["accessors"][acc];
    assert_eq!(a["componentType"], 5126);
    let start = accessor_start(doc, a);
    let n = a["count"].as_u64().unwrap() as usize * components(a) as usize;
    assert!(start + 4 * n <= bin.len(), "accessor {acc} past the buffer");
    (0..n).map(|k| f32::from_le_bytes(bin[start + 4 * k..start + 4 * k + 4].try_into().unwrap())).collect()
}

/// The bytes of a VEC4 unsigned-byte accessor (joint indices, weights).
pub fn accessor_bytes(doc: &Value, bin: &[u8], acc: usize) -> Vec<u8> {
    let a = &doc["accessors"][acc];
    let start = accessor_start(doc, a);
    bin[start..start + 4 * a["count"].as_u64().unwrap() as usize].to_vec()
}

/// The buffer holds every view and every view its accessors; POSITION accessors have bounds.
pub fn check_buffers(doc: &Value, bin: &[u8]) {
    assert_eq!(doc["buffers"][0]["byteLength"].as_u64().unwrap() as usize, bin.len());
    let views = doc["bufferViews"].as_array().unwrap();
    for v in views {
        let end = v["byteOffset"].as_u64().unwrap_or(0) + v["byteLength"].as_u64().unwrap();
        assert!(end as usize <= bin.len(), "view past the buffer");
    }
    for a in doc["accessors"].as_array().unwrap() {
        let v = &views[a["bufferView"].as_u64().unwrap() as usize];
        let comps = components(a);
        let bytes = match a["componentType"].as_u64().unwrap() {
            5120 | 5121 => 1,
            5122 | 5123 => 2,
            _ => 4,
        };
        let stride = v["byteStride"].as_u64().unwrap_or(comps * bytes);
        let need = a["byteOffset"].as_u64().unwrap_or(0) + stride * (a["count"].as_u64().unwrap() - 1) + comps * bytes;
        assert!(need <= v["byteLength"].as_u64().unwrap(), "accessor past its view: {a}");
    }
    for m in doc["meshes"].as_array().unwrap() {
        for p in m["primitives"].as_array().unwrap() {
            let a = &doc["accessors"][p["attributes"]["POSITION"].as_u64().unwrap() as usize];
            assert!(a["min"].is_array() && a["max"].is_array(), "POSITION without bounds: {a}");
        }
    }
}
