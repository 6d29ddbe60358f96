//! WordPiece tokenisation and pooling math of the `embeddings` feature; needs no model.
#![cfg(feature = "embeddings")]

use inbetween_script::embed::wordpiece::WordPiece;
use inbetween_script::embed::{cosine, l2_normalize, mean_pool, Embedder};

/// A tiny vocabulary: the id of a token is its line number.
const VOCAB: &str = "[PAD]\n[UNK]\n[CLS]\n[SEP]\nthe\nun\n##aff\n##able\nrun\n##ning\n,\n!\ncafe\noffice\nchair\nu\n##af\n##a\n中\nbedside\ntable\n";

fn tiny() -> WordPiece {
    WordPiece::from_vocab_text(VOCAB).unwrap()
}

#[test]
fn hand_computed_ids() {
    let wp = tiny();
    assert_eq!(wp.len(), 21);
    // "Unaffable" → un ##aff ##able (longest match first: "un" beats "u", "##aff" beats "##af"/"##a");
    // "café" loses its accent; "," and "!" split off.
    assert_eq!(wp.tokenize("Unaffable running, Café!"), ["un", "##aff", "##able", "run", "##ning", ",", "cafe", "!"]);
    assert_eq!(wp.encode("Unaffable running, Café!", 256), [2, 5, 6, 7, 8, 9, 10, 12, 11, 3]);
}

#[test]
fn uncoverable_words_become_unk() {
    let wp = tiny();
    // "unx": "un" matches but "##x" does not, so the whole word is [UNK] (not "un" + [UNK]).
    assert_eq!(wp.encode("unx the", 256), [2, 1, 4, 3]);
    // Over 100 characters is [UNK] without trying.
    let long = "a".repeat(101);
    assert_eq!(wp.word_pieces(&long), ["[UNK]"]);
}

#[test]
fn basic_tokeniser_cleans_and_splits() {
    // Control characters vanish, tabs/newlines are spaces, CJK ideographs stand alone, punctuation
    // (ASCII and Unicode) splits off, upper case and accents fold.
    assert_eq!(
        WordPiece::basic_tokens("The\tRUN\u{7}NING\n中the «Éte»"),
        ["the", "running", "中", "the", "«", "ete", "»"]
    );
    let wp = tiny();
    assert_eq!(wp.encode("the中the", 256), [2, 4, 18, 4, 3]);
    assert_eq!(wp.encode("", 256), [2, 3]);
}

#[test]
fn pad_free_truncation() {
    let wp = tiny();
    // Each text alone, no [PAD]; at most max_len ids with [CLS] and [SEP] kept.
    assert_eq!(wp.encode("the the the the", 4), [2, 4, 4, 3]);
    assert_eq!(wp.encode("the the", 256), [2, 4, 4, 3]);
    assert!(!wp.encode("the the the the", 256).contains(&0));
}

#[test]
fn glued_compounds_split_into_vocabulary_words() {
    let wp = tiny();
    assert_eq!(wp.split_compound("officechair"), "office chair");
    assert_eq!(wp.split_compound("bedsidetable"), "bedside table");
    assert_eq!(wp.split_compound("chair"), "chair");
    assert_eq!(wp.split_compound("xyzchair"), "xyzchair");
}

#[test]
fn vocabulary_needs_special_tokens() {
    let err = WordPiece::from_vocab_text("the\n[CLS]\n[SEP]\n").unwrap_err();
    assert!(err.to_string().contains("[UNK]"), "{err}");
}

#[test]
fn mean_pooling_and_normalisation() {
    // Three tokens × two dimensions: the mean of each column.
    let hidden = [1.0, 2.0, 3.0, 4.0, 5.0, 9.0];
    assert_eq!(mean_pool(&hidden, 3, 2), [3.0, 5.0]);
    assert_eq!(mean_pool(&[], 0, 2), [0.0, 0.0]);
    let mut v = vec![3.0, 4.0];
    l2_normalize(&mut v);
    assert!((v[0] - 0.6).abs() < 1e-6 && (v[1] - 0.8).abs() < 1e-6);
    let mut zero = vec![0.0, 0.0];
    l2_normalize(&mut zero);
    assert_eq!(zero, [0.0, 0.0]);
    assert!((cosine(&[1.0, 0.0], &[1.0, 1.0]) - std::f32::consts::FRAC_1_SQRT_2).abs() < 1e-6);
    assert_eq!(cosine(&[0.0, 0.0], &[1.0, 1.0]), 0.0);
}

#[test]
fn missing_model_names_the_file_and_the_script() {
    let dir = tempfile::tempdir().unwrap();
    let err = Embedder::load(dir.path()).unwrap_err().to_string();
    assert!(err.contains("config.json"), "{err}");
    assert!(err.contains("scripts/fetch-minilm.sh"), "{err}");
    std::fs::write(dir.path().join("config.json"), "{}").unwrap();
    let err = Embedder::load(dir.path()).unwrap_err().to_string();
    assert!(err.contains("model.safetensors") && err.contains("fetch-minilm.sh"), "{err}");
}

#[test]
fn default_dir_ends_in_the_model_name() {
    assert!(Embedder::default_dir().ends_with("all-MiniLM-L6-v2"));
}

#[test]
fn embedder_and_resolver_can_be_shared_across_threads() {
    fn send_sync<T: Send + Sync>() {}
    send_sync::<Embedder>();
    send_sync::<inbetween_script::embed::SemanticResolver>();
}
