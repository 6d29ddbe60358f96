//! Rules from tags to the SSG (§3.2, §4.1; Fig. 3 shows the dependencies CoreNLP would give, and
//! these patterns recover the same facts: objects with attributes and counts, relation nodes, and
//! characters with verbs, prepositions and targets).

use super::lexicon::{contains, number_value, GLUE_ADVERBS, PART_NOUNS, PERSON_NOUNS, PLURALIA_TANTUM};
use super::suggest::{closest, noun_suggestions, verb_suggestions};
use super::tag::{known_noun, tag, Tag, Tagged};
use super::token::tokenize;
use crate::catalogue::Catalogue;
use crate::error::{Diagnostic, SentenceRef};
use crate::sentences::{command_parts, RawSentence, SentenceKind, CAMERA_VIEWS, TIMES, WEATHERS};
use crate::ssg::{Action, CharacterNode, Command, NodeId, ObjectNode, Place, PlaceNode, Relation, RelationNode, Ssg};

/// What carries over from one sentence to the next: who "he"/"she" is, what "it" is.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ParseState {
    /// The last character named ("Tom sits. He sings." → Tom).
    pub last_character: Option<String>,
    /// Characters named so far, the most recent last ("him", "her": the latest other than the
    /// subject).
    pub recent: Vec<String>,
    /// The last plural subject ("Anna and Ben walk in. They sit." → Anna, Ben).
    pub last_group: Vec<String>,
    /// The last object a scene sentence named ("A table is in the middle$ Chairs are around it").
    pub last_object: Option<ObjectNode>,
    /// The last action target ("walks to the oilpainting ... is looking at it").
    pub last_target: Option<ObjectNode>,
}

/// Relation phrases, longest first. `None` marks a known preposition that is no spatial relation
/// the SSG has ("with", "between"): used between two objects it gets a diagnostic.
const RELATION_PHRASES: &[(&[&str], Relation)] = &[
    (&["in", "the", "front", "of"], Relation::InFrontOf),
    (&["at", "the", "front", "of"], Relation::InFrontOf),
    (&["at", "the", "back", "of"], Relation::Behind),
    (&["in", "the", "back", "of"], Relation::Behind),
    (&["on", "the", "left", "side", "of"], Relation::LeftOf),
    (&["on", "the", "right", "side", "of"], Relation::RightOf),
    (&["to", "the", "left", "of"], Relation::LeftOf),
    (&["to", "the", "right", "of"], Relation::RightOf),
    (&["on", "either", "side", "of"], Relation::EitherSide),
    (&["on", "both", "sides", "of"], Relation::EitherSide),
    (&["on", "each", "side", "of"], Relation::EitherSide),
    (&["at", "either", "side", "of"], Relation::EitherSide),
    (&["either", "side", "of"], Relation::EitherSide),
    (&["on", "top", "of"], Relation::On),
    (&["in", "front", "of"], Relation::InFrontOf),
    (&["on", "the", "left", "of"], Relation::LeftOf),
    (&["on", "the", "right", "of"], Relation::RightOf),
    (&["across", "from"], Relation::Opposite),
    (&["opposite", "to"], Relation::Opposite),
    (&["opposite", "of"], Relation::Opposite),
    (&["next", "to"], Relation::NextTo),
    (&["close", "to"], Relation::Near),
    (&["near", "to"], Relation::Near),
    (&["left", "of"], Relation::LeftOf),
    (&["right", "of"], Relation::RightOf),
    (&["in", "the", "front"], Relation::InFrontOf),
    (&["in", "front"], Relation::InFrontOf),
    (&["on"], Relation::On),
    (&["onto"], Relation::On),
    (&["upon"], Relation::On),
    (&["atop"], Relation::On),
    (&["near"], Relation::Near),
    (&["by"], Relation::Near),
    (&["beside"], Relation::NextTo),
    (&["alongside"], Relation::NextTo),
    (&["against"], Relation::Against),
    (&["opposite"], Relation::Opposite),
    (&["facing"], Relation::Facing),
    (&["around"], Relation::Around),
    (&["before"], Relation::InFrontOf),
    // "A chair is at the desk": where one sits or stands to use it, facing it.
    (&["at"], Relation::InFrontOf),
    (&["under"], Relation::Under),
    (&["underneath"], Relation::Under),
    (&["beneath"], Relation::Under),
    (&["below"], Relation::Under),
    (&["above"], Relation::Above),
    (&["over"], Relation::Above),
    (&["along"], Relation::NextTo),
    (&["in"], Relation::In),
    (&["inside"], Relation::In),
    (&["within"], Relation::In),
    (&["into"], Relation::In),
    (&["behind"], Relation::Behind),
];

/// Every relation word, for suggestions on unknown relation phrases.
const RELATION_WORDS: &[&str] = &[
    "on",
    "near",
    "in front of",
    "next to",
    "under",
    "above",
    "in",
    "behind",
    "beside",
    "by",
    "on top of",
    "before",
    "below",
    "over",
    "inside",
    "against",
    "at",
    "between",
    "opposite",
    "across from",
    "facing",
    "to the left of",
    "to the right of",
    "on either side of",
    "around",
    "along",
];

/// Words that name a wall (as the anchor of "against", "along", "by": [`Place::Wall`]).
const WALL_WORDS: &[&str] = &["wall", "walls"];
/// Words that name the room's door ([`Place::Door`]).
const DOOR_WORDS: &[&str] = &["door", "doorway", "entrance", "doors"];
/// Single words read as relations whatever their tag ("opposite" as an adjective, "facing" as a
/// participle, "around" as an adverb).
const UNTAGGED_RELATIONS: &[&str] = &["opposite", "facing", "around", "against", "beside"];

/// A matched relation phrase.
struct RelMatch {
    relation: Relation,
    /// Normalised preposition for actions ("in the front of" → "in front of", "before" → "in front of").
    prep: &'static str,
    len: usize,
    /// No "of" and no object follows ("are in the front", Fig. 5).
    dangling: bool,
}

fn relation_at(t: &[Tagged], i: usize) -> Option<RelMatch> {
    for (words, rel) in RELATION_PHRASES {
        let n = words.len();
        if i + n <= t.len() && words.iter().zip(&t[i..i + n]).all(|(w, x)| *w == x.lower) {
            // A single "left"/"right"/"over" that is a particle or a verb's adverb is no relation.
            if n == 1 && !matches!(t[i].tag, Tag::IN) && !UNTAGGED_RELATIONS.contains(&words[0]) {
                continue;
            }
            let dangling = words.last() == Some(&"front") || words.last() == Some(&"back");
            let prep = match (rel, n) {
                (Relation::InFrontOf, 1) if words[0] == "at" => "at",
                (Relation::InFrontOf, _) => "in front of",
                (Relation::On, 3) => "on",
                (_, 1) => match words[0] {
                    "on" => "on",
                    "onto" => "onto",
                    "in" => "in",
                    "into" => "into",
                    "near" => "near",
                    "by" => "by",
                    "beside" => "beside",
                    "under" => "under",
                    "above" => "above",
                    "over" => "over",
                    "behind" => "behind",
                    "inside" => "inside",
                    "against" => "against",
                    "below" => "below",
                    "beneath" => "beneath",
                    "underneath" => "underneath",
                    "within" => "within",
                    "alongside" => "alongside",
                    "along" => "along",
                    "upon" => "on",
                    "atop" => "on",
                    "opposite" => "opposite",
                    "facing" => "facing",
                    "around" => "around",
                    _ => "on",
                },
                (Relation::NextTo, _) => "next to",
                (Relation::LeftOf, _) => "to the left of",
                (Relation::RightOf, _) => "to the right of",
                (Relation::Opposite, _) => "opposite",
                (Relation::EitherSide, _) => "on either side of",
                (Relation::Near, _) => "near",
                (Relation::Behind, _) => "behind",
                _ => rel.phrase(),
            };
            return Some(RelMatch { relation: *rel, prep, len: n, dangling });
        }
    }
    None
}

/// A noun phrase: optional determiner/number, modifiers, head noun.
#[derive(Debug, Clone)]
struct Np {
    /// One past the head.
    end: usize,
    head: usize,
    /// Modifier token indices (adjectives, noun modifiers), in order.
    modifiers: Vec<usize>,
    count: Option<usize>,
    plural: bool,
    /// Token index of a pronoun ("it") standing for the phrase.
    pronoun: bool,
}

fn np_at(t: &[Tagged], i: usize) -> Option<Np> {
    let n = t.len();
    let mut j = i;
    let mut count = None;
    if j < n && t[j].tag == Tag::PRP && matches!(t[j].lower.as_str(), "it" | "them") {
        return Some(Np { end: j + 1, head: j, modifiers: vec![], count: None, plural: false, pronoun: true });
    }
    if j < n && t[j].tag == Tag::DT {
        count = match t[j].lower.as_str() {
            "a" | "an" | "one" | "another" | "each" | "every" => Some(1),
            "several" | "many" => Some(3),
            "few" => Some(3),
            "both" => Some(2),
            _ => None,
        };
        j += 1;
        // "a few", "a couple of", "a pair of".
        if j < n && t[j].lower == "few" {
            count = Some(3);
            j += 1;
        }
    }
    if j < n && matches!(t[j].tag, Tag::PRPS | Tag::POS) {
        j += 1;
    }
    if j < n && t[j].tag == Tag::CD {
        count = number_value(&t[j].lower).or(count);
        j += 1;
        if j < n && t[j].lower == "of" {
            j += 1;
            if j < n && t[j].tag == Tag::DT {
                j += 1;
            }
        }
    }
    let start = j;
    while j < n && matches!(t[j].tag, Tag::JJ | Tag::NN | Tag::NNS | Tag::VBN) {
        j += 1;
    }
    let run = start..j;
    let head = run.clone().rev().find(|&k| matches!(t[k].tag, Tag::NN | Tag::NNS))?;
    let modifiers: Vec<usize> = (start..head).collect();
    let plural = t[head].tag == Tag::NNS && !contains(PLURALIA_TANTUM, &t[head].lower);
    Some(Np { end: head + 1, head, modifiers, count, plural, pronoun: false })
}

/// What a noun phrase names.
enum Named {
    Object(ObjectNode),
    Room(String),
    /// A known non-object word ("music", "the man").
    Other,
    /// Unknown word (with its text).
    Unknown(String),
}

/// Resolves a noun phrase: catalogue object (trying compounds, "boxing ring" → "boxingring"),
/// room, or unknown.
fn resolve_np(t: &[Tagged], np: &Np, cat: &Catalogue, sentence: usize) -> Named {
    let head = &t[np.head];
    let head_cat = cat.resolve(&head.lower).or_else(|| cat.resolve(&head.lemma));
    let mut mods = np.modifiers.clone();
    let mut word = head.text.clone();
    // Compound of the last modifier and the head ("working shop", "music room", "boxing ring").
    if let Some(&last) = mods.last() {
        let joined = format!("{}{}", t[last].lower, head.lemma);
        let joined_surface = format!("{}{}", t[last].lower, head.lower);
        let spaced = format!("{} {}", t[last].lower, head.lemma);
        let jc = cat.resolve(&joined_surface).or_else(|| cat.resolve(&joined)).or_else(|| cat.resolve(&spaced));
        if let Some(jc) = jc {
            // A compound that is the category's own name ("boxing ring" → boxingring) names it;
            // one that is only a synonym keeps its modifier ("office desk" → desk [office]).
            if head_cat.is_none_or(|h| h.name != jc.name) || jc.name == joined || jc.name == joined_surface {
                mods.pop();
                return Named::Object(object(
                    jc.name.clone(),
                    t,
                    &mods,
                    np,
                    format!("{} {}", t[last].text, head.text),
                    sentence,
                ));
            }
        }
        if head_cat.is_none() {
            if let Some(r) = cat
                .resolve_room(&joined)
                .or_else(|| cat.resolve_room(&joined_surface))
                .or_else(|| cat.resolve_room(&spaced))
            {
                return Named::Room(r.name.clone());
            }
        }
    }
    if let Some(c) = head_cat {
        if np.plural || np.count.is_some_and(|c| c > 1) {
            word = head.text.clone();
        }
        return Named::Object(object(c.name.clone(), t, &mods, np, word, sentence));
    }
    if let Some(r) = cat.resolve_room(&head.lower).or_else(|| cat.resolve_room(&head.lemma)) {
        return Named::Room(r.name.clone());
    }
    if head.known || known_noun(&head.lower, cat) || head.tag == Tag::NNP {
        return Named::Other;
    }
    Named::Unknown(head.text.clone())
}

fn object(category: String, t: &[Tagged], mods: &[usize], np: &Np, word: String, sentence: usize) -> ObjectNode {
    let attributes =
        mods.iter().map(|&k| if t[k].tag == Tag::NNS { t[k].lemma.clone() } else { t[k].lower.clone() }).collect();
    let count = np.count.unwrap_or(if np.plural { 2 } else { 1 }).max(1);
    ObjectNode { category, attributes, count, word, sentence }
}

/// Parses one sentence with the state carried over from earlier ones.
pub fn parse_with(raw: &RawSentence, cat: &Catalogue, state: &mut ParseState) -> (Ssg, Vec<Diagnostic>) {
    let mut p = Parser {
        at: &raw.at,
        cat,
        ssg: Ssg::default(),
        diags: Vec::new(),
        sentence: raw.at.sentence.saturating_sub(1),
    };
    match raw.kind {
        SentenceKind::Command => p.command(),
        SentenceKind::Scene => p.scene(&tagged(raw, cat), state),
        SentenceKind::Direction => {
            let t = tagged(raw, cat);
            if !p.direction(&t, state) {
                p.scene(&t, state);
                if !p.ssg.objects.is_empty() || p.ssg.room.is_some() {
                    p.diag(
                        None,
                        "no `$` at the end, but it names only objects: read as a scene description".into(),
                        vec![],
                    );
                }
            }
        }
    }
    (p.ssg, p.diags)
}

fn tagged(raw: &RawSentence, cat: &Catalogue) -> Vec<Tagged> {
    let mut t = tag(&tokenize(&raw.at.text), cat);
    for k in 0..t.len() {
        let after_subject = k > 0 && matches!(t[k - 1].tag, Tag::NN | Tag::NNS | Tag::NNP | Tag::PRP);
        if after_subject && t[k].lower == "faces" {
            // "A chair faces the window", "Ben faces Anna": the verb, not the plural noun.
            t[k].tag = Tag::VBZ;
            t[k].lemma = "face".into();
            t[k].known = true;
        } else if t[k].tag == Tag::NNP
            && k > 0
            && t[k].text.chars().all(|c| c.is_ascii_uppercase())
            && cat.resolve(&t[k].lower).is_some()
        {
            // "the TV": an object written in capitals, not a name.
            t[k].tag = Tag::NN;
        }
    }
    t
}

struct Parser<'a> {
    at: &'a SentenceRef,
    cat: &'a Catalogue,
    ssg: Ssg,
    diags: Vec<Diagnostic>,
    sentence: usize,
}

/// Pieces of a scene sentence in order.
enum El {
    Group(Vec<NodeId>),
    /// A relation and its words as written (for messages).
    Rel(Relation, &'static str),
    /// A place in the room (no anchor object).
    Place(Place),
    /// "between": the next group's first two objects.
    Between,
    /// "at": [`Relation::InFrontOf`] for one thing, [`Relation::At`] for several.
    At,
    /// "each other", "one another" (after "face").
    EachOther,
    Which,
}

/// Room places written as a phrase ("in the middle of", "in a corner", "in the far corner of"):
/// the place, the phrase's length and whether it ends in "of" (an object may follow: "in the
/// middle of the table").
fn place_at(t: &[Tagged], i: usize) -> Option<(Place, usize, bool)> {
    let first = t.get(i)?.lower.as_str();
    if !matches!(first, "in" | "into" | "at") || !matches!(t.get(i + 1)?.lower.as_str(), "the" | "a" | "an" | "one") {
        return None;
    }
    // Up to two words before the place word ("the far corner", "the very middle").
    for k in i + 2..(i + 5).min(t.len()) {
        let place = match t[k].lower.as_str() {
            "middle" | "centre" | "center" => Place::Middle,
            "corner" | "corners" => Place::Corner,
            _ if matches!(t[k].tag, Tag::JJ | Tag::RB | Tag::VBN | Tag::VBD) => continue,
            "far" | "back" | "front" | "left" | "right" | "near" | "opposite" | "very" | "exact" => continue,
            _ => return None,
        };
        let of = t.get(k + 1).is_some_and(|x| x.lower == "of");
        return Some((place, k + 1 + usize::from(of) - i, of));
    }
    None
}

impl Parser<'_> {
    fn diag(&mut self, word: Option<String>, message: String, suggestions: Vec<String>) {
        self.diags.push(Diagnostic { at: self.at.clone(), word, message, suggestions });
    }

    fn unknown_object(&mut self, word: &str) {
        let s = noun_suggestions(word, self.cat);
        self.diag(Some(word.to_string()), format!("unknown object \"{word}\": not in the catalogue"), s);
    }

    fn command(&mut self) {
        let Some((what, value)) = command_parts(&self.at.text) else {
            self.diag(None, "not a command (write \"camera left\", \"weather rainy\", \"time night\")".into(), vec![]);
            return;
        };
        let sentence = self.sentence;
        let allowed: &[&str] = match what.as_str() {
            "camera" => &CAMERA_VIEWS,
            "weather" => &WEATHERS,
            _ => &TIMES,
        };
        if !allowed.contains(&value.as_str()) {
            let s = closest(&value, allowed.iter().copied());
            self.diag(
                Some(value.clone()),
                format!("unknown {what} setting \"{value}\" (known: {})", allowed.join(", ")),
                s,
            );
            return;
        }
        self.ssg.commands.push(match what.as_str() {
            "camera" => Command::Camera { view: value, sentence },
            "weather" => Command::Weather { weather: value, sentence },
            _ => Command::Time { time: value, sentence },
        });
    }

    fn add_object(&mut self, node: ObjectNode) -> NodeId {
        self.ssg.objects.push(node);
        self.ssg.objects.len() - 1
    }

    /// Scene description (§4.1): objects, their relations, the room.
    fn scene(&mut self, t: &[Tagged], state: &mut ParseState) {
        let n = t.len();
        let mut els: Vec<El> = Vec::new();
        let mut i = 0;
        let mut unknown_any = false;
        while i < n {
            if t[i].tag == Tag::WDT {
                els.push(El::Which);
                i += 1;
                continue;
            }
            if t[i].lower == "between" {
                els.push(El::Between);
                i += 1;
                continue;
            }
            if matches!(
                (t[i].lower.as_str(), t.get(i + 1).map(|x| x.lower.as_str())),
                ("each", Some("other")) | ("one", Some("another"))
            ) {
                els.push(El::EachOther);
                i += 2;
                continue;
            }
            if t[i].tag.is_verb() && t[i].lemma == "face" {
                els.push(El::Rel(Relation::Facing, "facing"));
                i += 1;
                continue;
            }
            if let Some((place, len, of)) = place_at(t, i) {
                let j = i + len;
                i = j;
                match np_at(t, j).filter(|np| of && !np.pronoun) {
                    // "in the middle of the wall": on (or against) the wall.
                    Some(np) if WALL_WORDS.contains(&t[np.head].lower.as_str()) => {
                        els.push(El::Place(Place::Wall));
                        i = np.end;
                    }
                    Some(np) => match resolve_np(t, &np, self.cat, self.sentence) {
                        // "in the middle of the table": on it.
                        Named::Object(_) => els.push(El::Rel(Relation::On, "on")),
                        Named::Room(r) => {
                            self.ssg.room.get_or_insert(r);
                            els.push(El::Place(place));
                            i = np.end;
                        }
                        _ => {
                            els.push(El::Place(place));
                            i = np.end;
                        }
                    },
                    None => els.push(El::Place(place)),
                }
                continue;
            }
            if let Some(m) = relation_at(t, i) {
                let j = i + m.len;
                if let Some(np) = np_at(t, j).filter(|np| !np.pronoun) {
                    let head = t[np.head].lower.as_str();
                    if WALL_WORDS.contains(&head) || DOOR_WORDS.contains(&head) {
                        let place = if WALL_WORDS.contains(&head) { Place::Wall } else { Place::Door };
                        els.push(El::Place(place));
                        i = np.end;
                        continue;
                    }
                    if let Named::Room(r) = resolve_np(t, &np, self.cat, self.sentence) {
                        if m.relation == Relation::In {
                            self.ssg.room.get_or_insert(r);
                            i = np.end;
                            continue;
                        }
                    }
                }
                if !m.dangling {
                    els.push(if m.prep == "at" { El::At } else { El::Rel(m.relation, m.prep) });
                }
                i = j;
                continue;
            }
            if t[i].tag == Tag::IN && !matches!(t[i].lower.as_str(), "of" | "as") {
                // A preposition the SSG has no relation for, between two objects.
                let before = matches!(els.last(), Some(El::Group(_)));
                if before && np_at(t, i + 1).is_some() {
                    let w = t[i].lower.clone();
                    let s = closest(&w, RELATION_WORDS.iter().copied());
                    self.diag(
                        Some(w.clone()),
                        format!("unknown relation \"{w}\" (known: {})", RELATION_WORDS.join(", ")),
                        s,
                    );
                }
                i += 1;
                continue;
            }
            // "Six chairs are around it": the last object named before.
            if t[i].tag == Tag::PRP
                && t[i].lower == "it"
                && matches!(els.last(), Some(El::Rel(..) | El::At | El::Between))
            {
                match state.last_object.clone() {
                    Some(mut o) => {
                        o.sentence = self.sentence;
                        o.word = "it".into();
                        let id = self.add_object(o);
                        els.push(El::Group(vec![id]));
                    }
                    None => self.diag(Some("it".into()), "\"it\" refers to no object named before".into(), vec![]),
                }
                i += 1;
                continue;
            }
            if let Some(np) = np_at(t, i).filter(|np| !np.pronoun) {
                // A coordinated group: NP ((,|and|or) NP)*.
                let mut group = Vec::new();
                let mut np = np;
                loop {
                    match resolve_np(t, &np, self.cat, self.sentence) {
                        Named::Object(o) => group.push(self.add_object(o)),
                        Named::Room(r) => {
                            self.ssg.room.get_or_insert(r);
                        }
                        Named::Other => {}
                        Named::Unknown(w) => {
                            unknown_any = true;
                            self.unknown_object(&w);
                        }
                    }
                    i = np.end;
                    let mut k = i;
                    while k < n && (t[k].lower == "," || t[k].tag == Tag::CC) {
                        k += 1;
                    }
                    if k == i {
                        break;
                    }
                    let anchor_group = matches!(els.last(), Some(El::Rel(..) | El::At | El::Between));
                    match np_at(t, k).filter(|np| !np.pronoun) {
                        // "near a table, and a chair is next to ...": a new clause, not one more anchor.
                        Some(next) if anchor_group && t.get(next.end).is_some_and(|x| x.tag.is_verb()) => break,
                        Some(next) if relation_at(t, k).is_none() => {
                            np = next;
                        }
                        _ => break,
                    }
                }
                if !group.is_empty() {
                    els.push(El::Group(group));
                }
                continue;
            }
            i += 1;
        }
        self.relations_from(&els);
        if let Some(o) = self.ssg.objects.iter().rev().find(|o| o.word != "it") {
            state.last_object = Some(o.clone());
        }
        if self.ssg.objects.is_empty() && self.ssg.room.is_none() && !unknown_any {
            self.diag(
                None,
                "could not read a scene description here (write e.g. \"A lamp is on the desk$\")".into(),
                vec![],
            );
        }
    }

    fn relations_from(&mut self, els: &[El]) {
        let group = |k: usize| match els.get(k) {
            Some(El::Group(g)) => Some(g.clone()),
            _ => None,
        };
        // The group a relation at `k` relates: the nearest group before it, else (the relation comes first: "On the desk there is a lamp") the group
        // after its anchor, at `k + skip`.
        let actives_of = |k: usize, skip: usize| -> Option<Vec<NodeId>> {
            match (0..k).rev().find_map(|p| match &els[p] {
                El::Group(g) => Some(g.clone()),
                El::Which => Some(Vec::new()),
                _ => None,
            }) {
                Some(prev) if !prev.is_empty() => Some(prev),
                Some(_) => None,
                None => group(k + skip),
            }
        };
        let sentence = self.sentence;
        for (k, el) in els.iter().enumerate() {
            match el {
                El::Place(place) => {
                    let Some(actives) = actives_of(k, 1) else {
                        self.left_out(place.phrase(), "nothing named stands there");
                        continue;
                    };
                    for a in actives {
                        self.ssg.places.push(PlaceNode { place: *place, active: a, sentence });
                    }
                }
                El::Between => {
                    let anchors = group(k + 1).unwrap_or_default();
                    let Some(actives) = actives_of(k, 2) else {
                        self.left_out("between", "nothing named stands there");
                        continue;
                    };
                    // "between the armchairs": the two instances of one plural node.
                    let anchors = if anchors.len() == 1 && self.ssg.objects[anchors[0]].count > 1 {
                        vec![anchors[0]; 2]
                    } else {
                        anchors
                    };
                    if anchors.len() < 2 {
                        self.left_out(
                            "between",
                            "it needs two things the scene can show (\"between the sofa and the TV\")",
                        );
                        continue;
                    }
                    for a in actives.into_iter().filter(|a| !anchors[..2].contains(a)) {
                        let place = Place::Between { first: anchors[0], second: anchors[1] };
                        self.ssg.places.push(PlaceNode { place, active: a, sentence });
                    }
                }
                El::Rel(..) | El::At => {
                    let (rel, phrase) = match el {
                        El::Rel(r, p) => (*r, *p),
                        _ => (Relation::At, "at"),
                    };
                    let each_other = matches!(els.get(k + 1), Some(El::EachOther));
                    let (actives, anchor) = if each_other {
                        match actives_of(k, 2) {
                            Some(a) => (a, None),
                            None => continue,
                        }
                    } else if matches!(els.get(k + 1), Some(El::Which)) {
                        // "a boxing ring above which a boxingbag hangs" (Fig. 5).
                        match (k.checked_sub(1).and_then(group), group(k + 2)) {
                            (Some(prev), Some(next)) => (next, Some(*prev.last().unwrap())),
                            _ => continue,
                        }
                    } else {
                        let Some(next) = group(k + 1) else {
                            if actives_of(k, 2).is_some() {
                                self.left_out(phrase, "no object the scene can show follows it");
                            }
                            continue;
                        };
                        match actives_of(k, 2) {
                            Some(a) => (a, Some(next[0])),
                            None => continue,
                        }
                    };
                    let Some(anchor) = anchor else {
                        // "Two armchairs face each other": each faces the next.
                        if actives.len() >= 2 {
                            for (n, &a) in actives.iter().enumerate() {
                                let b = actives[(n + 1) % actives.len()];
                                self.push_relation(rel, a, b);
                            }
                        } else if let Some(&a) = actives.first() {
                            self.push_relation(rel, a, a);
                        }
                        continue;
                    };
                    let several = actives.len() > 1 || actives.iter().any(|&a| self.ssg.objects[a].count > 1);
                    for (n, &a) in actives.iter().enumerate() {
                        if a == anchor {
                            continue;
                        }
                        let r = match rel {
                            // One seat "at" a desk sits in front of it (tucked when it can be).
                            Relation::At if !several => Relation::InFrontOf,
                            // "a lamp and a plant on either side of the sofa": one each side;
                            // one node of several instances is shared out by composition.
                            Relation::EitherSide if actives.len() > 1 => {
                                if n % 2 == 0 {
                                    Relation::LeftOf
                                } else {
                                    Relation::RightOf
                                }
                            }
                            Relation::EitherSide if self.ssg.objects[a].count == 1 => Relation::NextTo,
                            r => r,
                        };
                        self.push_relation(r, a, anchor);
                    }
                }
                El::Group(_) | El::Which | El::EachOther => {}
            }
        }
    }

    fn push_relation(&mut self, relation: Relation, active: NodeId, anchor: NodeId) {
        self.ssg.relations.push(RelationNode { relation, active, anchor, sentence: self.sentence });
    }

    /// A relation phrase the sentence has but the scene cannot show: said, never dropped quietly.
    fn left_out(&mut self, phrase: &str, why: &str) {
        self.diag(Some(phrase.to_string()), format!("\"{phrase}\" left out: {why}"), vec![]);
    }

    /// Character direction (§3.2, Fig. 3): who, then verbs in order with preposition, target and
    /// manner. Returns false when the sentence has no character but objects (a scene without `$`).
    /// A direction sentence, split into clauses where a new subject starts ("Max sits on the chair
    /// and Lena stands behind him"): a conjunction or comma followed by a name or a pronoun and then
    /// a verb.
    fn direction(&mut self, t: &[Tagged], state: &mut ParseState) -> bool {
        let mut cuts = vec![0];
        for k in 1..t.len() {
            if !(t[k - 1].tag == Tag::CC || t[k - 1].lower == ",") {
                continue;
            }
            let mut j = k;
            while j < t.len() && t[j].tag == Tag::RB {
                j += 1;
            }
            let subject = |x: &Tagged| {
                x.tag == Tag::NNP
                    || (x.tag == Tag::PRP && matches!(x.lower.as_str(), "he" | "she" | "they" | "we"))
                    || x.tag == Tag::CC
                    || x.lower == ","
            };
            while j < t.len() && subject(&t[j]) {
                j += 1;
            }
            while j < t.len() && matches!(t[j].tag, Tag::RB | Tag::MD) {
                j += 1;
            }
            let named = (k..j).any(|q| t[q].tag == Tag::NNP || t[q].tag == Tag::PRP);
            // Only after a clause with its own verb ("Anna and Ben walk" is one subject).
            let verb_before = t[cuts[cuts.len() - 1]..k].iter().any(|x| x.tag.is_verb());
            if named && verb_before && j < t.len() && t[j].tag.is_verb() {
                cuts.push(k);
            }
        }
        cuts.push(t.len());
        if cuts.len() == 2 {
            return self.clause(t, state);
        }
        for w in cuts.windows(2) {
            self.clause(&t[w[0]..w[1]], state);
        }
        true
    }

    /// A character named at `j` ("Tom", "Mary Ann") or a pronoun standing for one ("him", "her",
    /// "them": the latest character other than `subjects`): the names and the index after them.
    fn person_at(t: &[Tagged], j: usize, subjects: &[String], state: &ParseState) -> Option<(String, usize)> {
        let x = t.get(j)?;
        if x.tag == Tag::NNP {
            let end = (j..t.len()).find(|&k| t[k].tag != Tag::NNP).unwrap_or(t.len());
            return Some((t[j..end].iter().map(|x| x.text.as_str()).collect::<Vec<_>>().join(" "), end));
        }
        if x.tag == Tag::PRP && matches!(x.lower.as_str(), "him" | "her" | "them") {
            let other = |n: &&String| !subjects.iter().any(|s| s.eq_ignore_ascii_case(n));
            let pick = if x.lower == "them" {
                state.last_group.iter().find(other).or_else(|| state.recent.iter().rev().find(other))
            } else {
                state.recent.iter().rev().find(other)
            };
            return pick.map(|p| (p.clone(), j + 1));
        }
        None
    }

    fn clause(&mut self, t: &[Tagged], state: &mut ParseState) -> bool {
        let n = t.len();
        let Some(v) = t.iter().position(|x| x.tag.is_verb() || x.tag == Tag::MD) else {
            if t.iter().any(|x| x.tag == Tag::EX) || self.names_objects(t) {
                return false;
            }
            self.diag(None, "no verb found: write who does what (e.g. \"Eve walks to the desk\")".into(), vec![]);
            return true;
        };
        let subject: Vec<&Tagged> = t[..v].iter().filter(|x| x.tag != Tag::Punct).collect();
        if subject.iter().any(|x| x.tag == Tag::EX) {
            return false;
        }
        let plural_pronoun = subject.iter().any(|x| x.tag == Tag::PRP && matches!(x.lower.as_str(), "they" | "we"));
        let mut names: Vec<String> = Vec::new();
        let name = if subject.iter().any(|x| x.tag == Tag::NNP) {
            // "Anna and Ben", "Anna, Ben and Tom": every run of names.
            let mut run: Vec<&str> = Vec::new();
            for x in subject.iter().chain(std::iter::once(&&t[v])) {
                if x.tag == Tag::NNP {
                    run.push(x.text.as_str());
                } else if !run.is_empty() {
                    names.push(run.join(" "));
                    run.clear();
                }
            }
            names[0].clone()
        } else if subject.is_empty() || subject.iter().all(|x| matches!(x.tag, Tag::PRP | Tag::RB | Tag::CC)) {
            if plural_pronoun {
                // "they": the last plural subject while its members are the latest named, else
                // the last two characters named ("Anna sits. Ben sits next to her. They talk.").
                let n = state.recent.len();
                let g = state.last_group.len();
                let group_latest = g > 0
                    && g <= n
                    && state.last_group.iter().all(|m| state.recent[n - g..].iter().any(|r| r.eq_ignore_ascii_case(m)));
                if group_latest {
                    names = state.last_group.clone();
                } else if n >= 2 {
                    names = state.recent[n - 2..].to_vec();
                }
            }
            match (&state.last_character, names.first()) {
                (_, Some(first)) => first.clone(),
                (Some(c), None) => c.clone(),
                (None, None) => {
                    self.diag(None, "no character: say who acts (e.g. \"Eve walks to the desk\")".into(), vec![]);
                    return true;
                }
            }
        } else {
            let head = subject.iter().rev().find(|x| x.tag.is_noun());
            match head {
                Some(h) if contains(PERSON_NOUNS, &h.lemma) || contains(PERSON_NOUNS, &h.lower) => {
                    let words: Vec<String> = subject
                        .iter()
                        .map(|x| if x.tag == Tag::DT { x.lower.clone() } else { x.text.clone() })
                        .collect();
                    words.join(" ")
                }
                Some(h) if self.cat.resolve(&h.lower).is_some() || self.cat.resolve(&h.lemma).is_some() => {
                    return false;
                }
                _ => subject.iter().map(|x| x.text.as_str()).collect::<Vec<_>>().join(" "),
            }
        };
        if names.is_empty() {
            names.push(name.clone());
        }
        if names.len() > 1 {
            state.last_group = names.clone();
        }
        for m in &names {
            state.recent.retain(|r| !r.eq_ignore_ascii_case(m));
            state.recent.push(m.clone());
        }
        state.last_character = Some(names.last().cloned().unwrap_or_else(|| name.clone()));

        let mut actions: Vec<Action> = Vec::new();
        // Unknown nouns met while the action had no target, by action index.
        let mut unknown: Vec<(usize, String)> = Vec::new();
        // Adverbs before the verb ("Slowly, Tom walks") go to the first verb.
        let mut pending_manner: Vec<String> = t[..v]
            .iter()
            .filter(|x| x.tag == Tag::RB && !contains(GLUE_ADVERBS, &x.lower))
            .map(|x| x.lower.clone())
            .collect();
        let mut cur: Option<usize> = None;
        let mut last_target: Option<NodeId> = None;
        let mut i = v;
        while i < n {
            let x = &t[i];
            if x.tag == Tag::Punct || x.tag == Tag::CC || x.tag == Tag::MD {
                i += 1;
                continue;
            }
            if x.tag.is_verb() {
                let next_verb = t[i + 1..].iter().find(|y| y.tag != Tag::RB).is_some_and(|y| y.tag.is_verb());
                if matches!(x.lemma.as_str(), "be" | "have" | "do") && next_verb {
                    i += 1;
                    continue;
                }
                if !x.known {
                    let s = verb_suggestions(&x.lower);
                    self.diag(Some(x.text.clone()), format!("unknown verb \"{}\"", x.text), s);
                    cur = None;
                } else {
                    actions.push(Action {
                        verb: x.lemma.clone(),
                        preposition: None,
                        target: None,
                        manner: std::mem::take(&mut pending_manner),
                        destination: None,
                        person: None,
                    });
                    cur = Some(actions.len() - 1);
                }
                i += 1;
                continue;
            }
            if x.tag == Tag::RB {
                if !contains(GLUE_ADVERBS, &x.lower) {
                    match cur {
                        Some(c) => actions[c].manner.push(x.lower.clone()),
                        None => pending_manner.push(x.lower.clone()),
                    }
                }
                i += 1;
                continue;
            }
            if x.tag == Tag::TO && t.get(i + 1).is_some_and(|y| y.tag == Tag::VB) {
                i += 1;
                continue;
            }
            let spatial = relation_at(t, i).filter(|m| !m.dangling).map(|m| m.prep);
            let (prep, j) = if let Some(m) = relation_at(t, i) {
                (Some(m.prep.to_string()), i + m.len)
            } else if matches!(x.tag, Tag::IN | Tag::TO) {
                (Some(x.lower.clone()), i + 1)
            } else {
                (None, i)
            };
            if let Some((person, end)) = Self::person_at(t, j, &names, state) {
                if let Some(c) = cur.filter(|&c| actions[c].person.is_none() && actions[c].target.is_none()) {
                    actions[c].person = Some(person);
                    actions[c].preposition = prep;
                }
                i = end;
                continue;
            }
            let Some(np) = np_at(t, j) else {
                if prep.is_some() && j == i + 1 && matches!(x.lower.as_str(), "in" | "out" | "down" | "up" | "over") {
                    // "sits down", "walks in": a particle.
                    if let Some(c) = cur {
                        actions[c].manner.push(x.lower.clone());
                    }
                }
                i = j.max(i + 1);
                continue;
            };
            i = np.end;
            let Some(c) = cur else {
                // After an unknown verb: still name unknown objects.
                if let Named::Unknown(w) = resolve_np(t, &np, self.cat, self.sentence) {
                    self.unknown_object(&w);
                }
                continue;
            };
            let node = if np.pronoun {
                match last_target {
                    Some(id) => Some(id),
                    None => match state.last_target.clone() {
                        Some(mut o) => {
                            o.sentence = self.sentence;
                            Some(self.add_object(o))
                        }
                        None => {
                            self.diag(
                                Some(t[np.head].text.clone()),
                                format!("\"{}\" refers to no object named before", t[np.head].text),
                                vec![],
                            );
                            None
                        }
                    },
                }
            } else {
                match resolve_np(t, &np, self.cat, self.sentence) {
                    Named::Object(o) => Some(self.add_object(o)),
                    Named::Room(_) => None,
                    _ if contains(PART_NOUNS, &t[np.head].lower) => last_target.or_else(|| {
                        state.last_target.clone().map(|mut o| {
                            o.sentence = self.sentence;
                            self.add_object(o)
                        })
                    }),
                    Named::Other => None,
                    Named::Unknown(w) => {
                        unknown.push((c, w));
                        None
                    }
                }
            };
            if let Some(id) = node {
                if actions[c].target.is_none() {
                    actions[c].target = Some(id);
                    actions[c].preposition = prep;
                } else if actions[c].destination.is_none() && actions[c].target != Some(id) {
                    // A second object after a spatial phrase: where the target goes ("puts the
                    // cup on the counter").
                    if let Some(prep) = spatial {
                        actions[c].destination = Some((prep.to_string(), id));
                    }
                }
                last_target = Some(id);
            }
        }
        for (c, w) in unknown {
            if actions[c].target.is_none() {
                self.unknown_object(&w);
            }
        }
        if let Some(id) = last_target {
            state.last_target = Some(self.ssg.objects[id].clone());
        }
        if actions.is_empty() {
            if !self.diags.iter().any(|d| d.word.is_some()) {
                self.diag(
                    None,
                    format!("no action for {name}: write a verb (e.g. \"{name} walks to the desk\")"),
                    vec![],
                );
            }
            return true;
        }
        // A plural subject acts together; "they talk" (no one named) talk to each other.
        for (k, member) in names.iter().enumerate() {
            let mut mine = actions.clone();
            if names.len() > 1 {
                for a in mine.iter_mut().filter(|a| a.person.is_none() && a.target.is_none()) {
                    if crate::motion::verbs::social(&a.verb) {
                        a.person = Some(names[(k + 1) % names.len()].clone());
                    }
                }
            }
            self.ssg.characters.push(CharacterNode { name: member.clone(), actions: mine, sentence: self.sentence });
        }
        true
    }

    fn names_objects(&self, t: &[Tagged]) -> bool {
        t.iter()
            .any(|x| x.tag.is_noun() && (self.cat.resolve(&x.lower).is_some() || self.cat.resolve(&x.lemma).is_some()))
    }
}
