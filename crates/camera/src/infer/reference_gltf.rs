//! A style reference from a glTF camera animation (issue 24): the camera a user animated (in
//! Blender, or exported by `camera generate`) over the same two characters. The camera node's
//! translation and rotation channels are sampled at the scene's frames (LINEAR, quaternions by
//! slerp, held at the ends), and [`ReferenceClip::from_poses`] turns each pose into Toric
//! coordinates against the scene's first two characters, with their Eq. 1 features from the scene:
//! a [`ReferenceClip`] whose style the extractor computes.
//!
//! Read: `.gltf` (JSON, buffers as base64 data URIs) and `.glb`; accessors of FLOAT components.
//! The camera node is the first node with a `camera`; its static parents' transforms are applied.

use glam::{DQuat, DVec3};
use inbetween_io::gltf_buffer::base64_decode;
use serde_json::Value;

use super::ReferenceClip;
use crate::dataset::Scene;
use crate::toric::{CameraPose, Lens};

fn err(file: &str, m: impl std::fmt::Display) -> String {
    format!("{file}: {m}")
}

/// The glTF JSON and its binary chunk (GLB) from a file's bytes.
fn split(bytes: &[u8], file: &str) -> Result<(Value, Option<Vec<u8>>), String> {
    if bytes.starts_with(b"glTF") {
        let u32_at = |i: usize| -> Result<u32, String> {
            bytes
                .get(i..i + 4)
                .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
                .ok_or_else(|| err(file, format!("GLB truncated at byte {i}")))
        };
        let json_len = u32_at(12)? as usize;
        if u32_at(16)? != 0x4E4F_534A {
            return Err(err(file, "GLB: the first chunk is not JSON"));
        }
        let json = bytes.get(20..20 + json_len).ok_or_else(|| err(file, "GLB: JSON chunk truncated"))?;
        let doc: Value = serde_json::from_slice(json).map_err(|e| err(file, format!("GLB JSON: {e}")))?;
        let bin_at = 20 + json_len;
        let bin = match (u32_at(bin_at), u32_at(bin_at + 4)) {
            (Ok(len), Ok(0x004E_4942)) => Some(
                bytes
                    .get(bin_at + 8..bin_at + 8 + len as usize)
                    .ok_or_else(|| err(file, "GLB: BIN chunk truncated"))?
                    .to_vec(),
            ),
            _ => None,
        };
        return Ok((doc, bin));
    }
    let doc: Value = serde_json::from_slice(bytes).map_err(|e| {
        err(file, format!("line {} column {}: {e}; expected glTF 2.0 JSON or GLB", e.line(), e.column()))
    })?;
    Ok((doc, None))
}

/// The floats of accessor `i` (FLOAT components only), as rows of `n`.
fn floats(doc: &Value, bin: &Option<Vec<u8>>, i: usize, n: usize, file: &str) -> Result<Vec<Vec<f64>>, String> {
    let acc = &doc["accessors"][i];
    if acc["componentType"].as_u64() != Some(5126) {
        return Err(err(file, format!("accessor {i}: expected FLOAT components (5126)")));
    }
    let count = acc["count"].as_u64().ok_or_else(|| err(file, format!("accessor {i}: no count")))? as usize;
    let view = &doc["bufferViews"]
        [acc["bufferView"].as_u64().ok_or_else(|| err(file, format!("accessor {i}: no bufferView")))? as usize];
    let buffer_index = view["buffer"].as_u64().unwrap_or(0) as usize;
    let buffer = &doc["buffers"][buffer_index];
    let data: Vec<u8> = match buffer["uri"].as_str() {
        Some(uri) => {
            let b64 = uri.split_once(";base64,").map(|(_, d)| d).ok_or_else(|| {
                err(file, format!("buffer {buffer_index}: only embedded data URIs are read (found {:.40})", uri))
            })?;
            base64_decode(b64).ok_or_else(|| err(file, format!("buffer {buffer_index}: bad base64")))?
        }
        None => bin.clone().ok_or_else(|| err(file, format!("buffer {buffer_index}: no data")))?,
    };
    let start = view["byteOffset"].as_u64().unwrap_or(0) as usize + acc["byteOffset"].as_u64().unwrap_or(0) as usize;
    let stride = view["byteStride"].as_u64().map_or(4 * n, |s| s as usize);
    (0..count)
        .map(|r| {
            (0..n)
                .map(|c| {
                    let o = start + r * stride + 4 * c;
                    data.get(o..o + 4)
                        .map(|b| f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])))
                        .ok_or_else(|| err(file, format!("accessor {i}: reads past its buffer")))
                })
                .collect()
        })
        .collect()
}

/// Linear (slerp for rotations) sample of keyed values at time `t`, held at the ends.
fn sample(times: &[f64], values: &[Vec<f64>], t: f64, rotation: bool) -> Vec<f64> {
    let k = times.partition_point(|&x| x <= t);
    if k == 0 {
        return values[0].clone();
    }
    if k >= times.len() {
        return values[times.len() - 1].clone();
    }
    let (t0, t1) = (times[k - 1], times[k]);
    let w = if t1 > t0 { (t - t0) / (t1 - t0) } else { 0.0 };
    let (a, b) = (&values[k - 1], &values[k]);
    if rotation {
        let qa = DQuat::from_xyzw(a[0], a[1], a[2], a[3]);
        let qb = DQuat::from_xyzw(b[0], b[1], b[2], b[3]);
        let q = qa.slerp(qb, w);
        vec![q.x, q.y, q.z, q.w]
    } else {
        a.iter().zip(b).map(|(x, y)| x + (y - x) * w).collect()
    }
}

/// A node's static local transform (translation, rotation).
fn local(node: &Value) -> (DVec3, DQuat) {
    let v = |k: &str, n: usize| -> Option<Vec<f64>> {
        node[k].as_array().map(|a| a.iter().take(n).map(|x| x.as_f64().unwrap_or(0.0)).collect())
    };
    let t = v("translation", 3).map_or(DVec3::ZERO, |a| DVec3::new(a[0], a[1], a[2]));
    let r = v("rotation", 4).map_or(DQuat::IDENTITY, |a| DQuat::from_xyzw(a[0], a[1], a[2], a[3]));
    (t, r)
}

/// The reference clip of the glTF camera animation in `bytes` (`file` names it in errors) over
/// `scene`'s first two characters.
pub fn reference_from_gltf(bytes: &[u8], file: &str, scene: &Scene, lens: &Lens) -> Result<ReferenceClip, String> {
    let (doc, bin) = split(bytes, file)?;
    let nodes = doc["nodes"].as_array().ok_or_else(|| err(file, "no nodes"))?;
    let cam = nodes.iter().position(|n| n.get("camera").is_some()).ok_or_else(|| err(file, "no camera node"))?;
    // The chain of static parents above the camera node.
    let parent_of = |i: usize| {
        nodes
            .iter()
            .position(|n| n["children"].as_array().is_some_and(|c| c.iter().any(|x| x.as_u64() == Some(i as u64))))
    };
    let mut parents = Vec::new();
    let mut at = cam;
    while let Some(p) = parent_of(at) {
        if parents.contains(&p) || parents.len() > nodes.len() {
            return Err(err(file, "the node hierarchy has a cycle"));
        }
        parents.push(p);
        at = p;
    }
    let anim = doc["animations"].as_array().and_then(|a| a.first()).ok_or_else(|| err(file, "no animation"))?;
    let mut translation = None;
    let mut rotation = None;
    for ch in anim["channels"].as_array().into_iter().flatten() {
        if ch["target"]["node"].as_u64() != Some(cam as u64) {
            continue;
        }
        let s = &anim["samplers"][ch["sampler"].as_u64().unwrap_or(u64::MAX) as usize];
        let (input, output) = (s["input"].as_u64(), s["output"].as_u64());
        let (Some(input), Some(output)) = (input, output) else { continue };
        let times: Vec<f64> = floats(&doc, &bin, input as usize, 1, file)?.into_iter().map(|r| r[0]).collect();
        match ch["target"]["path"].as_str() {
            Some("translation") => translation = Some((times, floats(&doc, &bin, output as usize, 3, file)?)),
            Some("rotation") => rotation = Some((times, floats(&doc, &bin, output as usize, 4, file)?)),
            _ => {}
        }
    }
    if translation.is_none() && rotation.is_none() {
        return Err(err(file, format!("the animation does not move the camera node {cam}")));
    }
    let (t0, r0) = local(&nodes[cam]);
    let (mut pt, mut pr) = (DVec3::ZERO, DQuat::IDENTITY);
    for &p in parents.iter().rev() {
        let (t, r) = local(&nodes[p]);
        pt += pr * t;
        pr *= r;
    }
    let poses: Vec<CameraPose> = (0..scene.num_frames())
        .map(|f| {
            let time = f as f64 / scene.fps;
            let t = translation.as_ref().map_or(t0, |(ts, v)| {
                let s = sample(ts, v, time, false);
                DVec3::new(s[0], s[1], s[2])
            });
            let r = rotation.as_ref().map_or(r0, |(ts, v)| {
                let s = sample(ts, v, time, true);
                DQuat::from_xyzw(s[0], s[1], s[2], s[3]).normalize()
            });
            CameraPose { position: pt + pr * t, rotation: (pr * r).normalize() }
        })
        .collect();
    ReferenceClip::from_poses(scene, &poses, lens).map_err(|e| err(file, e))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dataset::Behaviour;
    use crate::infer::{example_keys, GenerateJob};

    #[test]
    fn a_generated_camera_exported_as_gltf_reads_back_as_its_own_toric_track() {
        let scene = Scene::procedural(4, 240, 30.0);
        let w = crate::weights::committed().unwrap();
        let keys = example_keys(&scene, &[0, 239]);
        let style = w.style(Behaviour::Orbit).unwrap();
        let track = GenerateJob::new(&w.model, &scene, &keys, &style).run().unwrap();
        let doc = crate::gltf::camera_gltf(&track, &scene).to_string();
        let clip = reference_from_gltf(doc.as_bytes(), "orbit.gltf", &scene, &track.lens).unwrap();
        assert_eq!(clip.camera.len(), 240);
        // The glTF stores f32 poses: the Toric coordinates come back within rounding.
        for (f, (got, want)) in clip.camera.iter().zip(track.toric()).enumerate() {
            for (g, w) in got.to_array().iter().zip(want.to_array()) {
                assert!((g - w).abs() < 1e-3, "frame {f}: {got:?} vs {want:?}");
            }
        }
        // Its style code is a code the generator takes.
        let code = clip.style(&w.model, std::path::Path::new("orbit.gltf")).unwrap();
        assert_eq!(code.len(), style.code.len());
        assert!(code.iter().all(|v| v.is_finite()));
    }

    #[test]
    fn bad_gltf_names_the_file_and_what_is_missing() {
        let scene = Scene::procedural(4, 60, 30.0);
        let lens = Lens::default();
        let e = reference_from_gltf(b"{\"asset\": ", "cam.gltf", &scene, &lens).unwrap_err();
        assert!(e.starts_with("cam.gltf: line 1"), "{e}");
        let e =
            reference_from_gltf(br#"{"asset":{"version":"2.0"},"nodes":[{"name":"x"}]}"#, "cam.gltf", &scene, &lens)
                .unwrap_err();
        assert_eq!(e, "cam.gltf: no camera node");
        let e = reference_from_gltf(br#"{"nodes":[{"camera":0}]}"#, "cam.gltf", &scene, &lens).unwrap_err();
        assert_eq!(e, "cam.gltf: no animation");
        let e = reference_from_gltf(b"glTF\x02\0\0\0", "cam.glb", &scene, &lens).unwrap_err();
        assert!(e.contains("GLB truncated"), "{e}");
    }
}
