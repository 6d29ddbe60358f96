//! A rule-based part-of-speech tagger (§3.2, Fig. 3 uses CoreNLP's Penn tags; we keep the tag set
//! but decide by word lists, the catalogue's nouns, suffixes and the previous tag, so no model
//! has to be downloaded).

use super::lemma::{known_verb_lemma, lemmatize, lemmatize_noun};
use super::lexicon::*;
pub use super::penn::Tag;
use super::token::Token;
use crate::catalogue::Catalogue;

/// A token with its tag and lemma.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Tagged {
    pub text: String,
    pub lower: String,
    pub tag: Tag,
    pub lemma: String,
    /// Whether some word list, the catalogue or a suffix rule knew the word; unknown words get a
    /// guessed tag and a "did you mean" diagnostic when the rules need them.
    pub known: bool,
}

/// Whether a lower-case word is a noun the tagger knows (catalogue object or room, person, common).
pub fn known_noun(lower: &str, cat: &Catalogue) -> bool {
    let lemma = lemmatize_noun(lower);
    [lower, lemma.as_str()].iter().any(|w| {
        cat.resolve(w).is_some()
            || cat.resolve_room(w).is_some()
            || contains(PERSON_NOUNS, w)
            || contains(COMMON_NOUNS, w)
    })
}

/// Tags a tokenised sentence.
pub fn tag(tokens: &[Token], cat: &Catalogue) -> Vec<Tagged> {
    let mut out: Vec<Tagged> = Vec::with_capacity(tokens.len());
    let mut seen_verb = false;
    for (i, t) in tokens.iter().enumerate() {
        let prev = out.last().map(|p: &Tagged| p.tag);
        let next = tokens.get(i + 1).map(|t| t.lower.as_str());
        let (mut tag, mut known) = tag_word(t, i, prev, next, seen_verb, cat);
        // "Emily sits" vs "Slowly, Tom walks": a capitalised first word in -ly is a name unless a
        // comma or another name follows.
        if i == 0
            && tag == Tag::RB
            && !contains(ADVERBS, &t.lower)
            && t.text.chars().next().is_some_and(char::is_uppercase)
        {
            let adverb =
                tokens.get(1).is_some_and(|n| n.text == "," || n.text.chars().next().is_some_and(char::is_uppercase));
            if !adverb {
                (tag, known) = (Tag::NNP, true);
            }
        }
        seen_verb |= tag.is_verb();
        let lemma = match tag {
            Tag::NN if cat.resolve(&t.lower).is_none() && t.lower.ends_with('s') && !known => lemmatize_noun(&t.lower),
            _ if AUXILIARIES.iter().any(|(f, _, _)| *f == t.lower) && tag.is_verb() => {
                AUXILIARIES.iter().find(|(f, _, _)| *f == t.lower).map(|a| a.1.to_string()).unwrap_or_default()
            }
            Tag::NNS if contains(PLURALIA_TANTUM, &t.lower) => t.lower.clone(),
            _ => lemmatize(&t.text, tag),
        };
        out.push(Tagged { text: t.text.clone(), lower: t.lower.clone(), tag, lemma, known });
    }
    out
}

fn tag_word(
    t: &Token,
    i: usize,
    prev: Option<Tag>,
    next: Option<&str>,
    seen_verb: bool,
    cat: &Catalogue,
) -> (Tag, bool) {
    let w = t.lower.as_str();
    if t.is_punct() {
        return (Tag::Punct, true);
    }
    if w == "'s" {
        return (
            if prev.is_some_and(Tag::is_noun) && next.is_some_and(|n| !is_verbish(n)) { Tag::POS } else { Tag::VBZ },
            true,
        );
    }
    if number_value(w).is_some() && !(w == "one" && prev == Some(Tag::DT)) {
        return (Tag::CD, true);
    }
    let capital = t.text.chars().next().is_some_and(char::is_uppercase);
    let after_subject = matches!(prev, Some(Tag::NN | Tag::NNS | Tag::NNP | Tag::PRP));
    let noun_context = matches!(prev, Some(Tag::DT | Tag::JJ | Tag::CD | Tag::PRPS | Tag::POS));
    // Closed classes first.
    if w == "there" && next.is_some_and(|n| matches!(n, "is" | "are" | "was" | "were" | "'s" | "stands" | "hangs")) {
        return (Tag::EX, true);
    }
    if w == "which" || w == "where" || w == "whose" {
        return (Tag::WDT, true);
    }
    if w == "that" && matches!(prev, Some(Tag::NN | Tag::NNS)) {
        return (Tag::WDT, true);
    }
    if w == "to" {
        return (Tag::TO, true);
    }
    if w == "her" {
        let noun_next = next.is_some_and(|n| known_noun(n, cat) || contains(ADJECTIVES, n));
        return (if noun_next { Tag::PRPS } else { Tag::PRP }, true);
    }
    if contains(DETERMINERS, w) {
        return (Tag::DT, true);
    }
    if contains(PRONOUNS, w) {
        return (Tag::PRP, true);
    }
    if contains(POSSESSIVES, w) {
        return (Tag::PRPS, true);
    }
    if contains(CONJUNCTIONS, w) {
        return (Tag::CC, true);
    }
    if contains(MODALS, w) {
        return (Tag::MD, true);
    }
    if let Some(&(_, _, tag)) = AUXILIARIES.iter().find(|(f, _, _)| *f == w) {
        return (penn(tag), true);
    }
    // Direction particles right after a verb ("turns right") before any other reading.
    if matches!(w, "right" | "left" | "around" | "back" | "away" | "up" | "down" | "forward" | "aside")
        && prev.is_some_and(Tag::is_verb)
        && next.is_none_or(|n| !known_noun(n, cat))
    {
        return (Tag::RB, true);
    }
    if contains(PREPOSITIONS, w) && !(w == "back" || w == "outside" && next.is_none()) {
        return (Tag::IN, true);
    }
    // Open classes: capitalised words not at the start are names.
    let verb = known_verb_lemma(w);
    let noun = known_noun(w, cat);
    if capital && i > 0 && !(noun && t.text.chars().skip(1).all(char::is_lowercase) && cat.resolve(w).is_some()) {
        return (Tag::NNP, true);
    }
    if capital
        && i == 0
        && verb.is_none()
        && !noun
        && !contains(ADVERBS, w)
        && !contains(ADJECTIVES, w)
        && !w.ends_with("ly")
    {
        return (Tag::NNP, true);
    }
    let plural = w.ends_with('s')
        && !w.ends_with("ss")
        && cat.resolve(w).is_none()
        && !contains(PLURALIA_TANTUM, w)
        && (cat.resolve(&lemmatize_noun(w)).is_some()
            || cat.resolve_room(&lemmatize_noun(w)).is_some()
            || contains(PERSON_NOUNS, &lemmatize_noun(w))
            || contains(COMMON_NOUNS, &lemmatize_noun(w)))
        || IRREGULAR_NOUNS.iter().any(|(p, _)| *p == w);
    let noun_tag = if plural { Tag::NNS } else { Tag::NN };
    match (verb.is_some(), noun) {
        (true, true) => {
            // "the record button" vs "Tom sits and calls": the previous word decides.
            let verb_context = after_subject
                || matches!(prev, Some(Tag::MD | Tag::TO | Tag::RB))
                || prev == Some(Tag::CC) && seen_verb
                || prev.is_none() && next.is_some_and(|n| contains(DETERMINERS, n) || contains(PREPOSITIONS, n));
            if verb_context && !noun_context {
                (verb_form(w), true)
            } else {
                (noun_tag, true)
            }
        }
        (true, false) => {
            if prev == Some(Tag::IN) {
                // "calls with phone": a verb-looking word after a preposition is its object.
                (noun_tag, true)
            } else if noun_context && w.ends_with("ing") && w.len() > 5 {
                // "a boxing ring", "an organized working shop": gerund as modifier.
                (Tag::JJ, true)
            } else if noun_context && w.ends_with("ed") && w.len() > 4 {
                (Tag::JJ, true)
            } else if noun_context {
                // "a boxing ring": a verb-looking word after a determiner or adjective is a noun.
                (noun_tag, true)
            } else {
                (verb_form(w), true)
            }
        }
        (false, true) => (noun_tag, true),
        (false, false) => {
            if contains(ADVERBS, w) || w.ends_with("ly") && w.len() > 4 {
                return (Tag::RB, true);
            }
            if contains(ADJECTIVES, w) || has_adjective_suffix(w) {
                return (Tag::JJ, true);
            }
            if w.ends_with("ed") && w.len() > 4 {
                // "an organized office desk": a participle before a noun is an adjective.
                let before_noun = next.is_some_and(|n| known_noun(n, cat) || contains(ADJECTIVES, n));
                return (if noun_context || before_noun { Tag::JJ } else { Tag::VBD }, true);
            }
            if w.ends_with("ing") && w.len() > 5 {
                let before_noun = next.is_some_and(|n| known_noun(n, cat));
                return (if noun_context && before_noun { Tag::JJ } else { Tag::VBG }, false);
            }
            if w.chars().all(|c| c.is_ascii_digit() || c == '.') {
                return (Tag::CD, true);
            }
            // Unknown: after a subject it is most likely the verb, otherwise a noun.
            if (after_subject || prev == Some(Tag::CC) && seen_verb) && !noun_context && !seen_verb_just_before(prev) {
                (if w.ends_with('s') { Tag::VBZ } else { Tag::VB }, false)
            } else {
                (Tag::NN, false)
            }
        }
    }
}

fn seen_verb_just_before(prev: Option<Tag>) -> bool {
    prev.is_some_and(Tag::is_verb)
}

fn is_verbish(w: &str) -> bool {
    known_verb_lemma(w).is_some() && !w.ends_with('s')
}

fn penn(name: &str) -> Tag {
    match name {
        "VBZ" => Tag::VBZ,
        "VBP" => Tag::VBP,
        "VBD" => Tag::VBD,
        "VBN" => Tag::VBN,
        "VBG" => Tag::VBG,
        _ => Tag::VB,
    }
}

/// The verb tag from the form ("sits" VBZ, "sitting" VBG, "sat" VBD).
fn verb_form(w: &str) -> Tag {
    if let Some(&(f, l)) = IRREGULAR_VERBS.iter().find(|(f, _)| *f == w) {
        if f == l || contains(VERBS, f) && f != "saw" && f != "left" && f != "lay" {
            return Tag::VB;
        }
        if f.ends_with('s') {
            return Tag::VBZ;
        }
        if f.ends_with("ing") {
            return Tag::VBG;
        }
        if f.ends_with('n') {
            return Tag::VBN;
        }
        return Tag::VBD;
    }
    if contains(VERBS, w) {
        Tag::VB
    } else if w.ends_with("ing") {
        Tag::VBG
    } else if w.ends_with("ed") {
        Tag::VBD
    } else if w.ends_with('s') {
        Tag::VBZ
    } else {
        Tag::VB
    }
}

fn has_adjective_suffix(w: &str) -> bool {
    w.len() > 5
        && ["ous", "ful", "ive", "able", "ible", "ical", "less", "ish", "ern", "ary", "ic", "ant", "ent", "y"]
            .iter()
            .any(|s| w.ends_with(s))
        && !w.ends_with("ly")
}

#[cfg(test)]
mod tests {
    use super::super::token::tokenize;
    use super::*;

    fn tags(s: &str) -> Vec<&'static str> {
        tag(&tokenize(s), &Catalogue::default()).into_iter().map(|t| t.tag.name()).collect()
    }

    #[test]
    fn direction_tags() {
        assert_eq!(tags("Tom sits and calls with phone"), ["NNP", "VBZ", "CC", "VBZ", "IN", "NN"]);
        assert_eq!(tags("The man walks unbelievably to the road"), ["DT", "NN", "VBZ", "RB", "TO", "DT", "NN"]);
        assert_eq!(tags("Tom turns right"), ["NNP", "VBZ", "RB"]);
        assert_eq!(tags("Worker is sawing the wood"), ["NN", "VBZ", "VBG", "DT", "NN"]);
    }
}
