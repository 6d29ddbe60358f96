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
//! - **Document.** [`skinned_gltf_document`] builds [`animated_gltf_document`]'s document with the
//!   body chosen up front per character (no bone boxes, mesh or material for one that has a skinned
//!   body, so nothing is added only to be removed) and adds per skinned character the skin (joints =
//!   the character's joint nodes, which carry the same animation channels), the mesh node, its
//!   texture (the image bytes embedded in the buffer) and material.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use glam::{DVec3, Mat4, Quat, Vec3};
use image::RgbImage;
use inbetween_core::clip::Clip;
use inbetween_core::fk::{forward, GlobalPose};
use inbetween_core::{Pose, Skeleton};
use inbetween_io::gltf_buffer::json::accessor::ComponentType;
use inbetween_io::gltf_buffer::json::validation::Checked::Valid;
use inbetween_io::gltf_buffer::json::{self, Index};
use inbetween_io::gltf_buffer::{material, mesh, node, GltfDoc, Type, ARRAY_BUFFER, ELEMENT_ARRAY_BUFFER};
use inbetween_render::canvas::Camera3;
use inbetween_render::Canvas;
use serde_json::Value;

use super::anim_gltf::{animated_document, AnimatedDocument, Body, CameraFn};
use super::gltf::write_document;
use super::preview::{draw_object, draw_room, scale_color};
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
        "skinned characters need the Kenney blocky characters (character-a.glb …); none found in: {} (set INBETWEEN_DATA to the shared data folder, or give `models` = <data>/assets/kenney_furniture)",
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

mod bind;
mod document;
mod preview;

pub use bind::bind_body;
pub use document::{skinned_gltf_document, write_skinned_gltf};
pub use preview::render_skinned_frame;

/// What the skinned outputs show: the furnished scene and its catalogue, the characters with their
/// motions and bodies (`None`: the character keeps its stick figure), the camera and the frame rate.
pub struct SkinnedCast<'a> {
    pub scene: &'a Scene,
    pub cat: &'a Catalogue,
    pub characters: &'a [(&'a str, &'a Clip)],
    pub bodies: &'a [Option<&'a SkinnedBody>],
    pub camera: &'a CameraFn<'a>,
    pub fps: f64,
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
    let chars: Vec<(&str, &Clip)> = anim.characters.iter().map(|c| (c.name.as_str(), &c.clip)).collect();
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
        let body = bind_body(&read_character(&file)?, c.clip.skeleton())?;
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
    let chars: Vec<(&str, &Clip)> = anim.characters.iter().map(|c| (c.name.as_str(), &c.clip)).collect();
    let refs: Vec<Option<&SkinnedBody>> = bodies.iter().map(Some).collect();
    let lookup = |category: &str| cat.model_path(category).filter(|p| p.is_file());
    let cast = SkinnedCast { scene: &anim.scene, cat, characters: &chars, bodies: &refs, camera, fps: anim.fps };
    let mut doc = document::skinned_document(&cast, &lookup)?;
    super::anim_gltf::add_prop_channels(&mut doc, anim, super::anim_gltf::animation_frames(&chars, anim.fps));
    let (doc, bin, _) = doc.finish();
    Ok((doc, bin))
}
