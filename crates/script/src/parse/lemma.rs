//! Lemmatising (§3.2: the SSG stores lemmas, "sits" → "sit", "chairs" → "chair").

use super::lexicon::{contains, IRREGULAR_NOUNS, IRREGULAR_VERBS, PLURALIA_TANTUM, VERBS};
use super::penn::Tag;

/// The lemma of a word with its tag: nouns singular, verbs base form, everything else lower case.
pub fn lemmatize(word: &str, tag: Tag) -> String {
    let lower = word.to_lowercase();
    match tag {
        Tag::NNS => lemmatize_noun(&lower),
        t if t.is_verb() => lemmatize_verb(&lower),
        _ => lower,
    }
}

/// The singular of a (lower-case) noun: irregulars, -ies, -ves, -es after sibilants, -s.
pub fn lemmatize_noun(lower: &str) -> String {
    if let Some(&(_, s)) = IRREGULAR_NOUNS.iter().find(|(p, _)| *p == lower) {
        return s.to_string();
    }
    if contains(PLURALIA_TANTUM, lower) || lower.len() <= 3 {
        return lower.to_string();
    }
    if let Some(stem) = lower.strip_suffix("ies") {
        return format!("{stem}y");
    }
    for suf in ["ches", "shes", "sses", "xes", "zes", "oes"] {
        if lower.ends_with(suf) {
            return lower[..lower.len() - 2].to_string();
        }
    }
    if lower.ends_with("ss") || lower.ends_with("us") || lower.ends_with("is") {
        return lower.to_string();
    }
    lower.strip_suffix('s').unwrap_or(lower).to_string()
}

/// The lemma of a known verb form, `None` when the word is no form of a verb in the list.
pub fn known_verb_lemma(lower: &str) -> Option<String> {
    if let Some(&(_, l)) = IRREGULAR_VERBS.iter().find(|(f, _)| *f == lower) {
        return Some(l.to_string());
    }
    if contains(VERBS, lower) {
        return Some(lower.to_string());
    }
    verb_candidates(lower).into_iter().find(|c| contains(VERBS, c))
}

/// The base form of a verb: the list first, then suffix rules for verbs it does not know.
pub fn lemmatize_verb(lower: &str) -> String {
    if let Some(l) = known_verb_lemma(lower) {
        return l;
    }
    let n = lower.len();
    if let Some(stem) = lower.strip_suffix("ing").filter(|_| n > 5) {
        return guess_stem(stem);
    }
    if let Some(stem) = lower.strip_suffix("ied") {
        return format!("{stem}y");
    }
    if let Some(stem) = lower.strip_suffix("ed").filter(|_| n > 4) {
        return guess_stem(stem);
    }
    if let Some(stem) = lower.strip_suffix("ies").filter(|_| n > 4) {
        return format!("{stem}y");
    }
    for suf in ["ches", "shes", "sses", "xes", "zes", "oes"] {
        if lower.ends_with(suf) {
            return lower[..n - 2].to_string();
        }
    }
    if lower.ends_with('s') && !lower.ends_with("ss") && n > 3 {
        return lower[..n - 1].to_string();
    }
    lower.to_string()
}

/// Possible base forms of an inflected verb, most likely first.
fn verb_candidates(lower: &str) -> Vec<String> {
    let mut out = Vec::new();
    let stems = |stem: &str, out: &mut Vec<String>| {
        out.push(stem.to_string());
        out.push(format!("{stem}e"));
        if let Some(u) = undouble(stem) {
            out.push(u);
        }
        if let Some(s) = stem.strip_suffix('i') {
            out.push(format!("{s}y"));
        }
    };
    if let Some(stem) = lower.strip_suffix("ing") {
        stems(stem, &mut out);
        if let Some(s) = stem.strip_suffix('y') {
            out.push(format!("{s}ie"));
        }
    }
    if let Some(stem) = lower.strip_suffix("ed") {
        stems(stem, &mut out);
    }
    if let Some(stem) = lower.strip_suffix('s') {
        out.push(stem.to_string());
        if let Some(s) = stem.strip_suffix('e') {
            out.push(s.to_string());
            if let Some(s) = s.strip_suffix('i') {
                out.push(format!("{s}y"));
            }
        }
    }
    out
}

/// "sitt" → "sit", "stopp" → "stop"; not "ll"/"ss"/"zz" ("call", "press").
fn undouble(stem: &str) -> Option<String> {
    let b = stem.as_bytes();
    let n = b.len();
    (stem.is_ascii() && n >= 3 && b[n - 1] == b[n - 2] && !matches!(b[n - 1], b'l' | b's' | b'z' | b'e' | b'o'))
        .then(|| stem[..n - 1].to_string())
}

/// A stem for an unknown verb: undouble a doubled consonant, add the `e` that -ing/-ed dropped
/// after v, c, z, u or a consonant+l/r ending of a long vowel.
fn guess_stem(stem: &str) -> String {
    if let Some(u) = undouble(stem) {
        return u;
    }
    let b = stem.as_bytes();
    let last = *b.last().unwrap_or(&b'a');
    let vowel = |c: u8| matches!(c, b'a' | b'e' | b'i' | b'o' | b'u');
    if matches!(last, b'v' | b'c' | b'z' | b'u' | b'g') && !stem.ends_with("ng") {
        return format!("{stem}e");
    }
    // consonant-vowel-consonant with a single vowel before ("creat" no, "organiz" yes via z).
    if b.len() >= 3
        && !vowel(last)
        && vowel(b[b.len() - 2])
        && !vowel(b[b.len() - 3])
        && matches!(last, b't' | b'd' | b'k' | b'p' | b'm' | b'n' | b'r' | b's')
        && b.len() <= 4
    {
        return format!("{stem}e");
    }
    stem.to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn verbs() {
        for (f, l) in [
            ("sits", "sit"),
            ("sat", "sit"),
            ("sitting", "sit"),
            ("hangs", "hang"),
            ("hung", "hang"),
            ("is", "is"),
            ("writes", "write"),
            ("wrote", "write"),
            ("writing", "write"),
            ("pushes", "push"),
            ("punching", "punch"),
            ("serving", "serve"),
            ("sawing", "saw"),
            ("hammering", "hammer"),
            ("stopped", "stop"),
            ("hurried", "hurry"),
            ("lying", "lie"),
            ("calls", "call"),
            ("goes", "go"),
            ("cries", "cry"),
            ("organized", "organize"),
            ("blorped", "blorp"),
            ("sneezing", "sneeze"),
        ] {
            // "is" is an auxiliary, handled by the tagger, not the verb list.
            let want = if f == "is" { "is" } else { l };
            assert_eq!(lemmatize_verb(f), want, "{f}");
        }
    }

    #[test]
    fn nouns() {
        for (f, l) in [
            ("chairs", "chair"),
            ("shelves", "shelf"),
            ("men", "man"),
            ("boxes", "box"),
            ("benches", "bench"),
            ("bodies", "body"),
            ("headphones", "headphones"),
            ("glass", "glass"),
            ("sofas", "sofa"),
        ] {
            assert_eq!(lemmatize_noun(f), l, "{f}");
        }
    }
}
