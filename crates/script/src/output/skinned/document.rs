//! The skinned glTF document: the animated document built without bone boxes for the characters
//! that have a body, and a skinned mesh per such character added on its joint nodes.

use super::*;

/// Accessors of component types the shared builder has no helper for, on the animated
/// document's appender.
impl Appender<'_> {
    /// An accessor over fresh bytes without bounds: `kind` is the glTF type, `component` its
    /// component type (UNSIGNED_BYTE / UNSIGNED_SHORT / UNSIGNED_INT).
    fn accessor(&mut self, bytes: &[u8], target: Option<u32>, component: u32, count: usize, kind: &str) -> usize {
        let view = self.view(bytes, target);
        self.push("accessors", json!({"bufferView": view, "componentType": component, "count": count, "type": kind}))
    }
}

/// Adds one skinned body to the document: texture, material, mesh, skin over the joint nodes
/// `first..first + joints`, and a scene-root node holding mesh and skin.
fn add_body(out: &mut Appender, name: &str, body: &SkinnedBody, first: usize) -> Result<(), ScriptError> {
    let joints = body.bind.len();
    if body.joints.iter().any(|&j| j as usize >= joints) {
        return Err(ScriptError::Invalid(format!(
            "character '{name}': a vertex is bound to a joint past the skeleton's {joints}"
        )));
    }
    let texture = body.image.as_ref().map(|img| {
        let view = out.view(&img.bytes, None);
        let image =
            out.push("images", json!({"name": format!("{name} texture"), "bufferView": view, "mimeType": img.mime}));
        let sampler = out.push("samplers", json!({"magFilter": 9729, "minFilter": 9729}));
        out.push("textures", json!({"sampler": sampler, "source": image}))
    });
    let mut pbr = json!({"baseColorFactor": body.base_color, "metallicFactor": 0.0, "roughnessFactor": 1.0});
    if let Some(t) = texture {
        pbr["baseColorTexture"] = json!({"index": t});
    }
    // Kenney's characters are unlit; viewers without the extension shade them as plain PBR.
    let material = out.push(
        "materials",
        json!({"name": format!("{name} skin"), "pbrMetallicRoughness": pbr, "extensions": {"KHR_materials_unlit": {}}}),
    );
    if !out.doc["extensionsUsed"].as_array().is_some_and(|u| u.iter().any(|e| e == "KHR_materials_unlit")) {
        out.push("extensionsUsed", json!("KHR_materials_unlit"));
    }
    let flat3 = |v: &[Vec3]| -> Vec<f32> { v.iter().flat_map(|p| p.to_array()).collect() };
    let pos = out.floats(&flat3(&body.positions), ElementType::Vec3, true, Some(ARRAY_BUFFER));
    let nor = out.floats(&flat3(&body.normals), ElementType::Vec3, false, Some(ARRAY_BUFFER));
    let uv: Vec<f32> = body.uvs.iter().flatten().copied().collect();
    let uv = out.floats(&uv, ElementType::Vec2, false, Some(ARRAY_BUFFER));
    let count = body.positions.len();
    // JOINTS_0: unsigned byte when the skeleton allows (4-byte elements keep vertex alignment).
    let (jbytes, jtype): (Vec<u8>, u32) = if joints <= 256 {
        (body.joints.iter().flat_map(|&j| [j as u8, 0, 0, 0]).collect(), 5121)
    } else {
        (body.joints.iter().flat_map(|&j| [j, 0, 0, 0]).flat_map(u16::to_le_bytes).collect(), 5123)
    };
    let jacc = out.accessor(&jbytes, Some(ARRAY_BUFFER), jtype, count, "VEC4");
    let w: Vec<f32> = (0..count).flat_map(|_| [1.0, 0.0, 0.0, 0.0]).collect();
    let wacc = out.floats(&w, ElementType::Vec4, false, Some(ARRAY_BUFFER));
    let idx = if count <= u16::MAX as usize {
        let b: Vec<u8> = body.indices.iter().flat_map(|&i| (i as u16).to_le_bytes()).collect();
        out.accessor(&b, Some(ELEMENT_ARRAY_BUFFER), UNSIGNED_SHORT, body.indices.len(), "SCALAR")
    } else {
        let b: Vec<u8> = body.indices.iter().flat_map(|&i| i.to_le_bytes()).collect();
        out.accessor(&b, Some(ELEMENT_ARRAY_BUFFER), 5125, body.indices.len(), "SCALAR")
    };
    let ibm: Vec<f32> = body.inverse_bind().iter().flat_map(|m| m.to_cols_array()).collect();
    let ibm = out.floats(&ibm, ElementType::Mat4, false, None);
    let mesh = out.push(
        "meshes",
        json!({"name": format!("{name} body"), "primitives": [{"attributes": {"POSITION": pos, "NORMAL": nor, "TEXCOORD_0": uv, "JOINTS_0": jacc, "WEIGHTS_0": wacc}, "indices": idx, "material": material}]}),
    );
    let skin = out.push("skins", json!({"name": format!("{name} skin"), "joints": (first..first + joints).collect::<Vec<usize>>(), "inverseBindMatrices": ibm, "skeleton": first}));
    // A scene root (the skin's joints place it; parent transforms would not apply to it anyway).
    let node = out.push("nodes", json!({"name": format!("{name} body"), "mesh": mesh, "skin": skin}));
    let roots = out
        .doc
        .pointer_mut("/scenes/0/nodes")
        .and_then(Value::as_array_mut)
        .ok_or_else(|| ScriptError::Invalid("the document has no scene".into()))?;
    roots.push(json!(node));
    Ok(())
}

/// The animated document of [`animated_gltf_document`] with every character that has a body
/// skinned: built without its bone boxes, the body added as a skinned mesh on its joint nodes
/// (which keep their animation channels). Characters without a body (`None`) keep the stick
/// figure.
pub fn skinned_gltf_document(
    cast: &SkinnedCast,
    model: &dyn Fn(&str) -> Option<PathBuf>,
) -> Result<(Value, Vec<u8>, Vec<String>), ScriptError> {
    let SkinnedCast { scene, cat, characters, bodies, camera, fps } = *cast;
    if bodies.len() != characters.len() {
        return Err(ScriptError::Invalid(format!("{} bodies for {} characters", bodies.len(), characters.len())));
    }
    for ((_, m), body) in characters.iter().zip(bodies) {
        if let Some(b) = body {
            if b.bind.len() != m.skeleton().len() {
                return Err(ScriptError::Invalid(format!(
                    "a body bound to {} joints for a skeleton of {}",
                    b.bind.len(),
                    m.skeleton().len()
                )));
            }
        }
    }
    // Bone boxes only for the characters without a body; the bodies go on their joint nodes.
    let kinds: Vec<Body> = bodies.iter().map(|b| if b.is_some() { Body::Skinned } else { Body::Boxes }).collect();
    let AnimatedDocument { mut doc, mut bin, notes, first_joint } =
        animated_document(scene, cat, characters, &kinds, camera, fps, model)?;
    let mut out = Appender { doc: &mut doc, bin: &mut bin };
    for (((name, _), body), &first) in characters.iter().zip(bodies).zip(&first_joint) {
        if let Some(b) = body {
            add_body(&mut out, name, b, first)?;
        }
    }
    pad_to_4(&mut bin);
    doc["buffers"] = json!([{"byteLength": bin.len()}]);
    doc["asset"]["generator"] = json!("inbetween script (animated, skinned Kenney characters)");
    Ok((doc, bin, notes))
}

/// Writes [`skinned_gltf_document`] as `.glb` (by extension) or `.gltf` with the buffer embedded,
/// atomically; furniture as in [`crate::output::write_animated_gltf`].
pub fn write_skinned_gltf(path: &Path, cast: &SkinnedCast) -> Result<(), ScriptError> {
    let lookup = |category: &str| cast.cat.model_path(category).filter(|p| p.is_file());
    let (doc, bin, _) = skinned_gltf_document(cast, &lookup)?;
    write_document(path, doc, bin)
}
