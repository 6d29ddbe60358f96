//! Named animations of the Kenney blocky characters (CC0 glTF, `assets/kenney_blocky_characters`)
//! as a second source of template actions (§3.2). The blocky rig (root, legs, torso, arms, head:
//! one segment per limb) maps joint for joint onto the common skeleton's hips, upper legs, lower
//! back, upper arms and neck; knees and elbows stay straight.

use super::rig::{clip, hip_height, Rig, FPS};
use crate::ScriptError;
use glam::{DQuat, DVec3};
use inbetween_core::clip::Clip;
use inbetween_core::Pose;
use serde_json::Value;
use std::path::Path;

fn bad(path: &Path, message: impl Into<String>) -> ScriptError {
    ScriptError::Asset { path: path.into(), message: message.into() }
}

/// The JSON and binary chunks of a `.glb` file.
fn read_glb(path: &Path) -> Result<(Value, Vec<u8>), ScriptError> {
    let bytes = std::fs::read(path).map_err(|e| ScriptError::io(path, e))?;
    let u32_at =
        |o: usize| -> Option<u32> { bytes.get(o..o + 4).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]])) };
    if bytes.len() < 20 || &bytes[0..4] != b"glTF" {
        return Err(bad(path, "not a binary glTF (.glb) file"));
    }
    let mut off = 12;
    let (mut json, mut bin) = (None, Vec::new());
    while let (Some(len), Some(kind)) = (u32_at(off), u32_at(off + 4)) {
        let data = bytes.get(off + 8..off + 8 + len as usize).ok_or_else(|| bad(path, "truncated chunk"))?;
        match kind {
            0x4E4F_534A => json = Some(serde_json::from_slice::<Value>(data).map_err(|e| bad(path, e.to_string()))?),
            0x004E_4942 => bin = data.to_vec(),
            _ => {}
        }
        off += 8 + len as usize;
    }
    Ok((json.ok_or_else(|| bad(path, "no JSON chunk"))?, bin))
}

/// Float components of an accessor (`comps` per element), honouring byte offsets and strides.
fn floats(json: &Value, bin: &[u8], accessor: usize, comps: usize) -> Option<Vec<f32>> {
    let acc = &json["accessors"][accessor];
    if acc["componentType"].as_u64()? != 5126 {
        return None;
    }
    let count = acc["count"].as_u64()? as usize;
    let view = &json["bufferViews"][acc["bufferView"].as_u64()? as usize];
    let base = view["byteOffset"].as_u64().unwrap_or(0) as usize + acc["byteOffset"].as_u64().unwrap_or(0) as usize;
    let stride = view["byteStride"].as_u64().map(|s| s as usize).unwrap_or(4 * comps);
    let mut out = Vec::with_capacity(count * comps);
    for i in 0..count {
        for c in 0..comps {
            let o = base + i * stride + 4 * c;
            let b = bin.get(o..o + 4)?;
            out.push(f32::from_le_bytes([b[0], b[1], b[2], b[3]]));
        }
    }
    Some(out)
}

/// A keyed track sampled at time `t` (linear: slerp/lerp between keys; step: previous key).
fn sample_track(times: &[f32], values: &[f32], comps: usize, t: f64, step: bool) -> Vec<f64> {
    let k = times.partition_point(|&x| (x as f64) <= t);
    let get = |i: usize| values[i * comps..(i + 1) * comps].iter().map(|&v| v as f64).collect::<Vec<f64>>();
    if k == 0 {
        return get(0);
    }
    if k >= times.len() || step {
        return get(k.min(times.len()) - 1);
    }
    let (t0, t1) = (times[k - 1] as f64, times[k] as f64);
    let w = if t1 > t0 { (t - t0) / (t1 - t0) } else { 0.0 };
    let (a, b) = (get(k - 1), get(k));
    if comps == 4 {
        let qa = DQuat::from_xyzw(a[0], a[1], a[2], a[3]).normalize();
        let qb = DQuat::from_xyzw(b[0], b[1], b[2], b[3]).normalize();
        let q = qa.slerp(qb, w);
        vec![q.x, q.y, q.z, q.w]
    } else {
        a.iter().zip(&b).map(|(x, y)| x + (y - x) * w).collect()
    }
}

/// Every named animation of a Kenney blocky character, retargeted onto the common skeleton at
/// 30 fps (name, clip).
pub fn read_animations(path: &Path) -> Result<Vec<(String, Clip)>, ScriptError> {
    let (json, bin) = read_glb(path)?;
    let rig = Rig::standard();
    let nodes: Vec<String> = json["nodes"]
        .as_array()
        .map(|a| a.iter().map(|n| n["name"].as_str().unwrap_or("").to_string()).collect())
        .unwrap_or_default();
    let target = |node: &str| -> Option<usize> {
        Some(match node {
            "root" => rig.hips,
            "leg-left" => rig.legs[0][0],
            "leg-right" => rig.legs[1][0],
            "torso" => rig.lower_back,
            "arm-left" => rig.arms[0][1],
            "arm-right" => rig.arms[1][1],
            "head" => rig.neck,
            _ => return None,
        })
    };
    // Kenney legs are 1 unit from the hip pivot to the sole.
    let scale = hip_height();
    let mut out = Vec::new();
    for anim in json["animations"].as_array().into_iter().flatten() {
        let name = anim["name"].as_str().unwrap_or("").to_string();
        let samplers = anim["samplers"].as_array().cloned().unwrap_or_default();
        // (joint, is_rotation, times, values, step)
        let mut tracks = Vec::new();
        let mut end: f64 = 0.0;
        for ch in anim["channels"].as_array().into_iter().flatten() {
            let Some(node) = ch["target"]["node"].as_u64().and_then(|n| nodes.get(n as usize)) else { continue };
            let Some(j) = target(node) else { continue };
            let rotation = match ch["target"]["path"].as_str() {
                Some("rotation") => true,
                Some("translation") if j == rig.hips => false,
                _ => continue,
            };
            let Some(s) = ch["sampler"].as_u64().and_then(|s| samplers.get(s as usize)) else { continue };
            let comps = if rotation { 4 } else { 3 };
            let (Some(ti), Some(vi)) = (s["input"].as_u64(), s["output"].as_u64()) else { continue };
            let (Some(times), Some(values)) =
                (floats(&json, &bin, ti as usize, 1), floats(&json, &bin, vi as usize, comps))
            else {
                return Err(bad(path, format!("animation '{name}': unreadable keys")));
            };
            if times.is_empty() || values.len() != times.len() * comps {
                continue;
            }
            end = end.max(*times.last().unwrap() as f64);
            let step = s["interpolation"].as_str() == Some("STEP");
            tracks.push((j, rotation, times, values, step));
        }
        if tracks.is_empty() {
            continue;
        }
        let frames = ((end * FPS).round() as usize + 1).max(2);
        let poses: Vec<Pose> = (0..frames)
            .map(|f| {
                let t = f as f64 / FPS;
                let mut p = rig.standing();
                for (j, rotation, times, values, step) in &tracks {
                    let v = sample_track(times, values, if *rotation { 4 } else { 3 }, t, *step);
                    if *rotation {
                        p.rotations[*j] = DQuat::from_xyzw(v[0], v[1], v[2], v[3]).normalize();
                    } else {
                        p.translations[*j] = DVec3::new(0.0, hip_height(), 0.0) + DVec3::new(v[0], v[1], v[2]) * scale;
                    }
                }
                p
            })
            .collect();
        out.push((name, clip(&rig, &poses)));
    }
    Ok(out)
}

/// Action tags of a Kenney animation name ("attack-kick-right" → kick); empty for names that are
/// no action of the verb table (static, holding, wheelchair moves, …).
pub fn tags_of_name(name: &str) -> Vec<String> {
    if name.starts_with("wheelchair") || name.starts_with("holding") {
        return Vec::new();
    }
    let mut tags: Vec<String> = Vec::new();
    for w in name.split(|c: char| !c.is_ascii_alphabetic()) {
        let t = match w {
            "melee" => Some("punch"),
            "interact" => Some("reach"),
            w => super::verbs::canonical(w),
        };
        if let Some(t) = t {
            if !tags.iter().any(|x| x == t) {
                tags.push(t.to_string());
            }
        }
    }
    tags
}

/// One rigid part of a Kenney character (a mesh node: "leg-left", "torso", "head", …), its
/// geometry in the character's rest frame (every node transform above it applied), Kenney units.
#[derive(Clone, Debug, PartialEq)]
pub struct KenneyPart {
    /// The node's name (the mesh's when the node has none).
    pub name: String,
    pub positions: Vec<[f32; 3]>,
    pub normals: Vec<[f32; 3]>,
    /// `TEXCOORD_0`, zeros when the mesh has none.
    pub uvs: Vec<[f32; 2]>,
    /// Triangle list.
    pub indices: Vec<u32>,
}

/// The colour texture of a Kenney character: the image file's bytes and MIME type.
#[derive(Clone, Debug, PartialEq)]
pub struct KenneyImage {
    pub bytes: Vec<u8>,
    pub mime: String,
}

/// A Kenney character's body: its mesh parts at rest plus its one material (the first primitive's:
/// every Kenney character uses a single texture).
#[derive(Clone, Debug, PartialEq)]
pub struct KenneyCharacter {
    pub source: std::path::PathBuf,
    pub parts: Vec<KenneyPart>,
    pub image: Option<KenneyImage>,
    /// Linear RGBA base colour factor of the material (white when absent).
    pub base_color: [f32; 4],
}

impl KenneyCharacter {
    pub fn part(&self, name: &str) -> Option<&KenneyPart> {
        self.parts.iter().find(|p| p.name == name)
    }
}

/// Local transform of a glTF node (matrix, or translation · rotation · scale).
fn node_matrix(node: &Value) -> glam::Mat4 {
    let f = |key: &str, n: usize| -> Option<Vec<f32>> {
        let a = node[key].as_array()?;
        let v: Vec<f32> = a.iter().filter_map(|x| x.as_f64().map(|x| x as f32)).collect();
        (v.len() == n).then_some(v)
    };
    if let Some(m) = f("matrix", 16) {
        return glam::Mat4::from_cols_slice(&m);
    }
    let t = f("translation", 3).map_or(glam::Vec3::ZERO, |v| glam::Vec3::new(v[0], v[1], v[2]));
    let r =
        f("rotation", 4).map_or(glam::Quat::IDENTITY, |v| glam::Quat::from_xyzw(v[0], v[1], v[2], v[3]).normalize());
    let s = f("scale", 3).map_or(glam::Vec3::ONE, |v| glam::Vec3::new(v[0], v[1], v[2]));
    glam::Mat4::from_scale_rotation_translation(s, r, t)
}

/// Index list of a primitive (u8, u16 or u32 indices; 0..count when it has none).
fn indices_of(json: &Value, bin: &[u8], prim: &Value, count: usize) -> Option<Vec<u32>> {
    let Some(acc) = prim["indices"].as_u64() else { return Some((0..count as u32).collect()) };
    let acc = &json["accessors"][acc as usize];
    let n = acc["count"].as_u64()? as usize;
    let size = match acc["componentType"].as_u64()? {
        5121 => 1,
        5123 => 2,
        5125 => 4,
        _ => return None,
    };
    let view = &json["bufferViews"][acc["bufferView"].as_u64()? as usize];
    let base = view["byteOffset"].as_u64().unwrap_or(0) as usize + acc["byteOffset"].as_u64().unwrap_or(0) as usize;
    let stride = view["byteStride"].as_u64().map_or(size, |s| s as usize);
    (0..n)
        .map(|i| {
            let b = bin.get(base + i * stride..base + i * stride + size)?;
            Some(match size {
                1 => b[0] as u32,
                2 => u16::from_le_bytes([b[0], b[1]]) as u32,
                _ => u32::from_le_bytes([b[0], b[1], b[2], b[3]]),
            })
        })
        .collect()
}

/// The colour image of material `m`: embedded (buffer view or data URI) or a file next to the GLB.
fn material_image(path: &Path, json: &Value, bin: &[u8], m: &Value) -> Result<Option<KenneyImage>, ScriptError> {
    let Some(tex) = m["pbrMetallicRoughness"]["baseColorTexture"]["index"].as_u64() else { return Ok(None) };
    let Some(src) = json["textures"][tex as usize]["source"].as_u64() else { return Ok(None) };
    let img = &json["images"][src as usize];
    let mime_of = |name: &str| {
        if name.to_ascii_lowercase().ends_with(".jpg") || name.to_ascii_lowercase().ends_with(".jpeg") {
            "image/jpeg"
        } else {
            "image/png"
        }
    };
    if let Some(v) = img["bufferView"].as_u64() {
        let view = &json["bufferViews"][v as usize];
        let (off, len) =
            (view["byteOffset"].as_u64().unwrap_or(0) as usize, view["byteLength"].as_u64().unwrap_or(0) as usize);
        let bytes = bin
            .get(off..off + len)
            .ok_or_else(|| bad(path, format!("image {src}: buffer view {v} runs past the binary chunk")))?;
        let mime = img["mimeType"].as_str().unwrap_or("image/png").to_string();
        return Ok(Some(KenneyImage { bytes: bytes.to_vec(), mime }));
    }
    let Some(uri) = img["uri"].as_str() else { return Ok(None) };
    if let Some(data) = uri.strip_prefix("data:") {
        let (head, b64) = data.split_once(',').ok_or_else(|| bad(path, format!("image {src}: malformed data URI")))?;
        let bytes = crate::output::gltf::base64_decode(b64)
            .ok_or_else(|| bad(path, format!("image {src}: bad base64 in data URI")))?;
        let mime = head.split(';').next().filter(|m| !m.is_empty()).unwrap_or("image/png").to_string();
        return Ok(Some(KenneyImage { bytes, mime }));
    }
    // A relative file (Kenney blocky characters: `Textures/texture-a.png`), percent-escapes aside.
    let file = path.parent().unwrap_or(Path::new(".")).join(uri.replace("%20", " "));
    let bytes =
        std::fs::read(&file).map_err(|e| bad(path, format!("texture '{uri}' (looked at {}): {e}", file.display())))?;
    Ok(Some(KenneyImage { bytes, mime: mime_of(uri).to_string() }))
}

/// Reads the body of a Kenney character GLB: every mesh node of its default scene, at rest, with
/// the first primitive's material (texture file read relative to the GLB). Errors name the file and
/// what is wrong with it.
pub fn read_character(path: &Path) -> Result<KenneyCharacter, ScriptError> {
    let (json, bin) = read_glb(path)?;
    let nodes = json["nodes"].as_array().cloned().unwrap_or_default();
    let scene = json["scene"].as_u64().unwrap_or(0) as usize;
    let roots: Vec<usize> = json["scenes"][scene]["nodes"]
        .as_array()
        .map(|a| a.iter().filter_map(|n| n.as_u64().map(|n| n as usize)).collect())
        .unwrap_or_else(|| (0..nodes.len()).collect());
    let mut parts = Vec::new();
    let mut material: Option<usize> = None;
    // Depth-first over the scene with world matrices; the depth bound guards against cycles.
    let mut stack: Vec<(usize, glam::Mat4, usize)> = roots.iter().map(|&r| (r, glam::Mat4::IDENTITY, 0)).collect();
    while let Some((n, parent, depth)) = stack.pop() {
        let node = nodes.get(n).ok_or_else(|| bad(path, format!("scene names node {n}, which does not exist")))?;
        if depth > 64 {
            return Err(bad(path, "node hierarchy deeper than 64 (a cycle?)"));
        }
        let world = parent * node_matrix(node);
        for c in node["children"].as_array().into_iter().flatten().filter_map(Value::as_u64) {
            stack.push((c as usize, world, depth + 1));
        }
        let Some(mesh) = node["mesh"].as_u64() else { continue };
        let mesh = &json["meshes"][mesh as usize];
        let name = node["name"].as_str().or(mesh["name"].as_str()).unwrap_or("").to_string();
        let normal_m = glam::Mat3::from_mat4(world).inverse().transpose();
        let mut part =
            KenneyPart { name: name.clone(), positions: vec![], normals: vec![], uvs: vec![], indices: vec![] };
        for prim in mesh["primitives"].as_array().into_iter().flatten() {
            if prim["mode"].as_u64().is_some_and(|m| m != 4) {
                return Err(bad(path, format!("part '{name}': only triangle lists are supported")));
            }
            let attr = &prim["attributes"];
            let unreadable = |what: &str| bad(path, format!("part '{name}': unreadable {what}"));
            let pos = attr["POSITION"]
                .as_u64()
                .and_then(|a| floats(&json, &bin, a as usize, 3))
                .ok_or_else(|| unreadable("POSITION"))?;
            let count = pos.len() / 3;
            let nor = match attr["NORMAL"].as_u64() {
                Some(a) => floats(&json, &bin, a as usize, 3)
                    .filter(|v| v.len() == pos.len())
                    .ok_or_else(|| unreadable("NORMAL"))?,
                None => vec![0.0; pos.len()],
            };
            let uv = match attr["TEXCOORD_0"].as_u64() {
                Some(a) => floats(&json, &bin, a as usize, 2)
                    .filter(|v| v.len() == 2 * count)
                    .ok_or_else(|| unreadable("TEXCOORD_0"))?,
                None => vec![0.0; 2 * count],
            };
            let idx = indices_of(&json, &bin, prim, count).ok_or_else(|| unreadable("indices"))?;
            if let Some(i) = idx.iter().find(|&&i| i as usize >= count) {
                return Err(bad(path, format!("part '{name}': index {i} past its {count} vertices")));
            }
            let first = part.positions.len() as u32;
            for k in 0..count {
                let p = world.transform_point3(glam::Vec3::new(pos[3 * k], pos[3 * k + 1], pos[3 * k + 2]));
                let nn = (normal_m * glam::Vec3::new(nor[3 * k], nor[3 * k + 1], nor[3 * k + 2])).normalize_or_zero();
                part.positions.push(p.to_array());
                part.normals.push(nn.to_array());
                part.uvs.push([uv[2 * k], uv[2 * k + 1]]);
            }
            part.indices.extend(idx.chunks_exact(3).flatten().map(|i| i + first));
            material = material.or(prim["material"].as_u64().map(|m| m as usize));
        }
        if !part.indices.is_empty() {
            parts.push(part);
        }
    }
    if parts.is_empty() {
        return Err(bad(path, "no mesh parts in its scene"));
    }
    parts.sort_by(|a, b| a.name.cmp(&b.name));
    let m = material.map_or(Value::Null, |m| json["materials"][m].clone());
    let image = material_image(path, &json, &bin, &m)?;
    let base_color = m["pbrMetallicRoughness"]["baseColorFactor"]
        .as_array()
        .map(|a| a.iter().filter_map(|x| x.as_f64().map(|x| x as f32)).collect::<Vec<f32>>())
        .filter(|v| v.len() == 4)
        .map_or([1.0; 4], |v| [v[0], v[1], v[2], v[3]]);
    Ok(KenneyCharacter { source: path.to_path_buf(), parts, image, base_color })
}
