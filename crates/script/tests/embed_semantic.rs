//! `--semantic`: unknown words taught to the catalogue through embeddings, every replacement
//! reported (feature `embeddings`; skipped when the model is not installed).
#![cfg(feature = "embeddings")]

use inbetween_script::catalogue::builtin::builtin;
use inbetween_script::embed::Embedder;
use inbetween_script::parse::parse_script;
use inbetween_script::semantic::teach_unknown_words;

#[test]
fn an_unknown_furniture_word_is_read_as_its_nearest_category_and_said_so() {
    let dir = Embedder::default_dir();
    if !dir.join("model.safetensors").is_file() {
        println!("skipped: no model at {}, run scripts/fetch-minilm.sh", dir.display());
        return;
    }
    let text = "A footrest is near a desk$.";
    let cat = builtin();
    assert!(parse_script(text, &cat).diagnostics.iter().any(|d| d.word.as_deref() == Some("footrest")));
    let (taught, notes) = teach_unknown_words(text, &cat, None).unwrap();
    assert_eq!(notes.len(), 1, "{notes:?}");
    assert!(notes[0].message.contains("footrest") && notes[0].message.contains("cosine"), "{}", notes[0].message);
    let parsed = parse_script(text, &taught);
    assert!(parsed.diagnostics.is_empty(), "{:?}", parsed.diagnostics);
    assert_eq!(parsed.sentences[0].ssg.objects.len(), 2);
}

#[test]
fn a_nonsense_word_stays_unknown() {
    let dir = Embedder::default_dir();
    if !dir.join("model.safetensors").is_file() {
        println!("skipped: no model at {}, run scripts/fetch-minilm.sh", dir.display());
        return;
    }
    let (_, notes) = teach_unknown_words("A democracy is near a desk$.", &builtin(), None).unwrap();
    assert!(notes.is_empty(), "{notes:?}");
}
