//! A motion clip as a glTF 2.0 document: one node per joint in the skeleton's hierarchy (rest
//! offsets as translations, BVH `End Site`s as leaf nodes named `<joint>_end`), and one animation
//! holding a rotation channel for every joint and a translation channel for every joint with
//! position channels, sampled at every frame (LINEAR interpolation, times in seconds). Lengths are
//! the clip's own units times `scale`.
//!
//! Blender and three.js's GLTFLoader read it natively; the studio's viewer loads takes this way,
//! because a browser parses the binary buffer many times faster than BVH text.

use inbetween_core::{Motion, Pose, Skeleton};
use serde_json::Value;

use crate::gltf_buffer::json::{animation::Property, Index, Node};
use crate::gltf_buffer::{node, scene, Anim, GltfDoc, Type};

/// The document (buffer 0 without `uri`) and its binary buffer; pass both to [`glb_bytes`] or
/// [`crate::gltf_buffer::data_uri`].
pub fn motion_document(motion: &Motion, name: &str, scale: f64) -> (Value, Vec<u8>) {
    let poses: Vec<_> = (0..motion.num_frames()).map(|f| motion.pose(f)).collect();
    poses_document(&motion.skeleton, motion.frame_time, &poses, name, scale)
}

/// [`motion_document`] of the clip with these local poses, one per frame `frame_time` seconds
/// apart (for a pose clip not written as channels: no Euler angles on the way).
pub fn poses_document(
    skeleton: &Skeleton,
    frame_time: f64,
    poses: &[Pose],
    name: &str,
    scale: f64,
) -> (Value, Vec<u8>) {
    let joints = skeleton.joints();
    let mut d = GltfDoc::new("inbetween");
    let f32s = |v: glam::DVec3| [v.x as f32, v.y as f32, v.z as f32];
    for j in joints {
        d.push(Node { translation: Some(f32s(j.offset * scale)), ..node(j.name.as_str()) });
    }
    let mut children: Vec<Vec<Index<Node>>> = vec![Vec::new(); joints.len()];
    let mut roots = Vec::new();
    for (i, j) in joints.iter().enumerate() {
        match j.parent {
            Some(p) => children[p].push(Index::new(i as u32)),
            None => roots.push(Index::new(i as u32)),
        }
    }
    for (i, j) in joints.iter().enumerate() {
        if let Some(e) = j.end_site {
            let end = d.push(Node { translation: Some(f32s(e * scale)), ..node(format!("{}_end", j.name)) });
            children[i].push(end);
        }
    }
    for (i, c) in children.into_iter().enumerate() {
        if !c.is_empty() {
            d.root.nodes[i].children = Some(c);
        }
    }
    d.root.scenes.push(scene(Some(name.to_string()), roots));
    d.root.scene = Some(Index::new(0));
    let n = poses.len();
    let times: Vec<f32> = (0..n).map(|f| (f as f64 * frame_time) as f32).collect();
    let input = d.floats(&times, Type::Scalar, true, None);
    let mut anim = Anim::default();
    for (j, joint) in joints.iter().enumerate() {
        let target = Index::new(j as u32);
        let rot: Vec<f32> = poses
            .iter()
            .flat_map(|p| {
                let q = p.rotations[j];
                [q.x as f32, q.y as f32, q.z as f32, q.w as f32]
            })
            .collect();
        let out = d.floats(&rot, Type::Vec4, false, None);
        anim.channel(input, out, target, Property::Rotation);
        if joint.channels.iter().any(|c| !c.is_rotation()) {
            let tr: Vec<f32> = poses.iter().flat_map(|p| f32s(p.translations[j] * scale)).collect();
            let out = d.floats(&tr, Type::Vec3, false, None);
            anim.channel(input, out, target, Property::Translation);
        }
    }
    if n > 0 {
        d.push(anim.finish(name));
    }
    d.finish()
}

/// [`poses_document`] as a binary glTF (`.glb`) file's bytes.
pub fn poses_glb(skeleton: &Skeleton, frame_time: f64, poses: &[Pose], name: &str, scale: f64) -> Vec<u8> {
    let (doc, bin) = poses_document(skeleton, frame_time, poses, name, scale);
    glb_bytes(&doc, &bin)
}

/// [`motion_document`] as a binary glTF (`.glb`) file's bytes.
pub fn motion_glb(motion: &Motion, name: &str, scale: f64) -> Vec<u8> {
    let (doc, bin) = motion_document(motion, name, scale);
    glb_bytes(&doc, &bin)
}

/// A GLB container (glTF 2.0 §4.4): the 12-byte header, the JSON chunk padded with spaces, and the
/// binary chunk (buffer 0, zero-padded) when not empty.
pub fn glb_bytes(doc: &Value, bin: &[u8]) -> Vec<u8> {
    let mut js = doc.to_string().into_bytes();
    while !js.len().is_multiple_of(4) {
        js.push(b' ');
    }
    let mut b = bin.to_vec();
    crate::gltf_buffer::pad_to_4(&mut b);
    let total = 12 + 8 + js.len() + if b.is_empty() { 0 } else { 8 + b.len() };
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(js.len() as u32).to_le_bytes());
    out.extend_from_slice(&0x4E4F_534Au32.to_le_bytes());
    out.extend_from_slice(&js);
    if !b.is_empty() {
        out.extend_from_slice(&(b.len() as u32).to_le_bytes());
        out.extend_from_slice(&0x004E_4942u32.to_le_bytes());
        out.extend_from_slice(&b);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use inbetween_core::procedural::{gait, GaitParams};

    #[test]
    fn every_joint_is_a_node_and_the_samples_are_the_poses() {
        let m = gait(&GaitParams { frames: 12, ..GaitParams::walk() });
        let (doc, bin) = motion_document(&m, "walk", 0.5);
        let joints = m.skeleton.joints();
        let ends = joints.iter().filter(|j| j.end_site.is_some()).count();
        assert_eq!(doc["nodes"].as_array().unwrap().len(), joints.len() + ends);
        assert_eq!(doc["nodes"][1]["name"], joints[1].name.as_str());
        let roots = doc["scenes"][0]["nodes"].as_array().unwrap();
        assert_eq!(roots.len(), joints.iter().filter(|j| j.parent.is_none()).count());
        let anim = &doc["animations"][0];
        let rotations =
            anim["channels"].as_array().unwrap().iter().filter(|c| c["target"]["path"] == "rotation").count();
        assert_eq!(rotations, joints.len());
        // The rotation of joint 3 at frame 7 reads back from the buffer.
        let ch = anim["channels"]
            .as_array()
            .unwrap()
            .iter()
            .find(|c| c["target"]["node"] == 3 && c["target"]["path"] == "rotation")
            .unwrap();
        let acc = &doc["accessors"]
            [anim["samplers"][ch["sampler"].as_u64().unwrap() as usize]["output"].as_u64().unwrap() as usize];
        assert_eq!(acc["count"], 12);
        let view = &doc["bufferViews"][acc["bufferView"].as_u64().unwrap() as usize];
        let at = view["byteOffset"].as_u64().unwrap() as usize + 7 * 16;
        let f = |k: usize| f32::from_le_bytes(bin[at + 4 * k..at + 4 * k + 4].try_into().unwrap());
        let q = m.pose(7).rotations[3];
        assert_eq!([f(0), f(1), f(2), f(3)], [q.x as f32, q.y as f32, q.z as f32, q.w as f32]);
        // A GLB: header, total length, JSON chunk first.
        let glb = motion_glb(&m, "walk", 1.0);
        assert_eq!(&glb[0..4], b"glTF");
        assert_eq!(u32::from_le_bytes(glb[8..12].try_into().unwrap()) as usize, glb.len());
        assert_eq!(&glb[16..20], &0x4E4F_534Au32.to_le_bytes());
    }
}
