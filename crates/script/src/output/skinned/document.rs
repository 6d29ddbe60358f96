//! The skinned glTF document: the animated document with its bone boxes removed and a skinned
//! mesh per character added on the joint nodes.

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

/// Indices of a character's joint nodes in an animated document: the node named `name` whose only
/// child is the skeleton's root joint; its joints follow that child in skeleton order.
fn joint_nodes(doc: &Value, name: &str, skeleton: &Skeleton, taken: &BTreeSet<usize>) -> Option<(usize, usize)> {
    let nodes = doc["nodes"].as_array()?;
    let root_name = skeleton.joint(0).name.as_str();
    nodes.iter().enumerate().find_map(|(i, n)| {
        if taken.contains(&i) || n["name"].as_str() != Some(name) {
            return None;
        }
        let first = n["children"].as_array().filter(|c| c.len() == 1)?[0].as_u64()? as usize;
        let ok = skeleton
            .joints()
            .iter()
            .enumerate()
            .all(|(j, jt)| nodes.get(first + j).is_some_and(|x| x["name"].as_str() == Some(jt.name.as_str())));
        (ok && nodes[first]["name"].as_str() == Some(root_name)).then_some((i, first))
    })
}

/// Removes nodes (and meshes and materials nothing uses any more), re-indexing every reference:
/// node children, scene roots, animation targets, skins and mesh/material indices.
fn remove_nodes(doc: &mut Value, drop: &BTreeSet<usize>) {
    let n = doc["nodes"].as_array().map_or(0, Vec::len);
    let map: Vec<Option<usize>> = {
        let mut k = 0;
        (0..n)
            .map(|i| {
                if drop.contains(&i) {
                    None
                } else {
                    k += 1;
                    Some(k - 1)
                }
            })
            .collect()
    };
    let re = |v: &Value| v.as_u64().and_then(|i| map.get(i as usize).copied().flatten()).map(|i| json!(i));
    let old: Vec<Value> = doc["nodes"].as_array().cloned().unwrap_or_default();
    let mut nodes: Vec<Value> =
        old.into_iter().enumerate().filter(|(i, _)| !drop.contains(i)).map(|(_, v)| v).collect();
    for node in &mut nodes {
        if let Some(c) = node["children"].as_array() {
            let kids: Vec<Value> = c.iter().filter_map(&re).collect();
            if kids.is_empty() {
                if let Some(o) = node.as_object_mut() {
                    o.remove("children");
                }
            } else {
                node["children"] = json!(kids);
            }
        }
    }
    doc["nodes"] = json!(nodes);
    for scene in doc["scenes"].as_array_mut().into_iter().flatten() {
        let roots: Vec<Value> = scene["nodes"].as_array().into_iter().flatten().filter_map(&re).collect();
        scene["nodes"] = json!(roots);
    }
    for anim in doc["animations"].as_array_mut().into_iter().flatten() {
        for ch in anim["channels"].as_array_mut().into_iter().flatten() {
            if let Some(t) = re(&ch["target"]["node"]) {
                ch["target"]["node"] = t;
            }
        }
    }
    for skin in doc["skins"].as_array_mut().into_iter().flatten() {
        let joints: Vec<Value> = skin["joints"].as_array().into_iter().flatten().filter_map(&re).collect();
        skin["joints"] = json!(joints);
        if let Some(s) = re(&skin["skeleton"]) {
            skin["skeleton"] = s;
        }
    }
    compact(
        doc,
        "meshes",
        |d| d["nodes"].as_array().into_iter().flatten().filter_map(|n| n["mesh"].as_u64()).collect(),
        |d, m| {
            for node in d["nodes"].as_array_mut().into_iter().flatten() {
                if let Some(i) = node["mesh"].as_u64() {
                    node["mesh"] = json!(m[i as usize]);
                }
            }
        },
    );
    let used_materials = |d: &Value| -> BTreeSet<u64> {
        d["meshes"]
            .as_array()
            .into_iter()
            .flatten()
            .flat_map(|m| m["primitives"].as_array().into_iter().flatten().filter_map(|p| p["material"].as_u64()))
            .collect()
    };
    compact(doc, "materials", used_materials, |d, m| {
        for mesh in d["meshes"].as_array_mut().into_iter().flatten() {
            for p in mesh["primitives"].as_array_mut().into_iter().flatten() {
                if let Some(i) = p["material"].as_u64() {
                    p["material"] = json!(m[i as usize]);
                }
            }
        }
    });
    compact(
        doc,
        "accessors",
        |d| accessor_refs(d).iter().filter_map(|r| r.as_u64()).collect(),
        |d, m| {
            for r in accessor_refs_mut(d) {
                if let Some(i) = r.as_u64() {
                    *r = json!(m[i as usize]);
                }
            }
        },
    );
    // Buffer views of the dropped accessors (their bytes stay in the buffer, unreferenced).
    let view_users = ["accessors", "images"];
    let used_views = |d: &Value| -> BTreeSet<u64> {
        view_users
            .iter()
            .flat_map(|k| d[*k].as_array().into_iter().flatten().filter_map(|x| x["bufferView"].as_u64()))
            .collect()
    };
    compact(doc, "bufferViews", used_views, |d, m| {
        for k in view_users {
            for x in d[k].as_array_mut().into_iter().flatten() {
                if let Some(i) = x["bufferView"].as_u64() {
                    x["bufferView"] = json!(m[i as usize]);
                }
            }
        }
    });
}

/// Every accessor reference of a document (before skins exist: mesh attributes and indices,
/// animation sampler inputs and outputs).
fn accessor_refs(doc: &Value) -> Vec<&Value> {
    let mut out = Vec::new();
    for mesh in doc["meshes"].as_array().into_iter().flatten() {
        for p in mesh["primitives"].as_array().into_iter().flatten() {
            out.extend(p["attributes"].as_object().into_iter().flat_map(|a| a.values()));
            out.push(&p["indices"]);
        }
    }
    for anim in doc["animations"].as_array().into_iter().flatten() {
        for s in anim["samplers"].as_array().into_iter().flatten() {
            out.extend([&s["input"], &s["output"]]);
        }
    }
    out
}

fn accessor_refs_mut(doc: &mut Value) -> Vec<&mut Value> {
    let mut out = Vec::new();
    let (meshes, anims) = match doc.as_object_mut() {
        Some(o) => {
            let mut meshes = None;
            let mut anims = None;
            for (k, v) in o.iter_mut() {
                match k.as_str() {
                    "meshes" => meshes = Some(v),
                    "animations" => anims = Some(v),
                    _ => {}
                }
            }
            (meshes, anims)
        }
        None => return out,
    };
    for mesh in meshes.and_then(Value::as_array_mut).into_iter().flatten() {
        for p in mesh["primitives"].as_array_mut().into_iter().flatten() {
            let Some(p) = p.as_object_mut() else { continue };
            for (k, v) in p.iter_mut() {
                match k.as_str() {
                    "attributes" => out.extend(v.as_object_mut().into_iter().flat_map(|a| a.values_mut())),
                    "indices" => out.push(v),
                    _ => {}
                }
            }
        }
    }
    for anim in anims.and_then(Value::as_array_mut).into_iter().flatten() {
        for s in anim["samplers"].as_array_mut().into_iter().flatten() {
            let Some(s) = s.as_object_mut() else { continue };
            out.extend(s.iter_mut().filter(|(k, _)| *k == "input" || *k == "output").map(|(_, v)| v));
        }
    }
    out
}

/// Drops the entries of `doc[key]` outside `used(doc)` and lets `fix` re-index references with
/// the old → new map.
fn compact(doc: &mut Value, key: &str, used: impl Fn(&Value) -> BTreeSet<u64>, fix: impl Fn(&mut Value, &[usize])) {
    let used = used(doc);
    let Some(items) = doc[key].as_array().cloned() else { return };
    if used.len() == items.len() {
        return;
    }
    let mut map = vec![usize::MAX; items.len()];
    let mut kept = Vec::new();
    for (i, it) in items.into_iter().enumerate() {
        if used.contains(&(i as u64)) {
            map[i] = kept.len();
            kept.push(it);
        }
    }
    doc[key] = json!(kept);
    fix(doc, &map);
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
/// skinned: its bone boxes removed, the body added as a skinned mesh on its joint nodes (which keep
/// their animation channels). Characters without a body (`None`) keep the stick figure.
pub fn skinned_gltf_document(
    cast: &SkinnedCast,
    model: &dyn Fn(&str) -> Option<PathBuf>,
) -> Result<(Value, Vec<u8>, Vec<String>), ScriptError> {
    let SkinnedCast { scene, cat, characters, bodies, camera, fps } = *cast;
    if bodies.len() != characters.len() {
        return Err(ScriptError::Invalid(format!("{} bodies for {} characters", bodies.len(), characters.len())));
    }
    let (mut doc, mut bin, notes) = animated_gltf_document(scene, cat, characters, camera, fps, model)?;
    let mut taken = BTreeSet::new();
    let mut found = Vec::new();
    for (name, m) in characters {
        let (root, first) = joint_nodes(&doc, name, m.skeleton(), &taken).ok_or_else(|| {
            ScriptError::Invalid(format!("character '{name}': no joint nodes in the animated document"))
        })?;
        taken.insert(root);
        found.push((root, first));
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
    // The stick figure's boxes of skinned characters: mesh children of their joint nodes.
    let mut drop = BTreeSet::new();
    for (((_, m), body), &(_, first)) in characters.iter().zip(bodies).zip(&found) {
        if body.is_none() {
            continue;
        }
        for j in first..first + m.skeleton().len() {
            for c in doc["nodes"][j]["children"].as_array().into_iter().flatten().filter_map(Value::as_u64) {
                if doc["nodes"][c as usize].get("mesh").is_some() {
                    drop.insert(c as usize);
                }
            }
        }
    }
    remove_nodes(&mut doc, &drop);
    let shift = |i: usize| i - drop.range(..i).count();
    let mut out = Appender { doc: &mut doc, bin: &mut bin };
    for (((name, _), body), &(_, first)) in characters.iter().zip(bodies).zip(&found) {
        if let Some(b) = body {
            add_body(&mut out, name, b, shift(first))?;
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
