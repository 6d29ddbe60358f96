//! glTF 2.0 export of a furnished scene: a node per object named by its label (translation at the
//! footprint centre on its base, rotation about +Y), holding a box in its category's colour or,
//! when a model file is known, that GLB's meshes merged in (buffers, accessors, materials, images
//! re-indexed) and scaled to the object's size; plus a floor quad. `.glb` writes the binary
//! container, anything else a `.gltf` with the buffer embedded as base64.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use glam::{Mat4, Quat, Vec3};
use inbetween_io::gltf_buffer::{data_uri, ElementType, GltfBuffer, ARRAY_BUFFER};
use serde_json::{json, Value};

/// GLB container assembly lives in io (one writer for every engine).
pub use inbetween_io::motion_gltf::glb_bytes;

use crate::catalogue::Catalogue;
use crate::error::ScriptError;
use crate::scene::Scene;

/// The embedded buffer's text encoding, shared with every glTF writer (also used to read data URIs
/// of models).
pub use inbetween_io::gltf_buffer::{base64, base64_decode};

/// A parsed GLB: its JSON and its binary chunk.
#[derive(Debug, Clone)]
pub struct Glb {
    pub json: Value,
    pub bin: Vec<u8>,
}

/// Parses a binary glTF (header, JSON chunk, optional BIN chunk).
pub fn parse_glb(bytes: &[u8]) -> Result<Glb, String> {
    let u32_at = |o: usize| bytes.get(o..o + 4).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]));
    if bytes.get(0..4) != Some(b"glTF") {
        return Err("not a GLB file (no 'glTF' magic)".into());
    }
    if u32_at(4) != Some(2) {
        return Err("only glTF 2.0 GLB files are supported".into());
    }
    let total = (u32_at(8).ok_or("truncated header")? as usize).min(bytes.len());
    let (mut json, mut bin) = (None, Vec::new());
    let mut at = 12;
    while at + 8 <= total {
        let len = u32_at(at).ok_or("truncated chunk")? as usize;
        let kind = u32_at(at + 4).ok_or("truncated chunk")?;
        let data = bytes.get(at + 8..at + 8 + len).ok_or("chunk runs past the end of the file")?;
        match kind {
            0x4E4F_534A => json = Some(serde_json::from_slice(data).map_err(|e| format!("bad JSON chunk: {e}"))?),
            0x004E_4942 => bin = data.to_vec(),
            _ => {}
        }
        at += 8 + len;
    }
    Ok(Glb { json: json.ok_or("no JSON chunk")?, bin })
}

/// A `.gltf` file's bytes: the document with its one buffer inline as a data URI.
pub fn gltf_text_bytes(mut doc: Value, bin: &[u8]) -> Vec<u8> {
    doc["buffers"][0]["uri"] = json!(data_uri(bin));
    doc.to_string().into_bytes()
}

fn srgb_to_linear(c: u8) -> f32 {
    let c = c as f32 / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// The document under construction: arrays glTF indexes into, plus the one binary buffer (with
/// its bufferViews and accessors).
#[derive(Default)]
struct Doc {
    buf: GltfBuffer,
    meshes: Vec<Value>,
    materials: Vec<Value>,
    nodes: Vec<Value>,
    images: Vec<Value>,
    textures: Vec<Value>,
    samplers: Vec<Value>,
    extensions_used: BTreeSet<String>,
    extensions_required: BTreeSet<String>,
}

/// A model merged into the document: its node templates (already re-indexed meshes), its scene
/// roots and its bounding box in the roots' frame.
struct Merged {
    nodes: Vec<Value>,
    roots: Vec<usize>,
    min: Vec3,
    max: Vec3,
}

impl Doc {
    /// Vertex attribute data (ARRAY_BUFFER view); POSITION needs `bounds`.
    fn vec3s(&mut self, values: &[[f32; 3]], bounds: bool) -> usize {
        self.buf.floats(values.as_flattened(), ElementType::Vec3, bounds, Some(ARRAY_BUFFER))
    }

    fn material(&mut self, name: &str, color: [u8; 3]) -> usize {
        let c = color.map(srgb_to_linear);
        self.materials.push(json!({
            "name": name,
            "pbrMetallicRoughness": {"baseColorFactor": [c[0], c[1], c[2], 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.9}
        }));
        self.materials.len() - 1
    }

    /// Accessors (position, normal, indices) of a box with flat faces: x, z ∈ [-½, ½], y ∈ [0, 1].
    fn unit_box(&mut self) -> (usize, usize, usize) {
        let (pos, nor, idx) = box_geometry(0.5);
        (self.vec3s(&pos, true), self.vec3s(&nor, false), self.buf.indices(&idx))
    }

    /// Appends a GLB's buffers, views, accessors, images, samplers, textures, materials and
    /// meshes with shifted indices; returns its node templates and bounds.
    fn merge(&mut self, glb: &Glb) -> Result<Merged, String> {
        let j = &glb.json;
        let arr = |k: &str| j.get(k).and_then(Value::as_array).cloned().unwrap_or_default();
        let buffers = arr("buffers");
        if buffers.len() > 1 || buffers.first().is_some_and(|b| b.get("uri").is_some()) {
            return Err("models with external or several buffers are not supported".into());
        }
        for im in arr("images") {
            if im.get("uri").and_then(Value::as_str).is_some_and(|u| !u.starts_with("data:")) {
                return Err("models with external image files are not supported".into());
            }
        }
        self.buf.align();
        let bin_off = self.buf.bin.len();
        self.buf.bin.extend_from_slice(&glb.bin);
        let (v0, a0, m0, t0, i0, s0, me0) = (
            self.buf.views.len(),
            self.buf.accessors.len(),
            self.materials.len(),
            self.textures.len(),
            self.images.len(),
            self.samplers.len(),
            self.meshes.len(),
        );
        let add = |v: &mut Value, key: &str, off: usize| {
            if let Some(x) = v.get(key).and_then(Value::as_u64) {
                v[key] = json!(x as usize + off);
            }
        };
        for mut bv in arr("bufferViews") {
            let off = bv.get("byteOffset").and_then(Value::as_u64).unwrap_or(0) as usize;
            bv["buffer"] = json!(0);
            bv["byteOffset"] = json!(bin_off + off);
            self.buf.views.push(bv);
        }
        for mut a in arr("accessors") {
            add(&mut a, "bufferView", v0);
            if let Some(sp) = a.get_mut("sparse") {
                for part in ["indices", "values"] {
                    if let Some(p) = sp.get_mut(part) {
                        add(p, "bufferView", v0);
                    }
                }
            }
            self.buf.accessors.push(a);
        }
        for mut im in arr("images") {
            add(&mut im, "bufferView", v0);
            self.images.push(im);
        }
        self.samplers.extend(arr("samplers"));
        for mut t in arr("textures") {
            add(&mut t, "source", i0);
            add(&mut t, "sampler", s0);
            self.textures.push(t);
        }
        fn shift_textures(v: &mut Value, off: usize) {
            if let Value::Object(map) = v {
                for (k, val) in map.iter_mut() {
                    if k.ends_with("Texture") {
                        if let Some(i) = val.get("index").and_then(Value::as_u64) {
                            val["index"] = json!(i as usize + off);
                        }
                    }
                    shift_textures(val, off);
                }
            }
        }
        for mut m in arr("materials") {
            shift_textures(&mut m, t0);
            self.materials.push(m);
        }
        for mut mesh in arr("meshes") {
            if let Some(prims) = mesh.get_mut("primitives").and_then(Value::as_array_mut) {
                for p in prims {
                    if let Some(Value::Object(at)) = p.get_mut("attributes") {
                        for v in at.values_mut() {
                            *v = json!(v.as_u64().unwrap_or(0) as usize + a0);
                        }
                    }
                    if let Some(Value::Array(ts)) = p.get_mut("targets") {
                        for t in ts {
                            if let Value::Object(at) = t {
                                for v in at.values_mut() {
                                    *v = json!(v.as_u64().unwrap_or(0) as usize + a0);
                                }
                            }
                        }
                    }
                    add(p, "indices", a0);
                    add(p, "material", m0);
                }
            }
            self.meshes.push(mesh);
        }
        for key in ["extensionsUsed", "extensionsRequired"] {
            for e in arr(key).iter().filter_map(Value::as_str) {
                if key == "extensionsUsed" { &mut self.extensions_used } else { &mut self.extensions_required }
                    .insert(e.to_string());
            }
        }
        // Node templates: meshes re-indexed, skins and cameras dropped.
        let nodes: Vec<Value> = arr("nodes")
            .into_iter()
            .map(|mut n| {
                add(&mut n, "mesh", me0);
                if let Value::Object(m) = &mut n {
                    m.remove("skin");
                    m.remove("camera");
                    m.remove("weights");
                }
                n
            })
            .collect();
        let scene = j.get("scene").and_then(Value::as_u64).unwrap_or(0) as usize;
        let roots: Vec<usize> =
            match j.get("scenes").and_then(|s| s.get(scene)).and_then(|s| s.get("nodes")).and_then(Value::as_array) {
                Some(r) => {
                    r.iter().filter_map(Value::as_u64).map(|x| x as usize).filter(|&x| x < nodes.len()).collect()
                }
                None => (0..nodes.len()).collect(),
            };
        // Bounds through the node transforms, from POSITION min/max.
        let (mut lo, mut hi) = (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN));
        let accessors = arr("accessors");
        let meshes = arr("meshes");
        let mut stack: Vec<(usize, Mat4, usize)> = roots.iter().map(|&r| (r, Mat4::IDENTITY, 0)).collect();
        while let Some((k, parent, depth)) = stack.pop() {
            let Some(n) = arr("nodes").get(k).cloned() else { continue };
            if depth > 64 {
                continue;
            }
            let m = parent * node_matrix(&n);
            if let Some(mi) = n.get("mesh").and_then(Value::as_u64) {
                for p in meshes
                    .get(mi as usize)
                    .and_then(|x| x.get("primitives"))
                    .and_then(Value::as_array)
                    .into_iter()
                    .flatten()
                {
                    let Some(acc) = p
                        .pointer("/attributes/POSITION")
                        .and_then(Value::as_u64)
                        .and_then(|a| accessors.get(a as usize))
                    else {
                        continue;
                    };
                    let v3 = |key: &str| -> Option<Vec3> {
                        let a = acc.get(key)?.as_array()?;
                        Some(Vec3::new(
                            a.first()?.as_f64()? as f32,
                            a.get(1)?.as_f64()? as f32,
                            a.get(2)?.as_f64()? as f32,
                        ))
                    };
                    let (Some(mn), Some(mx)) = (v3("min"), v3("max")) else { continue };
                    for c in 0..8 {
                        let p = Vec3::new(
                            if c & 1 == 0 { mn.x } else { mx.x },
                            if c & 2 == 0 { mn.y } else { mx.y },
                            if c & 4 == 0 { mn.z } else { mx.z },
                        );
                        let w = m.transform_point3(p);
                        lo = lo.min(w);
                        hi = hi.max(w);
                    }
                }
            }
            for c in n.get("children").and_then(Value::as_array).into_iter().flatten().filter_map(Value::as_u64) {
                stack.push((c as usize, m, depth + 1));
            }
        }
        if lo.x > hi.x {
            return Err("the model has no mesh with POSITION bounds".into());
        }
        Ok(Merged { nodes, roots, min: lo, max: hi })
    }

    /// Copies model node `k` (and its subtree) into the document; returns the new index.
    fn instantiate(&mut self, m: &Merged, k: usize, depth: usize) -> usize {
        let mut n = m.nodes[k].clone();
        let children: Vec<usize> = if depth < 64 {
            n.get("children")
                .and_then(Value::as_array)
                .cloned()
                .unwrap_or_default()
                .iter()
                .filter_map(Value::as_u64)
                .map(|c| c as usize)
                .filter(|&c| c < m.nodes.len())
                .collect()
        } else {
            Vec::new()
        };
        let new_children: Vec<usize> = children.into_iter().map(|c| self.instantiate(m, c, depth + 1)).collect();
        if new_children.is_empty() {
            if let Value::Object(o) = &mut n {
                o.remove("children");
            }
        } else {
            n["children"] = json!(new_children);
        }
        self.nodes.push(n);
        self.nodes.len() - 1
    }
}

/// A node's local matrix from `matrix` or translation/rotation/scale.
fn node_matrix(n: &Value) -> Mat4 {
    let nums = |k: &str| -> Option<Vec<f32>> {
        Some(n.get(k)?.as_array()?.iter().filter_map(|v| v.as_f64().map(|x| x as f32)).collect())
    };
    if let Some(m) = nums("matrix").filter(|m| m.len() == 16) {
        return Mat4::from_cols_slice(&m);
    }
    let t = nums("translation").filter(|v| v.len() == 3).map(|v| Vec3::new(v[0], v[1], v[2])).unwrap_or(Vec3::ZERO);
    let r = nums("rotation")
        .filter(|v| v.len() == 4)
        .map(|v| Quat::from_xyzw(v[0], v[1], v[2], v[3]).normalize())
        .unwrap_or(Quat::IDENTITY);
    let s = nums("scale").filter(|v| v.len() == 3).map(|v| Vec3::new(v[0], v[1], v[2])).unwrap_or(Vec3::ONE);
    Mat4::from_scale_rotation_translation(s, r, t)
}

/// The glTF document of `scene` and its binary buffer (buffer 0, no uri yet). `model` maps a
/// category name to a GLB file to use instead of a box; models that cannot be read fall back to
/// boxes and are named in the returned notes.
pub fn gltf_document(
    scene: &Scene,
    cat: &Catalogue,
    model: &dyn Fn(&str) -> Option<PathBuf>,
) -> (Value, Vec<u8>, Vec<String>) {
    let mut d = Doc::default();
    let mut notes = Vec::new();
    let (bp, bn, bi) = d.unit_box();
    let mut box_mesh: BTreeMap<String, usize> = BTreeMap::new();
    let mut models: BTreeMap<String, Option<Merged>> = BTreeMap::new();
    let mut children = Vec::new();

    // Floor quad.
    let (w, dd) = (scene.room.width, scene.room.depth);
    let fp = d.vec3s(&[[0.0, 0.0, 0.0], [0.0, 0.0, dd], [w, 0.0, dd], [w, 0.0, 0.0]], true);
    let fnrm = d.vec3s(&[[0.0, 1.0, 0.0]; 4], false);
    let fi = d.buf.indices(&[0, 1, 2, 0, 2, 3]);
    let fmat = d.material("floor", [200, 200, 195]);
    d.meshes.push(json!({"name": "floor", "primitives": [{"attributes": {"POSITION": fp, "NORMAL": fnrm}, "indices": fi, "material": fmat}]}));
    d.nodes.push(json!({"name": "floor", "mesh": d.meshes.len() - 1}));
    children.push(d.nodes.len() - 1);

    for o in &scene.objects {
        if !models.contains_key(&o.category) {
            let merged = model(&o.category).and_then(|path| {
                let res = std::fs::read(&path)
                    .map_err(|e| e.to_string())
                    .and_then(|b| parse_glb(&b))
                    .and_then(|g| d.merge(&g));
                res.map_err(|e| notes.push(format!("{}: {e}; using a box for '{}'", path.display(), o.category))).ok()
            });
            models.insert(o.category.clone(), merged);
        }
        let child = if let Some(m) = models.get(&o.category).and_then(Option::as_ref) {
            let roots: Vec<usize> = m.roots.clone().into_iter().map(|r| d.instantiate(m, r, 0)).collect();
            let ext = (m.max - m.min).max(Vec3::splat(1e-6));
            let s = Vec3::from_array(o.size) / ext;
            let t = -Vec3::new((m.min.x + m.max.x) / 2.0 * s.x, m.min.y * s.y, (m.min.z + m.max.z) / 2.0 * s.z);
            json!({"name": format!("{} model", o.label), "translation": t.to_array(), "scale": s.to_array(), "children": roots})
        } else {
            let mesh = *box_mesh.entry(o.category.clone()).or_insert_with(|| {
                let mat = d.material(&o.category, super::category_color(cat, &o.category));
                d.meshes.push(json!({"name": format!("{} box", o.category), "primitives": [{"attributes": {"POSITION": bp, "NORMAL": bn}, "indices": bi, "material": mat}]}));
                d.meshes.len() - 1
            });
            json!({"name": format!("{} box", o.label), "mesh": mesh, "scale": o.size.map(|v| v.max(1e-4))})
        };
        d.nodes.push(child);
        let c = d.nodes.len() - 1;
        let (s, co) = (o.yaw / 2.0).sin_cos();
        d.nodes
            .push(json!({"name": o.label, "translation": o.position, "rotation": [0.0, s, 0.0, co], "children": [c]}));
        children.push(d.nodes.len() - 1);
    }
    d.nodes.push(json!({"name": scene.room.name, "children": children}));
    let root = d.nodes.len() - 1;
    d.buf.align();
    let mut doc = json!({
        "asset": {"version": "2.0", "generator": "inbetween script"},
        "scene": 0,
        "scenes": [{"name": scene.room.name, "nodes": [root]}],
        "nodes": d.nodes,
        "meshes": d.meshes,
        "materials": d.materials,
        "accessors": d.buf.accessors,
        "bufferViews": d.buf.views,
        "buffers": [{"byteLength": d.buf.bin.len()}],
    });
    for (k, v) in [("images", d.images), ("textures", d.textures), ("samplers", d.samplers)] {
        if !v.is_empty() {
            doc[k] = json!(v);
        }
    }
    if !d.extensions_used.is_empty() {
        doc["extensionsUsed"] = json!(d.extensions_used);
    }
    if !d.extensions_required.is_empty() {
        doc["extensionsRequired"] = json!(d.extensions_required);
    }
    (doc, d.buf.bin, notes)
}

/// Writes `scene` as `.glb` (by extension) or `.gltf` with an embedded buffer (atomic): Kenney
/// meshes for categories whose model [`Catalogue::model_path`] knows, boxes for the rest.
pub fn write_gltf(path: &Path, scene: &Scene, cat: &Catalogue) -> Result<(), ScriptError> {
    write_gltf_with_models(path, scene, cat, None).map(|_| ())
}

/// [`write_gltf`] also looking for `<models_dir>/<model>.glb` for categories that name a model
/// ([`crate::catalogue::Category::model`]) the catalogue has no path for. Returns notes on
/// models that could not be read and fell back to boxes.
pub fn write_gltf_with_models(
    path: &Path,
    scene: &Scene,
    cat: &Catalogue,
    models_dir: Option<&Path>,
) -> Result<Vec<String>, ScriptError> {
    let lookup = |category: &str| -> Option<PathBuf> {
        if let Some(p) = cat.model_path(category).filter(|p| p.is_file()) {
            return Some(p);
        }
        let stem = cat.get(category)?.model.clone()?;
        let p = models_dir?.join(format!("{stem}.glb"));
        p.is_file().then_some(p)
    };
    let (doc, bin, notes) = gltf_document(scene, cat, &lookup);
    write_document(path, doc, bin)?;
    Ok(notes)
}

/// Writes a document with its buffer as `.glb` (by extension) or `.gltf` with an embedded buffer,
/// atomically.
pub(crate) fn write_document(path: &Path, doc: Value, bin: Vec<u8>) -> Result<(), ScriptError> {
    let glb = path.extension().and_then(|e| e.to_str()).is_some_and(|e| e.eq_ignore_ascii_case("glb"));
    let bytes = if glb { glb_bytes(&doc, &bin) } else { gltf_text_bytes(doc, &bin) };
    inbetween_io::write_atomic(path, &bytes).map_err(|e| ScriptError::io(path, e))
}

/// Positions, flat normals and triangle indices of a unit box, x, z ∈ [-½, ½] and y ∈ [-½, ½] +
/// `lift` (0.5: standing on the origin, as scene objects; 0: centred, as bone boxes).
pub(crate) fn box_geometry(lift: f32) -> (Vec<[f32; 3]>, Vec<[f32; 3]>, Vec<u16>) {
    let faces: [([f32; 3], [f32; 3], [f32; 3]); 6] = [
        ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]),
        ([-1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]),
        ([0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]),
        ([0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
        ([0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
        ([0.0, 0.0, -1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]),
    ];
    let (mut pos, mut nor, mut idx) = (Vec::new(), Vec::new(), Vec::new());
    for (n, u, v) in faces {
        // u × v = n, so corners in (u, v) order wind counter-clockwise seen from outside.
        let base = pos.len() as u16;
        for (a, b) in [(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)] {
            let p: [f32; 3] = std::array::from_fn(|k| n[k] * 0.5 + u[k] * a + v[k] * b);
            pos.push([p[0], p[1] + lift, p[2]]);
            nor.push(n);
        }
        idx.extend([base, base + 1, base + 2, base, base + 2, base + 3]);
    }
    (pos, nor, idx)
}
