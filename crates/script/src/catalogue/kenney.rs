//! Kenney CC0 furniture glTFs (`../shared/data/assets/kenney_furniture`), used when present:
//! measured bounding boxes and the model path for glTF output. Loaded by path, never committed.
//!
//! We read only the GLB header and JSON chunk with serde_json (no `gltf` dependency): the
//! POSITION accessors' min/max (required by the glTF spec) transformed by the node hierarchy give
//! the bounding box without touching the vertex buffer. Kenney models are built at about half
//! real scale with +z as the front (checked on the chair's backrest and the bed's headboard), so a
//! model is scaled uniformly to keep the catalogue's height (flat things, e.g. rugs: their width)
//! and its proportions give the category's new width and depth.

use std::path::Path;

use glam::{Mat4, Quat, Vec3};
use serde_json::Value;

use super::{Catalogue, ModelInfo};
use crate::error::ScriptError;

/// Model stem → the categories it furnishes.
pub const MODELS: &[(&str, &[&str])] = &[
    ("desk", &["desk"]),
    ("bedSingle", &["bed"]),
    ("loungeSofa", &["sofa"]),
    ("chairDesk", &["chair", "officechair"]),
    ("tableRound", &["table", "diningtable"]),
    ("tableCoffee", &["coffeetable"]),
    ("sideTable", &["nightstand"]),
    ("lampRoundFloor", &["floorlamp"]),
    ("lampRoundTable", &["lamp", "desklamp"]),
    ("bookcaseOpen", &["bookshelf"]),
    ("bookcaseClosed", &["wardrobe"]),
    ("cabinetTelevision", &["cabinet"]),
    ("televisionVintage", &["tv"]),
    ("pottedPlant", &["plant"]),
    ("rugRound", &["rug"]),
    ("trashcan", &["trashcan"]),
    ("kitchenFridgeSmall", &["fridge"]),
    ("kitchenSink", &["sink"]),
    ("kitchenCabinet", &["counter"]),
    ("books", &["book"]),
    ("cardboardBoxOpen", &["box"]),
];

/// The catalogue with Kenney models: for every model of [`MODELS`] found in `dir`, the category
/// gets `model = stem`, a size measured from the mesh (scaled to the catalogue's height) and a
/// [`ModelInfo`] for glTF output. Missing files are skipped (the box stays); a file that is there
/// but cannot be read is an error naming it.
pub fn with_models(mut cat: Catalogue, dir: &Path) -> Result<Catalogue, ScriptError> {
    if !dir.is_dir() {
        return Err(ScriptError::Asset { path: dir.to_path_buf(), message: "not a folder of Kenney models".into() });
    }
    for &(stem, categories) in MODELS {
        let path = dir.join(format!("{stem}.glb"));
        if !path.is_file() {
            continue;
        }
        let bytes = std::fs::read(&path).map_err(|e| ScriptError::io(&path, e))?;
        let (min, max) = glb_bounds(&bytes).map_err(|message| ScriptError::Asset { path: path.clone(), message })?;
        let ext = [max[0] - min[0], max[1] - min[1], max[2] - min[2]];
        if ext.iter().any(|&e| !(e.is_finite() && e > 0.0)) {
            return Err(ScriptError::Asset { path, message: format!("empty or degenerate bounding box {ext:?}") });
        }
        for &name in categories {
            let Some(c) = cat.category_mut(name) else {
                continue;
            };
            // Flat things keep their width; everything else its height.
            let flat = c.size[1] < 0.05;
            let scale = if flat { c.size[0] / ext[0] } else { c.size[1] / ext[1] };
            // A flat thing keeps its catalogue thickness too (a rug must not grow into a step).
            let size = [ext[0] * scale, if flat { c.size[1] } else { ext[1] * scale }, ext[2] * scale];
            // Contact points keep their place relative to the box.
            for p in &mut c.contacts {
                for ((l, new), old) in p.local.iter_mut().zip(size).zip(c.size) {
                    *l *= new / old;
                }
            }
            c.size = size;
            c.model = Some(stem.to_string());
            cat.set_model(name, ModelInfo { path: path.clone(), min, max, scale });
        }
    }
    Ok(cat)
}

/// Bounding box (min, max) of a binary glTF's meshes in model units, after node transforms.
pub fn glb_bounds(bytes: &[u8]) -> Result<([f32; 3], [f32; 3]), String> {
    let json = glb_json(bytes)?;
    let nodes = json.get("nodes").and_then(Value::as_array).cloned().unwrap_or_default();
    let meshes = json.get("meshes").and_then(Value::as_array).ok_or("no meshes")?;
    let accessors = json.get("accessors").and_then(Value::as_array).ok_or("no accessors")?;
    // Roots: the default scene's nodes, else every node that is nobody's child.
    let scene = json.get("scene").and_then(Value::as_u64).unwrap_or(0) as usize;
    let roots: Vec<usize> = match json.get("scenes").and_then(|s| s.get(scene)).and_then(|s| s.get("nodes")) {
        Some(Value::Array(a)) => a.iter().filter_map(Value::as_u64).map(|i| i as usize).collect(),
        _ => {
            let children: Vec<usize> = nodes
                .iter()
                .flat_map(|n| n.get("children").and_then(Value::as_array).cloned().unwrap_or_default())
                .filter_map(|c| c.as_u64().map(|c| c as usize))
                .collect();
            (0..nodes.len()).filter(|i| !children.contains(i)).collect()
        }
    };
    let mut lo = Vec3::splat(f32::INFINITY);
    let mut hi = Vec3::splat(f32::NEG_INFINITY);
    let mut stack: Vec<(usize, Mat4, usize)> = roots.into_iter().map(|r| (r, Mat4::IDENTITY, 0)).collect();
    while let Some((i, parent, depth)) = stack.pop() {
        if depth > 64 {
            return Err("node hierarchy deeper than 64 (a cycle?)".into());
        }
        let node = nodes.get(i).ok_or_else(|| format!("node {i} does not exist"))?;
        let world = parent * local_matrix(node)?;
        if let Some(m) = node.get("mesh").and_then(Value::as_u64) {
            let mesh = meshes.get(m as usize).ok_or_else(|| format!("mesh {m} does not exist"))?;
            for prim in mesh.get("primitives").and_then(Value::as_array).into_iter().flatten() {
                let Some(acc) = prim.get("attributes").and_then(|a| a.get("POSITION")).and_then(Value::as_u64) else {
                    continue;
                };
                let a = accessors.get(acc as usize).ok_or_else(|| format!("accessor {acc} does not exist"))?;
                let (amin, amax) = (vec3(a.get("min")), vec3(a.get("max")));
                let (Some(amin), Some(amax)) = (amin, amax) else {
                    return Err(format!("POSITION accessor {acc} has no min/max"));
                };
                grow_by_box(&mut lo, &mut hi, &world, amin, amax);
            }
        }
        for c in node.get("children").and_then(Value::as_array).into_iter().flatten() {
            let c = c.as_u64().ok_or("bad child index")? as usize;
            stack.push((c, world, depth + 1));
        }
    }
    if !lo.is_finite() || !hi.is_finite() {
        return Err("no mesh with POSITION in the default scene".into());
    }
    Ok((lo.to_array(), hi.to_array()))
}

/// The JSON chunk of a GLB (header: magic "glTF", version 2, length; first chunk: JSON).
fn glb_json(bytes: &[u8]) -> Result<Value, String> {
    let u32_at = |o: usize| -> Result<u32, String> {
        bytes
            .get(o..o + 4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .ok_or_else(|| format!("truncated at byte {o}"))
    };
    if bytes.get(0..4) != Some(b"glTF") {
        return Err("not a binary glTF (no \"glTF\" magic)".into());
    }
    let version = u32_at(4)?;
    if version != 2 {
        return Err(format!("glTF version {version}, expected 2"));
    }
    let len = u32_at(12)? as usize;
    if u32_at(16)? != 0x4E4F_534A {
        return Err("first chunk is not JSON".into());
    }
    let chunk = bytes.get(20..20 + len).ok_or_else(|| format!("JSON chunk of {len} bytes runs past the file end"))?;
    serde_json::from_slice(chunk).map_err(|e| format!("JSON chunk: {e}"))
}

fn vec3(v: Option<&Value>) -> Option<Vec3> {
    let a = v?.as_array()?;
    Some(Vec3::new(a.first()?.as_f64()? as f32, a.get(1)?.as_f64()? as f32, a.get(2)?.as_f64()? as f32))
}

fn floats<const N: usize>(v: Option<&Value>) -> Result<Option<[f32; N]>, String> {
    let Some(v) = v else { return Ok(None) };
    let a = v.as_array().filter(|a| a.len() == N).ok_or_else(|| format!("expected {N} numbers"))?;
    let mut out = [0.0; N];
    for (o, x) in out.iter_mut().zip(a) {
        *o = x.as_f64().ok_or("expected a number")? as f32;
    }
    Ok(Some(out))
}

fn local_matrix(node: &Value) -> Result<Mat4, String> {
    if let Some(m) = floats::<16>(node.get("matrix"))? {
        return Ok(Mat4::from_cols_array(&m));
    }
    let t = floats::<3>(node.get("translation"))?.unwrap_or([0.0; 3]);
    let r = floats::<4>(node.get("rotation"))?.unwrap_or([0.0, 0.0, 0.0, 1.0]);
    let s = floats::<3>(node.get("scale"))?.unwrap_or([1.0; 3]);
    Ok(Mat4::from_scale_rotation_translation(Vec3::from(s), Quat::from_array(r).normalize(), Vec3::from(t)))
}

/// Grows the box `lo..hi` to hold the box `mn..mx` carried by `m` (all eight corners): a mesh's
/// POSITION bounds through its node transforms (also [`crate::output::gltf`]'s model merge).
pub(crate) fn grow_by_box(lo: &mut Vec3, hi: &mut Vec3, m: &glam::Mat4, mn: Vec3, mx: Vec3) {
    for k in 0..8 {
        let corner = Vec3::new(
            if k & 1 == 0 { mn.x } else { mx.x },
            if k & 2 == 0 { mn.y } else { mx.y },
            if k & 4 == 0 { mn.z } else { mx.z },
        );
        let p = m.transform_point3(corner);
        *lo = lo.min(p);
        *hi = hi.max(p);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A GLB with one node (translated, scaled ×2) holding one mesh whose POSITION spans a unit cube.
    pub(crate) fn tiny_glb() -> Vec<u8> {
        let json = serde_json::json!({
            "asset": {"version": "2.0"},
            "scene": 0,
            "scenes": [{"nodes": [0]}],
            "nodes": [{"children": [1], "translation": [1.0, 0.0, 0.0]}, {"mesh": 0, "scale": [2.0, 2.0, 2.0]}],
            "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
            "accessors": [{"componentType": 5126, "count": 8, "type": "VEC3", "min": [0.0, 0.0, -1.0], "max": [1.0, 1.0, 0.0]}]
        });
        let mut text = serde_json::to_vec(&json).unwrap();
        while !text.len().is_multiple_of(4) {
            text.push(b' ');
        }
        let mut out = Vec::new();
        out.extend_from_slice(b"glTF");
        out.extend_from_slice(&2u32.to_le_bytes());
        out.extend_from_slice(&((12 + 8 + text.len()) as u32).to_le_bytes());
        out.extend_from_slice(&(text.len() as u32).to_le_bytes());
        out.extend_from_slice(&0x4E4F_534Au32.to_le_bytes());
        out.extend_from_slice(&text);
        out
    }

    #[test]
    fn bounds_follow_node_transforms() {
        let (lo, hi) = glb_bounds(&tiny_glb()).unwrap();
        assert_eq!(lo, [1.0, 0.0, -2.0]);
        assert_eq!(hi, [3.0, 2.0, 0.0]);
    }

    #[test]
    fn broken_files_say_why() {
        assert!(glb_bounds(b"nope").unwrap_err().contains("magic"));
        let mut g = tiny_glb();
        g.truncate(40);
        assert!(glb_bounds(&g).unwrap_err().contains("past the file end"));
    }
}
