//! What a furnished scene becomes on disk: scene JSON, glTF (boxes, or the Kenney meshes when the
//! catalogue knows model files) and PNG previews (top-down plan and a perspective view), every
//! file written atomically.

pub mod anim_gltf;
pub mod anim_preview;
pub mod bvh_out;
pub mod gltf;
pub mod preview;
pub mod skinned;

use std::path::{Path, PathBuf};

use crate::catalogue::Catalogue;
use crate::error::ScriptError;
use crate::scene::{Mount, Scene};

pub use anim_gltf::{animated_gltf_document, story_gltf_document, write_animated_gltf, write_story_gltf};
pub use anim_preview::{render_preview_gif, render_top_down_trails, AnimPreviewOptions};
pub use bvh_out::write_character_bvh;
pub use gltf::{glb_bytes, gltf_document, gltf_text_bytes, write_gltf, write_gltf_with_models};
pub use preview::{perspective, top_down, VIEWS};

/// The scene as pretty JSON, each object with its `mount` (floor, on, wall or ceiling: what
/// holds it up; `mounts` from [`crate::invariants::mounts`]).
pub fn scene_json_bytes(scene: &Scene, mounts: &[Mount]) -> Result<Vec<u8>, ScriptError> {
    let err = |e: serde_json::Error| ScriptError::Invalid(format!("scene JSON: {e}"));
    let mut value = serde_json::to_value(scene).map_err(err)?;
    if let Some(objects) = value.get_mut("objects").and_then(|o| o.as_array_mut()) {
        for (o, m) in objects.iter_mut().zip(mounts) {
            let mount = serde_json::to_value(m).map_err(err)?;
            if let Some(map) = o.as_object_mut() {
                map.insert("mount".into(), mount);
            }
        }
    }
    serde_json::to_vec_pretty(&value).map_err(err)
}

/// Writes [`scene_json_bytes`] (atomic).
pub fn write_json(path: &Path, scene: &Scene, cat: &Catalogue) -> Result<(), ScriptError> {
    let bytes = scene_json_bytes(scene, &crate::invariants::mounts(scene, cat))?;
    inbetween_io::write_atomic(path, &bytes).map_err(|e| ScriptError::io(path, e))
}

/// Reads a scene written by [`write_json`].
pub fn read_json(path: &Path) -> Result<Scene, ScriptError> {
    let text = std::fs::read_to_string(path).map_err(|e| ScriptError::io(path, e))?;
    serde_json::from_str(&text)
        .map_err(|e| ScriptError::Asset { path: path.to_path_buf(), message: format!("not a scene JSON: {e}") })
}

/// Writes an image as PNG (atomic).
pub fn write_png(path: &Path, img: &image::RgbImage) -> Result<(), ScriptError> {
    inbetween_render::write_png(path, img)
        .map_err(|e| ScriptError::Asset { path: path.to_path_buf(), message: e.to_string() })
}

/// Writes `top.png` (plan) and `view.png` (perspective from `view`) into `dir`; returns their paths.
pub fn write_previews(dir: &Path, scene: &Scene, cat: &Catalogue, view: &str) -> Result<Vec<PathBuf>, ScriptError> {
    let top = dir.join("top.png");
    write_png(&top, &top_down(scene, cat))?;
    let persp = dir.join("view.png");
    write_png(&persp, &perspective(scene, cat, view))?;
    Ok(vec![top, persp])
}

/// One box of the placeholder drawn for an object without a model ([`placeholder_boxes`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlaceholderBox {
    /// "box" (the whole object), or "seat" and "back" (a seat with a backrest).
    pub part: &'static str,
    /// Where the box's base centre sits along the object's depth axis (+z the front), metres.
    pub z: f32,
    /// Width, height, depth, metres.
    pub size: [f32; 3],
}

/// Fraction of a seat's depth its backrest takes.
pub const BACKREST_DEPTH: f32 = 0.2;

/// The boxes that stand for `o` when it has no model: one box of its size; or, for a seat whose
/// seat contact lies under 90 % of its height (a chair, an armchair, a sofa: a backrest above the
/// seat), a seat box as high as the seat contact and a backrest box along its rear edge
/// ([`BACKREST_DEPTH`] of its depth) to its full height, so a seated character's legs rest on the
/// seat instead of passing through a box as tall as the back. Stools, benches and beds stay one box.
pub fn placeholder_boxes(o: &crate::scene::PlacedObject, cat: &Catalogue) -> Vec<PlaceholderBox> {
    let whole = vec![PlaceholderBox { part: "box", z: 0.0, size: o.size }];
    let Some(c) = cat.get(&o.category) else { return whole };
    let seat_y = c
        .contacts
        .iter()
        .filter(|p| p.kind == crate::catalogue::ContactKind::Seat)
        .map(|p| p.local[1])
        .fold(f32::NAN, f32::max);
    let ([w, h, d], base_h) = (o.size, c.size[1]);
    if !(seat_y.is_finite() && base_h > 1e-6 && seat_y < 0.9 * base_h) {
        return whole;
    }
    let seat_h = seat_y / base_h * h;
    let back_d = BACKREST_DEPTH * d;
    vec![
        PlaceholderBox { part: "seat", z: 0.0, size: [w, seat_h, d] },
        PlaceholderBox { part: "back", z: -(d - back_d) / 2.0, size: [w, h, back_d] },
    ]
}

/// `o` reduced to one of its placeholder boxes, placed in the world (same yaw).
pub fn placed_box(o: &crate::scene::PlacedObject, b: &PlaceholderBox) -> crate::scene::PlacedObject {
    let xz = crate::layout::geom::to_world(crate::layout::geom::center(o), o.yaw, [0.0, b.z]);
    crate::scene::PlacedObject { position: [xz[0], o.position[1], xz[1]], size: b.size, ..o.clone() }
}

/// The preview colour of a category: the catalogue's, else a stable colour from its name.
pub fn category_color(cat: &Catalogue, category: &str) -> [u8; 3] {
    if let Some(c) = cat.get(category) {
        return c.color;
    }
    let h = category.bytes().fold(0xcbf2_9ce4_8422_2325u64, |h, b| (h ^ b as u64).wrapping_mul(0x100_0000_01b3));
    let h = inbetween_core::seed::mix(h);
    [(80 + h % 150) as u8, (80 + (h >> 8) % 150) as u8, (80 + (h >> 16) % 150) as u8]
}
