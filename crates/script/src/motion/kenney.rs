//! Named animations of the Kenney blocky characters (CC0 glTF, `assets/kenney_blocky_characters`)
//! as a second source of template actions (§3.2). The blocky rig (root, legs, torso, arms, head:
//! one segment per limb) maps joint for joint onto the common skeleton's hips, upper legs, lower
//! back, upper arms and neck; knees and elbows stay straight.

use super::rig::{clip, hip_height, Rig, FPS};
use crate::ScriptError;
use glam::{DQuat, DVec3};
use inbetween_core::{Motion, Pose};
use serde_json::Value;
use std::path::Path;

fn bad(path: &Path, message: impl Into<String>) -> ScriptError {
    ScriptError::Asset { path: path.into(), message: message.into() }
}

/// The JSON and binary chunks of a `.glb` file.
fn read_glb(path: &Path) -> Result<(Value, Vec<u8>), ScriptError> {
    let bytes = std::fs::read(path).map_err(|e| ScriptError::io(path, e))?;
    let u32_at = |o: usize| -> Option<u32> { bytes.get(o..o + 4).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]])) };
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
pub fn read_animations(path: &Path) -> Result<Vec<(String, Motion)>, ScriptError> {
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
            let (Some(times), Some(values)) = (floats(&json, &bin, ti as usize, 1), floats(&json, &bin, vi as usize, comps)) else {
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
