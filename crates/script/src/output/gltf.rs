//! glTF 2.0 export of a furnished scene: a node per object named by its label (translation at the
//! footprint centre on its base, rotation about +Y), holding a box in its category's colour or,
//! when a model file is known, that GLB's meshes merged in (buffers, accessors, materials, images
//! re-indexed) and scaled to the object's size; plus a floor quad. `.glb` writes the binary
//! container, anything else a `.gltf` with the buffer embedded as base64.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use glam::{Mat4, Quat, Vec3};
use inbetween_io::gltf_buffer::json::mesh::Semantic::{Normals, Positions};
use inbetween_io::gltf_buffer::json::scene::UnitQuaternion;
use inbetween_io::gltf_buffer::json::validation::{Checked::Valid, USize64};
use inbetween_io::gltf_buffer::json::{self, Accessor, Index, Node};
use inbetween_io::gltf_buffer::{data_uri, material, mesh, node, GltfDoc, Type, ARRAY_BUFFER};
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

/// The scene document under construction ([`GltfDoc`]: typed glTF and buffer 0).
struct Doc {
    d: GltfDoc,
}

/// A model merged into the document: its node templates (already re-indexed meshes), its scene
/// roots and its bounding box in the roots' frame.
struct Merged {
    nodes: Vec<Node>,
    roots: Vec<usize>,
    min: Vec3,
    max: Vec3,
}

/// `i` moved up by `by` (an index into an array another one was appended to).
fn shift<T>(i: Index<T>, by: usize) -> Index<T> {
    Index::new((i.value() + by) as u32)
}

impl Doc {
    /// Vertex attribute data (ARRAY_BUFFER view); POSITION needs `bounds`.
    fn vec3s(&mut self, values: &[[f32; 3]], bounds: bool) -> Index<Accessor> {
        self.d.floats(values.as_flattened(), Type::Vec3, bounds, Some(ARRAY_BUFFER))
    }

    fn material(&mut self, name: &str, color: [u8; 3]) -> Index<json::Material> {
        let c = color.map(srgb_to_linear);
        self.d.push(material(name, [c[0], c[1], c[2], 1.0], 0.9))
    }

    /// Accessors (position, normal, indices) of a box with flat faces: x, z ∈ [-½, ½], y ∈ [0, 1].
    fn unit_box(&mut self) -> (Index<Accessor>, Index<Accessor>, Index<Accessor>) {
        let (pos, nor, idx) = box_geometry(0.5);
        (self.vec3s(&pos, true), self.vec3s(&nor, false), self.d.indices(&idx))
    }

    /// Appends a GLB's buffer, views, accessors, images, samplers, textures, materials and meshes
    /// with shifted indices; returns its node templates and bounds.
    fn merge(&mut self, glb: &Glb) -> Result<Merged, String> {
        let j: json::Root =
            serde_json::from_value(glb.json.clone()).map_err(|e| format!("not a glTF 2.0 document: {e}"))?;
        if j.buffers.len() > 1 || j.buffers.first().is_some_and(|b| b.uri.is_some()) {
            return Err("models with external or several buffers are not supported".into());
        }
        if j.images.iter().any(|im| im.uri.as_deref().is_some_and(|u| !u.starts_with("data:"))) {
            return Err("models with external image files are not supported".into());
        }
        let r = &mut self.d.root;
        self.d.bin.resize(self.d.bin.len().next_multiple_of(4), 0);
        let bin_off = self.d.bin.len();
        self.d.bin.extend_from_slice(&glb.bin);
        let (v0, a0, m0, t0, i0, s0, me0) = (
            r.buffer_views.len(),
            r.accessors.len(),
            r.materials.len(),
            r.textures.len(),
            r.images.len(),
            r.samplers.len(),
            r.meshes.len(),
        );
        for mut bv in j.buffer_views.iter().cloned() {
            let off = bv.byte_offset.map_or(0, |o| o.0 as usize);
            bv.buffer = Index::new(0);
            bv.byte_offset = Some(USize64::from(bin_off + off));
            r.buffer_views.push(bv);
        }
        for mut a in j.accessors.iter().cloned() {
            a.buffer_view = a.buffer_view.map(|v| shift(v, v0));
            if let Some(sp) = &mut a.sparse {
                sp.indices.buffer_view = shift(sp.indices.buffer_view, v0);
                sp.values.buffer_view = shift(sp.values.buffer_view, v0);
            }
            r.accessors.push(a);
        }
        for mut im in j.images.iter().cloned() {
            im.buffer_view = im.buffer_view.map(|v| shift(v, v0));
            r.images.push(im);
        }
        r.samplers.extend(j.samplers.iter().cloned());
        for mut t in j.textures.iter().cloned() {
            t.source = shift(t.source, i0);
            t.sampler = t.sampler.map(|s| shift(s, s0));
            r.textures.push(t);
        }
        for mut m in j.materials.iter().cloned() {
            let pbr = &mut m.pbr_metallic_roughness;
            for info in [&mut pbr.base_color_texture, &mut pbr.metallic_roughness_texture, &mut m.emissive_texture]
                .into_iter()
                .flatten()
            {
                info.index = shift(info.index, t0);
            }
            if let Some(n) = &mut m.normal_texture {
                n.index = shift(n.index, t0);
            }
            if let Some(o) = &mut m.occlusion_texture {
                o.index = shift(o.index, t0);
            }
            r.materials.push(m);
        }
        for mut mesh in j.meshes.iter().cloned() {
            for p in &mut mesh.primitives {
                for a in p.attributes.values_mut() {
                    *a = shift(*a, a0);
                }
                for t in p.targets.iter_mut().flatten() {
                    for a in [&mut t.positions, &mut t.normals, &mut t.tangents].into_iter().flatten() {
                        *a = shift(*a, a0);
                    }
                }
                p.indices = p.indices.map(|i| shift(i, a0));
                p.material = p.material.map(|m| shift(m, m0));
            }
            r.meshes.push(mesh);
        }
        for e in &j.extensions_used {
            self.d.use_extension(e);
        }
        for e in &j.extensions_required {
            if !self.d.root.extensions_required.contains(e) {
                self.d.root.extensions_required.push(e.clone());
            }
        }
        // Node templates: meshes re-indexed, skins and cameras dropped.
        let nodes: Vec<Node> = j
            .nodes
            .iter()
            .cloned()
            .map(|n| Node { mesh: n.mesh.map(|m| shift(m, me0)), skin: None, camera: None, weights: None, ..n })
            .collect();
        let scene = j.scene.map_or(0, |s| s.value());
        let roots: Vec<usize> = match j.scenes.get(scene) {
            Some(s) => s.nodes.iter().map(|x| x.value()).filter(|&x| x < nodes.len()).collect(),
            None => (0..nodes.len()).collect(),
        };
        // Bounds through the node transforms, from POSITION min/max.
        let (mut lo, mut hi) = (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN));
        let mut stack: Vec<(usize, Mat4, usize)> = roots.iter().map(|&r| (r, Mat4::IDENTITY, 0)).collect();
        while let Some((k, parent, depth)) = stack.pop() {
            let Some(n) = j.nodes.get(k) else { continue };
            if depth > 64 {
                continue;
            }
            let m = parent * node_matrix(n);
            for p in n.mesh.and_then(|mi| j.meshes.get(mi.value())).into_iter().flat_map(|x| &x.primitives) {
                let Some(acc) =
                    p.attributes.get(&Valid(json::mesh::Semantic::Positions)).and_then(|a| j.accessors.get(a.value()))
                else {
                    continue;
                };
                let v3 = |v: &Option<Value>| -> Option<Vec3> {
                    let a = v.as_ref()?.as_array()?;
                    Some(Vec3::new(a.first()?.as_f64()? as f32, a.get(1)?.as_f64()? as f32, a.get(2)?.as_f64()? as f32))
                };
                let (Some(mn), Some(mx)) = (v3(&acc.min), v3(&acc.max)) else { continue };
                crate::catalogue::kenney::grow_by_box(&mut lo, &mut hi, &m, mn, mx);
            }
            for c in n.children.iter().flatten() {
                stack.push((c.value(), m, depth + 1));
            }
        }
        if lo.x > hi.x {
            return Err("the model has no mesh with POSITION bounds".into());
        }
        Ok(Merged { nodes, roots, min: lo, max: hi })
    }

    /// Copies model node `k` (and its subtree) into the document; returns the new index.
    fn instantiate(&mut self, m: &Merged, k: usize, depth: usize) -> Index<Node> {
        let mut n = m.nodes[k].clone();
        let children: Vec<usize> = if depth < 64 {
            n.children.iter().flatten().map(|c| c.value()).filter(|&c| c < m.nodes.len()).collect()
        } else {
            Vec::new()
        };
        let new_children: Vec<Index<Node>> = children.into_iter().map(|c| self.instantiate(m, c, depth + 1)).collect();
        n.children = (!new_children.is_empty()).then_some(new_children);
        self.d.push(n)
    }
}

/// A node's local matrix from `matrix` or translation/rotation/scale.
fn node_matrix(n: &Node) -> Mat4 {
    if let Some(m) = n.matrix {
        return Mat4::from_cols_array(&m);
    }
    let t = n.translation.map_or(Vec3::ZERO, Vec3::from_array);
    let r = n.rotation.map_or(Quat::IDENTITY, |q| Quat::from_array(q.0).normalize());
    let s = n.scale.map_or(Vec3::ONE, Vec3::from_array);
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
    let (d, notes) = scene_document(scene, cat, model, "inbetween script");
    let (doc, bin) = d.finish();
    (doc, bin, notes)
}

/// [`gltf_document`] before it is finished: the typed document (the room node its scene's only
/// root) for writers that add to it (`generator` names them), and the notes.
pub(crate) fn scene_document(
    scene: &Scene,
    cat: &Catalogue,
    model: &dyn Fn(&str) -> Option<PathBuf>,
    generator: &str,
) -> (GltfDoc, Vec<String>) {
    let mut d = Doc { d: GltfDoc::new(generator) };
    let mut notes = Vec::new();
    let (bp, bn, bi) = d.unit_box();
    let mut box_mesh: BTreeMap<String, Index<json::Mesh>> = BTreeMap::new();
    let mut models: BTreeMap<String, Option<Merged>> = BTreeMap::new();
    let mut children = Vec::new();

    // Floor quad.
    let (w, dd) = (scene.room.width, scene.room.depth);
    let fp = d.vec3s(&[[0.0, 0.0, 0.0], [0.0, 0.0, dd], [w, 0.0, dd], [w, 0.0, 0.0]], true);
    let fnrm = d.vec3s(&[[0.0, 1.0, 0.0]; 4], false);
    let fi = d.d.indices(&[0, 1, 2, 0, 2, 3]);
    let fmat = d.material("floor", [200, 200, 195]);
    let floor = d.d.push(mesh("floor", &[(Positions, fp), (Normals, fnrm)], Some(fi), Some(fmat)));
    children.push(d.d.push(Node { mesh: Some(floor), ..node("floor") }));

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
            let roots: Vec<Index<Node>> = m.roots.clone().into_iter().map(|r| d.instantiate(m, r, 0)).collect();
            let ext = (m.max - m.min).max(Vec3::splat(1e-6));
            let s = Vec3::from_array(o.size) / ext;
            let t = -Vec3::new((m.min.x + m.max.x) / 2.0 * s.x, m.min.y * s.y, (m.min.z + m.max.z) / 2.0 * s.z);
            Node {
                translation: Some(t.to_array()),
                scale: Some(s.to_array()),
                children: Some(roots),
                ..node(format!("{} model", o.label))
            }
        } else {
            let mesh_index = *box_mesh.entry(o.category.clone()).or_insert_with(|| {
                let mat = d.material(&o.category, super::category_color(cat, &o.category));
                d.d.push(mesh(format!("{} box", o.category), &[(Positions, bp), (Normals, bn)], Some(bi), Some(mat)))
            });
            let boxes = super::placeholder_boxes(o, cat);
            let part = |b: &super::PlaceholderBox| Node {
                mesh: Some(mesh_index),
                translation: (b.z != 0.0).then_some([0.0, 0.0, b.z]),
                scale: Some(b.size.map(|v| v.max(1e-4))),
                ..node(format!("{} {}", o.label, b.part))
            };
            match boxes.as_slice() {
                [one] => part(one),
                parts => {
                    let children = parts.iter().map(|b| d.d.push(part(b))).collect();
                    Node { children: Some(children), ..node(format!("{} box", o.label)) }
                }
            }
        };
        let c = d.d.push(child);
        let (s, co) = (o.yaw / 2.0).sin_cos();
        children.push(d.d.push(Node {
            translation: Some(o.position),
            rotation: Some(UnitQuaternion([0.0, s, 0.0, co])),
            children: Some(vec![c]),
            ..node(o.label.as_str())
        }));
    }
    let root = d.d.push(Node { children: Some(children), ..node(scene.room.name.as_str()) });
    d.d.root.scenes.push(inbetween_io::gltf_buffer::scene(Some(scene.room.name.clone()), vec![root]));
    d.d.root.scene = Some(Index::new(0));
    d.d.root.extensions_used.sort();
    d.d.root.extensions_required.sort();
    (d.d, notes)
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
