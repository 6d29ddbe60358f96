//! Rules from tags to the SSG (§3.2, §4.1; Fig. 3 shows the dependencies CoreNLP would give, and
//! these patterns recover the same facts: objects with attributes and counts, relation nodes, and
//! characters with verbs, prepositions and targets).

use super::lexicon::{contains, number_value, GLUE_ADVERBS, PART_NOUNS, PERSON_NOUNS, PLURALIA_TANTUM};
use super::suggest::{closest, noun_suggestions, verb_suggestions};
use super::tag::{known_noun, tag, Tag, Tagged};
use super::token::tokenize;
use crate::catalogue::Catalogue;
use crate::error::{Diagnostic, SentenceRef};
use crate::script::{command_parts, RawSentence, SentenceKind, CAMERA_VIEWS, TIMES, WEATHERS};
use crate::ssg::{Action, CharacterNode, Command, NodeId, ObjectNode, Relation, RelationNode, Ssg};

/// What carries over from one sentence to the next: who "he"/"she" is, what "it" is.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ParseState {
    /// The last character named ("Tom sits. He sings." → Tom).
    pub last_character: Option<String>,
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
    (&["to", "the", "left", "of"], Relation::NextTo),
    (&["to", "the", "right", "of"], Relation::NextTo),
    (&["on", "top", "of"], Relation::On),
    (&["in", "front", "of"], Relation::InFrontOf),
    (&["on", "the", "left", "of"], Relation::NextTo),
    (&["on", "the", "right", "of"], Relation::NextTo),
    (&["next", "to"], Relation::NextTo),
    (&["close", "to"], Relation::Near),
    (&["near", "to"], Relation::Near),
    (&["left", "of"], Relation::NextTo),
    (&["right", "of"], Relation::NextTo),
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
    (&["against"], Relation::NextTo),
    (&["before"], Relation::InFrontOf),
    // "A chair is at the desk": where one sits or stands to use it, facing it.
    (&["at"], Relation::InFrontOf),
    (&["under"], Relation::Under),
    (&["underneath"], Relation::Under),
    (&["beneath"], Relation::Under),
    (&["below"], Relation::Under),
    (&["above"], Relation::Above),
    (&["over"], Relation::Above),
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
];

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
            if n == 1 && !matches!(t[i].tag, Tag::IN) {
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
                    "upon" => "on",
                    "atop" => "on",
                    _ => "on",
                },
                (Relation::NextTo, _) => "next to",
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
        SentenceKind::Scene => p.scene(&tagged(raw, cat)),
        SentenceKind::Direction => {
            let t = tagged(raw, cat);
            if !p.direction(&t, state) {
                p.scene(&t);
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
    tag(&tokenize(&raw.at.text), cat)
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
    Rel(Relation),
    Which,
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
    fn scene(&mut self, t: &[Tagged]) {
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
            if let Some(m) = relation_at(t, i) {
                let j = i + m.len;
                if let Some(np) = np_at(t, j).filter(|np| !np.pronoun) {
                    if let Named::Room(r) = resolve_np(t, &np, self.cat, self.sentence) {
                        if m.relation == Relation::In {
                            self.ssg.room.get_or_insert(r);
                            i = np.end;
                            continue;
                        }
                    }
                }
                if !m.dangling {
                    els.push(El::Rel(m.relation));
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
                        format!("unknown relation \"{w}\" (known: on, near, in front of, next to, under, above, in, behind)"),
                        s,
                    );
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
                    let anchor_group = matches!(els.last(), Some(El::Rel(_)));
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
        for (k, el) in els.iter().enumerate() {
            let El::Rel(rel) = el else { continue };
            let (actives, anchor) = if matches!(els.get(k + 1), Some(El::Which)) {
                // "a boxing ring above which a boxingbag hangs" (Fig. 5).
                match (k.checked_sub(1).and_then(group), group(k + 2)) {
                    (Some(prev), Some(next)) => (next, *prev.last().unwrap()),
                    _ => continue,
                }
            } else {
                let Some(next) = group(k + 1) else { continue };
                match (0..k).rev().find_map(|p| match &els[p] {
                    El::Group(g) => Some(g.clone()),
                    El::Which => Some(Vec::new()),
                    El::Rel(_) => None,
                }) {
                    Some(prev) if !prev.is_empty() => (prev, next[0]),
                    Some(_) => continue,
                    // "On the desk there is a lamp": the relation comes first.
                    None => match group(k + 2) {
                        Some(after) => (after, next[0]),
                        None => continue,
                    },
                }
            };
            for a in actives {
                if a != anchor {
                    self.ssg.relations.push(RelationNode {
                        relation: *rel,
                        active: a,
                        anchor,
                        sentence: self.sentence,
                    });
                }
            }
        }
    }

    /// Character direction (§3.2, Fig. 3): who, then verbs in order with preposition, target and
    /// manner. Returns false when the sentence has no character but objects (a scene without `$`).
    fn direction(&mut self, t: &[Tagged], state: &mut ParseState) -> bool {
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
        let name = if let Some(first) = subject.iter().position(|x| x.tag == Tag::NNP) {
            let names: Vec<&str> =
                subject[first..].iter().take_while(|x| x.tag == Tag::NNP).map(|x| x.text.as_str()).collect();
            names.join(" ")
        } else if subject.is_empty() || subject.iter().all(|x| matches!(x.tag, Tag::PRP | Tag::RB | Tag::CC)) {
            match &state.last_character {
                Some(c) => c.clone(),
                None => {
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
        state.last_character = Some(name.clone());

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
        self.ssg.characters.push(CharacterNode { name, actions, sentence: self.sentence });
        true
    }

    fn names_objects(&self, t: &[Tagged]) -> bool {
        t.iter()
            .any(|x| x.tag.is_noun() && (self.cat.resolve(&x.lower).is_some() || self.cat.resolve(&x.lemma).is_some()))
    }
}
