//! Two-character scenes: per-frame root and shoulder positions, JSON I/O with clear errors, and a
//! seeded procedural generator like the paper's synthetic scenes (§4.5): walk, turn, approach, part,
//! circle and converse segments with varied speeds and distances.

use crate::features::{CharacterFeatures, CharacterFrame};
use crate::CameraError;
use glam::{DVec2, DVec3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;
use std::path::Path;

/// One character as the camera engine sees it: its root and shoulder points at every frame (the
/// script engine's `CharacterTrack` is a whole animated skeleton; this is what framing needs).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CharacterPoints {
    pub name: String,
    pub root: Vec<DVec3>,
    pub shoulder_l: Vec<DVec3>,
    pub shoulder_r: Vec<DVec3>,
}

impl CharacterPoints {
    pub fn frame(&self, f: usize) -> CharacterFrame {
        CharacterFrame { root: self.root[f], shoulder_l: self.shoulder_l[f], shoulder_r: self.shoulder_r[f] }
    }
}

/// Closest two characters' framing targets may be, in metres (the Toric mapping needs two distinct
/// points; it refuses below 1e-9 m).
pub const TARGETS_APART: f64 = 1e-6;

/// A scene: two or more characters sampled at `fps`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Scene {
    pub fps: f64,
    pub characters: Vec<CharacterPoints>,
}

impl Scene {
    pub fn num_frames(&self) -> usize {
        self.characters.first().map_or(0, |c| c.root.len())
    }

    /// Checks shapes and values; the message names the character, the frame and what was expected.
    pub fn validate(&self) -> Result<(), String> {
        // A network step (1/6 s, `step_frames`) must span at least one frame.
        let min = super::FPS / super::DOWNSAMPLE as f64;
        if !(self.fps.is_finite() && self.fps >= min) {
            return Err(format!(
                "{} fps: expected at least {min} fps (the camera networks step every 1/6 s)",
                self.fps
            ));
        }
        if self.characters.len() < 2 {
            return Err(format!("expected at least 2 characters, got {}", self.characters.len()));
        }
        let n = self.num_frames();
        if n < 2 {
            return Err(format!("expected at least 2 frames, got {n}"));
        }
        for c in &self.characters {
            for (what, v) in [("root", &c.root), ("shoulder_l", &c.shoulder_l), ("shoulder_r", &c.shoulder_r)] {
                if v.len() != n {
                    return Err(format!("character `{}`: {what} has {} frames, expected {n}", c.name, v.len()));
                }
                if let Some(f) = v.iter().position(|p| !p.is_finite()) {
                    return Err(format!("character `{}`: {what} at frame {f} is not finite", c.name));
                }
            }
            if let Some(f) = (0..n).find(|&f| (c.shoulder_r[f] - c.shoulder_l[f]).length() < 1e-6) {
                return Err(format!("character `{}`: shoulders coincide at frame {f}", c.name));
            }
        }
        // Keys name their targets, so a name must pick one character.
        let mut names: Vec<(&str, usize)> =
            self.characters.iter().enumerate().map(|(i, c)| (c.name.as_str(), i)).collect();
        names.sort_unstable();
        if let Some(w) = names.windows(2).find(|w| w[0].0 == w[1].0) {
            return Err(format!(
                "characters {} and {} are both named `{}`; expected distinct names (keys name their targets)",
                w[0].1, w[1].1, w[0].0
            ));
        }
        self.check_targets_apart()
    }

    /// No two characters' framing targets (between the shoulders, above them) at the same place in
    /// any frame: the camera could not frame such a pair. A grid of [`TARGETS_APART`] cells keeps it
    /// O(frames · characters).
    fn check_targets_apart(&self) -> Result<(), String> {
        let mut grid: std::collections::HashMap<[i64; 3], Vec<usize>> = std::collections::HashMap::new();
        let cell = |p: DVec3| (p / TARGETS_APART).floor().as_i64vec3().to_array();
        for f in 0..self.num_frames() {
            grid.clear();
            for (i, c) in self.characters.iter().enumerate() {
                let p = c.frame(f).target();
                let [x, y, z] = cell(p);
                for d in 0..27i64 {
                    let key = [x + d % 3 - 1, y + (d / 3) % 3 - 1, z + d / 9 - 1];
                    for &j in grid.get(&key).into_iter().flatten() {
                        if (self.characters[j].frame(f).target() - p).length() <= TARGETS_APART {
                            return Err(format!(
                                "characters `{}` and `{}` stand at the same position at frame {f} (their framing \
                                 targets are less than {TARGETS_APART} m apart); expected two separate characters",
                                self.characters[j].name, c.name
                            ));
                        }
                    }
                }
                grid.entry(cell(p)).or_default().push(i);
            }
        }
        Ok(())
    }

    /// Index of a character by name or by decimal index.
    pub fn character_index(&self, key: &str) -> Option<usize> {
        self.characters
            .iter()
            .position(|c| c.name == key)
            .or_else(|| key.parse::<usize>().ok().filter(|&i| i < self.characters.len()))
    }

    /// Eq. 1 features of the pair (a, b) at every frame.
    pub fn character_features(&self, a: usize, b: usize, main_is_a: bool) -> Vec<CharacterFeatures> {
        let (ca, cb) = (&self.characters[a], &self.characters[b]);
        (0..self.num_frames()).map(|f| CharacterFeatures::compute(&ca.frame(f), &cb.frame(f), main_is_a)).collect()
    }

    pub fn load(path: &Path) -> Result<Scene, CameraError> {
        let scene: Scene = crate::read_json(path)?;
        scene.validate().map_err(|m| CameraError::invalid(path, m))?;
        Ok(scene)
    }

    pub fn save(&self, path: &Path) -> Result<(), CameraError> {
        crate::write_json(path, self)
    }

    /// A seeded procedural scene of `frames` frames at `fps` with two characters.
    pub fn procedural(seed: u64, frames: usize, fps: f64) -> Scene {
        Choreographer::new(seed, fps).run(frames)
    }
}

/// The kinds of segment a procedural scene strings together.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Action {
    /// Both walk side by side along a gently curving path.
    Walk,
    /// One character turns on the spot to a new heading.
    Turn,
    /// They walk towards each other and stop at talking distance.
    Approach,
    /// They walk apart.
    Part,
    /// They circle about their midpoint, facing each other.
    Circle,
    /// They stand face to face with small sways.
    Converse,
}

pub const ACTIONS: [Action; 6] =
    [Action::Walk, Action::Turn, Action::Approach, Action::Part, Action::Circle, Action::Converse];

/// Kinematic state of one procedural character (ground position, heading, velocity).
#[derive(Debug, Clone, Copy)]
struct Body {
    pos: DVec2,
    vel: DVec2,
    yaw: f64,
    phase: f64,
}

/// Drives two [`Body`]s through random actions with smooth (critically damped) transitions.
struct Choreographer {
    rng: ChaCha8Rng,
    dt: f64,
    fps: f64,
    bodies: [Body; 2],
}

fn yaw_of(dir: DVec2) -> f64 {
    // front = (sin yaw, cos yaw) in (x, z).
    dir.x.atan2(dir.y)
}

fn dir_of(yaw: f64) -> DVec2 {
    DVec2::new(yaw.sin(), yaw.cos())
}

fn turn_towards(yaw: f64, target: f64, max_step: f64) -> f64 {
    let diff = crate::features::wrap_angle(target - yaw);
    yaw + diff.clamp(-max_step, max_step)
}

impl Choreographer {
    fn new(seed: u64, fps: f64) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let d0 = rng.random_range(1.2..4.0);
        let yaw0 = rng.random_range(-PI..PI);
        let across = dir_of(yaw0 + PI / 2.0) * (d0 * 0.5);
        let body = |pos: DVec2, yaw: f64| Body { pos, vel: DVec2::ZERO, yaw, phase: 0.0 };
        let bodies = [body(-across, yaw0 + PI / 2.0), body(across, yaw0 - PI / 2.0)];
        Choreographer { rng, dt: 1.0 / fps, fps, bodies }
    }

    fn run(mut self, frames: usize) -> Scene {
        let mut tracks: Vec<CharacterPoints> = ["A", "B"]
            .iter()
            .map(|n| CharacterPoints { name: n.to_string(), root: vec![], shoulder_l: vec![], shoulder_r: vec![] })
            .collect();
        let mut f = 0;
        while f < frames {
            let action = ACTIONS[self.rng.random_range(0..ACTIONS.len())];
            let len = ((self.rng.random_range(3.0..9.0) * self.fps) as usize).min(frames - f);
            let speed = self.rng.random_range(0.6..1.7);
            let curve = self.rng.random_range(-0.25..0.25);
            let who = self.rng.random_range(0..2usize);
            let turn_to = self.rng.random_range(-PI..PI);
            let spin = self.rng.random_range(0.2..0.6) * if self.rng.random_bool(0.5) { 1.0 } else { -1.0 };
            let talk = self.rng.random_range(1.0..2.2);
            for _ in 0..len {
                self.step(action, speed, curve, who, turn_to, spin, talk);
                for (track, body) in tracks.iter_mut().zip(&self.bodies) {
                    let fr = pose_of(body);
                    track.root.push(fr.root);
                    track.shoulder_l.push(fr.shoulder_l);
                    track.shoulder_r.push(fr.shoulder_r);
                }
            }
            f += len;
        }
        Scene { fps: self.fps, characters: tracks }
    }

    /// Advances one frame: each body gets a desired velocity and heading from the action, then
    /// moves towards them with bounded acceleration and turn rate.
    #[allow(clippy::too_many_arguments)]
    fn step(&mut self, action: Action, speed: f64, curve: f64, who: usize, turn_to: f64, spin: f64, talk: f64) {
        let [b0, b1] = self.bodies;
        let sep = b1.pos - b0.pos;
        let d = sep.length().max(1e-6);
        let n01 = sep / d;
        let mut want = [(DVec2::ZERO, b0.yaw), (DVec2::ZERO, b1.yaw)];
        match action {
            Action::Walk => {
                // Head where both roughly face (or across their line when they face apart).
                let avg = dir_of(b0.yaw) + dir_of(b1.yaw);
                let base = if avg.length() > 1e-3 { yaw_of(avg) } else { yaw_of(n01.perp()) };
                let h = base + curve * self.dt * 10.0;
                let v = dir_of(h) * speed;
                // Keep a side-by-side spacing of about 1 m while walking.
                let spread = n01 * ((d - 1.0).clamp(-1.0, 1.0) * 0.5);
                want = [(v + spread, h), (v - spread, h)];
            }
            Action::Turn => {
                want[who].1 = turn_to;
            }
            Action::Approach => {
                let v = if d > talk { speed * 0.5 } else { 0.0 };
                want = [(n01 * v, yaw_of(n01)), (-n01 * v, yaw_of(-n01))];
            }
            Action::Part => {
                let v = if d < 8.0 { speed * 0.5 } else { 0.0 };
                want = [(-n01 * v, yaw_of(-n01)), (n01 * v, yaw_of(n01))];
            }
            Action::Circle => {
                let tangent = n01.perp() * spin * d * 0.5;
                want = [(-tangent, yaw_of(n01)), (tangent, yaw_of(-n01))];
            }
            Action::Converse => {
                let sway = (b0.phase * 0.35).sin() * 0.25;
                want = [(DVec2::ZERO, yaw_of(n01) + sway), (DVec2::ZERO, yaw_of(-n01) - sway * 0.7)];
            }
        }
        // Never walk through each other nor drift further than 9 m apart.
        let correction = if d < 0.8 {
            n01 * (0.8 - d) * 2.0
        } else if d > 9.0 {
            -n01 * (d - 9.0)
        } else {
            DVec2::ZERO
        };
        let dt = self.dt;
        for (i, body) in self.bodies.iter_mut().enumerate() {
            let (v, yaw) = want[i];
            let v = v + if i == 0 { -correction } else { correction };
            body.vel += (v - body.vel) * (1.0 - (-dt * 3.0).exp());
            body.pos += body.vel * dt;
            body.yaw = turn_towards(body.yaw, yaw, 2.5 * dt);
            body.phase += dt * (2.0 + 6.0 * body.vel.length());
        }
    }
}

/// Root and shoulders of a body: walking bob and a small shoulder counter-rotation.
fn pose_of(b: &Body) -> CharacterFrame {
    let speed = b.vel.length().min(2.0);
    let bob = 0.02 * speed * (2.0 * b.phase).sin();
    let twist = 0.08 * speed * b.phase.sin();
    let root = DVec3::new(b.pos.x, 0.95 + bob, b.pos.y);
    let front = DVec3::new((b.yaw + twist).sin(), 0.0, (b.yaw + twist).cos());
    let right = front.cross(DVec3::Y);
    let chest = root + DVec3::Y * 0.47;
    CharacterFrame { root, shoulder_l: chest - right * 0.2, shoulder_r: chest + right * 0.2 }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn procedural_scene_is_seeded_valid_and_sane() {
        let s = Scene::procedural(7, 600, 30.0);
        assert_eq!(s.num_frames(), 600);
        s.validate().unwrap();
        assert_eq!(s, Scene::procedural(7, 600, 30.0), "same seed, same scene");
        assert_ne!(s, Scene::procedural(8, 600, 30.0));
        let feats = s.character_features(0, 1, true);
        for (f, x) in feats.iter().enumerate() {
            assert!(x.d_ab > 0.5 && x.d_ab < 12.0, "frame {f}: d_AB {}", x.d_ab);
        }
        // Characters move at plausible speeds (< 3 m/s between frames).
        let root = &s.characters[0].root;
        for f in 1..root.len() {
            assert!((root[f] - root[f - 1]).length() * 30.0 < 3.0, "frame {f} too fast");
        }
    }

    #[test]
    fn coinciding_and_same_named_characters_are_refused() {
        let mut s = Scene::procedural(1, 40, 30.0);
        s.characters.push(CharacterPoints { name: "C".into(), ..s.characters[0].clone() });
        let e = s.validate().unwrap_err();
        assert!(
            e.contains(&format!("characters `{}` and `C` stand at the same position at frame 0", s.characters[0].name)),
            "{e}"
        );
        // One frame in the middle is enough; a nudge of a millimetre is two characters.
        let mut s = Scene::procedural(1, 40, 30.0);
        let mut c = s.characters[1].clone();
        c.name = "C".into();
        for f in 0..40 {
            let off = if f == 17 { DVec3::ZERO } else { DVec3::X * 0.5 };
            c.root[f] = s.characters[0].root[f] + off;
            c.shoulder_l[f] = s.characters[0].shoulder_l[f] + off;
            c.shoulder_r[f] = s.characters[0].shoulder_r[f] + off;
        }
        s.characters.push(c.clone());
        assert!(s.validate().unwrap_err().contains("at frame 17"));
        s.characters[2].root[17].x += 1e-3;
        s.characters[2].shoulder_l[17].x += 1e-3;
        s.characters[2].shoulder_r[17].x += 1e-3;
        assert_eq!(s.validate(), Ok(()));
        let mut s = Scene::procedural(1, 40, 30.0);
        s.characters[1].name = s.characters[0].name.clone();
        let e = s.validate().unwrap_err();
        assert!(e.starts_with("characters 0 and 1 are both named"), "{e}");
    }

    #[test]
    fn json_round_trip_and_errors_name_the_problem() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("scene.json");
        let s = Scene::procedural(1, 40, 30.0);
        s.save(&path).unwrap();
        let back = Scene::load(&path).unwrap();
        let max_diff = back
            .characters
            .iter()
            .zip(&s.characters)
            .flat_map(|(x, y)| x.root.iter().zip(&y.root).map(|(p, q)| (*p - *q).abs().max_element()))
            .fold(0.0, f64::max);
        assert!(max_diff < 1e-12, "JSON keeps positions (max diff {max_diff})");

        let mut bad = s.clone();
        bad.characters[1].shoulder_r.pop();
        bad.save(&path).unwrap();
        let e = Scene::load(&path).unwrap_err().to_string();
        assert!(e.contains("scene.json") && e.contains("`B`") && e.contains("shoulder_r"), "{e}");

        std::fs::write(&path, "{\"fps\": 30,\n \"characters\": [oops]}").unwrap();
        let e = Scene::load(&path).unwrap_err().to_string();
        assert!(e.contains("scene.json:2"), "parse errors give the line: {e}");
    }
}
