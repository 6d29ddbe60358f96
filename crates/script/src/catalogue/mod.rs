//! The object catalogue: categories with bounding boxes, contact points and synonyms (§3.2, §5.1),
//! and the room kinds. The built-in catalogue is box models only and needs no files; Kenney CC0
//! furniture glTFs, when present, give real meshes and measured sizes (see [`kenney`]).

pub mod builtin;
pub mod kenney;

use std::collections::HashMap;
use std::path::PathBuf;

use serde::{Deserialize, Serialize};

/// How an object is held up.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Support {
    /// Stands on the floor (desk, bed, sofa).
    Floor,
    /// Small: rests on a surface (cup, laptop, lamp) and falls back to the floor only if nothing fits.
    Surface,
    /// Hangs on a wall (painting, blackboard, shelf on the wall).
    Wall,
    /// Hangs from the ceiling (boxing bag, chandelier).
    Ceiling,
}

/// What a contact point is for (NSM's interaction points; part 2 puts joints there).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ContactKind {
    /// Where the hips go when sitting.
    Seat,
    /// A surface to put things on or lean on (table top).
    Top,
    /// Where the hands type or play (keyboard, piano keys).
    Keys,
    /// Something to grasp (handle, microphone, phone).
    Grip,
    /// Where a character stands to use or look at the object (front of a painting).
    Stand,
    /// Where to hit (boxing bag).
    Strike,
}

/// A contact point in the object's own frame (metres, origin at the footprint centre on its base,
/// front towards +z).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ContactPoint {
    pub kind: ContactKind,
    pub local: [f32; 3],
}

/// An object category.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Category {
    /// Canonical name, lower case, one word ("desk", "oilpainting").
    pub name: String,
    /// Other words for it, lower case, including the paper's compounds ("couch", "modernchair").
    pub synonyms: Vec<String>,
    /// Default width (x), height (y), depth (z), metres.
    pub size: [f32; 3],
    pub support: Support,
    /// Whether other objects can stand on its top (table, desk, shelf).
    pub surface: bool,
    pub contacts: Vec<ContactPoint>,
    /// Box colour in previews, sRGB.
    pub color: [u8; 3],
    /// Kenney furniture model stem (`desk` for `desk.glb`) used when the assets are present.
    pub model: Option<String>,
}

/// Whether objects of this category hold things on shelves inside their box (a bookshelf).
pub fn has_shelves(category: &str) -> bool {
    category == "bookshelf"
}

impl Category {
    /// Whether things rest on its shelves, inside its box, as well as on its top.
    pub fn has_shelves(&self) -> bool {
        has_shelves(&self.name)
    }

    /// Whether people sit on it (it has a seat contact): placed "in front of" something, a seat
    /// turns to face it.
    pub fn is_seat(&self) -> bool {
        self.contacts.iter().any(|p| p.kind == ContactKind::Seat)
    }
}

/// A room kind: "office", "bedroom", ... with its default size and the objects it usually holds.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RoomKind {
    pub name: String,
    pub synonyms: Vec<String>,
    /// Width (x), height (y), depth (z), metres.
    pub size: [f32; 3],
}

/// A measured Kenney model for a category (see [`kenney`]). Glue for glTF output: the model's own
/// bounding box (model units, after node transforms) and the uniform scale that maps it to
/// [`Category::size`]. To put the model's footprint centre at the base on the origin, translate
/// by `-(min + max) / 2` in x and z and `-min` in y, then scale.
#[derive(Debug, Clone, PartialEq)]
pub struct ModelInfo {
    pub path: PathBuf,
    pub min: [f32; 3],
    pub max: [f32; 3],
    /// Metres per model unit.
    pub scale: f32,
}

/// All categories and room kinds, with a word index.
#[derive(Debug, Clone, Default)]
pub struct Catalogue {
    categories: Vec<Category>,
    rooms: Vec<RoomKind>,
    /// Lower-case word (name or synonym) → category index.
    words: HashMap<String, usize>,
    /// Lower-case word → room index.
    room_words: HashMap<String, usize>,
    /// Category name → class ("officechair" → "seat"); matching treats classmates as partial matches.
    classes: HashMap<String, String>,
    /// Category name → measured Kenney model.
    models: HashMap<String, ModelInfo>,
}

impl Catalogue {
    pub fn new(categories: Vec<Category>, rooms: Vec<RoomKind>) -> Catalogue {
        let mut words = HashMap::new();
        for (i, c) in categories.iter().enumerate() {
            for w in std::iter::once(&c.name).chain(&c.synonyms) {
                words.entry(w.to_lowercase()).or_insert(i);
            }
        }
        let mut room_words = HashMap::new();
        for (i, r) in rooms.iter().enumerate() {
            for w in std::iter::once(&r.name).chain(&r.synonyms) {
                room_words.entry(w.to_lowercase()).or_insert(i);
            }
        }
        Catalogue { categories, rooms, words, room_words, classes: HashMap::new(), models: HashMap::new() }
    }

    /// Sets the class of categories (`(category, class)` pairs); a category without one is its own class.
    pub fn with_classes<'a>(mut self, pairs: impl IntoIterator<Item = (&'a str, &'a str)>) -> Catalogue {
        for (c, k) in pairs {
            self.classes.insert(c.to_string(), k.to_string());
        }
        self
    }

    /// The class of a category ("desk" → "table"); the name itself when it has none.
    pub fn class_of<'a>(&'a self, category: &'a str) -> &'a str {
        self.classes.get(category).map(String::as_str).unwrap_or(category)
    }

    /// How well two categories match (§4.1: "same category or class"): 1 equal, 0.5 classmates, 0.
    pub fn similarity(&self, a: &str, b: &str) -> f64 {
        if a == b {
            1.0
        } else if self.class_of(a) == self.class_of(b) {
            0.5
        } else {
            0.0
        }
    }

    /// The Kenney model file of a category, when [`kenney::with_models`] found one.
    pub fn model_path(&self, category: &str) -> Option<PathBuf> {
        self.models.get(category).map(|m| m.path.clone())
    }

    /// The measured Kenney model of a category.
    pub fn model(&self, category: &str) -> Option<&ModelInfo> {
        self.models.get(category)
    }

    /// Mutable access for loaders that measure sizes (names must not change: the word index keeps them).
    pub(crate) fn category_mut(&mut self, name: &str) -> Option<&mut Category> {
        self.categories.iter_mut().find(|c| c.name == name)
    }

    pub(crate) fn set_model(&mut self, category: &str, info: ModelInfo) {
        self.models.insert(category.to_string(), info);
    }

    /// Teaches the catalogue another word for a category (semantic matching of words outside
    /// the synonym tables). Returns false when the category does not exist.
    pub fn add_synonym(&mut self, word: &str, category: &str) -> bool {
        let Some(i) = self.categories.iter().position(|c| c.name == category) else { return false };
        self.words.entry(word.to_lowercase()).or_insert(i);
        true
    }

    /// Another word for a room kind.
    pub fn add_room_synonym(&mut self, word: &str, room: &str) -> bool {
        let Some(i) = self.rooms.iter().position(|r| r.name == room) else { return false };
        self.room_words.entry(word.to_lowercase()).or_insert(i);
        true
    }

    /// The category a (singular, lower-case) noun names, through synonyms.
    pub fn resolve(&self, word: &str) -> Option<&Category> {
        self.words.get(&word.to_lowercase()).map(|&i| &self.categories[i])
    }

    /// The room kind a noun names ("office", "meetingroom").
    pub fn resolve_room(&self, word: &str) -> Option<&RoomKind> {
        self.room_words.get(&word.to_lowercase()).map(|&i| &self.rooms[i])
    }

    /// A category by its canonical name.
    pub fn get(&self, name: &str) -> Option<&Category> {
        self.categories.iter().find(|c| c.name == name)
    }

    pub fn categories(&self) -> &[Category] {
        &self.categories
    }

    pub fn rooms(&self) -> &[RoomKind] {
        &self.rooms
    }

    /// Every word the catalogue knows (objects and rooms), for "did you mean" suggestions.
    pub fn known_words(&self) -> impl Iterator<Item = &str> {
        self.words.keys().chain(self.room_words.keys()).map(String::as_str)
    }
}
