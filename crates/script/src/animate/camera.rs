//! Camera commands ("camera left", "camera front", ...) as shots over the animation, and the
//! camera placed for a frame. With one character: relative to it and the room, looking at its
//! chest. With two or more: a two-shot of the first two placed in the camera engine's Toric
//! space ([`inbetween_core::toric`]: both heads at fixed screen positions), on the side of the
//! pair the command names; "top" and "wide" keep the room-relative placement.

use glam::{DVec2, DVec3, Vec3};
use inbetween_core::camera::{AimedCamera, CameraTrack};
use inbetween_core::fk::forward;
use inbetween_core::toric::{to_pose, Lens, Toric};

use super::{Animation, CameraShot};
use crate::layout::geom;
use crate::motion::rig::Rig;
use crate::scene::PlacedObject;
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
        .map(|k| CameraShot {
            view: kept[k].1.clone(),
            start: kept[k].0,
            end: kept.get(k + 1).map(|n| n.0).unwrap_or(total),
        })
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

/// The framing a camera command asks for at a frame, ignoring furniture (the outputs use
/// [`camera_track`], which also keeps the characters in sight). With two or more
/// characters, a Toric two-shot when one fits in the room (see the module doc). Otherwise the target is the first
/// character's chest (the room's centre at chest height without characters); the eye sits 3 m
/// from it towards the named side of the room (front: +z, the door wall; back: −z; left: −x;
/// right: +x), 2.2 m above for "top"-like views, 1.3 m away for "close", at the front wall's top
/// corner side for "wide", clamped into the room.
pub fn camera_pose(anim: &Animation, frame: usize) -> AimedCamera {
    let head = |c: usize| smoothed_head(&anim.characters[c], frame);
    if let Some(shot) = two_shot(anim, frame, head) {
        return shot;
    }
    room_pose(anim, frame, chest_at(anim, frame))
}

/// The camera of every frame of the animation (at least one), what the outputs show:
/// [`camera_pose`]'s framing (each character's forward kinematics run once per frame instead of
/// once per frame and neighbour), moved where furniture would block the view of whom it frames
/// or where it would stand too near them (see [`keep_in_sight`]).
/// [`ShotCameras::pose`] answers any frame from it (past its end through [`camera_pose`]).
pub fn camera_track(anim: &Animation) -> ShotCameras<'_> {
    let (poses, framed) = camera_poses(anim);
    ShotCameras { anim, track: CameraTrack { fps: anim.fps, first_frame: 0, frames: poses }, framed }
}

/// The shot camera of every frame of an animation, computed once, and whom each frame keeps in
/// sight.
pub struct ShotCameras<'a> {
    anim: &'a Animation,
    /// The camera per frame from frame 0, at the animation's rate.
    pub track: CameraTrack<AimedCamera>,
    /// How many characters (the first ones) each frame's camera keeps in sight: two in a
    /// two-shot, one where furniture stands between the pair (see [`keep_in_sight`]).
    pub framed: Vec<usize>,
}

impl ShotCameras<'_> {
    /// The camera at `frame`: [`camera_pose`]'s value.
    pub fn pose(&self, frame: usize) -> AimedCamera {
        self.track.at(frame).unwrap_or_else(|| camera_pose(self.anim, frame))
    }
}

fn camera_poses(anim: &Animation) -> (Vec<AimedCamera>, Vec<usize>) {
    let bodies: Vec<Option<Vec<[DVec3; 2]>>> = anim.characters.iter().take(2).map(body_points).collect();
    let heads: Vec<Option<Vec<DVec3>>> =
        bodies.iter().map(|b| b.as_ref().map(|b| b.iter().map(|p| p[0]).collect())).collect();
    let chest = chest_positions(anim);
    let framing: Vec<AimedCamera> = (0..anim.frames().max(1))
        .map(|frame| {
            let head = |c: usize| heads[c].as_deref().map(|h| smoothed(h, frame));
            if let Some(shot) = two_shot(anim, frame, head) {
                return shot;
            }
            let chest = match &chest {
                Some(c) if !c.is_empty() => Some(c[frame.min(c.len() - 1)]),
                _ => chest_at(anim, frame),
            };
            room_pose(anim, frame, chest)
        })
        .collect();
    keep_in_sight(anim, &bodies, framing)
}

/// Head and hips of a character at every frame (None off the common rig or without frames).
fn body_points(track: &super::CharacterTrack) -> Option<Vec<[DVec3; 2]>> {
    let n = track.clip.num_frames();
    if n == 0 {
        return None;
    }
    let rig = Rig::try_of(track.clip.skeleton().clone()).ok()?;
    Some(
        (0..n)
            .map(|k| {
                let g = forward(&rig.skeleton, &track.clip.pose(k));
                [g.positions[rig.head], g.positions[rig.hips]]
            })
            .collect(),
    )
}

/// Hips lower than this (metres) are seated or crouched: hidden by a desk or a seat back is
/// fine, so only the head must be seen.
const SEATED_HIPS: f64 = 0.75;
/// A line of sight ends this short of the joint it aims at (the head's radius), metres.
pub(crate) const SIGHT_END_MARGIN: f64 = 0.1;
/// Closest a camera may be to a head or hips it frames, metres: nearer, it looks into the
/// character (a story's first shot put the camera at the door the characters walk in from, 0.4 m
/// from a head).
pub(crate) const NEAREST_EYE: f64 = 1.2;
/// Frames the command's own camera must stay clear before a moved camera goes back to it.
const RETURN_AFTER: usize = 30;

/// How many characters a shot frames at a frame: the first two in a two-shot-able view (two or
/// more characters, not "top" or "wide"), else the first.
pub(crate) fn framed_count(anim: &Animation, frame: usize) -> usize {
    let view = view_at(anim, frame);
    if anim.characters.len() >= 2 && view != "top" && view != "wide" {
        2
    } else {
        1
    }
}

/// The points a shot must see at a frame: the head of each of the first `framed` characters and
/// their hips while standing or walking. `bodies[c]`: [`body_points`] of character `c`.
pub(crate) fn sight_targets(bodies: &[Option<Vec<[DVec3; 2]>>], frame: usize, framed: usize) -> Vec<DVec3> {
    let mut out = Vec::new();
    for b in bodies.iter().take(framed).flatten() {
        let [head, hips] = b[frame.min(b.len() - 1)];
        out.push(head);
        if hips.y >= SEATED_HIPS {
            out.push(hips);
        }
    }
    out
}

/// Whether a camera at `eye` sees every target past the obstacles' boxes (and is not inside one),
/// from at least [`NEAREST_EYE`]; a box holding the target itself does not hide it.
pub(crate) fn sees(obstacles: &[&PlacedObject], eye: DVec3, targets: &[DVec3]) -> bool {
    if obstacles.iter().any(|o| geom::point_in_box(o, eye)) || targets.iter().any(|t| t.distance(eye) < NEAREST_EYE) {
        return false;
    }
    targets.iter().all(|&t| {
        let d = t - eye;
        let len = d.length();
        len <= SIGHT_END_MARGIN || {
            let end = eye + d * ((len - SIGHT_END_MARGIN) / len);
            // The box a joint is in is the seat it sits in (the armchair round the hips).
            !obstacles.iter().any(|o| !geom::point_in_box(o, t) && geom::segment_hits_box(o, eye, end))
        }
    })
}

/// The objects that can block a view: every object but the carried props.
pub(crate) fn obstacles(anim: &Animation) -> Vec<&PlacedObject> {
    (0..anim.scene.objects.len())
        .filter(|&i| super::carried_from(anim, i).is_none())
        .map(|i| &anim.scene.objects[i])
        .collect()
}

/// Other places for a blocked camera, best first: (turn about the target in degrees, distance
/// factor, metres raised). The first is the command's own camera.
const MOVES: [(f64, f64, f64); 28] = [
    (0.0, 1.0, 0.0),
    (0.0, 1.0, 0.5),
    (20.0, 1.0, 0.0),
    (-20.0, 1.0, 0.0),
    (0.0, 0.7, 0.0),
    (20.0, 1.0, 0.5),
    (-20.0, 1.0, 0.5),
    (0.0, 0.7, 0.6),
    (40.0, 1.0, 0.0),
    (-40.0, 1.0, 0.0),
    (40.0, 0.8, 0.6),
    (-40.0, 0.8, 0.6),
    (0.0, 0.5, 0.3),
    (0.0, 1.0, 1.2),
    (60.0, 0.8, 0.3),
    (-60.0, 0.8, 0.3),
    (90.0, 0.7, 0.5),
    (-90.0, 0.7, 0.5),
    (0.0, 0.4, 0.8),
    (180.0, 0.7, 0.5),
    // Over the furniture, looking down.
    (30.0, 0.8, 1.4),
    (-30.0, 0.8, 1.4),
    (90.0, 0.8, 1.3),
    (-90.0, 0.8, 1.3),
    (180.0, 0.8, 1.3),
    (0.0, 0.5, 1.6),
    (135.0, 0.6, 1.5),
    (-135.0, 0.6, 1.5),
];

/// Closest to its target a moved camera is put, metres along the floor (a command's camera
/// pressed against a wall beside the characters would otherwise stay as near after the move).
const MOVED_DISTANCE: f64 = 2.0;

/// The camera `eye` moved by `MOVES[k]` about `target` (at least [`MOVED_DISTANCE`] from it along
/// the floor), kept inside the room.
fn moved(anim: &Animation, k: usize, eye: [f32; 3], target: [f32; 3]) -> [f32; 3] {
    let (turn, scale, raise) = MOVES[k];
    if k == 0 {
        return eye;
    }
    let t = DVec3::new(target[0] as f64, target[1] as f64, target[2] as f64);
    let v = DVec3::new(eye[0] as f64, eye[1] as f64, eye[2] as f64) - t;
    let v = glam::DQuat::from_rotation_y(turn.to_radians()) * v * scale;
    let across = DVec2::new(v.x, v.z);
    let v = if across.length() < MOVED_DISTANCE {
        let a = across.normalize_or(DVec2::Y) * MOVED_DISTANCE;
        DVec3::new(a.x, v.y, a.y)
    } else {
        v
    };
    let e = t + v + DVec3::Y * raise;
    let room = &anim.scene.room;
    let m = 0.05;
    [
        (e.x as f32).clamp(m, room.width - m),
        (e.y as f32).clamp(0.1, room.height - m),
        (e.z as f32).clamp(m, room.depth - m),
    ]
}

/// The command's cameras (`framing`, per frame) moved where furniture would block the view
/// (issue 27) or the camera stands nearer than [`NEAREST_EYE`] to whom it frames: while the camera in use sees its targets it stays; when it is blocked the first
/// of [`MOVES`] that sees them takes over (a cut), and the command's own camera comes back after
/// it has been clear for [`RETURN_AFTER`] frames. Where no move sees both characters of a
/// two-shot (furniture stands between them) the shot keeps the first in sight; where no move
/// sees even that, the command's camera stays. Returns the cameras and how many characters each
/// frame keeps in sight.
fn keep_in_sight(
    anim: &Animation,
    bodies: &[Option<Vec<[DVec3; 2]>>],
    framing: Vec<AimedCamera>,
) -> (Vec<AimedCamera>, Vec<usize>) {
    let obstacles = obstacles(anim);
    let counts: Vec<usize> = (0..framing.len()).map(|f| framed_count(anim, f)).collect();
    if anim.characters.is_empty() {
        return (framing, counts);
    }
    let v3 = |p: [f32; 3]| DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64);
    let (mut current, mut clear_run) = (0usize, 0usize);
    let mut framed = Vec::with_capacity(framing.len());
    let poses = framing
        .into_iter()
        .enumerate()
        .map(|(f, cam)| {
            let (eye, target) = (cam.eye.to_array(), cam.target.to_array());
            let mut n = counts[f];
            let mut targets = sight_targets(bodies, f, n);
            let ok = |k: usize, targets: &[DVec3]| sees(&obstacles, v3(moved(anim, k, eye, target)), targets);
            if n > 1 && !(0..MOVES.len()).any(|k| ok(k, &targets)) {
                n = 1;
                targets = sight_targets(bodies, f, n);
            }
            clear_run = if ok(0, &targets) { clear_run + 1 } else { 0 };
            if current != 0 && clear_run >= RETURN_AFTER {
                current = 0;
            }
            if !ok(current, &targets) {
                current = (0..MOVES.len()).find(|&k| ok(k, &targets)).unwrap_or(0);
            }
            framed.push(n);
            AimedCamera { eye: Vec3::from(moved(anim, current, eye, target)), ..cam }
        })
        .collect();
    (poses, framed)
}

/// Vertical field of view of two-shots (degrees) and the preview's aspect ratio.
const TWO_SHOT_FOV: f64 = 50.0;
const TWO_SHOT_ASPECT: f64 = 1.5;
/// Frames either side averaged for the two-shot targets, so the camera does not bob with the
/// characters' steps.
const TARGET_SMOOTHING: usize = 10;
/// Closest the two heads may be for a two-shot, metres.
const MIN_PAIR_DISTANCE: f64 = 0.3;

/// A character's head at a frame, averaged over ±[`TARGET_SMOOTHING`] frames.
fn smoothed_head(track: &super::CharacterTrack, frame: usize) -> Option<DVec3> {
    let n = track.clip.num_frames();
    if n == 0 {
        return None;
    }
    let rig = Rig::try_of(track.clip.skeleton().clone()).ok()?;
    let f = frame.min(n - 1);
    let range = f.saturating_sub(TARGET_SMOOTHING)..=(f + TARGET_SMOOTHING).min(n - 1);
    let count = range.clone().count() as f64;
    let sum: DVec3 = range.map(|k| forward(&rig.skeleton, &track.clip.pose(k)).positions[rig.head]).sum();
    Some(sum / count)
}

/// [`smoothed_head`] from the heads of every frame (the same sum in the same order).
fn smoothed(heads: &[DVec3], frame: usize) -> DVec3 {
    let f = frame.min(heads.len() - 1);
    let range = f.saturating_sub(TARGET_SMOOTHING)..=(f + TARGET_SMOOTHING).min(heads.len() - 1);
    let count = range.clone().count() as f64;
    let sum: DVec3 = heads[range].iter().copied().sum();
    sum / count
}

/// The first character's chest at a frame (None without characters or frames).
fn chest_at(anim: &Animation, frame: usize) -> Option<DVec3> {
    let c = anim.characters.first().filter(|c| c.clip.num_frames() > 0)?;
    let f = frame.min(c.clip.num_frames() - 1);
    Some(match Rig::try_of(c.clip.skeleton().clone()) {
        Ok(rig) => forward(&rig.skeleton, &c.clip.pose(f)).positions[rig.spine1],
        Err(_) => c.clip.pose(f).translations[0] + DVec3::Y * 0.3,
    })
}

/// [`chest_at`] for every frame of the first character.
fn chest_positions(anim: &Animation) -> Option<Vec<DVec3>> {
    let c = anim.characters.first()?;
    let rig = Rig::try_of(c.clip.skeleton().clone()).ok()?;
    Some((0..c.clip.num_frames()).map(|f| forward(&rig.skeleton, &c.clip.pose(f)).positions[rig.spine1]).collect())
}

/// The Toric framing of a view (A: the first character, B: the second): both heads in the upper
/// third, A left of B, `spread` times the default distance apart on screen, θ on the arc by the view (front/back/left/right: the symmetric two-shot;
/// close: over A's shoulder), the camera lifted 15° above the pair.
fn framing(view: &str, lens: &Lens, spread: f64) -> Toric {
    let (pa, pb) = match view {
        "close" => (DVec2::new(-0.45 * spread, 0.3), DVec2::new(0.3 * spread, 0.3)),
        _ => (DVec2::new(-0.3 * spread, 0.3), DVec2::new(0.3 * spread, 0.3)),
    };
    let toric = Toric { pa, pb, theta: 0.0, phi: 15f64.to_radians() };
    let max = toric.theta_max(lens);
    let theta = if view == "close" { 0.3 * max } else { 0.5 * max };
    Toric { theta, ..toric }
}

/// How far a camera position lies on the named side of the pair (front: +z, back: −z, left: −x,
/// right: +x; close and others: front); a two-shot must be on that side (score > 0).
fn side_score(view: &str, eye: DVec3, mid: DVec3) -> f64 {
    let d = eye - mid;
    match view {
        "back" => -d.z,
        "left" => -d.x,
        "right" => d.x,
        _ => d.z,
    }
}

/// Two-shot of the first two characters through the camera engine, or None (fewer than two
/// characters, a "top"/"wide" view, heads too close, or no framing that puts the camera inside
/// the room on the named side).
/// `head(c)`: character `c`'s smoothed head at this frame.
fn two_shot(anim: &Animation, frame: usize, head: impl Fn(usize) -> Option<DVec3>) -> Option<AimedCamera> {
    let view = view_at(anim, frame);
    if anim.characters.len() < 2 || view == "top" || view == "wide" {
        return None;
    }
    let a = head(0)?;
    let b = head(1)?;
    if a.distance(b) < MIN_PAIR_DISTANCE {
        return None;
    }
    let lens = Lens { fovy: TWO_SHOT_FOV.to_radians(), aspect: TWO_SHOT_ASPECT };
    let room = &anim.scene.room;
    let inside = |p: DVec3| {
        p.x >= 0.0
            && p.x <= room.width as f64
            && p.z >= 0.0
            && p.z <= room.depth as f64
            && p.y > 0.1
            && p.y < room.height as f64
    };
    let mid = (a + b) * 0.5;
    // Tightest framing whose camera fits in the room: heads further apart on screen bring the
    // camera closer. Swapping A and B puts the camera on the other side of the pair.
    let pose = [1.0, 1.6, 2.2].into_iter().find_map(|spread| {
        let toric = framing(view, &lens, spread);
        [(a, b), (b, a)]
            .into_iter()
            .filter_map(|(p, q)| to_pose(&toric, p, q, &lens).ok())
            .filter(|c| inside(c.position) && side_score(view, c.position, mid) > 0.0)
            .max_by(|x, y| side_score(view, x.position, mid).total_cmp(&side_score(view, y.position, mid)))
    })?;
    // The look-at target: the point of the viewing axis level with the pair (roll is dropped).
    let target = pose.position + pose.forward() * (mid - pose.position).dot(pose.forward()).max(0.5);
    let f = |v: DVec3| Vec3::new(v.x as f32, v.y as f32, v.z as f32);
    Some(AimedCamera { eye: f(pose.position), target: f(target), fovy_deg: TWO_SHOT_FOV as f32 })
}

/// The room-relative placement around the first character's `chest` (see [`camera_pose`]).
fn room_pose(anim: &Animation, frame: usize, chest: Option<DVec3>) -> AimedCamera {
    let room = &anim.scene.room;
    let chest = chest.unwrap_or_else(|| DVec3::new(room.width as f64 / 2.0, 1.3, room.depth as f64 / 2.0));
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
    let eye = Vec3::new(eye[0].clamp(0.0, w), eye[1].clamp(0.05, h), eye[2].clamp(0.0, d));
    AimedCamera { eye, target: Vec3::from(t), fovy_deg: fov }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::animate::{CameraShot, CharacterTrack};
    use crate::motion::rig::{yaw, FPS};
    use crate::scene::{Room, Scene};
    use inbetween_core::clip::Clip;

    fn standing_at(rig: &Rig, x: f64, z: f64, heading: f64, frames: usize) -> Clip {
        let mut p = rig.standing();
        p.translations[rig.hips].x += x;
        p.translations[rig.hips].z += z;
        p.rotations[rig.hips] = (yaw(heading) * p.rotations[rig.hips]).normalize();
        Clip::from_poses(rig.skeleton.clone(), 1.0 / FPS, &vec![p; frames]).unwrap()
    }

    fn two_people(view: &str) -> Animation {
        let rig = Rig::standard();
        let room = Room { name: "room".into(), width: 6.0, depth: 5.0, height: 2.8 };
        let track = |name: &str, x: f64| CharacterTrack {
            name: name.into(),
            clip: standing_at(&rig, x, 2.5, 0.0, 40),
            segments: Vec::new(),
            props: Vec::new(),
            slides: Vec::new(),
        };
        Animation {
            fps: FPS,
            scene: Scene { room, objects: Vec::new(), camera: Vec::new(), weather: None },
            characters: vec![track("Eve", 2.0), track("Bob", 3.5)],
            camera: vec![CameraShot { view: view.into(), start: 0, end: 40 }],
            notes: Vec::new(),
        }
    }

    fn head(anim: &Animation, c: usize, f: usize) -> DVec3 {
        let rig = Rig::standard();
        forward(&rig.skeleton, &anim.characters[c].clip.pose(f)).positions[rig.head]
    }

    /// Screen positions of both heads for the returned camera, in the two-shot lens.
    fn screen(anim: &Animation, f: usize) -> (DVec2, DVec2, DVec3) {
        let cam = camera_pose(anim, f);
        let posed = cam.posed(TWO_SHOT_ASPECT);
        (posed.project(head(anim, 0, f)).unwrap(), posed.project(head(anim, 1, f)).unwrap(), cam.eye.as_dvec3())
    }

    #[test]
    fn the_camera_track_equals_the_camera_of_each_frame_bit_for_bit() {
        for view in ["front", "back", "left", "top", "wide", "close"] {
            let mut anim = two_people(view);
            // Moving characters, so the smoothing window matters.
            for (c, track) in anim.characters.iter_mut().enumerate() {
                let rig = Rig::standard();
                let poses: Vec<_> = (0..40)
                    .map(|f| {
                        let mut p = track.clip.pose(f);
                        p.translations[rig.hips].x += 0.02 * f as f64 * (c as f64 - 0.5);
                        p
                    })
                    .collect();
                track.clip = Clip::from_poses(rig.skeleton.clone(), 1.0 / FPS, &poses).unwrap();
            }
            let track = camera_track(&anim);
            assert_eq!(track.track.frames.len(), anim.frames());
            assert_eq!((track.track.fps, track.track.first_frame), (anim.fps, 0));
            for f in 0..anim.frames() + 3 {
                assert_eq!(track.pose(f), camera_pose(&anim, f), "{view}, frame {f}");
            }
            anim.characters.truncate(1);
            let track = camera_track(&anim);
            for f in 0..anim.frames() + 3 {
                assert_eq!(track.pose(f), camera_pose(&anim, f), "{view}, one character, frame {f}");
            }
        }
    }

    #[test]
    fn two_characters_are_framed_together_from_the_named_side() {
        for (view, side) in [("front", DVec3::Z), ("back", DVec3::NEG_Z)] {
            let anim = two_people(view);
            let (a, b, eye) = screen(&anim, 20);
            for p in [a, b] {
                assert!(p.x.abs() < 0.9 && p.y.abs() < 0.9, "{view}: head off screen at {p:?}");
            }
            assert!((a.x - b.x).abs() > 0.3, "{view}: heads overlap on screen ({a:?}, {b:?})");
            let mid = (head(&anim, 0, 20) + head(&anim, 1, 20)) * 0.5;
            assert!((eye - mid).dot(side) > 0.5, "{view}: camera at {eye:?} not on the {side:?} side of {mid:?}");
            let room = &anim.scene.room;
            assert!(eye.x >= 0.0 && eye.x <= room.width as f64 && eye.z >= 0.0 && eye.z <= room.depth as f64);
        }
    }

    #[test]
    fn one_character_or_a_top_view_keeps_the_room_camera() {
        let mut anim = two_people("top");
        assert_eq!(camera_pose(&anim, 5), room_pose(&anim, 5, chest_at(&anim, 5)));
        anim.camera[0].view = "front".into();
        anim.characters.truncate(1);
        assert_eq!(camera_pose(&anim, 5), room_pose(&anim, 5, chest_at(&anim, 5)));
    }
}
