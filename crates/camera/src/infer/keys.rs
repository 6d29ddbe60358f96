//! The keyframes file (schema) and its validation against a scene: frames inside the scene and
//! strictly increasing, known target names, distinct targets, a camera the Toric mapping accepts.
//! A key's camera is Toric coordinates x^c (Eq. 2), or a world pose that is turned into them at
//! the key's frame against its two targets (the paper's interface sets "the camera pose" of a
//! keyframe, §6.1 and Fig. 9). Every error names the keys file and the key.

use crate::dataset::{Behaviour, Scene};
use crate::toric::{from_pose, to_pose, CameraPose, Lens, Toric};
use crate::CameraError;
use glam::{DQuat, DVec2, DVec3};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Largest difference between a pose key's field of view and the job's lens, radians: one lens
/// frames the whole track, so a pose seen through another lens would not be the pose asked for.
pub const FOV_TOLERANCE_RAD: f64 = 1e-6;

/// A key's camera, as the keys file gives it: `{"pa": [x, y], "pb": [x, y], "theta": θ, "phi": φ}`
/// (Toric coordinates, Eq. 2) or `{"position": [x, y, z], "rotation": [x, y, z, w], "fov_deg": f}`
/// (a world pose in metres, +Y up, looking down its local −Z; `fov_deg` optional, the vertical
/// field of view, which must then be the job's lens's).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(untagged, try_from = "CameraFields")]
pub enum KeyCamera {
    Toric(Toric),
    Pose(KeyPose),
}

/// A camera pose given for a key (converted with [`from_pose`] at the key's frame).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct KeyPose {
    /// World position, metres.
    pub position: DVec3,
    /// Camera → world rotation, (x, y, z, w).
    pub rotation: DQuat,
    /// Vertical field of view, degrees (`None`: the job's lens).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fov_deg: Option<f64>,
}

impl From<Toric> for KeyCamera {
    fn from(t: Toric) -> KeyCamera {
        KeyCamera::Toric(t)
    }
}

impl From<KeyPose> for KeyCamera {
    fn from(p: KeyPose) -> KeyCamera {
        KeyCamera::Pose(p)
    }
}

impl KeyCamera {
    /// The Toric coordinates when the key gives them (a pose is converted by [`Keys::resolve`]).
    pub fn toric(&self) -> Option<Toric> {
        match self {
            KeyCamera::Toric(t) => Some(*t),
            KeyCamera::Pose(_) => None,
        }
    }
}

impl KeyPose {
    /// Toric coordinates of this pose for targets `a` and `b` through `lens`; the error says what
    /// is wrong with the pose in words.
    pub fn to_toric(&self, a: DVec3, b: DVec3, lens: &Lens) -> Result<Toric, String> {
        if !self.position.is_finite() {
            return Err(format!("position {} is not finite", self.position));
        }
        let q = self.rotation;
        let len = q.length();
        if !(q.is_finite() && (len - 1.0).abs() < 1e-3) {
            return Err(format!(
                "rotation [{}, {}, {}, {}] is not a unit quaternion (x, y, z, w; length {len:.4})",
                q.x, q.y, q.z, q.w
            ));
        }
        if let Some(fov) = self.fov_deg {
            if !(fov.is_finite() && (fov.to_radians() - lens.fovy).abs() <= FOV_TOLERANCE_RAD) {
                return Err(format!(
                    "vertical field of view {fov}° differs from the lens's {:.4}°: one lens frames the whole \
                     track (give the job a lens of {fov}°)",
                    lens.fovy.to_degrees()
                ));
            }
        }
        let pose = CameraPose { position: self.position, rotation: q.normalize() };
        let toric = from_pose(&pose, a, b, lens).map_err(|e| e.to_string())?;
        to_pose(&toric, a, b, lens).map_err(|e| e.to_string())?;
        Ok(toric)
    }
}

/// Every field a key's camera may have; [`KeyCamera`] is one of its two complete sets.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CameraFields {
    pa: Option<DVec2>,
    pb: Option<DVec2>,
    theta: Option<f64>,
    phi: Option<f64>,
    position: Option<DVec3>,
    rotation: Option<DQuat>,
    fov_deg: Option<f64>,
}

impl TryFrom<CameraFields> for KeyCamera {
    type Error = String;

    fn try_from(c: CameraFields) -> Result<KeyCamera, String> {
        let toric = [c.pa.is_some(), c.pb.is_some(), c.theta.is_some(), c.phi.is_some()];
        let pose = c.position.is_some() || c.rotation.is_some() || c.fov_deg.is_some();
        if pose && toric.iter().any(|&t| t) {
            return Err("a key's camera is either Toric coordinates (pa, pb, theta, phi) or a pose (position, \
                        rotation, fov_deg), not both"
                .into());
        }
        if pose {
            return match (c.position, c.rotation) {
                (Some(position), Some(rotation)) => {
                    Ok(KeyCamera::Pose(KeyPose { position, rotation, fov_deg: c.fov_deg }))
                }
                _ => Err("a camera pose needs `position` ([x, y, z], metres) and `rotation` ([x, y, z, w])".into()),
            };
        }
        match (c.pa, c.pb, c.theta, c.phi) {
            (Some(pa), Some(pb), Some(theta), Some(phi)) => Ok(KeyCamera::Toric(Toric { pa, pb, theta, phi })),
            _ => {
                let missing: Vec<&str> =
                    ["pa", "pb", "theta", "phi"].iter().zip(toric).filter(|(_, has)| !has).map(|(n, _)| *n).collect();
                Err(format!(
                    "a key's camera needs Toric coordinates (missing {}) or a pose (position, rotation, fov_deg)",
                    missing.join(", ")
                ))
            }
        }
    }
}

/// One user keyframe.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Keyframe {
    pub frame: usize,
    pub camera: KeyCamera,
    /// The two characters framed from the previous key up to this one (names or indices; default
    /// the first two). Changing them between keys is a character transition.
    #[serde(default)]
    pub targets: Option<[String; 2]>,
    /// Desired camera velocity at this key (x^c units per second): resets the generator's state
    /// through H (§4.3) so the camera leaves the key with this speed and direction.
    #[serde(default)]
    pub velocity: Option<[f64; 6]>,
}

/// The keyframes file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Keys {
    /// The main character (name or index; default the first target).
    #[serde(default)]
    pub main: Option<String>,
    pub keys: Vec<Keyframe>,
}

/// A key checked against a scene, targets resolved to character indices.
#[derive(Debug, Clone, PartialEq)]
pub struct ResolvedKey {
    pub frame: usize,
    pub camera: Toric,
    pub pair: (usize, usize),
    pub velocity: Option<[f64; 6]>,
}

/// Keys checked against a scene.
#[derive(Debug, Clone, PartialEq)]
pub struct ResolvedKeys {
    /// At least one, at strictly increasing frames inside the scene.
    pub keys: Vec<ResolvedKey>,
    /// The main character's index (`None`: the first target of each pair).
    pub main: Option<usize>,
}

impl ResolvedKeys {
    pub fn first_frame(&self) -> usize {
        self.keys[0].frame
    }

    /// The last generated frame: the last key, or the scene's end with a single key.
    pub fn last_frame(&self, scene: &Scene) -> usize {
        if self.keys.len() == 1 {
            scene.num_frames() - 1
        } else {
            self.keys[self.keys.len() - 1].frame
        }
    }

    /// Whether character `pair.0` is the main one (x^v's M, Eq. 1).
    pub fn main_is_a(&self, pair: (usize, usize)) -> bool {
        self.main.is_none_or(|m| m == pair.0)
    }
}

impl Keys {
    pub fn load(path: &Path) -> Result<Keys, CameraError> {
        crate::read_json(path)
    }

    /// Checks the keys against a scene and resolves target names; errors name `origin` and the key.
    pub fn resolve(&self, scene: &Scene, lens: &Lens, origin: &Path) -> Result<ResolvedKeys, CameraError> {
        if self.keys.is_empty() {
            return Err(CameraError::invalid(origin, "expected at least one keyframe"));
        }
        let n = scene.num_frames();
        let find = |k: usize, name: &str| {
            scene.character_index(name).ok_or_else(|| {
                let names: Vec<&str> = scene.characters.iter().map(|c| c.name.as_str()).collect();
                CameraError::invalid(
                    origin,
                    format!("key {k}: unknown target `{name}` (characters: {})", names.join(", ")),
                )
            })
        };
        let mut out: Vec<ResolvedKey> = Vec::new();
        for (k, key) in self.keys.iter().enumerate() {
            if key.frame >= n {
                return Err(CameraError::invalid(
                    origin,
                    format!("key {k}: frame {} is past the scene's last frame {}", key.frame, n.saturating_sub(1)),
                ));
            }
            if let Some(prev) = out.last() {
                if key.frame <= prev.frame {
                    return Err(CameraError::invalid(
                        origin,
                        format!("key {k}: frame {} does not come after frame {}", key.frame, prev.frame),
                    ));
                }
            }
            if let Some(v) = key.velocity.filter(|v| v.iter().any(|x| !x.is_finite())) {
                return Err(CameraError::invalid(origin, format!("key {k}: velocity {v:?} is not finite")));
            }
            let pair = match &key.targets {
                Some([a, b]) => (find(k, a)?, find(k, b)?),
                None => (0, 1),
            };
            if pair.0 == pair.1 {
                return Err(CameraError::invalid(origin, format!("key {k}: both targets are the same character")));
            }
            let (a, b) = (
                scene.characters[pair.0].frame(key.frame).target(),
                scene.characters[pair.1].frame(key.frame).target(),
            );
            let camera = match &key.camera {
                KeyCamera::Toric(t) => {
                    to_pose(t, a, b, lens)
                        .map_err(|e| CameraError::invalid(origin, format!("key {k}: camera: {e}")))?;
                    *t
                }
                KeyCamera::Pose(p) => p.to_toric(a, b, lens).map_err(|e| {
                    let (na, nb) = (&scene.characters[pair.0].name, &scene.characters[pair.1].name);
                    CameraError::invalid(
                        origin,
                        format!(
                            "key {k} (frame {}): the camera pose cannot frame A = `{na}` and B = `{nb}` there: {e}",
                            key.frame
                        ),
                    )
                })?,
            };
            out.push(ResolvedKey { frame: key.frame, camera, pair, velocity: key.velocity });
        }
        let main = match &self.main {
            Some(m) => Some(
                scene
                    .character_index(m)
                    .ok_or_else(|| CameraError::invalid(origin, format!("main: unknown character `{m}`")))?,
            ),
            None => None,
        };
        Ok(ResolvedKeys { keys: out, main })
    }
}

/// Keyframes taken from a relative-track filming of `scene` at `frames` (a plausible start to edit).
pub fn example_keys(scene: &Scene, frames: &[usize]) -> Keys {
    use rand::SeedableRng;
    let lens = Lens::default();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
    let params = crate::dataset::BehaviourParams::sample(&mut rng);
    let track = crate::dataset::film(scene, 0, 1, true, Behaviour::Relative, &params, &lens);
    Keys {
        main: Some(scene.characters[0].name.clone()),
        keys: frames
            .iter()
            .map(|&f| Keyframe { frame: f, camera: track[f].into(), targets: None, velocity: None })
            .collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::toric::CameraPose;

    #[test]
    fn bad_keys_name_the_file_and_the_key() {
        let scene = Scene::procedural(2, 100, 30.0);
        let lens = Lens::default();
        let check = |keys: &Keys, want: &[&str]| {
            let e = keys.resolve(&scene, &lens, Path::new("keys.json")).unwrap_err().to_string();
            assert!(want.iter().all(|w| e.contains(w)) && e.contains("keys.json"), "{e}");
        };
        let mut keys = example_keys(&scene, &[0, 50]);
        keys.keys[1].frame = 150;
        check(&keys, &["key 1", "frame 150"]);
        let mut keys = example_keys(&scene, &[0, 50]);
        keys.keys[0].targets = Some(["A".into(), "Zed".into()]);
        check(&keys, &["key 0", "Zed"]);
        let mut keys = example_keys(&scene, &[0, 50]);
        keys.keys[1].frame = 0;
        check(&keys, &["key 1", "does not come after"]);
        let mut keys = example_keys(&scene, &[0, 50]);
        keys.keys[1].velocity = Some([0.0, f64::NAN, 0.0, 0.0, 0.0, 0.0]);
        check(&keys, &["key 1", "velocity"]);
        check(&Keys { main: None, keys: vec![] }, &["at least one keyframe"]);
        let mut keys = example_keys(&scene, &[0, 50]);
        keys.main = Some("Nobody".into());
        check(&keys, &["main", "Nobody"]);
        let ok = example_keys(&scene, &[0, 50]).resolve(&scene, &lens, Path::new("k")).unwrap();
        assert_eq!((ok.first_frame(), ok.last_frame(&scene), ok.main), (0, 50, Some(0)));
    }

    fn targets(scene: &Scene, f: usize) -> (DVec3, DVec3) {
        (scene.characters[0].frame(f).target(), scene.characters[1].frame(f).target())
    }

    /// Poses built from known Toric coordinates at each key's frame read back as them (through the
    /// keys file's JSON, as front ends hand them over).
    #[test]
    fn pose_keys_resolve_to_the_toric_they_were_built_from() {
        let scene = Scene::procedural(2, 100, 30.0);
        let lens = Lens::default();
        let toric_keys = example_keys(&scene, &[0, 50, 99]);
        let mut keys = toric_keys.clone();
        for key in &mut keys.keys {
            let (a, b) = targets(&scene, key.frame);
            let pose = to_pose(&key.camera.toric().unwrap(), a, b, &lens).unwrap();
            key.camera = KeyPose { position: pose.position, rotation: pose.rotation, fov_deg: Some(45.0) }.into();
        }
        let json = serde_json::to_string(&keys).unwrap();
        assert!(json.contains("\"position\"") && json.contains("\"fov_deg\":45.0"), "{json}");
        let back: Keys = serde_json::from_str(&json).unwrap();
        assert_eq!(back, keys);
        let resolved = back.resolve(&scene, &lens, Path::new("k")).unwrap();
        for (r, k) in resolved.keys.iter().zip(&toric_keys.keys) {
            let (got, want) = (r.camera.to_array(), k.camera.toric().unwrap().to_array());
            assert!((0..6).all(|i| (got[i] - want[i]).abs() < 1e-9), "frame {}: {got:?} vs {want:?}", r.frame);
        }
        // Toric keys keep their JSON form.
        let t = serde_json::to_value(&toric_keys.keys[0]).unwrap();
        assert!(t["camera"]["pa"].is_array() && t["camera"]["theta"].is_number(), "{t}");
    }

    #[test]
    fn a_pose_that_cannot_be_expressed_is_refused_naming_the_key_and_its_frame() {
        let scene = Scene::procedural(2, 100, 30.0);
        let lens = Lens::default();
        let (a, b) = targets(&scene, 50);
        let side = (b - a).cross(DVec3::Y).normalize();
        let mid = (a + b) * 0.5;
        let resolve = |camera: KeyCamera| {
            let mut keys = example_keys(&scene, &[0, 50]);
            keys.keys[1].camera = camera;
            keys.resolve(&scene, &lens, Path::new("keys.json")).unwrap_err().to_string()
        };
        // Looking away from both targets.
        let away = CameraPose::look_at(mid + side * 4.0, mid + side * 8.0);
        let e = resolve(KeyPose { position: away.position, rotation: away.rotation, fov_deg: None }.into());
        assert!(
            e.contains("keys.json") && e.contains("key 1 (frame 50)") && e.contains("target A is behind the camera"),
            "{e}"
        );
        let good = CameraPose::look_at(mid + side * 4.0 + DVec3::Y, mid);
        let e = resolve(KeyPose { position: good.position, rotation: good.rotation, fov_deg: Some(30.0) }.into());
        assert!(e.contains("frame 50") && e.contains("field of view 30°") && e.contains("45.0000°"), "{e}");
        let e = resolve(KeyPose { position: good.position, rotation: good.rotation * 2.0, fov_deg: None }.into());
        assert!(e.contains("frame 50") && e.contains("not a unit quaternion"), "{e}");
        let ok = KeyPose { position: good.position, rotation: good.rotation, fov_deg: Some(45.0) };
        let mut keys = example_keys(&scene, &[0, 50]);
        keys.keys[1].camera = ok.into();
        assert!(keys.resolve(&scene, &lens, Path::new("k")).is_ok());
        // The file's form: one of the two sets of fields, said in words.
        let parse = |camera: &str| {
            serde_json::from_str::<Keys>(&format!(r#"{{"keys": [{{"frame": 0, "camera": {camera}}}]}}"#))
                .unwrap_err()
                .to_string()
        };
        let e = parse(r#"{"pa": [0, 0], "position": [0, 0, 0], "rotation": [0, 0, 0, 1]}"#);
        assert!(e.contains("not both"), "{e}");
        assert!(parse(r#"{"position": [0, 1, 5]}"#).contains("needs `position`"));
        assert!(parse(r#"{"pa": [0, 0], "pb": [0.2, 0]}"#).contains("missing theta, phi"));
        assert!(parse(r#"{"pa": [0, 0], "pb": [0.2, 0], "theta": 1, "phi": 0, "roll": 0}"#).contains("roll"));
    }
}
