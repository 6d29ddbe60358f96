//! The semantic scene graph (SSG, §3.2 and §4.1): object nodes, relation nodes between two objects,
//! character nodes with their action and target, and verbal commands.
//!
//! The same type stores a parsed sentence (the query graph G_q) and a database scene (an element of
//! 𝔾_db). Node ids are indices into `objects`.

use serde::{Deserialize, Serialize};

/// Index of an object node in [`Ssg::objects`].
pub type NodeId = usize;

/// A spatial relation between two objects (the preposition of the sentence).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Relation {
    /// Resting on the anchor's top surface.
    On,
    /// Within a few tens of centimetres of the anchor, on the floor.
    Near,
    /// In front of the anchor (along the anchor's facing direction).
    InFrontOf,
    /// Beside the anchor, left or right, touching or nearly.
    NextTo,
    /// Under the anchor (beneath a table top).
    Under,
    /// Above the anchor (hanging or on the wall over it).
    Above,
    /// Inside the anchor's footprint (a room, a box, a ring).
    In,
    /// Behind the anchor.
    Behind,
    /// Touching the anchor's side, back or front ("a cabinet is against the desk"). This and the
    /// relations below are the text's words from issue 39 on; database scenes are described with
    /// the eight above ([`Relation::ALL`]).
    Against,
    /// Across from the anchor: past its front, turned to face it ("a desk is opposite the bed").
    Opposite,
    /// Turned to face the anchor, wherever it stands ("an armchair faces the TV").
    Facing,
    /// Beside the anchor on its own left (as someone using it sees it: +x of its frame).
    LeftOf,
    /// Beside the anchor on its own right (−x of its frame).
    RightOf,
    /// At one of the anchor's edges, facing it, where a person uses it ("two chairs at the
    /// table"; one seat "at" something keeps [`Relation::InFrontOf`]).
    At,
    /// Several things on both sides of the anchor: composition gives each instance
    /// [`Relation::LeftOf`] or [`Relation::RightOf`] in turn ("two nightstands on either side of the
    /// bed").
    EitherSide,
    /// Several things round the anchor, each [`Relation::At`] one of its edges ("four chairs
    /// around the table").
    Around,
}

impl Relation {
    /// The relations database scenes are described with (derived from their placements).
    pub const ALL: [Relation; 8] = [
        Relation::On,
        Relation::Near,
        Relation::InFrontOf,
        Relation::NextTo,
        Relation::Under,
        Relation::Above,
        Relation::In,
        Relation::Behind,
    ];

    /// The relation's words as written in a script ("in front of").
    pub fn phrase(self) -> &'static str {
        match self {
            Relation::On => "on",
            Relation::Near => "near",
            Relation::InFrontOf => "in front of",
            Relation::NextTo => "next to",
            Relation::Under => "under",
            Relation::Above => "above",
            Relation::In => "in",
            Relation::Behind => "behind",
            Relation::Against => "against",
            Relation::Opposite => "opposite",
            Relation::Facing => "facing",
            Relation::LeftOf => "to the left of",
            Relation::RightOf => "to the right of",
            Relation::At => "at",
            Relation::EitherSide => "on either side of",
            Relation::Around => "around",
        }
    }
}

/// Where in the room an object goes, or between which two objects (issue 39).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", tag = "kind")]
pub enum Place {
    /// "in the middle / centre of the room".
    Middle,
    /// "in a / the corner": against two walls that meet.
    Corner,
    /// "against / along the wall": its back to a wall, facing into the room.
    Wall,
    /// "by / near the door": within a metre of the door (the middle of the z = depth wall).
    Door,
    /// "between X and Y": on the line joining their centres, away from both ends.
    Between { first: NodeId, second: NodeId },
}

impl Place {
    /// The words as written in a script.
    pub fn phrase(self) -> &'static str {
        match self {
            Place::Middle => "in the middle of the room",
            Place::Corner => "in the corner",
            Place::Wall => "against the wall",
            Place::Door => "by the door",
            Place::Between { .. } => "between",
        }
    }
}

/// A place node: `active` stands at `place`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlaceNode {
    pub place: Place,
    pub active: NodeId,
    pub sentence: usize,
}

/// An object node: one category, with the attributes the text gives it ("organized", "office").
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ObjectNode {
    /// Canonical catalogue category ("desk", "bed", "sofa"), after synonyms.
    pub category: String,
    /// Adjectives and noun modifiers ("organized", "office"), lemmatised, lower case.
    pub attributes: Vec<String>,
    /// How many ("two chairs" → 2). At least 1.
    pub count: usize,
    /// The word as written ("couch"), for messages and labels.
    pub word: String,
    /// Index of the sentence it came from (0-based), for incremental edits and messages.
    pub sentence: usize,
}

/// A relation node (u, v): `active` relates to `anchor` (u.anchor = v, v.active ∋ u).
/// "A cup on a table": active = cup, anchor = table, relation = On.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RelationNode {
    pub relation: Relation,
    pub active: NodeId,
    pub anchor: NodeId,
    pub sentence: usize,
}

/// A character node: who does what, to or with which object (§3.2, Fig. 3).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CharacterNode {
    /// As written ("Eve", "Tom", "the man", "Worker").
    pub name: String,
    /// Verb lemmas in order ("walk", "sit", "sing").
    pub actions: Vec<Action>,
    pub sentence: usize,
}

/// One verb of a character sentence with its target and manner.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Action {
    /// Verb lemma ("walk", "sit", "punch").
    pub verb: String,
    /// Preposition linking the verb to its target ("to", "on", "with"), if any.
    pub preposition: Option<String>,
    /// Target object: an index into [`Ssg::objects`] when it is a scene object.
    pub target: Option<NodeId>,
    /// Adverbs ("madly", "unbelievably") and particles ("right" in "turns right").
    pub manner: Vec<String>,
    /// Where the target goes, for verbs that move it ("puts the cup *on the counter*"): the
    /// normalised preposition and the object, when a second object follows the target.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub destination: Option<(String, NodeId)>,
    /// The character the action is done to or with ("sits next to *Ben*", "talks to *him*"), as
    /// named (issue 39).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub person: Option<String>,
}

/// Verbal commands (§3.2): camera placement, weather, time of day.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", tag = "kind")]
pub enum Command {
    /// "camera left", "camera front", "camera top", "camera close", ...
    Camera { view: String, sentence: usize },
    /// "weather rainy", "weather sunny", ...
    Weather { weather: String, sentence: usize },
    /// "time night", ...
    Time { time: String, sentence: usize },
}

/// A semantic scene graph.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Ssg {
    /// The room or place the sentence names ("office", "gallery", "meetingroom"), if any.
    pub room: Option<String>,
    pub objects: Vec<ObjectNode>,
    pub relations: Vec<RelationNode>,
    /// Room places and "between" (issue 39).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub places: Vec<PlaceNode>,
    pub characters: Vec<CharacterNode>,
    pub commands: Vec<Command>,
}

impl Ssg {
    /// u.active: the relation nodes whose anchor is `id` (incoming).
    pub fn actives_of(&self, id: NodeId) -> impl Iterator<Item = &RelationNode> {
        self.relations.iter().filter(move |r| r.anchor == id)
    }

    /// u.anchor: the relation nodes whose active object is `id` (outgoing).
    pub fn anchors_of(&self, id: NodeId) -> impl Iterator<Item = &RelationNode> {
        self.relations.iter().filter(move |r| r.active == id)
    }

    /// Appends `other`, renumbering its node ids; returns the offset its ids moved by.
    pub fn merge(&mut self, other: Ssg) -> usize {
        let offset = self.objects.len();
        if self.room.is_none() {
            self.room = other.room;
        }
        self.objects.extend(other.objects);
        self.relations.extend(other.relations.into_iter().map(|mut r| {
            r.active += offset;
            r.anchor += offset;
            r
        }));
        self.places.extend(other.places.into_iter().map(|mut p| {
            p.active += offset;
            if let Place::Between { first, second } = &mut p.place {
                *first += offset;
                *second += offset;
            }
            p
        }));
        self.characters.extend(other.characters.into_iter().map(|mut c| {
            for a in &mut c.actions {
                if let Some(t) = &mut a.target {
                    *t += offset;
                }
                if let Some((_, d)) = &mut a.destination {
                    *d += offset;
                }
            }
            c
        }));
        self.commands.extend(other.commands);
        offset
    }
}
