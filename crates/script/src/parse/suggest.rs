//! "Did you mean" suggestions for unknown words: the closest known words by edit distance.

use super::lexicon::VERBS;
use crate::catalogue::Catalogue;

/// Optimal-string-alignment distance (Levenshtein plus adjacent swaps, "jumsp" → "jumps" = 1).
pub fn edit_distance(a: &str, b: &str) -> usize {
    let a: Vec<char> = a.chars().collect();
    let b: Vec<char> = b.chars().collect();
    osa(&a, &b)
}

/// [`edit_distance`] of two character sequences (one table, row-major).
fn osa(a: &[char], b: &[char]) -> usize {
    let w = b.len() + 1;
    let mut d = vec![0usize; (a.len() + 1) * w];
    for i in 0..=a.len() {
        d[i * w] = i;
    }
    for (j, v) in d[..w].iter_mut().enumerate() {
        *v = j;
    }
    for i in 1..=a.len() {
        for j in 1..=b.len() {
            let cost = usize::from(a[i - 1] != b[j - 1]);
            let mut v = (d[(i - 1) * w + j] + 1).min(d[i * w + j - 1] + 1).min(d[(i - 1) * w + j - 1] + cost);
            if i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] {
                v = v.min(d[(i - 2) * w + j - 2] + 1);
            }
            d[i * w + j] = v;
        }
    }
    d[a.len() * w + b.len()]
}

/// Up to three candidates closest to `word`, nearest first, ties alphabetical (deterministic).
/// Only candidates within 1 + len/4 edits are offered.
pub fn closest<'a>(word: &str, candidates: impl IntoIterator<Item = &'a str>) -> Vec<String> {
    let w = word.to_lowercase();
    let wc: Vec<char> = w.chars().collect();
    let limit = 1 + wc.len() / 4;
    // The distance is at least the difference in length: a candidate longer or shorter by more
    // than the limit is never offered, so it is not measured.
    let mut scored: Vec<(usize, &str)> = candidates
        .into_iter()
        .filter(|c| *c != w)
        .filter_map(|c| {
            let n = c.chars().count();
            if n.abs_diff(wc.len()) > limit {
                return None;
            }
            let cc: Vec<char> = c.chars().collect();
            Some((osa(&wc, &cc), c, n))
        })
        .filter(|&(d, _, n)| d <= limit && d < n)
        .map(|(d, c, _)| (d, c))
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

    /// `closest` as it was before the length filter (every candidate measured).
    fn closest_reference<'a>(word: &str, candidates: impl IntoIterator<Item = &'a str>) -> Vec<String> {
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

    #[test]
    fn the_length_filter_offers_what_measuring_every_candidate_offers() {
        let cat = crate::catalogue::builtin::builtin();
        let words: Vec<&str> = cat.known_words().chain(VERBS.iter().copied()).collect();
        // Every known word with one letter dropped, doubled or swapped, plus words of every length.
        let mut probes: Vec<String> = Vec::new();
        for w in words.iter().step_by(3) {
            let c: Vec<char> = w.chars().collect();
            for i in 0..c.len() {
                let mut drop = c.clone();
                drop.remove(i);
                probes.push(drop.iter().collect());
                let mut double = c.clone();
                double.insert(i, c[i]);
                probes.push(double.iter().collect());
                if i + 1 < c.len() {
                    let mut swap = c.clone();
                    swap.swap(i, i + 1);
                    probes.push(swap.iter().collect());
                }
            }
        }
        probes.extend((0..24).map(|n| "xq".repeat(n / 2) + &"é".repeat(n % 2)));
        for p in &probes {
            assert_eq!(closest(p, words.iter().copied()), closest_reference(p, words.iter().copied()), "{p}");
        }
        assert!(probes.len() > 1000, "{}", probes.len());
    }
}
