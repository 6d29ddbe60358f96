//! "Did you mean" suggestions for unknown words: the closest known words by edit distance.

use super::lexicon::VERBS;
use crate::catalogue::Catalogue;

/// Optimal-string-alignment distance (Levenshtein plus adjacent swaps, "jumsp" → "jumps" = 1).
pub fn edit_distance(a: &str, b: &str) -> usize {
    let a: Vec<char> = a.chars().collect();
    let b: Vec<char> = b.chars().collect();
    let mut d = vec![vec![0usize; b.len() + 1]; a.len() + 1];
    for (i, row) in d.iter_mut().enumerate() {
        row[0] = i;
    }
    for (j, v) in d[0].iter_mut().enumerate() {
        *v = j;
    }
    for i in 1..=a.len() {
        for j in 1..=b.len() {
            let cost = usize::from(a[i - 1] != b[j - 1]);
            let mut v = (d[i - 1][j] + 1).min(d[i][j - 1] + 1).min(d[i - 1][j - 1] + cost);
            if i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] {
                v = v.min(d[i - 2][j - 2] + 1);
            }
            d[i][j] = v;
        }
    }
    d[a.len()][b.len()]
}

/// Up to three candidates closest to `word`, nearest first, ties alphabetical (deterministic).
/// Only candidates within 1 + len/4 edits are offered.
pub fn closest<'a>(word: &str, candidates: impl IntoIterator<Item = &'a str>) -> Vec<String> {
    let w = word.to_lowercase();
    let limit = 1 + w.chars().count() / 4;
    let mut scored: Vec<(usize, &str)> = candidates
        .into_iter()
        .filter(|c| *c != w)
        .map(|c| (edit_distance(&w, c), c))
        .filter(|&(d, c)| d <= limit && d < c.chars().count())
        .collect();
    scored.sort();
    scored.dedup_by(|a, b| a.1 == b.1);
    scored.into_iter().take(3).map(|(_, c)| c.to_string()).collect()
}

/// Closest catalogue words (objects and rooms) and known verbs to an unknown word.
pub fn suggestions(word: &str, cat: &Catalogue) -> Vec<String> {
    closest(word, cat.known_words().chain(VERBS.iter().copied()))
}

/// Closest catalogue words (objects and rooms), for an unknown object noun.
/// Falls back to prepositions and verbs when no object is close ("betwen" → "between").
pub fn noun_suggestions(word: &str, cat: &Catalogue) -> Vec<String> {
    let s = closest(word, cat.known_words());
    if !s.is_empty() {
        return s;
    }
    closest(word, super::lexicon::PREPOSITIONS.iter().chain(VERBS).copied())
}

/// Closest known verbs, for an unknown verb.
pub fn verb_suggestions(word: &str) -> Vec<String> {
    let base = super::lemma::lemmatize_verb(&word.to_lowercase());
    let mut a = closest(word, VERBS.iter().copied());
    for s in closest(&base, VERBS.iter().copied()) {
        if !a.contains(&s) {
            a.push(s);
        }
    }
    a.sort_by_key(|s| (edit_distance(&base, s).min(edit_distance(word, s)), s.clone()));
    a.truncate(3);
    a
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn distances() {
        assert_eq!(edit_distance("sofa", "soda"), 1);
        assert_eq!(edit_distance("jumsp", "jumps"), 1);
        assert_eq!(edit_distance("", "abc"), 3);
        assert_eq!(closest("chiar", ["chair", "desk", "char"]), ["chair", "char"]);
    }
}
