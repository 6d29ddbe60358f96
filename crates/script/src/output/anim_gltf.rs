//! Animated glTF 2.0 of a story: the furnished scene exactly as [`super::gltf::gltf_document`]
//! builds it, plus per character a node hierarchy mirroring its skeleton (one node per joint,
//! named by the joint, translation = rest offset) with a simple rigid body (a box per bone,
//! attached under the joint nodes, so viewers without skin support still show a figure), plus an
//! animated perspective camera. One animation ("story") holds every channel, LINEAR, one key per
//! frame: each character's root translation and every joint's rotation, and the camera's
//! translation and rotation. `.glb` writes the binary container, anything else a `.gltf` with the
//! buffer embedded as base64.

use std::path::{Path, PathBuf};

use glam::{DQuat, DVec3, Quat};
use inbetween_core::camera::AimedCamera;
use inbetween_core::clip::Clip;
use inbetween_io::gltf_buffer::json::animation::{Interpolation, Property};
use inbetween_io::gltf_buffer::json::mesh::Semantic::{Normals, Positions};
use inbetween_io::gltf_buffer::json::scene::UnitQuaternion;
use inbetween_io::gltf_buffer::json::{self, Accessor, Index, Node};
use inbetween_io::gltf_buffer::{material, mesh, node, perspective, Anim, GltfDoc, Type, ARRAY_BUFFER};
use serde_json::{json, Value};

use super::gltf::{scene_document, write_document};
use crate::catalogue::Catalogue;
use crate::error::ScriptError;
use crate::scene::Scene;

/// Per-frame camera: `frame →` eye, target and vertical field of view, metres, Y up.
pub type CameraFn<'a> = dyn Fn(usize) -> AimedCamera + 'a;

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

/// A box mesh centred on the origin, unit edges, flat normals, in `material`.
fn centred_box(d: &mut GltfDoc, name: &str, material: Index<json::Material>) -> Index<json::Mesh> {
    let (pos, nor, idx) = super::gltf::box_geometry(0.0);
    let (pos, nor): (Vec<f32>, Vec<f32>) = (pos.concat(), nor.concat());
    let p = d.floats(&pos, Type::Vec3, true, Some(ARRAY_BUFFER));
    let nn = d.floats(&nor, Type::Vec3, false, Some(ARRAY_BUFFER));
    let i = d.indices(&idx);
    d.push(mesh(name, &[(Positions, p), (Normals, nn)], Some(i), Some(material)))
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
fn bone_node(name: String, mesh: Index<json::Mesh>, offset: DVec3, thickness: f32) -> Option<Node> {
    let len = offset.length();
    if len < 1e-3 {
        return None;
    }
    let q = DQuat::from_rotation_arc(DVec3::Y, offset / len).normalize();
    let t = offset / 2.0;
    Some(Node {
        mesh: Some(mesh),
        translation: Some([t.x as f32, t.y as f32, t.z as f32]),
        rotation: Some(UnitQuaternion([q.x as f32, q.y as f32, q.z as f32, q.w as f32])),
        scale: Some([thickness, len as f32, thickness]),
        ..node(name)
    })
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
    let cast: Vec<_> = characters.iter().map(|&(n, c)| (n, c, Body::Boxes)).collect();
    Ok(animated_document(scene, cat, &cast, camera, fps, model)?.finish())
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
    pub d: GltfDoc,
    /// The "story" animation, added to the document by [`AnimatedDocument::finish`].
    pub anim: Anim,
    pub notes: Vec<String>,
    /// Per character, the node index of its root joint; its other joints follow in skeleton order.
    pub first_joint: Vec<usize>,
    /// The field-of-view channel (its position among the channels, its sampler, the JSON
    /// pointer it drives): `gltf-json` 1.4 has no KHR_animation_pointer target (its targets need a
    /// node and a TRS path), so it is written into the JSON when the document is finished.
    fov: Option<(usize, usize, String)>,
}

impl AnimatedDocument {
    /// The document as JSON and its buffer.
    pub fn finish(mut self) -> (Value, Vec<u8>, Vec<String>) {
        let anim = std::mem::take(&mut self.anim);
        self.d.push(anim.finish(ANIMATION_NAME));
        let (mut doc, bin) = self.d.finish();
        if let Some((at, sampler, pointer)) = self.fov {
            let channel = json!({"sampler": sampler, "target": {"path": "pointer", "extensions": {FOV_EXTENSION: {"pointer": pointer}}}});
            if let Some(c) = doc["animations"][0]["channels"].as_array_mut() {
                c.insert(at.min(c.len()), channel);
            }
        }
        (doc, bin, self.notes)
    }
}

/// [`animated_gltf_document`] with each character's body chosen up front (`cast[c].2`), so a
/// skinned character never gets bone boxes; not finished, so the caller can add to it.
pub(crate) fn animated_document(
    scene: &Scene,
    cat: &Catalogue,
    cast: &[(&str, &Clip, Body)],
    camera: &CameraFn,
    fps: f64,
    model: &dyn Fn(&str) -> Option<PathBuf>,
) -> Result<AnimatedDocument, ScriptError> {
    check_fps(fps)?;
    let characters: Vec<(&str, &Clip)> = cast.iter().map(|&(n, c, _)| (n, c)).collect();
    let mut first_joint = Vec::with_capacity(characters.len());
    let (mut d, notes) = scene_document(scene, cat, model, "inbetween script (animated)");
    let mut roots: Vec<Index<Node>> = Vec::new();
    let mut anim = Anim::default();
    // Time accessors shared by every channel with the same key count and frame time.
    let mut times: Vec<(usize, u64, Index<Accessor>)> = Vec::new();
    let mut time_acc = |d: &mut GltfDoc, n: usize, dt: f64| -> Index<Accessor> {
        if let Some(&(_, _, acc)) = times.iter().find(|t| t.0 == n && t.1 == dt.to_bits()) {
            return acc;
        }
        let t: Vec<f32> = (0..n).map(|f| (f as f64 * dt) as f32).collect();
        let acc = d.floats(&t, Type::Scalar, true, None);
        times.push((n, dt.to_bits(), acc));
        acc
    };

    for (ci, &(name, m, body)) in cast.iter().enumerate() {
        let sk = m.skeleton();
        let n = m.num_frames();
        let mesh = (body == Body::Boxes).then(|| {
            let c = CHARACTER_COLORS[ci % CHARACTER_COLORS.len()].map(srgb_to_linear);
            let mat = d.push(material(format!("{name} body"), [c[0], c[1], c[2], 1.0], 0.7));
            centred_box(&mut d, &format!("{name} bone"), mat)
        });
        let poses = m.poses();
        let input = time_acc(&mut d, n, m.frame_time());
        // Joint nodes first (their indices are needed for children lists), filled in below.
        let first = d.root.nodes.len();
        first_joint.push(first);
        let mut kids: Vec<Vec<Index<Node>>> = vec![Vec::new(); sk.len()];
        for (j, joint) in sk.joints().iter().enumerate() {
            let t = poses[0].translations[j];
            let q = poses[0].rotations[j].normalize();
            d.push(Node {
                translation: Some([t.x as f32, t.y as f32, t.z as f32]),
                rotation: Some(UnitQuaternion([q.x as f32, q.y as f32, q.z as f32, q.w as f32])),
                ..node(joint.name.as_str())
            });
            if let Some(p) = joint.parent {
                kids[p].push(Index::new((first + j) as u32));
            }
        }
        for (j, joint) in sk.joints().iter().enumerate() {
            let Some(mesh) = mesh else { break };
            if let Some(p) = joint.parent {
                if let Some(b) =
                    bone_node(format!("{} bone", joint.name), mesh, joint.offset, bone_thickness(&joint.name))
                {
                    kids[p].push(d.push(b));
                }
            }
            if let Some(e) = joint.end_site {
                if let Some(b) = bone_node(format!("{} end bone", joint.name), mesh, e, bone_thickness(&joint.name)) {
                    kids[j].push(d.push(b));
                }
            }
        }
        for (j, k) in kids.into_iter().enumerate() {
            if !k.is_empty() {
                d.root.nodes[first + j].children = Some(k);
            }
        }
        roots.push(d.push(Node { children: Some(vec![Index::new(first as u32)]), ..node(name) }));
        // Channels: translation where the joint has position channels, rotation where it rotates.
        for (j, joint) in sk.joints().iter().enumerate() {
            let target = Index::new((first + j) as u32);
            if joint.has_translation() {
                let v: Vec<f32> = poses.iter().flat_map(|p| p.translations[j].to_array().map(|x| x as f32)).collect();
                let out = d.floats(&v, Type::Vec3, false, None);
                anim.channel(input, out, target, Property::Translation);
            }
            if joint.rotation_order().is_some() {
                let v = continuous_quats(poses.iter().map(|p| p.rotations[j].as_quat()));
                let out = d.floats(&v, Type::Vec4, false, None);
                anim.channel(input, out, target, Property::Rotation);
            }
        }
    }

    // The camera.
    let n = animation_frames(&characters, fps);
    let shots: Vec<AimedCamera> = (0..n).map(camera).collect();
    let yfov = shots[0].fovy_deg;
    if let Some(f) = shots.iter().position(|s| !s.fov_is_valid()) {
        return Err(ScriptError::Invalid(format!(
            "camera field of view {}° at frame {f} must lie in (0, 180)",
            shots[f].fovy_deg
        )));
    }
    if let Some(f) = shots.iter().position(|s| !s.is_finite()) {
        return Err(ScriptError::Invalid(format!("camera pose at frame {f} is not finite")));
    }
    let cam = d.push(perspective(Some("story camera".into()), yfov.to_radians(), None, 0.05, Some(200.0)));
    // glTF cameras look down their local −Z with +Y up, as core's camera poses do.
    let look = |s: &AimedCamera| s.pose().rotation.as_quat();
    let q0 = look(&shots[0]);
    let cam_node = d.push(Node {
        camera: Some(cam),
        translation: Some(shots[0].eye.to_array()),
        rotation: Some(UnitQuaternion(q0.to_array())),
        ..node("camera")
    });
    roots.push(cam_node);
    let input = time_acc(&mut d, n, 1.0 / fps);
    let pos: Vec<f32> = shots.iter().flat_map(|s| s.eye.to_array()).collect();
    let out = d.floats(&pos, Type::Vec3, false, None);
    anim.channel(input, out, cam_node, Property::Translation);
    let rot = continuous_quats(shots.iter().map(look));
    let out = d.floats(&rot, Type::Vec4, false, None);
    anim.channel(input, out, cam_node, Property::Rotation);
    let mut fov = None;
    if shots.iter().any(|s| s.fovy_deg != yfov) {
        // Core glTF cannot animate a camera's field of view: KHR_animation_pointer (used, not
        // required; viewers without it keep the frame-0 value) steps it at every change.
        let v: Vec<f32> = shots.iter().map(|s| s.fovy_deg.to_radians()).collect();
        let out = d.floats(&v, Type::Scalar, false, None);
        let sampler = anim.sampler(input, out, Interpolation::Step);
        fov = Some((anim.channels.len(), sampler.value(), format!("/cameras/{}/perspective/yfov", cam.value())));
        d.use_extension(FOV_EXTENSION);
    }
    d.root.scenes[0].nodes.extend(roots);
    Ok(AnimatedDocument { d, anim, notes, first_joint, fov })
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
    let cast: Vec<_> = chars.iter().map(|&(n, c)| (n, c, Body::Boxes)).collect();
    let mut doc = animated_document(&anim.scene, cat, &cast, camera, anim.fps, &lookup)?;
    add_prop_channels(&mut doc, anim, animation_frames(&chars, anim.fps));
    let (doc, bin, _notes) = doc.finish();
    Ok((doc, bin))
}

/// Channels moving every carried prop's object node (the scene's node named by its label) over
/// frames `0..n` at the animation's rate.
pub(crate) fn add_prop_channels(doc: &mut AnimatedDocument, anim: &crate::animate::Animation, n: usize) {
    let carried: Vec<usize> = (0..anim.scene.objects.len()).filter(|&i| crate::animate::moves(anim, i)).collect();
    if carried.is_empty() || n == 0 {
        return;
    }
    let d = &mut doc.d;
    let t: Vec<f32> = (0..n).map(|f| (f as f64 / anim.fps) as f32).collect();
    let input = d.floats(&t, Type::Scalar, true, None);
    for i in carried {
        let label = anim.scene.objects[i].label.as_str();
        // Object nodes come first in the document (before the characters' joints).
        let Some(node) = d.root.nodes.iter().position(|x| x.name.as_deref() == Some(label)) else {
            continue;
        };
        let node = Index::new(node as u32);
        let poses: Vec<(DVec3, DQuat)> = (0..n).map(|f| crate::animate::object_pose(anim, i, f)).collect();
        let pos: Vec<f32> = poses.iter().flat_map(|(p, _)| [p.x as f32, p.y as f32, p.z as f32]).collect();
        let rot = continuous_quats(poses.iter().map(|(_, q)| q.as_quat()));
        for (values, kind, path) in [(pos, Type::Vec3, Property::Translation), (rot, Type::Vec4, Property::Rotation)] {
            let output = d.floats(&values, kind, false, None);
            doc.anim.channel(input, output, node, path);
        }
    }
}
