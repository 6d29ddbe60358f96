//! glTF 2.0 export of a generated camera: one perspective camera node animated by translation and
//! rotation (LINEAR samplers, one key per frame), plus a node per framed character (its target
//! point) so a viewer shows what the camera follows. Buffers are embedded as a base64 data URI.

use crate::dataset::Scene;
use crate::infer::CameraTrack;
use inbetween_io::gltf_buffer::{data_uri, ElementType, GltfBuffer};
use serde_json::json;

/// The glTF document (JSON) of `track` over `scene`.
pub fn camera_gltf(track: &CameraTrack, scene: &Scene) -> serde_json::Value {
    // Animation data only: views without a target, bounds on the time input as the spec asks.
    let mut b = GltfBuffer::default();
    let times: Vec<f32> = track.frames.iter().map(|f| (f.frame as f64 / track.fps) as f32).collect();
    let t_acc = b.floats(&times, ElementType::Scalar, true, None);
    let pos: Vec<f32> = track.frames.iter().flat_map(|f| f.pose.position.to_array().map(|v| v as f32)).collect();
    let rot: Vec<f32> = track.frames.iter().flat_map(|f| f.pose.rotation.to_array().map(|v| v as f32)).collect();
    let p_acc = b.floats(&pos, ElementType::Vec3, false, None);
    let r_acc = b.floats(&rot, ElementType::Vec4, false, None);
    let mut nodes = vec![json!({"name": "camera", "camera": 0})];
    let mut samplers = vec![
        json!({"input": t_acc, "output": p_acc, "interpolation": "LINEAR"}),
        json!({"input": t_acc, "output": r_acc, "interpolation": "LINEAR"}),
    ];
    let mut channels = vec![
        json!({"sampler": 0, "target": {"node": 0, "path": "translation"}}),
        json!({"sampler": 1, "target": {"node": 0, "path": "rotation"}}),
    ];
    for (i, c) in scene.characters.iter().enumerate() {
        let tgt: Vec<f32> =
            track.frames.iter().flat_map(|f| c.frame(f.frame).target().to_array().map(|v| v as f32)).collect();
        let acc = b.floats(&tgt, ElementType::Vec3, false, None);
        nodes.push(json!({"name": format!("target {}", c.name)}));
        samplers.push(json!({"input": t_acc, "output": acc, "interpolation": "LINEAR"}));
        channels.push(json!({"sampler": samplers.len() - 1, "target": {"node": i + 1, "path": "translation"}}));
    }
    let lens = track.lens;
    json!({
        "asset": {"version": "2.0", "generator": "inbetween camera"},
        "scene": 0,
        "scenes": [{"nodes": (0..nodes.len()).collect::<Vec<_>>()}],
        "nodes": nodes,
        "cameras": [{"type": "perspective", "perspective": {"yfov": lens.fovy, "aspectRatio": lens.aspect, "znear": 0.05, "zfar": 500.0}}],
        "animations": [{"name": format!("camera ({})", track.style), "samplers": samplers, "channels": channels}],
        "buffers": [{"byteLength": b.bin.len(), "uri": data_uri(&b.bin)}],
        "bufferViews": b.views,
        "accessors": b.accessors,
    })
}

/// Writes the glTF file atomically.
pub fn write_gltf(path: &std::path::Path, track: &CameraTrack, scene: &Scene) -> Result<(), crate::CameraError> {
    let doc = camera_gltf(track, scene);
    inbetween_io::write_atomic(path, doc.to_string().as_bytes())
        .map_err(|source| crate::CameraError::Io { path: path.into(), source })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gltf_has_consistent_accessors() {
        let scene = Scene::procedural(1, 60, 30.0);
        let device = inbetween_nn::backend::cpu();
        let cfg = crate::model::ModelConfig { hidden: 8, tta_dim: 8, ..Default::default() };
        let model = crate::infer::FastModel::from_burn(&cfg.init(&device), cfg);
        let keys = crate::infer::example_keys(&scene, &[0, 59]);
        let style = crate::infer::Style { name: "t".into(), code: vec![0.0; 4] };
        let track = crate::infer::GenerateJob::new(&model, &scene, &keys, &style).run().unwrap();
        let doc = camera_gltf(&track, &scene);
        let accessors = doc["accessors"].as_array().unwrap();
        assert_eq!(accessors[0]["count"], 60);
        assert_eq!(accessors[1]["type"], "VEC3");
        assert_eq!(accessors[2]["type"], "VEC4");
        let total: u64 = doc["bufferViews"].as_array().unwrap().iter().map(|v| v["byteLength"].as_u64().unwrap()).sum();
        assert_eq!(doc["buffers"][0]["byteLength"].as_u64().unwrap(), total);
        assert_eq!(doc["animations"][0]["channels"].as_array().unwrap().len(), 4);
    }
}
