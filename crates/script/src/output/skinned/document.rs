//! The skinned glTF document: the animated document built without bone boxes for the characters
//! that have a body, and a skinned mesh per such character added on its joint nodes.

use super::*;

/// Adds one skinned body to the document: texture, material, mesh, skin over the joint nodes
/// `first..first + joints`, and a scene-root node holding mesh and skin.
fn add_body(d: &mut GltfDoc, name: &str, body: &SkinnedBody, first: usize) -> Result<(), ScriptError> {
    let joints = body.bind.len();
    if body.joints.iter().any(|&j| j as usize >= joints) {
        return Err(ScriptError::Invalid(format!(
            "character '{name}': a vertex is bound to a joint past the skeleton's {joints}"
        )));
    }
    let texture = body.image.as_ref().map(|img| {
        let view = d.view(&img.bytes, None);
        let source = d.push(json::Image {
            buffer_view: Some(view),
            mime_type: Some(json::image::MimeType(img.mime.to_string())),
            name: Some(format!("{name} texture")),
            uri: None,
            extensions: None,
            extras: Default::default(),
        });
        let linear = json::texture::Sampler {
            mag_filter: Some(Valid(json::texture::MagFilter::Linear)),
            min_filter: Some(Valid(json::texture::MinFilter::Linear)),
            ..Default::default()
        };
        let sampler = d.push(linear);
        d.push(json::Texture {
            name: None,
            sampler: Some(sampler),
            source,
            extensions: None,
            extras: Default::default(),
        })
    });
    // Kenney's characters are unlit; viewers without the extension shade them as plain PBR.
    let mut skin_material = material(format!("{name} skin"), body.base_color, 1.0);
    skin_material.pbr_metallic_roughness.base_color_texture =
        texture.map(|index| json::texture::Info { index, tex_coord: 0, extensions: None, extras: Default::default() });
    skin_material.extensions = Some(json::extensions::material::Material {
        unlit: Some(json::extensions::material::Unlit {}),
        ..Default::default()
    });
    let material = d.push(skin_material);
    d.use_extension("KHR_materials_unlit");
    let flat3 = |v: &[Vec3]| -> Vec<f32> { v.iter().flat_map(|p| p.to_array()).collect() };
    let pos = d.floats(&flat3(&body.positions), Type::Vec3, true, Some(ARRAY_BUFFER));
    let nor = d.floats(&flat3(&body.normals), Type::Vec3, false, Some(ARRAY_BUFFER));
    let uv: Vec<f32> = body.uvs.iter().flatten().copied().collect();
    let uv = d.floats(&uv, Type::Vec2, false, Some(ARRAY_BUFFER));
    let count = body.positions.len();
    // JOINTS_0: unsigned byte when the skeleton allows (4-byte elements keep vertex alignment).
    let (jbytes, jtype) = if joints <= 256 {
        (body.joints.iter().flat_map(|&j| [j as u8, 0, 0, 0]).collect::<Vec<u8>>(), ComponentType::U8)
    } else {
        (body.joints.iter().flat_map(|&j| [j, 0, 0, 0]).flat_map(u16::to_le_bytes).collect(), ComponentType::U16)
    };
    let jacc = d.accessor(&jbytes, Some(ARRAY_BUFFER), jtype, count, Type::Vec4);
    let w: Vec<f32> = (0..count).flat_map(|_| [1.0, 0.0, 0.0, 0.0]).collect();
    let wacc = d.floats(&w, Type::Vec4, false, Some(ARRAY_BUFFER));
    let idx = if count <= u16::MAX as usize {
        let b: Vec<u8> = body.indices.iter().flat_map(|&i| (i as u16).to_le_bytes()).collect();
        d.accessor(&b, Some(ELEMENT_ARRAY_BUFFER), ComponentType::U16, body.indices.len(), Type::Scalar)
    } else {
        let b: Vec<u8> = body.indices.iter().flat_map(|&i| i.to_le_bytes()).collect();
        d.accessor(&b, Some(ELEMENT_ARRAY_BUFFER), ComponentType::U32, body.indices.len(), Type::Scalar)
    };
    let ibm: Vec<f32> = body.inverse_bind().iter().flat_map(|m| m.to_cols_array()).collect();
    let ibm = d.floats(&ibm, Type::Mat4, false, None);
    use json::mesh::Semantic::{Joints, Normals, Positions, TexCoords, Weights};
    let attributes = [(Positions, pos), (Normals, nor), (TexCoords(0), uv), (Joints(0), jacc), (Weights(0), wacc)];
    let body_mesh = d.push(mesh(format!("{name} body"), &attributes, Some(idx), Some(material)));
    let skin = d.push(json::Skin {
        extensions: None,
        extras: Default::default(),
        inverse_bind_matrices: Some(ibm),
        joints: (first..first + joints).map(|j| Index::new(j as u32)).collect(),
        name: Some(format!("{name} skin")),
        skeleton: Some(Index::new(first as u32)),
    });
    // A scene root (the skin's joints place it; parent transforms would not apply to it anyway).
    let root = d.push(json::Node { mesh: Some(body_mesh), skin: Some(skin), ..node(format!("{name} body")) });
    let scene = d.root.scenes.first_mut().ok_or_else(|| ScriptError::Invalid("the document has no scene".into()))?;
    scene.nodes.push(root);
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
    Ok(skinned_document(cast, model)?.finish())
}

/// [`skinned_gltf_document`] before it is finished.
pub(crate) fn skinned_document(
    cast: &SkinnedCast,
    model: &dyn Fn(&str) -> Option<PathBuf>,
) -> Result<AnimatedDocument, ScriptError> {
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
    let kinds: Vec<_> = characters
        .iter()
        .zip(bodies)
        .map(|(&(n, c), b)| (n, c, if b.is_some() { Body::Skinned } else { Body::Boxes }))
        .collect();
    let mut doc = animated_document(scene, cat, &kinds, camera, fps, model)?;
    for (((name, _), body), &first) in characters.iter().zip(bodies).zip(&doc.first_joint.clone()) {
        if let Some(b) = body {
            add_body(&mut doc.d, name, b, first)?;
        }
    }
    doc.d.root.asset.generator = Some("inbetween script (animated, skinned Kenney characters)".into());
    Ok(doc)
}

/// Writes [`skinned_gltf_document`] as `.glb` (by extension) or `.gltf` with the buffer embedded,
/// atomically; furniture as in [`crate::output::write_animated_gltf`].
pub fn write_skinned_gltf(path: &Path, cast: &SkinnedCast) -> Result<(), ScriptError> {
    let lookup = |category: &str| cast.cat.model_path(category).filter(|p| p.is_file());
    let (doc, bin, _) = skinned_gltf_document(cast, &lookup)?;
    write_document(path, doc, bin)
}
