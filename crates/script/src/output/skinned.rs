//! Skinned Kenney characters (issue 13, beyond the paper): a Kenney blocky character (rigid part
//! meshes, no skin of its own, `motion::kenney::read_character`) is retargeted onto the common
//! rig (`motion::rig`) and exported as ONE skinned mesh per character in the animated glTF.
//!
//! - **Bind pose** = the skeleton's rest pose (identity rotations, rest offsets), lifted so its
//!   lowest joint or end site touches the floor; its joint world matrices give the inverse bind
//!   matrices.
//! - **Placement.** Each Kenney part is a segment (pivot → far end: a leg's or an arm's top centre →
//!   bottom centre, the torso's and head's bottom centre → top centre). It is mapped onto a rig
//!   segment: legs from the hip joint height to the floor, arms from the shoulder (`Arm` joint) to
//!   the farthest point of the hand, the torso from the hip joints to the shoulders, the head on top
//!   at its own proportions. Lengths along the segment are fitted to the rig; across it one scale
//!   `w` for the whole character (the rig's shoulder half-span over the Kenney arm's centre) keeps
//!   the blocky proportions. Arms are rotated into the rig's T-pose.
//! - **Binding.** Rigid, weight 1: each part is cut by planes across its segment at the rig's
//!   joints (knee and ankle, elbow and wrist, spine joints), triangles clipped with their
//!   attributes interpolated, and every piece bound to the joint of its span (`UpLeg`/`Leg`/`Foot`,
//!   `Arm`/`ForeArm`/`Hand`, `LowerBack`/`Spine`/`Spine1`, `Head`).
//! - **Document.** [`skinned_gltf_document`] takes [`animated_gltf_document`]'s output, removes the
//!   stick figure's bone boxes (their nodes, mesh and material) and adds per character the skin
//!   (joints = the character's joint nodes, which carry the same animation channels), the mesh node,
//!   its texture (the image bytes embedded in the buffer) and material.

use std::collections::{BTreeSet, HashMap};
use std::path::{Path, PathBuf};

use glam::{DVec3, Mat4, Quat, Vec3};
use image::RgbImage;
use inbetween_core::fk::{forward, GlobalPose};
use inbetween_core::{Motion, Pose, Skeleton};
use inbetween_io::gltf_buffer::{pad_to_4, ElementType, ARRAY_BUFFER, ELEMENT_ARRAY_BUFFER, UNSIGNED_SHORT};
use inbetween_render::canvas::Camera3;
use inbetween_render::Canvas;
use serde_json::{json, Value};

use super::anim_gltf::{animated_gltf_document, Appender, CameraFn};
use super::gltf::write_document;
use super::preview::{draw_object, draw_room, fill_convex, scale_color};
use crate::catalogue::Catalogue;
use crate::error::ScriptError;
use crate::motion::kenney::{read_character, KenneyCharacter, KenneyImage, KenneyPart};
use crate::scene::Scene;

/// Folder of the Kenney blocky characters inside the shared data (and next to the furniture).
pub const BLOCKY_DIR: &str = "assets/kenney_blocky_characters";

/// The blocky characters, in the order characters of a story wear them (repeats after six).
pub const BLOCKY_LETTERS: [char; 6] = ['a', 'c', 'f', 'h', 'l', 'o'];

/// File names of the skinned outputs in a story folder (next to `story.gltf`, which keeps the
/// stick figures).
pub const SKINNED_GLTF: &str = "story_skinned.gltf";
pub const SKINNED_PNG: &str = "story_skinned.png";

/// The folders searched for `character-a.glb` …, in order: next to the furniture models
/// (`<models>/../kenney_blocky_characters`), then the shared data's [`BLOCKY_DIR`].
pub fn character_dirs(models: Option<&Path>) -> Vec<PathBuf> {
    let mut dirs = Vec::new();
    if let Some(m) = models {
        dirs.push(m.parent().unwrap_or(Path::new(".")).join("kenney_blocky_characters"));
    }
    match inbetween_io::data::shared_data_dir() {
        Ok(d) | Err(d) => dirs.push(d.join(BLOCKY_DIR)),
    }
    dirs
}

/// The first of [`character_dirs`] holding `character-a.glb`, or an error naming every folder
/// looked in.
pub fn find_character_dir(models: Option<&Path>) -> Result<PathBuf, ScriptError> {
    first_character_dir(&character_dirs(models))
}

/// The first of `dirs` holding `character-a.glb`, or an error naming them all.
pub fn first_character_dir(dirs: &[PathBuf]) -> Result<PathBuf, ScriptError> {
    if let Some(d) = dirs.iter().find(|d| character_file(d, 0).is_file()) {
        return Ok(d.clone());
    }
    let looked: Vec<String> = dirs.iter().map(|d| d.display().to_string()).collect();
    Err(ScriptError::Invalid(format!(
        "skinned characters need the Kenney blocky characters (character-a.glb …); none found in: {} (set INBETWEEN_DATA to the shared data folder, or pass --models <data>/assets/kenney_furniture)",
        looked.join(", ")
    )))
}

/// The GLB that character `index` of a story wears: `character-<letter>.glb`, letters in
/// [`BLOCKY_LETTERS`] order.
pub fn character_file(dir: &Path, index: usize) -> PathBuf {
    dir.join(format!("character-{}.glb", BLOCKY_LETTERS[index % BLOCKY_LETTERS.len()]))
}

/// A Kenney character bound to a skeleton: one mesh in bind space, each vertex rigidly bound
/// (weight 1) to one joint.
#[derive(Clone, Debug)]
pub struct SkinnedBody {
    pub positions: Vec<Vec3>,
    pub normals: Vec<Vec3>,
    pub uvs: Vec<[f32; 2]>,
    /// Joint (skeleton index) of every vertex.
    pub joints: Vec<u16>,
    /// Triangle list.
    pub indices: Vec<u32>,
    /// World matrix of every joint in the bind pose; the inverse bind matrices are their inverses.
    pub bind: Vec<Mat4>,
    pub image: Option<KenneyImage>,
    pub base_color: [f32; 4],
    /// The Kenney GLB it came from.
    pub source: PathBuf,
}

impl SkinnedBody {
    pub fn inverse_bind(&self) -> Vec<Mat4> {
        self.bind.iter().map(|m| m.inverse()).collect()
    }

    /// Height of the bind-pose mesh (top minus bottom), metres.
    pub fn height(&self) -> f32 {
        let (lo, hi) = self.positions.iter().fold((f32::MAX, f32::MIN), |(lo, hi), p| (lo.min(p.y), hi.max(p.y)));
        hi - lo
    }
}

/// The bind pose: rest pose with the root lifted so the lowest joint or end site is on the floor.
pub fn bind_pose(skeleton: &Skeleton) -> (Pose, GlobalPose) {
    let mut pose = Pose::rest(skeleton);
    let g = forward(skeleton, &pose);
    let lowest = (0..skeleton.len())
        .flat_map(|j| std::iter::once(g.positions[j]).chain(g.end_site(skeleton, j)))
        .map(|p| p.y)
        .fold(f64::MAX, f64::min);
    pose.translations[0].y -= lowest;
    let g = forward(skeleton, &pose);
    (pose, g)
}

/// World matrices (rotation and translation) of every joint of a global pose, as glTF nodes
/// compose them.
pub fn joint_matrices(g: &GlobalPose) -> Vec<Mat4> {
    g.positions
        .iter()
        .zip(&g.rotations)
        .map(|(p, q)| Mat4::from_rotation_translation(q.as_quat().normalize(), p.as_vec3()))
        .collect()
}

/// Linear blend skinning, rigid case: every vertex moved by its joint's world matrix times its
/// inverse bind matrix. `world[j]` is joint j's world matrix at the frame.
pub fn skin_positions(body: &SkinnedBody, world: &[Mat4]) -> Vec<Vec3> {
    let skin: Vec<Mat4> = world.iter().zip(body.inverse_bind()).map(|(w, ib)| *w * ib).collect();
    body.positions.iter().zip(&body.joints).map(|(p, &j)| skin[j as usize].transform_point3(*p)).collect()
}

/// How one part is placed: Kenney segment `from → from + axis_k · len_k` onto the rig segment
/// `to → to + axis_r · len_r`, scaled by `width` across it; then cut into spans along the rig
/// segment, span k starting `cuts[k].0` metres from `to` and bound to joint `cuts[k].1`.
#[derive(Clone)]
struct Placement {
    from: Vec3,
    axis_k: Vec3,
    len_k: f32,
    to: Vec3,
    axis_r: Vec3,
    len_r: f32,
    width: f32,
    cuts: Vec<(f32, usize)>,
}

impl Placement {
    fn rotation(&self) -> Quat {
        Quat::from_rotation_arc(self.axis_k, self.axis_r)
    }

    /// A Kenney point into bind space.
    fn point(&self, q: Vec3) -> Vec3 {
        let d = q - self.from;
        let a = d.dot(self.axis_k);
        let scaled = self.axis_k * a * (self.len_r / self.len_k) + (d - self.axis_k * a) * self.width;
        self.to + self.rotation() * scaled
    }

    /// A Kenney normal into bind space (inverse transpose of the scale).
    fn normal(&self, n: Vec3) -> Vec3 {
        let a = n.dot(self.axis_k);
        let scaled = self.axis_k * a / (self.len_r / self.len_k) + (n - self.axis_k * a) / self.width;
        (self.rotation() * scaled).normalize_or_zero()
    }

    /// Distance along the rig segment of a bind-space point.
    fn along(&self, p: Vec3) -> f32 {
        (p - self.to).dot(self.axis_r)
    }
}

/// Top and bottom centres of a part's bounding box.
fn top_bottom(part: &KenneyPart) -> (Vec3, Vec3) {
    let (lo, hi) = part.positions.iter().fold((Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)), |(lo, hi), p| {
        (lo.min(Vec3::from(*p)), hi.max(Vec3::from(*p)))
    });
    let c = (lo + hi) / 2.0;
    (Vec3::new(c.x, hi.y, c.z), Vec3::new(c.x, lo.y, c.z))
}

fn segment(a: Vec3, b: Vec3) -> (Vec3, f32) {
    let d = b - a;
    (d.normalize_or(Vec3::NEG_Y), d.length().max(1e-4))
}

/// Rig joints by name; an error names the ones missing.
fn joints_named(skeleton: &Skeleton, names: &[&str]) -> Result<Vec<usize>, ScriptError> {
    let missing: Vec<&str> = names.iter().copied().filter(|n| skeleton.find(n).is_none()).collect();
    if !missing.is_empty() {
        return Err(ScriptError::Invalid(format!(
            "skinning needs the standard skeleton's joints; missing: {}",
            missing.join(", ")
        )));
    }
    Ok(names.iter().map(|n| skeleton.find(n).expect("checked above")).collect())
}

/// The farthest joint or end site below `j` (inclusive) from point `from`.
fn farthest_below(skeleton: &Skeleton, g: &GlobalPose, j: usize, from: DVec3) -> DVec3 {
    let mut best = g.positions[j];
    let mut stack = vec![j];
    while let Some(k) = stack.pop() {
        for p in std::iter::once(g.positions[k]).chain(g.end_site(skeleton, k)) {
            if p.distance(from) > best.distance(from) {
                best = p;
            }
        }
        stack.extend(skeleton.children(k));
    }
    best
}

/// Vertices of one piece under construction, merged when identical.
#[derive(Default)]
struct Builder {
    body_pos: Vec<Vec3>,
    body_nor: Vec<Vec3>,
    body_uv: Vec<[f32; 2]>,
    body_joint: Vec<u16>,
    indices: Vec<u32>,
    seen: HashMap<VertexKey, u32>,
}

/// Bit patterns of position, normal and uv, and the joint: identical vertices merge.
type VertexKey = ([u32; 3], [u32; 3], [u32; 2], u16);

/// A clipped vertex: position, normal, uv.
type V = (Vec3, Vec3, [f32; 2]);

fn lerp_v(a: &V, b: &V, t: f32) -> V {
    (a.0.lerp(b.0, t), a.1.lerp(b.1, t), [a.2[0] + (b.2[0] - a.2[0]) * t, a.2[1] + (b.2[1] - a.2[1]) * t])
}

/// Sutherland–Hodgman: the part of polygon `poly` where `f(p) ≥ 0` (`> 0` when `strict`, so a face
/// lying on a cut plane goes to one side only); `f` is affine in p.
fn clip(poly: &[V], f: impl Fn(Vec3) -> f32, strict: bool) -> Vec<V> {
    let inside = |x: f32| if strict { x > 0.0 } else { x >= 0.0 };
    let mut out = Vec::new();
    for i in 0..poly.len() {
        let (a, b) = (&poly[i], &poly[(i + 1) % poly.len()]);
        let (fa, fb) = (f(a.0), f(b.0));
        if inside(fa) {
            out.push(*a);
        }
        if inside(fa) != inside(fb) && fa != fb {
            out.push(lerp_v(a, b, fa / (fa - fb)));
        }
    }
    out
}

impl Builder {
    fn vertex(&mut self, v: &V, joint: u16) -> u32 {
        let n = v.1.normalize_or_zero();
        let key = (v.0.to_array().map(f32::to_bits), n.to_array().map(f32::to_bits), v.2.map(f32::to_bits), joint);
        if let Some(&i) = self.seen.get(&key) {
            return i;
        }
        let i = self.body_pos.len() as u32;
        self.body_pos.push(v.0);
        self.body_nor.push(n);
        self.body_uv.push(v.2);
        self.body_joint.push(joint);
        self.seen.insert(key, i);
        i
    }

    /// Adds a part placed by `pl`, each triangle clipped into the spans of `pl.cuts`.
    fn add(&mut self, part: &KenneyPart, pl: &Placement) {
        let verts: Vec<V> = (0..part.positions.len())
            .map(|i| (pl.point(Vec3::from(part.positions[i])), pl.normal(Vec3::from(part.normals[i])), part.uvs[i]))
            .collect();
        for tri in part.indices.chunks_exact(3) {
            let poly: Vec<V> = tri.iter().map(|&i| verts[i as usize]).collect();
            for (k, &(start, joint)) in pl.cuts.iter().enumerate() {
                let mut piece = poly.clone();
                if k > 0 {
                    piece = clip(&piece, |p| pl.along(p) - start, false);
                }
                if let Some(&(end, _)) = pl.cuts.get(k + 1) {
                    piece = clip(&piece, |p| end - pl.along(p), true);
                }
                if piece.len() < 3 {
                    continue;
                }
                let ids: Vec<u32> = piece.iter().map(|v| self.vertex(v, joint as u16)).collect();
                for w in 1..ids.len() - 1 {
                    let (a, b, c) = (ids[0], ids[w], ids[w + 1]);
                    let (pa, pb, pc) =
                        (self.body_pos[a as usize], self.body_pos[b as usize], self.body_pos[c as usize]);
                    if (pb - pa).cross(pc - pa).length_squared() > 1e-14 {
                        self.indices.extend([a, b, c]);
                    }
                }
            }
        }
    }
}

/// Retargets a Kenney character onto `skeleton` (standard joint names) in its bind pose (see the
/// module comment). Needs a "torso" part; legs, arms and head are placed when present, any other
/// part rides on the torso.
pub fn bind_body(ch: &KenneyCharacter, skeleton: &Skeleton) -> Result<SkinnedBody, ScriptError> {
    let names = [
        "LowerBack",
        "Spine1",
        "Head",
        "LeftUpLeg",
        "LeftLeg",
        "LeftFoot",
        "RightUpLeg",
        "RightLeg",
        "RightFoot",
        "LeftArm",
        "LeftForeArm",
        "LeftHand",
        "RightArm",
        "RightForeArm",
        "RightHand",
    ];
    let j = joints_named(skeleton, &names)?;
    let [lower_back, spine1, head, lul, ll, lf, rul, rl, rf, la, lfa, lh, ra, rfa, rh] = j[..] else {
        unreachable!("15 names")
    };
    let spine = skeleton.find("Spine");
    let (_, g) = bind_pose(skeleton);
    let p = |j: usize| g.positions[j].as_vec3();
    let bad = |m: String| ScriptError::Asset { path: ch.source.clone(), message: m };
    let torso = ch.part("torso").ok_or_else(|| bad("no 'torso' part: not a Kenney blocky character".into()))?;

    // One width scale: the rig's shoulder half-span over the Kenney arm's centre offset.
    let (kt_top, kt_bot) = top_bottom(torso);
    let shoulder_half = (p(la) - p(ra)).length() / 2.0;
    let arm_centre =
        ch.part("arm-left").or(ch.part("arm-right")).map(|a| (top_bottom(a).0 - kt_top).with_y(0.0).length());
    let torso_half = torso.positions.iter().map(|q| (q[0] - kt_top.x).abs()).fold(0.0f32, f32::max);
    let width = shoulder_half / arm_centre.filter(|c| *c > 1e-3).unwrap_or(torso_half.max(1e-3) * 1.5);

    let hip_mid = (p(lul) + p(rul)) / 2.0;
    let shoulder_mid = (p(la) + p(ra)) / 2.0;
    let (torso_axis, torso_len) = segment(hip_mid, shoulder_mid);
    let (kt_axis, kt_len) = segment(kt_bot, kt_top);
    let mut torso_cuts = vec![(f32::MIN, lower_back)];
    if let Some(s) = spine {
        torso_cuts.push(((p(s) - hip_mid).dot(torso_axis), s));
    }
    torso_cuts.push(((p(spine1) - hip_mid).dot(torso_axis), spine1));
    let torso_pl = Placement {
        from: kt_bot,
        axis_k: kt_axis,
        len_k: kt_len,
        to: hip_mid,
        axis_r: torso_axis,
        len_r: torso_len,
        width,
        cuts: torso_cuts,
    };

    let mut b = Builder::default();
    for part in &ch.parts {
        let (top, bot) = top_bottom(part);
        let pl = match part.name.as_str() {
            "leg-left" | "leg-right" => {
                let (up, knee, ankle) = if part.name == "leg-left" { (lul, ll, lf) } else { (rul, rl, rf) };
                // Across: where the Kenney proportions put it under the torso; along: hip joint to floor.
                let at = torso_pl.point(Vec3::new(top.x, kt_bot.y, top.z));
                let to = Vec3::new(at.x, p(up).y, at.z);
                let (axis_k, len_k) = segment(top, bot);
                let along = |jj: usize| p(up).y - p(jj).y;
                Placement {
                    from: top,
                    axis_k,
                    len_k,
                    to,
                    axis_r: Vec3::NEG_Y,
                    len_r: to.y,
                    width,
                    cuts: vec![(f32::MIN, up), (along(knee), knee), (along(ankle), ankle)],
                }
            }
            "arm-left" | "arm-right" => {
                let (arm, elbow, wrist) = if part.name == "arm-left" { (la, lfa, lh) } else { (ra, rfa, rh) };
                let tip = farthest_below(skeleton, &g, wrist, g.positions[arm]).as_vec3();
                let (axis_r, len_r) = segment(p(arm), tip);
                let (axis_k, len_k) = segment(top, bot);
                let along = |jj: usize| (p(jj) - p(arm)).dot(axis_r);
                Placement {
                    from: top,
                    axis_k,
                    len_k,
                    to: p(arm),
                    axis_r,
                    len_r,
                    width,
                    cuts: vec![(f32::MIN, arm), (along(elbow), elbow), (along(wrist), wrist)],
                }
            }
            "head" => {
                let (axis_k, len_k) = segment(bot, top);
                let to = torso_pl.to + torso_pl.axis_r * torso_pl.len_r;
                Placement {
                    from: bot,
                    axis_k,
                    len_k,
                    to,
                    axis_r: Vec3::Y,
                    len_r: len_k * width,
                    width,
                    cuts: vec![(f32::MIN, head)],
                }
            }
            // Anything else rides on the torso, on the head above the shoulders.
            _ => Placement { cuts: [torso_pl.cuts.clone(), vec![(torso_len, head)]].concat(), ..torso_pl.clone() },
        };
        b.add(part, &pl);
    }
    Ok(SkinnedBody {
        positions: b.body_pos,
        normals: b.body_nor,
        uvs: b.body_uv,
        joints: b.body_joint,
        indices: b.indices,
        bind: joint_matrices(&g),
        image: ch.image.clone(),
        base_color: ch.base_color,
        source: ch.source.clone(),
    })
}

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

/// What the skinned outputs show: the furnished scene and its catalogue, the characters with their
/// motions and bodies (`None`: the character keeps its stick figure), the camera and the frame rate.
pub struct SkinnedCast<'a> {
    pub scene: &'a Scene,
    pub cat: &'a Catalogue,
    pub characters: &'a [(&'a str, &'a Motion)],
    pub bodies: &'a [Option<&'a SkinnedBody>],
    pub camera: &'a CameraFn<'a>,
    pub fps: f64,
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
        let (root, first) = joint_nodes(&doc, name, &m.skeleton, &taken).ok_or_else(|| {
            ScriptError::Invalid(format!("character '{name}': no joint nodes in the animated document"))
        })?;
        taken.insert(root);
        found.push((root, first));
    }
    for ((_, m), body) in characters.iter().zip(bodies) {
        if let Some(b) = body {
            if b.bind.len() != m.skeleton.len() {
                return Err(ScriptError::Invalid(format!(
                    "a body bound to {} joints for a skeleton of {}",
                    b.bind.len(),
                    m.skeleton.len()
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
        for j in first..first + m.skeleton.len() {
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
/// atomically; furniture as in [`super::write_animated_gltf`].
pub fn write_skinned_gltf(path: &Path, cast: &SkinnedCast) -> Result<(), ScriptError> {
    let lookup = |category: &str| cast.cat.model_path(category).filter(|p| p.is_file());
    let (doc, bin, _) = skinned_gltf_document(cast, &lookup)?;
    write_document(path, doc, bin)
}

/// A body's colour lookup: its texture (wrapping like glTF's default REPEAT sampler) or its base
/// colour.
struct Paint {
    texture: Option<image::RgbaImage>,
    base: [f32; 4],
}

impl Paint {
    fn of(body: &SkinnedBody) -> Paint {
        let texture = body.image.as_ref().and_then(|i| image::load_from_memory(&i.bytes).ok()).map(|i| i.to_rgba8());
        Paint { texture, base: body.base_color }
    }

    fn at(&self, uv: [f32; 2]) -> [u8; 3] {
        let lin_to_srgb = |c: f32| {
            (255.0 * if c <= 0.003_130_8 { c * 12.92 } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 })
                .round()
                .clamp(0.0, 255.0) as u8
        };
        let base = [0, 1, 2].map(|k| lin_to_srgb(self.base[k]));
        let Some(t) = &self.texture else { return base };
        let (w, h) = (t.width() as f32, t.height() as f32);
        let x = ((uv[0].rem_euclid(1.0) * w) as u32).min(t.width() - 1);
        let y = ((uv[1].rem_euclid(1.0) * h) as u32).min(t.height() - 1);
        let p = t.get_pixel(x, y).0;
        [0, 1, 2].map(|k| (p[k] as f32 * self.base[k].clamp(0.0, 1.0)).round() as u8)
    }
}

/// Story frame `frame` seen through `camera(frame)`: room, boxes and every skinned body (its
/// triangles coloured from the texture at their centre, Lambert-shaded), everything painted far
/// to near; characters without a body are left out. A check of the skin, not a renderer.
pub fn render_skinned_frame(cast: &SkinnedCast, frame: usize, size: (u32, u32)) -> RgbImage {
    let SkinnedCast { scene, cat, characters, bodies, camera, fps } = *cast;
    let (eye, target, fov) = camera(frame);
    let cam = Camera3::new(Vec3::from(eye).as_dvec3(), Vec3::from(target).as_dvec3(), DVec3::Y, fov as f64)
        .with_viewport(size.0, size.1);
    let mut cv = Canvas::new(size.0, size.1, [246, 247, 250]);
    draw_room(&mut cv, &cam, scene);
    let light = Vec3::new(0.4, 1.0, 0.6).normalize();
    // (depth, object index | triangle in pixels and its colour)
    type Item = (f64, Result<usize, ([(f32, f32); 3], [u8; 3])>);
    let mut items: Vec<Item> = Vec::new();
    for (i, o) in scene.objects.iter().enumerate() {
        let c = crate::layout::geom::center(o);
        let p = DVec3::new(c[0] as f64, (o.position[1] + o.size[1] / 2.0) as f64, c[1] as f64);
        items.push((cam.to_camera(p).z, Ok(i)));
    }
    let t = frame as f64 / fps;
    for ((_, m), body) in characters.iter().zip(bodies) {
        let Some(body) = body else { continue };
        let f = ((t / m.frame_time).round().max(0.0) as usize).min(m.num_frames().saturating_sub(1));
        let world = joint_matrices(&forward(&m.skeleton, &m.pose(f)));
        let pts = skin_positions(body, &world);
        let paint = Paint::of(body);
        for tri in body.indices.chunks_exact(3) {
            let tri = [tri[0], tri[1], tri[2]];
            let [a, b, c] = tri.map(|v| pts[v as usize]);
            let n = (b - a).cross(c - a).normalize_or_zero();
            let centre = (a + b + c) / 3.0;
            if n.dot(cam.eye.as_vec3() - centre) <= 0.0 {
                continue;
            }
            let (Some(pa), Some(pb), Some(pc)) =
                (cam.project(a.as_dvec3()), cam.project(b.as_dvec3()), cam.project(c.as_dvec3()))
            else {
                continue;
            };
            let depth = cam.to_camera(centre.as_dvec3()).z;
            let shade = 0.6 + 0.4 * n.dot(light).max(0.0);
            // Texture detail: the triangle split 4 × 4 (in pixels and uv alike), each piece
            // coloured at its centre.
            let px = [(pa.0, pa.1), (pb.0, pb.1), (pc.0, pc.1)];
            let uv = tri.map(|v| body.uvs[v as usize]);
            for (sub, suv) in subdivide(px, uv, 2) {
                let c = [0, 1].map(|k| (suv[0][k] + suv[1][k] + suv[2][k]) / 3.0);
                items.push((depth, Err((sub, scale_color(paint.at(c), shade)))));
            }
        }
    }
    items.sort_by(|a, b| b.0.total_cmp(&a.0));
    for (_, item) in items {
        match item {
            Ok(i) => {
                let o = &scene.objects[i];
                draw_object(&mut cv, &cam, o, super::category_color(cat, &o.category));
            }
            Err((tri, colour)) => fill_convex(&mut cv, &tri, colour),
        }
    }
    cv.into_image()
}

type Tri2 = ([(f32, f32); 3], [[f32; 2]; 3]);

/// Midpoint subdivision, `levels` times (4^levels triangles), of a pixel triangle and its uvs.
fn subdivide(px: [(f32, f32); 3], uv: [[f32; 2]; 3], levels: u32) -> Vec<Tri2> {
    let mut tris = vec![(px, uv)];
    for _ in 0..levels {
        tris = tris
            .into_iter()
            .flat_map(|(p, u)| {
                let mp = |i: usize, j: usize| ((p[i].0 + p[j].0) / 2.0, (p[i].1 + p[j].1) / 2.0);
                let mu = |i: usize, j: usize| [(u[i][0] + u[j][0]) / 2.0, (u[i][1] + u[j][1]) / 2.0];
                let (p01, p12, p20, u01, u12, u20) = (mp(0, 1), mp(1, 2), mp(2, 0), mu(0, 1), mu(1, 2), mu(2, 0));
                [
                    ([p[0], p01, p20], [u[0], u01, u20]),
                    ([p01, p[1], p12], [u01, u[1], u12]),
                    ([p20, p12, p[2]], [u20, u12, u[2]]),
                    ([p01, p12, p20], [u01, u12, u20]),
                ]
            })
            .collect();
    }
    tris
}

/// What [`write_skinned_story`] wrote.
#[derive(Debug, Clone)]
pub struct SkinnedStory {
    pub files: Vec<PathBuf>,
    /// Which GLB each character wears, and the body's height.
    pub notes: Vec<String>,
}

/// The skinned outputs of an animated story into `dir`: [`SKINNED_GLTF`] (every character a
/// Kenney blocky character, `character-a.glb`, `-c`, … in story order, found by
/// [`find_character_dir`]) and [`SKINNED_PNG`] (the story's middle frame through its camera).
/// Without the Kenney files: an error naming where it looked, nothing written.
pub fn write_skinned_story(
    dir: &Path,
    anim: &crate::animate::Animation,
    cat: &Catalogue,
    models: Option<&Path>,
) -> Result<SkinnedStory, ScriptError> {
    let chars: Vec<(&str, &Motion)> = anim.characters.iter().map(|c| (c.name.as_str(), &c.motion)).collect();
    let (bodies, notes) = skinned_bodies(anim, models)?;
    let refs: Vec<Option<&SkinnedBody>> = bodies.iter().map(Some).collect();
    let track = crate::animate::camera_track(anim);
    let cam = |f: usize| track.pose(f);
    let gltf = dir.join(SKINNED_GLTF);
    let (doc, bin) = skinned_story_document(anim, cat, &bodies, &cam)?;
    write_document(&gltf, doc, bin)?;
    let png = dir.join(SKINNED_PNG);
    let cast = SkinnedCast { scene: &anim.scene, cat, characters: &chars, bodies: &refs, camera: &cam, fps: anim.fps };
    let frames = super::anim_gltf::animation_frames(&chars, anim.fps);
    let img = render_skinned_frame(&cast, frames / 2, (640, 480));
    super::write_png(&png, &img)?;
    Ok(SkinnedStory { files: vec![gltf, png], notes })
}

/// Every character's Kenney blocky body (`character-a.glb`, `-c`, … in story order, found by
/// [`find_character_dir`]) bound to its rig, and a note per character (which GLB, how tall).
pub fn skinned_bodies(
    anim: &crate::animate::Animation,
    models: Option<&Path>,
) -> Result<(Vec<SkinnedBody>, Vec<String>), ScriptError> {
    let glbs = find_character_dir(models)?;
    let mut bodies = Vec::new();
    let mut notes = Vec::new();
    for (i, c) in anim.characters.iter().enumerate() {
        let file = character_file(&glbs, i);
        let body = bind_body(&read_character(&file)?, &c.motion.skeleton)?;
        notes.push(format!(
            "{} wears {} ({} triangles, {:.2} m tall)",
            c.name,
            file.display(),
            body.indices.len() / 3,
            body.height()
        ));
        bodies.push(body);
    }
    Ok((bodies, notes))
}

/// The document and buffer of [`SKINNED_GLTF`] in memory: the story with each character wearing
/// its body from [`skinned_bodies`], and the carried props moving as in story.gltf.
pub fn skinned_story_document(
    anim: &crate::animate::Animation,
    cat: &Catalogue,
    bodies: &[SkinnedBody],
    camera: &super::anim_gltf::CameraFn,
) -> Result<(Value, Vec<u8>), ScriptError> {
    let chars: Vec<(&str, &Motion)> = anim.characters.iter().map(|c| (c.name.as_str(), &c.motion)).collect();
    let refs: Vec<Option<&SkinnedBody>> = bodies.iter().map(Some).collect();
    let lookup = |category: &str| cat.model_path(category).filter(|p| p.is_file());
    let cast = SkinnedCast { scene: &anim.scene, cat, characters: &chars, bodies: &refs, camera, fps: anim.fps };
    let (mut doc, mut bin, _) = skinned_gltf_document(&cast, &lookup)?;
    super::anim_gltf::add_prop_channels(&mut doc, &mut bin, anim, super::anim_gltf::animation_frames(&chars, anim.fps));
    Ok((doc, bin))
}
