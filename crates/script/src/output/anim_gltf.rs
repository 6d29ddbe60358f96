//! Animated glTF 2.0 of a story: the furnished scene exactly as [`super::gltf::gltf_document`]
//! builds it, plus per character a node hierarchy mirroring its skeleton (one node per joint,
//! named by the joint, translation = rest offset) with a simple rigid body (a box per bone,
//! attached under the joint nodes, so viewers without skin support still show a figure), plus an
//! animated perspective camera. One animation ("story") holds every channel, LINEAR, one key per
//! frame: each character's root translation and every joint's rotation, and the camera's
//! translation and rotation. `.glb` writes the binary container, anything else a `.gltf` with the
//! buffer embedded as base64.

use std::path::{Path, PathBuf};

use glam::{DQuat, DVec3, Mat3, Quat, Vec3};
use inbetween_core::clip::Clip;
use inbetween_io::gltf_buffer::{self, ElementType, ARRAY_BUFFER, ELEMENT_ARRAY_BUFFER};
use serde_json::{json, Value};

use super::gltf::{gltf_document, write_document};
use crate::catalogue::Catalogue;
use crate::error::ScriptError;
use crate::scene::Scene;

/// Per-frame camera: `frame → (eye, target, vertical field of view in degrees)`, metres, Y up.
pub type CameraFn<'a> = dyn Fn(usize) -> ([f32; 3], [f32; 3], f32) + 'a;

/// Body colours of characters (sRGB), in order; repeats after six.
pub const CHARACTER_COLORS: [[u8; 3]; 6] =
    [[214, 39, 40], [31, 119, 180], [44, 160, 44], [148, 103, 189], [255, 127, 14], [23, 190, 207]];

/// The extension that animates the camera's field of view when the camera closure changes it.
pub const FOV_EXTENSION: &str = "KHR_animation_pointer";

/// Name of the single animation in the document.
pub const ANIMATION_NAME: &str = "story";

/// Frames of the story at `fps`: enough to cover the longest character clip (each clip is
/// sampled at its own frame time), at least 1.
pub fn animation_frames(characters: &[(&str, &Clip)], fps: f64) -> usize {
    let dur = characters.iter().map(|(_, m)| m.duration()).fold(0.0f64, f64::max);
    if !(fps.is_finite() && fps > 0.0) {
        return 1;
    }
    (dur * fps + 1e-6).floor() as usize + 1
}

/// Checks the inputs every animated writer needs (a character's clip has at least one frame by
/// construction).
pub(crate) fn check_fps(fps: f64) -> Result<(), ScriptError> {
    if !(fps.is_finite() && fps > 0.0) {
        return Err(ScriptError::Invalid(format!("animation frame rate {fps} must be a positive number")));
    }
    Ok(())
}

/// The glTF camera rotation (looking down its local -Z, +Y up) that looks from `eye` to `target`.
pub fn look_rotation(eye: Vec3, target: Vec3) -> Quat {
    let f = (target - eye).normalize_or(Vec3::NEG_Z);
    let mut r = f.cross(Vec3::Y);
    if r.length_squared() < 1e-10 {
        r = f.any_orthonormal_vector();
    }
    let r = r.normalize();
    let u = r.cross(f);
    Quat::from_mat3(&Mat3::from_cols(r, u, -f)).normalize()
}

/// Appends binary data and accessors to an existing document and its buffer (also used by
/// [`super::skinned`]).
pub(crate) struct Appender<'a> {
    pub(crate) doc: &'a mut Value,
    pub(crate) bin: &'a mut Vec<u8>,
}

impl Appender<'_> {
    pub(crate) fn push(&mut self, key: &str, v: Value) -> usize {
        if !self.doc.get(key).is_some_and(Value::is_array) {
            self.doc[key] = json!([]);
        }
        let a = self.doc[key].as_array_mut().expect("array just ensured");
        a.push(v);
        a.len() - 1
    }

    /// Adds `bytes` as a bufferView (4-byte aligned, see [`gltf_buffer::append_view`]).
    pub(crate) fn view(&mut self, bytes: &[u8], target: Option<u32>) -> usize {
        let v = gltf_buffer::append_view(self.bin, bytes, target);
        self.push("bufferViews", v)
    }

    /// FLOAT accessor of `kind` elements in a view of its own.
    pub(crate) fn floats(&mut self, values: &[f32], kind: ElementType, bounds: bool, target: Option<u32>) -> usize {
        let view = self.view(&gltf_buffer::f32_bytes(values), target);
        self.push("accessors", gltf_buffer::float_accessor(view, values, kind, bounds))
    }

    /// UNSIGNED_SHORT index accessor in an ELEMENT_ARRAY_BUFFER view.
    fn indices(&mut self, idx: &[u16]) -> usize {
        let view = self.view(&gltf_buffer::u16_bytes(idx), Some(ELEMENT_ARRAY_BUFFER));
        self.push("accessors", gltf_buffer::u16_index_accessor(view, idx.len()))
    }

    /// A box mesh centred on the origin, unit edges, flat normals; one per material.
    fn centred_box(&mut self, name: &str, material: usize) -> usize {
        let (pos, nor, idx) = super::gltf::box_geometry(0.0);
        let (pos, nor): (Vec<f32>, Vec<f32>) = (pos.concat(), nor.concat());
        let p = self.floats(&pos, ElementType::Vec3, true, Some(ARRAY_BUFFER));
        let nn = self.floats(&nor, ElementType::Vec3, false, Some(ARRAY_BUFFER));
        let i = self.indices(&idx);
        self.push("meshes", json!({"name": name, "primitives": [{"attributes": {"POSITION": p, "NORMAL": nn}, "indices": i, "material": material}]}))
    }
}

fn srgb_to_linear(c: u8) -> f32 {
    let c = c as f32 / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Cross-section of the body box along the bone ending at `joint` (from its parent, or to its
/// end site), metres.
fn bone_thickness(joint: &str) -> f32 {
    let has = |s: &str| joint.contains(s);
    if has("Head") {
        0.17
    } else if has("Spine") || has("LowerBack") {
        0.16
    } else if has("Finger") || has("Index") || has("Thumb") || has("Toe") {
        0.035
    } else {
        0.07
    }
}

/// A node that stretches a centred unit box along `offset` (from the parent joint's origin).
fn bone_node(name: String, mesh: usize, offset: DVec3, thickness: f32) -> Option<Value> {
    let len = offset.length();
    if len < 1e-3 {
        return None;
    }
    let q = DQuat::from_rotation_arc(DVec3::Y, offset / len).normalize();
    let t = offset / 2.0;
    Some(json!({
        "name": name,
        "mesh": mesh,
        "translation": [t.x as f32, t.y as f32, t.z as f32],
        "rotation": [q.x as f32, q.y as f32, q.z as f32, q.w as f32],
        "scale": [thickness, len as f32, thickness],
    }))
}

/// Unit quaternions (x, y, z, w) with consecutive keys in the same hemisphere, so LINEAR
/// (slerp) keys never take the long way round.
fn continuous_quats(qs: impl Iterator<Item = Quat>) -> Vec<f32> {
    let mut out = Vec::new();
    let mut prev: Option<Quat> = None;
    for q in qs {
        let mut q = q.normalize();
        if prev.is_some_and(|p| p.dot(q) < 0.0) {
            q = -q;
        }
        prev = Some(q);
        out.extend(q.to_array());
    }
    out
}

/// The animated document and its binary buffer (buffer 0, no uri yet), plus notes on models that
/// fell back to boxes. `model` maps a category to a GLB file as in [`gltf_document`]. Characters
/// are sampled at their own frame time, the camera at `fps` for [`animation_frames`] frames; the
/// camera's `yfov` is the one at frame 0, and when the closure changes it a STEP channel through
/// [`FOV_EXTENSION`] animates it (core glTF cannot).
pub fn animated_gltf_document(
    scene: &Scene,
    cat: &Catalogue,
    characters: &[(&str, &Clip)],
    camera: &CameraFn,
    fps: f64,
    model: &dyn Fn(&str) -> Option<PathBuf>,
) -> Result<(Value, Vec<u8>, Vec<String>), ScriptError> {
    let bodies = vec![Body::Boxes; characters.len()];
    let out = animated_document(scene, cat, characters, &bodies, camera, fps, model)?;
    Ok((out.doc, out.bin, out.notes))
}

/// How a character's body is drawn in an animated document.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Body {
    /// A box along every bone (the stick figure), children of the joint nodes.
    Boxes,
    /// None here: the caller skins a mesh onto the joint nodes ([`super::skinned`]).
    Skinned,
}

/// An animated document under construction and where each character's joint nodes are.
pub(crate) struct AnimatedDocument {
    pub doc: Value,
    pub bin: Vec<u8>,
    pub notes: Vec<String>,
    /// Per character, the node index of its root joint; its other joints follow in skeleton order.
    pub first_joint: Vec<usize>,
}

/// [`animated_gltf_document`] with each character's body chosen up front (`bodies[c]`), so a
/// skinned character never gets bone boxes. The buffer is padded but `buffers` is left for the
/// caller to set when it adds no more data.
#[allow(clippy::too_many_arguments)]
pub(crate) fn animated_document(
    scene: &Scene,
    cat: &Catalogue,
    characters: &[(&str, &Clip)],
    bodies: &[Body],
    camera: &CameraFn,
    fps: f64,
    model: &dyn Fn(&str) -> Option<PathBuf>,
) -> Result<AnimatedDocument, ScriptError> {
    check_fps(fps)?;
    if bodies.len() != characters.len() {
        return Err(ScriptError::Invalid(format!("{} bodies for {} characters", bodies.len(), characters.len())));
    }
    let mut first_joint = Vec::with_capacity(characters.len());
    let (mut doc, mut bin, notes) = gltf_document(scene, cat, model);
    let mut roots: Vec<usize> = Vec::new();
    let mut samplers: Vec<Value> = Vec::new();
    let mut channels: Vec<Value> = Vec::new();
    let mut a = Appender { doc: &mut doc, bin: &mut bin };
    // Time accessors shared by every channel with the same key count and frame time.
    let mut times: Vec<(usize, u64, usize)> = Vec::new();
    let mut time_acc = |a: &mut Appender, n: usize, dt: f64| -> usize {
        if let Some(&(_, _, acc)) = times.iter().find(|t| t.0 == n && t.1 == dt.to_bits()) {
            return acc;
        }
        let t: Vec<f32> = (0..n).map(|f| (f as f64 * dt) as f32).collect();
        let acc = a.floats(&t, ElementType::Scalar, true, None);
        times.push((n, dt.to_bits(), acc));
        acc
    };
    let channel =
        |samplers: &mut Vec<Value>, channels: &mut Vec<Value>, input: usize, output: usize, node: usize, path: &str| {
            samplers.push(json!({"input": input, "output": output, "interpolation": "LINEAR"}));
            channels.push(json!({"sampler": samplers.len() - 1, "target": {"node": node, "path": path}}));
        };

    for (ci, ((name, m), body)) in characters.iter().zip(bodies).enumerate() {
        let sk = m.skeleton();
        let n = m.num_frames();
        let mesh = (*body == Body::Boxes).then(|| {
            let color = CHARACTER_COLORS[ci % CHARACTER_COLORS.len()].map(srgb_to_linear);
            let mat = a.push(
                "materials",
                json!({"name": format!("{name} body"), "pbrMetallicRoughness": {"baseColorFactor": [color[0], color[1], color[2], 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.7}}),
            );
            a.centred_box(&format!("{name} bone"), mat)
        });
        let poses = m.poses();
        let input = time_acc(&mut a, n, m.frame_time());
        // Joint nodes first (their indices are needed for children lists), filled in below.
        let first = a.doc["nodes"].as_array().map_or(0, Vec::len);
        first_joint.push(first);
        let mut kids: Vec<Vec<usize>> = vec![Vec::new(); sk.len()];
        for (j, joint) in sk.joints().iter().enumerate() {
            let t = poses[0].translations[j];
            let q = poses[0].rotations[j].normalize();
            a.push(
                "nodes",
                json!({"name": joint.name, "translation": [t.x as f32, t.y as f32, t.z as f32], "rotation": [q.x as f32, q.y as f32, q.z as f32, q.w as f32]}),
            );
            if let Some(p) = joint.parent {
                kids[p].push(first + j);
            }
        }
        for (j, joint) in sk.joints().iter().enumerate() {
            let Some(mesh) = mesh else { break };
            if let Some(p) = joint.parent {
                if let Some(b) =
                    bone_node(format!("{} bone", joint.name), mesh, joint.offset, bone_thickness(&joint.name))
                {
                    let k = a.push("nodes", b);
                    kids[p].push(k);
                }
            }
            if let Some(e) = joint.end_site {
                if let Some(b) = bone_node(format!("{} end bone", joint.name), mesh, e, bone_thickness(&joint.name)) {
                    let k = a.push("nodes", b);
                    kids[j].push(k);
                }
            }
        }
        for (j, k) in kids.into_iter().enumerate() {
            if !k.is_empty() {
                a.doc["nodes"][first + j]["children"] = json!(k);
            }
        }
        let root = a.push("nodes", json!({"name": name, "children": [first]}));
        roots.push(root);
        // Channels: translation where the joint has position channels, rotation where it rotates.
        for (j, joint) in sk.joints().iter().enumerate() {
            if joint.has_translation() {
                let v: Vec<f32> = poses.iter().flat_map(|p| p.translations[j].to_array().map(|x| x as f32)).collect();
                let out = a.floats(&v, ElementType::Vec3, false, None);
                channel(&mut samplers, &mut channels, input, out, first + j, "translation");
            }
            if joint.rotation_order().is_some() {
                let v = continuous_quats(poses.iter().map(|p| p.rotations[j].as_quat()));
                let out = a.floats(&v, ElementType::Vec4, false, None);
                channel(&mut samplers, &mut channels, input, out, first + j, "rotation");
            }
        }
    }

    // The camera.
    let n = animation_frames(characters, fps);
    let shots: Vec<([f32; 3], [f32; 3], f32)> = (0..n).map(camera).collect();
    let yfov = shots[0].2;
    if let Some(f) = shots.iter().position(|s| !(s.2.is_finite() && s.2 > 0.0 && s.2 < 180.0)) {
        return Err(ScriptError::Invalid(format!(
            "camera field of view {}° at frame {f} must lie in (0, 180)",
            shots[f].2
        )));
    }
    if let Some(f) = shots.iter().position(|s| !(s.0.iter().chain(&s.1).all(|v| v.is_finite()))) {
        return Err(ScriptError::Invalid(format!("camera pose at frame {f} is not finite")));
    }
    let cam = a.push("cameras", json!({"name": "story camera", "type": "perspective", "perspective": {"yfov": yfov.to_radians(), "znear": 0.05, "zfar": 200.0}}));
    let eye0 = shots[0].0;
    let q0 = look_rotation(Vec3::from(shots[0].0), Vec3::from(shots[0].1));
    let cam_node =
        a.push("nodes", json!({"name": "camera", "camera": cam, "translation": eye0, "rotation": q0.to_array()}));
    roots.push(cam_node);
    let input = time_acc(&mut a, n, 1.0 / fps);
    let pos: Vec<f32> = shots.iter().flat_map(|s| s.0).collect();
    let out = a.floats(&pos, ElementType::Vec3, false, None);
    channel(&mut samplers, &mut channels, input, out, cam_node, "translation");
    let rot = continuous_quats(shots.iter().map(|s| look_rotation(Vec3::from(s.0), Vec3::from(s.1))));
    let out = a.floats(&rot, ElementType::Vec4, false, None);
    channel(&mut samplers, &mut channels, input, out, cam_node, "rotation");
    if shots.iter().any(|s| s.2 != yfov) {
        // Core glTF cannot animate a camera's field of view: KHR_animation_pointer (used, not
        // required; viewers without it keep the frame-0 value) steps it at every change.
        let v: Vec<f32> = shots.iter().map(|s| s.2.to_radians()).collect();
        let out = a.floats(&v, ElementType::Scalar, false, None);
        samplers.push(json!({"input": input, "output": out, "interpolation": "STEP"}));
        let pointer = format!("/cameras/{cam}/perspective/yfov");
        channels.push(json!({"sampler": samplers.len() - 1, "target": {"path": "pointer", "extensions": {"KHR_animation_pointer": {"pointer": pointer}}}}));
        if !a.doc["extensionsUsed"].as_array().is_some_and(|u| u.iter().any(|e| e == FOV_EXTENSION)) {
            a.push("extensionsUsed", json!(FOV_EXTENSION));
        }
    }

    a.push("animations", json!({"name": ANIMATION_NAME, "samplers": samplers, "channels": channels}));
    gltf_buffer::pad_to_4(&mut bin);
    if let Some(s) = doc.pointer_mut("/scenes/0/nodes").and_then(Value::as_array_mut) {
        s.extend(roots.into_iter().map(|r| json!(r)));
    }
    doc["buffers"] = json!([{"byteLength": bin.len()}]);
    doc["asset"]["generator"] = json!("inbetween script (animated)");
    Ok(AnimatedDocument { doc, bin, notes, first_joint })
}

/// Writes the animated scene (see the module comment) as `.glb` (by extension) or `.gltf` with an
/// embedded buffer, atomically. Categories whose model file the catalogue knows get that mesh,
/// the rest boxes. `camera(frame)` gives eye, target and vertical field of view (degrees) for
/// frames `0..animation_frames(characters, fps)`. Models that cannot be read fall back to boxes
/// silently (see [`animated_gltf_document`] for the notes).
pub fn write_animated_gltf(
    path: &Path,
    scene: &Scene,
    cat: &Catalogue,
    characters: &[(&str, &Clip)],
    camera: &CameraFn,
    fps: f64,
) -> Result<(), ScriptError> {
    let lookup = |category: &str| cat.model_path(category).filter(|p| p.is_file());
    let (doc, bin, _notes) = animated_gltf_document(scene, cat, characters, camera, fps, &lookup)?;
    write_document(path, doc, bin)
}

/// [`write_animated_gltf`] of a story: also the props its characters carry
/// ([`crate::animate::CarriedProp`]) get translation and rotation channels on their object nodes,
/// so they rest until picked up and then follow the hand.
pub fn write_story_gltf(
    path: &Path,
    anim: &crate::animate::Animation,
    cat: &Catalogue,
    camera: &CameraFn,
) -> Result<(), ScriptError> {
    let (doc, bin) = story_gltf_document(anim, cat, camera)?;
    write_document(path, doc, bin)
}

/// The document and binary buffer [`write_story_gltf`] writes, in memory (for a server that
/// sends the story as GLB and offers the .gltf: build once, serialise both ways with
/// [`super::gltf::glb_bytes`] and [`super::gltf::gltf_text_bytes`]).
pub fn story_gltf_document(
    anim: &crate::animate::Animation,
    cat: &Catalogue,
    camera: &CameraFn,
) -> Result<(Value, Vec<u8>), ScriptError> {
    let chars: Vec<(&str, &Clip)> = anim.characters.iter().map(|c| (c.name.as_str(), &c.clip)).collect();
    let lookup = |category: &str| cat.model_path(category).filter(|p| p.is_file());
    let (mut doc, mut bin, _notes) = animated_gltf_document(&anim.scene, cat, &chars, camera, anim.fps, &lookup)?;
    let n = animation_frames(&chars, anim.fps);
    add_prop_channels(&mut doc, &mut bin, anim, n);
    Ok((doc, bin))
}

/// Channels moving every carried prop's object node (the scene's node named by its label) over
/// frames `0..n` at the animation's rate.
pub(crate) fn add_prop_channels(doc: &mut Value, bin: &mut Vec<u8>, anim: &crate::animate::Animation, n: usize) {
    let carried: Vec<usize> =
        (0..anim.scene.objects.len()).filter(|&i| crate::animate::carried_from(anim, i).is_some()).collect();
    if carried.is_empty() || n == 0 {
        return;
    }
    let mut a = Appender { doc, bin };
    let t: Vec<f32> = (0..n).map(|f| (f as f64 / anim.fps) as f32).collect();
    let input = a.floats(&t, ElementType::Scalar, true, None);
    for i in carried {
        let label = anim.scene.objects[i].label.as_str();
        // Object nodes come first in the document (before the characters' joints).
        let Some(node) = a.doc["nodes"].as_array().and_then(|ns| ns.iter().position(|x| x["name"] == label)) else {
            continue;
        };
        let poses: Vec<(DVec3, DQuat)> = (0..n).map(|f| crate::animate::object_pose(anim, i, f)).collect();
        let pos: Vec<f32> = poses.iter().flat_map(|(p, _)| [p.x as f32, p.y as f32, p.z as f32]).collect();
        let rot = continuous_quats(poses.iter().map(|(_, q)| q.as_quat()));
        for (values, kind, path) in [(pos, ElementType::Vec3, "translation"), (rot, ElementType::Vec4, "rotation")] {
            let output = a.floats(&values, kind, false, None);
            let samplers = a.doc["animations"][0]["samplers"].as_array_mut().map_or(0, |s| {
                s.push(json!({"input": input, "output": output, "interpolation": "LINEAR"}));
                s.len() - 1
            });
            if let Some(c) = a.doc["animations"][0]["channels"].as_array_mut() {
                c.push(json!({"sampler": samplers, "target": {"node": node, "path": path}}));
            }
        }
    }
    gltf_buffer::pad_to_4(bin);
    doc["buffers"] = json!([{"byteLength": bin.len()}]);
}
