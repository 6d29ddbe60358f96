//! Camera commands ("camera left", "camera front", ...) as shots over the animation, and the
//! camera placed for a frame: relative to the first character and the room, looking at the
//! character's chest, inside the room or on its boundary.

use glam::DVec3;
use inbetween_core::fk::forward;

use super::{Animation, CameraShot};
use crate::motion::rig::Rig;
use crate::ssg::{Command, Ssg};

/// The shots: each camera command holds from the first action written after it (the last command
/// before the first action holds from frame 0); "front" when the script gives none. `marks`:
/// (sentence, first frame) of every character action.
pub fn camera_shots(anim: &Animation, query: &Ssg, marks: &[(usize, usize)]) -> Vec<CameraShot> {
    let total = anim.frames();
    let mut cuts: Vec<(usize, String)> = Vec::new();
    let commands: Vec<(usize, String)> = query
        .commands
        .iter()
        .filter_map(|c| match c {
            Command::Camera { view, sentence } => Some((*sentence, view.to_lowercase())),
            _ => None,
        })
        .collect();
    if commands.is_empty() {
        if let Some(v) = anim.scene.camera.last() {
            cuts.push((0, v.to_lowercase()));
        }
    }
    for (s, view) in commands {
        let start = marks.iter().filter(|(ms, _)| *ms > s).map(|(_, f)| *f).min().unwrap_or(total);
        cuts.push((start, view));
    }
    cuts.sort_by_key(|c| c.0);
    // Several commands before the same action: the last one holds.
    let mut kept: Vec<(usize, String)> = Vec::new();
    for c in cuts {
        match kept.last_mut() {
            Some(last) if last.0 == c.0 => *last = c,
            _ => kept.push(c),
        }
    }
    kept.retain(|c| c.0 < total);
    if kept.is_empty() {
        kept.push((0, "front".into()));
    }
    kept[0].0 = 0;
    (0..kept.len())
        .map(|k| CameraShot { view: kept[k].1.clone(), start: kept[k].0, end: kept.get(k + 1).map(|n| n.0).unwrap_or(total) })
        .collect()
}


/// The view at a frame ("front" when no shot covers it).
pub fn view_at(anim: &Animation, frame: usize) -> &str {
    anim.camera
        .iter()
        .find(|s| frame >= s.start && frame < s.end)
        .or(anim.camera.last())
        .map(|s| s.view.as_str())
        .unwrap_or("front")
}

/// Camera for a frame: (eye, target, vertical field of view in degrees). The target is the first
/// character's chest (the room's centre at chest height without characters); the eye sits 3 m
/// from it towards the named side of the room (front: +z, the door wall; back: −z; left: −x;
/// right: +x), 2.2 m above for "top"-like views, 1.3 m away for "close", at the front wall's top
/// corner side for "wide", clamped into the room.
pub fn camera_pose(anim: &Animation, frame: usize) -> ([f32; 3], [f32; 3], f32) {
    let room = &anim.scene.room;
    let chest = match anim.characters.first() {
        Some(c) if c.motion.num_frames() > 0 => {
            let rig = Rig::of(c.motion.skeleton.clone());
            let f = frame.min(c.motion.num_frames() - 1);
            forward(&rig.skeleton, &c.motion.pose(f)).positions[rig.spine1]
        }
        _ => DVec3::new(room.width as f64 / 2.0, 1.3, room.depth as f64 / 2.0),
    };
    let t = [chest.x as f32, chest.y as f32, chest.z as f32];
    let (w, h, d) = (room.width, room.height, room.depth);
    let eye_h = 1.6f32.min(h - 0.05);
    let (eye, fov) = match view_at(anim, frame) {
        "back" => ([t[0], eye_h, t[2] - 3.0], 50.0),
        "left" => ([t[0] - 3.0, eye_h, t[2]], 50.0),
        "right" => ([t[0] + 3.0, eye_h, t[2]], 50.0),
        // A hair off vertical so a look-at with +Y up stays defined.
        "top" => ([t[0], h - 0.05, t[2] + 0.05], 70.0),
        "close" => ([t[0], 1.5f32.min(h - 0.05), t[2] + 1.3], 40.0),
        "wide" => ([if t[0] < w / 2.0 { w } else { 0.0 }, h - 0.1, d], 75.0),
        _ => ([t[0], eye_h, t[2] + 3.0], 50.0),
    };
    let eye = [eye[0].clamp(0.0, w), eye[1].clamp(0.05, h), eye[2].clamp(0.0, d)];
    (eye, t, fov)
}
