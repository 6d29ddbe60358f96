//! glTF 2.0 export of a generated camera: one perspective camera node animated by translation and
//! rotation (LINEAR samplers, one key per frame), plus a node per framed character (its target
//! point) so a viewer shows what the camera follows. Buffers are embedded as a base64 data URI.

use crate::dataset::Scene;
use crate::infer::GeneratedTrack;
use inbetween_io::gltf_buffer::json::{animation::Property, Index, Node};
use inbetween_io::gltf_buffer::{data_uri, node, perspective, scene, Anim, GltfDoc, Type};

/// The glTF document (JSON) of `track` over `scene`.
pub fn camera_gltf(track: &GeneratedTrack, scene_: &Scene) -> serde_json::Value {
    // Animation data only: views without a target, bounds on the time input as the spec asks.
    let mut d = GltfDoc::new("inbetween camera");
    let camera = track.camera();
    let times: Vec<f32> = (0..camera.frames.len()).map(|i| camera.seconds(i) as f32).collect();
    let t_acc = d.floats(&times, Type::Scalar, true, None);
    let pos: Vec<f32> = camera.frames.iter().flat_map(|c| c.pose.position.to_array().map(|v| v as f32)).collect();
    let rot: Vec<f32> = camera.frames.iter().flat_map(|c| c.pose.rotation.to_array().map(|v| v as f32)).collect();
    let p_acc = d.floats(&pos, Type::Vec3, false, None);
    let r_acc = d.floats(&rot, Type::Vec4, false, None);
    let lens = track.lens;
    let cam = d.push(perspective(None, lens.fovy as f32, Some(lens.aspect as f32), 0.05, Some(500.0)));
    let cam_node = d.push(Node { camera: Some(cam), ..node("camera") });
    let mut anim = Anim::default();
    anim.channel(t_acc, p_acc, cam_node, Property::Translation);
    anim.channel(t_acc, r_acc, cam_node, Property::Rotation);
    for c in &scene_.characters {
        let tgt: Vec<f32> =
            track.frames.iter().flat_map(|f| c.frame(f.frame).target().to_array().map(|v| v as f32)).collect();
        let acc = d.floats(&tgt, Type::Vec3, false, None);
        let n = d.push(node(format!("target {}", c.name)));
        anim.channel(t_acc, acc, n, Property::Translation);
    }
    d.push(anim.finish(format!("camera ({})", track.style)));
    let nodes = (0..d.root.nodes.len() as u32).map(Index::new).collect();
    d.root.scenes.push(scene(None, nodes));
    d.root.scene = Some(Index::new(0));
    let (mut doc, bin) = d.finish();
    doc["buffers"][0]["uri"] = serde_json::json!(data_uri(&bin));
    doc
}

/// Writes the glTF file atomically.
pub fn write_gltf(path: &std::path::Path, track: &GeneratedTrack, scene: &Scene) -> Result<(), crate::CameraError> {
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
