//! Tagging, lemmas, counts and diagnostics for unknown words (§3.2).

mod parse_common;

use inbetween_script::parse::{
    lemmatize, lemmatize_noun, lemmatize_verb, number_value, parse_script, parse_sentence, suggestions, tag, tokenize,
    Tag,
};
use inbetween_script::sentences::split;
use inbetween_script::ssg::Relation;
use parse_common::paper_catalogue;

fn tags(s: &str) -> Vec<&'static str> {
    tag(&tokenize(s), &paper_catalogue()).into_iter().map(|t| t.tag.name()).collect()
}

#[test]
fn penn_tags_of_caption_sentences() {
    assert_eq!(
        tags("In the room, an organized office desk is near a bed"),
        ["IN", "DT", "NN", ".", "DT", "JJ", "NN", "NN", "VBZ", "IN", "DT", "NN"]
    );
    assert_eq!(tags("Eve sits on the couch"), ["NNP", "VBZ", "IN", "DT", "NN"]);
    assert_eq!(tags("There are two chairs"), ["EX", "VBP", "CD", "NNS"]);
    assert_eq!(
        tags("Anny walks to the recorder and pushes the record button"),
        ["NNP", "VBZ", "TO", "DT", "NN", "CC", "VBZ", "DT", "NN", "NN"]
    );
    assert_eq!(
        tags("There is a boxing ring above which a boxingbag hangs"),
        ["EX", "VBZ", "DT", "JJ", "NN", "IN", "WDT", "DT", "NN", "VBZ"]
    );
    assert_eq!(tags("Tom sat on his chair"), ["NNP", "VBD", "IN", "PRP$", "NN"]);
}

#[test]
fn lemmas() {
    for (w, l) in
        [("sits", "sit"), ("sat", "sit"), ("hangs", "hang"), ("hung", "hang"), ("writes", "write"), ("wrote", "write")]
    {
        assert_eq!(lemmatize_verb(w), l);
    }
    for (w, l) in [
        ("chairs", "chair"),
        ("shelves", "shelf"),
        ("women", "woman"),
        ("couches", "couch"),
        ("headphones", "headphones"),
    ] {
        assert_eq!(lemmatize_noun(w), l);
    }
    assert_eq!(lemmatize("Sitting", Tag::VBG), "sit");
    assert_eq!(lemmatize("Stopped", Tag::VBD), "stop");
    // "is"/"are" are "be": the tagger lemmatises auxiliaries.
    let t = tag(&tokenize("The chairs are near the desk and the lamp is on it"), &paper_catalogue());
    assert_eq!(t[2].lemma, "be");
    assert_eq!(t[9].lemma, "be");
    assert_eq!(t[1].lemma, "chair");
}

#[test]
fn counts() {
    assert_eq!(number_value("two"), Some(2));
    assert_eq!(number_value("12"), Some(12));
    assert_eq!(number_value("chair"), None);
    let cat = paper_catalogue();
    let p = parse_script(
        "Two chairs are near a table$ There are 3 lamps and an old piano$ A couple of stools are by the bed$",
        &cat,
    );
    let g = &p.sentences[0].ssg;
    assert_eq!((g.objects[0].category.as_str(), g.objects[0].count), ("chair", 2));
    assert_eq!((g.objects[1].category.as_str(), g.objects[1].count), ("table", 1));
    assert_eq!(g.objects[0].word, "chairs");
    let g = &p.sentences[1].ssg;
    assert_eq!(g.objects[0].count, 3);
    assert_eq!((g.objects[1].count, g.objects[1].attributes.clone()), (1, vec!["old".to_string()]));
    let g = &p.sentences[2].ssg;
    assert_eq!((g.objects[0].category.as_str(), g.objects[0].count), ("stool", 2));
    assert_eq!(g.relations[0].relation, Relation::Near);
}

#[test]
fn relation_phrases() {
    let cat = paper_catalogue();
    for (text, rel) in [
        ("A lamp is on top of the desk$", Relation::On),
        ("A lamp is beside the bed$", Relation::NextTo),
        ("A chair is by the desk$", Relation::Near),
        ("A chair is in the front of the desk$", Relation::InFrontOf),
        ("A chair is before the desk$", Relation::InFrontOf),
        ("A picture is hanging above the bed$", Relation::Above),
        ("A stool is under the table$", Relation::Under),
        ("A shelf is behind the sofa$", Relation::Behind),
        ("A bottle is in the shelf$", Relation::In),
        ("A sofa is next to the piano$", Relation::NextTo),
    ] {
        let (g, d) = parse_sentence(&split(text)[0], &cat);
        assert!(d.is_empty(), "{text}: {d:?}");
        assert_eq!(g.relations.len(), 1, "{text}");
        assert_eq!(g.relations[0].relation, rel, "{text}");
        assert_eq!(g.objects[g.relations[0].active].count, 1);
    }
    // The relation first: "On the desk there is a lamp" → lamp On desk.
    let (g, _) = parse_sentence(&split("On the desk there is a lamp$")[0], &cat);
    assert_eq!(
        (g.objects[g.relations[0].active].category.as_str(), g.objects[g.relations[0].anchor].category.as_str()),
        ("lamp", "desk")
    );
}

#[test]
fn unknown_words_get_suggestions_and_the_rest_runs() {
    let cat = paper_catalogue();
    let p = parse_script("A chiar is near the dsk$\nEve jumsp to the desk.\nA lamp is across the desk$\ncamera lefft\nEve sits on the sofa.", &cat);
    let d = &p.diagnostics;
    let find = |w: &str| {
        d.iter().find(|x| x.word.as_deref() == Some(w)).unwrap_or_else(|| panic!("no diagnostic for {w}: {d:?}"))
    };
    let chiar = find("chiar");
    assert_eq!(chiar.suggestions.first().map(String::as_str), Some("chair"));
    assert_eq!((chiar.at.line, chiar.at.sentence), (1, 1));
    assert!(chiar.to_string().contains("line 1, sentence 1") && chiar.to_string().contains("chair"));
    assert_eq!(find("dsk").suggestions.first().map(String::as_str), Some("desk"));
    let jumsp = find("jumsp");
    assert_eq!(jumsp.suggestions.first().map(String::as_str), Some("jump"));
    assert_eq!(jumsp.at.line, 2);
    assert!(find("across").message.contains("relation"));
    assert_eq!(find("lefft").suggestions, ["left"]);
    // The last sentence still parses.
    let last = p.sentences.last().unwrap();
    assert_eq!(last.ssg.characters[0].actions[0].verb, "sit");
    assert_eq!(last.ssg.objects[0].category, "sofa");
    // The scene with a known anchor keeps its known object.
    assert_eq!(p.sentences[2].ssg.objects.len(), 2);
    assert!(suggestions("sofaa", &cat).contains(&"sofa".to_string()));
    assert!(suggestions("wlak", &cat).contains(&"walk".to_string()));
}

#[test]
fn unusable_sentences_get_a_diagnostic() {
    let cat = paper_catalogue();
    let p = parse_script("Very quickly!\nIt is near$\nEve walks to the sofa.", &cat);
    assert_eq!(p.sentences.len(), 3);
    assert!(p.diagnostics.iter().any(|d| d.at.sentence == 1), "{:?}", p.diagnostics);
    assert!(p.diagnostics.iter().any(|d| d.at.sentence == 2), "{:?}", p.diagnostics);
    assert!(p.diagnostics.iter().all(|d| d.at.sentence != 3));
    assert_eq!(p.sentences[2].ssg.characters[0].name, "Eve");
}

#[test]
fn pronouns_carry_over_sentences() {
    let cat = paper_catalogue();
    let p = parse_script("Tom walks to the piano. He plays it madly.", &cat);
    let g = &p.sentences[1].ssg;
    assert_eq!(g.characters[0].name, "Tom");
    let a = &g.characters[0].actions[0];
    assert_eq!((a.verb.as_str(), a.manner.clone()), ("play", vec!["madly".to_string()]));
    assert_eq!(g.objects[a.target.unwrap()].category, "piano");
    assert_eq!(g.objects[0].sentence, 1);
    // Alone, "it" refers to nothing: a diagnostic, not a panic.
    let (g, d) = parse_sentence(&split("He plays it.")[0], &cat);
    assert!(g.characters.is_empty());
    assert!(!d.is_empty());
}

#[test]
fn names_and_leading_adverbs() {
    let cat = paper_catalogue();
    let p = parse_script("Emily sits on the chair and plays piano. Slowly, Tom walks to the sofa.", &cat);
    let emily = &p.sentences[0].ssg.characters[0];
    assert_eq!(emily.name, "Emily");
    assert_eq!(emily.actions.iter().map(|a| a.verb.as_str()).collect::<Vec<_>>(), ["sit", "play"]);
    let g = &p.sentences[1].ssg;
    assert_eq!(g.characters[0].name, "Tom");
    assert_eq!(g.characters[0].actions[0].manner, ["slowly"]);
    assert_eq!(g.objects[g.characters[0].actions[0].target.unwrap()].category, "sofa");
}
