//! The keyframes file (schema) and its validation against a scene: frames inside the scene and
//! strictly increasing, known target names, distinct targets, a camera the Toric mapping accepts.
//! Every error names the keys file and the key.

use crate::dataset::{Behaviour, Scene};
use crate::toric::{to_pose, Lens, Toric};
use crate::CameraError;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// One user keyframe.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Keyframe {
    pub frame: usize,
    pub camera: Toric,
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
            to_pose(&key.camera, a, b, lens)
                .map_err(|e| CameraError::invalid(origin, format!("key {k}: camera: {e}")))?;
            out.push(ResolvedKey { frame: key.frame, camera: key.camera, pair, velocity: key.velocity });
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
        keys: frames.iter().map(|&f| Keyframe { frame: f, camera: track[f], targets: None, velocity: None }).collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
}
