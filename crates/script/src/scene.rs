//! A furnished scene: the room and every placed object, in metres (Y up, floor at y = 0).
//! This is what layout produces, what the outputs write and what part 2 animates in.

use serde::{Deserialize, Serialize};

/// The room: an axis-aligned box from (0, 0, 0) to (width, height, depth).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Room {
    /// Room kind ("office", "bedroom", "gallery"); "room" when the text names none.
    pub name: String,
    /// Extent along x, metres.
    pub width: f32,
    /// Extent along z, metres.
    pub depth: f32,
    /// Ceiling height, metres.
    pub height: f32,
}

/// Where a placed object came from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", tag = "kind")]
pub enum Origin {
    /// Named in the script: sentence index and object node id in that sentence's SSG.
    Script { sentence: usize, node: usize },
    /// Brought in from a matched database scene to complete it (scene name, its node id).
    Database { scene: String, node: usize },
}

/// One object in the scene.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlacedObject {
    /// Unique label in the scene ("desk", "chair 2").
    pub label: String,
    /// Catalogue category.
    pub category: String,
    pub attributes: Vec<String>,
    /// Centre of the footprint, at the object's base: x, y (base height: 0 on the floor, the
    /// supporter's top when on something), z. Metres.
    pub position: [f32; 3],
    /// Rotation about +Y, radians; 0 faces +z (the object's front looks towards +z).
    pub yaw: f32,
    /// Width (x), height (y), depth (z) in the object's own frame, metres, after scaling.
    pub size: [f32; 3],
    /// Index into [`Scene::objects`] of the object this one rests on (relation "on"), if any.
    pub support: Option<usize>,
    pub origin: Origin,
}

impl PlacedObject {
    /// Footprint half extents along world x and z (the yaw turns the box).
    pub fn half_extents_xz(&self) -> [f32; 2] {
        let (s, c) = self.yaw.sin_cos();
        let (hw, hd) = (self.size[0] / 2.0, self.size[2] / 2.0);
        [hw * c.abs() + hd * s.abs(), hw * s.abs() + hd * c.abs()]
    }

    /// Height of the object's top above the floor, metres.
    pub fn top(&self) -> f32 {
        self.position[1] + self.size[1]
    }
}

/// How an object is held up (`mount` in scene.json).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Mount {
    /// Stands on the floor.
    Floor,
    /// Rests on the top of its support object.
    On,
    /// Hangs on a wall.
    Wall,
    /// Hangs from the ceiling.
    Ceiling,
}

/// The furnished scene.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Scene {
    pub room: Room,
    pub objects: Vec<PlacedObject>,
    /// Camera views asked for by commands ("left", "front"), in script order.
    pub camera: Vec<String>,
    /// Weather asked for by commands, last one wins.
    pub weather: Option<String>,
}

impl Scene {
    pub fn find(&self, label: &str) -> Option<&PlacedObject> {
        self.objects.iter().find(|o| o.label == label)
    }
}
