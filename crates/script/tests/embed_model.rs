//! all-MiniLM-L6-v2 through the `embeddings` feature. Needs the model (scripts/fetch-minilm.sh);
//! without it each test prints why it skipped and passes.
#![cfg(feature = "embeddings")]

use std::sync::OnceLock;
use std::time::Instant;

use inbetween_script::catalogue::builtin::builtin;
use inbetween_script::catalogue::{Catalogue, Category};
use inbetween_script::embed::{cosine, Embedder, SemanticResolver, DIM};

fn model_dir() -> Option<std::path::PathBuf> {
    let dir = Embedder::default_dir();
    dir.join("model.safetensors").is_file().then_some(dir)
}

fn skipped() {
    println!("skipped: no model at {}, run scripts/fetch-minilm.sh", Embedder::default_dir().display());
}

/// One resolver for all tests of this file (loading and embedding the catalogue take seconds).
fn resolver() -> Option<&'static SemanticResolver> {
    static R: OnceLock<Option<SemanticResolver>> = OnceLock::new();
    R.get_or_init(|| {
        let dir = model_dir()?;
        let t = Instant::now();
        let embedder = Embedder::load(&dir).expect("load all-MiniLM-L6-v2");
        let load = t.elapsed();
        let t = Instant::now();
        let r = SemanticResolver::new(embedder, &builtin()).expect("embed the catalogue");
        println!(
            "timing: load {:.0} ms, catalogue embedded in {:.0} ms",
            load.as_secs_f64() * 1e3,
            t.elapsed().as_secs_f64() * 1e3
        );
        Some(r)
    })
    .as_ref()
    .or_else(|| {
        skipped();
        None
    })
}

#[test]
fn embedding_has_384_dimensions_and_unit_norm() {
    let Some(r) = resolver() else { return };
    let e = r.embedder();
    for text in ["couch", "In the room, an organized office desk is near a bed.", ""] {
        let v = e.embed(text).unwrap();
        assert_eq!(v.len(), DIM);
        let norm = v.iter().map(|x| x * x).sum::<f32>().sqrt();
        assert!((norm - 1.0).abs() < 1e-4, "{text:?}: norm {norm}");
    }
    // Pad-free encoding: a text's embedding does not depend on what else was embedded.
    assert_eq!(e.embed("couch").unwrap(), e.embed("couch").unwrap());
}

#[test]
fn real_vocabulary_gives_bert_uncased_ids() {
    let Some(r) = resolver() else { return };
    let wp = r.embedder().tokenizer();
    // bert-base-uncased facts (all-MiniLM-L6-v2 uses its vocabulary).
    assert_eq!(wp.len(), 30522);
    assert_eq!(wp.encode("Hello world", 256), [101, 7592, 2088, 102]);
    assert_eq!(wp.tokenize("I have a new GPU!"), ["i", "have", "a", "new", "gp", "##u", "!"]);
}

/// Ids from Hugging Face `tokenizers` 0.23 with this model's tokenizer.json (no padding, no
/// truncation): accents, Unicode punctuation, CJK, URLs, contractions and long words.
const REFERENCE: &[(&str, &[u32])] = &[
    (
        "In the room, an organized office desk is near a bed$",
        &[101, 1999, 1996, 2282, 1010, 2019, 4114, 2436, 4624, 2003, 2379, 1037, 2793, 1002, 102],
    ),
    ("Eve walks to the house.", &[101, 6574, 7365, 2000, 1996, 2160, 1012, 102]),
    ("Tom sits on a modernchair", &[101, 3419, 7719, 2006, 1037, 2715, 24925, 2099, 102]),
    ("camera left", &[101, 4950, 2187, 102]),
    (
        "Café naïve résumé — “quoted” text… and 3.5 m² (approx.)!",
        &[
            101, 7668, 15743, 13746, 1517, 1523, 9339, 1524, 3793, 1529, 1998, 1017, 1012, 1019, 7030, 1006, 22480,
            1012, 1007, 999, 102,
        ],
    ),
    (
        "The quick brown fox jumps over the lazy dog; it's 10:30 a.m.",
        &[
            101, 1996, 4248, 2829, 4419, 14523, 2058, 1996, 13971, 3899, 1025, 2009, 1005, 1055, 2184, 1024, 2382,
            1037, 1012, 1049, 1012, 102,
        ],
    ),
    ("Ünïcödé façade Ångström São Paulo Kraków", &[101, 27260, 8508, 17076, 15687, 7509, 9094, 14576, 102]),
    ("中文字符 and 日本語 mixed", &[101, 1746, 1861, 100, 100, 1998, 1864, 1876, 1950, 3816, 102]),
    ("tabs\tand", &[101, 21628, 2015, 1998, 102]),
    ("newlines  and   spaces", &[101, 2047, 12735, 1998, 7258, 102]),
    (
        "Supercalifragilisticexpialidocious antidisestablishmentarianism",
        &[
            101, 3565, 9289, 10128, 29181, 24411, 4588, 10288, 19312, 21273, 10085, 6313, 3424, 10521, 4355, 7875,
            13602, 3672, 12199, 2964, 102,
        ],
    ),
    (
        "email@example.com http://example.org/path?x=1&y=2",
        &[
            101, 10373, 1030, 2742, 1012, 4012, 8299, 1024, 1013, 1013, 2742, 1012, 8917, 1013, 4130, 1029, 1060, 1027,
            1015, 1004, 1061, 1027, 1016, 102,
        ],
    ),
    ("don't won't they're O'Neil", &[101, 2123, 1005, 1056, 2180, 1005, 1056, 2027, 1005, 2128, 1051, 1005, 6606, 102]),
    (
        "@#$%^&*()_+-=[]{}|\\:\";'<>?,./~`",
        &[
            101, 1030, 1001, 1002, 1003, 1034, 1004, 1008, 1006, 1007, 1035, 1009, 1011, 1027, 1031, 1033, 1063, 1065,
            1064, 1032, 1024, 1000, 1025, 1005, 1026, 1028, 1029, 1010, 1012, 1013, 1066, 1036, 102,
        ],
    ),
    ("Zoë's œuvre ﬁnal straße", &[101, 11199, 1005, 1055, 1107, 2226, 12229, 1984, 12032, 2358, 27807, 102]),
];

#[test]
fn ids_match_hugging_face_tokenizers() {
    let Some(r) = resolver() else { return };
    let wp = r.embedder().tokenizer();
    for (text, ids) in REFERENCE {
        assert_eq!(wp.encode(text, 512), *ids, "{text:?}: {:?}", wp.tokenize(text));
    }
}

#[test]
fn couch_is_nearer_sofa_than_piano() {
    let Some(r) = resolver() else { return };
    let e = r.embedder();
    let couch = e.embed("couch").unwrap();
    let sofa = e.embed("sofa").unwrap();
    let piano = e.embed("piano").unwrap();
    let (s, p) = (cosine(&couch, &sofa), cosine(&couch, &piano));
    println!("cos(couch, sofa) = {s:.3}, cos(couch, piano) = {p:.3}");
    assert!(s > p + 0.2, "couch–sofa {s}, couch–piano {p}");
}

#[test]
fn per_word_embedding_time() {
    let Some(r) = resolver() else { return };
    let e = r.embedder();
    let words = ["divan", "cello", "kitten", "lectern", "hatstand", "refectory", "bookcase", "spatula"];
    e.embed("warm-up").unwrap();
    let t = Instant::now();
    for _ in 0..4 {
        for w in words {
            e.embed(w).unwrap();
        }
    }
    let per = t.elapsed().as_secs_f64() * 1e3 / (4 * words.len()) as f64;
    let t = Instant::now();
    e.embed("In the room, an organized office desk is near a bed and a lamp is on the desk.").unwrap();
    println!("timing: {per:.2} ms per word, {:.2} ms per sentence", t.elapsed().as_secs_f64() * 1e3);
}

#[test]
fn known_words_resolve_directly() {
    let Some(r) = resolver() else { return };
    assert_eq!(r.nearest("Couch").unwrap(), Some(("sofa".to_string(), 1.0)));
    assert_eq!(r.nearest("armchair").unwrap(), Some(("armchair".to_string(), 1.0)));
    assert_eq!(r.nearest_room("lounge").unwrap(), Some(("livingroom".to_string(), 1.0)));
}

/// The scores behind the thresholds (printed with --nocapture; the crate README quotes them).
#[test]
fn words_outside_the_tables() {
    let Some(r) = resolver() else { return };
    let best = |w: &str| r.nearest(w).unwrap().map(|(c, _)| c);
    for (word, category) in [
        ("sofa bed", "sofa"),
        ("bunk bed", "bed"),
        ("wardrobe closet", "wardrobe"),
        ("footrest", "stool"),
        ("microwave", "stove"),
        ("candle", "lamp"),
        ("cello", "guitar"),
    ] {
        assert_eq!(best(word).as_deref(), Some(category), "{word}: {:?}", &r.rank(word).unwrap()[..3]);
    }
    for word in ["kitten", "dog", "banana", "democracy", "happiness"] {
        assert_eq!(best(word), None, "{word}: {:?}", &r.rank(word).unwrap()[..3]);
    }
    let room = |w: &str| r.nearest_room(w).unwrap().map(|(c, _)| c);
    assert_eq!(room("dining room").as_deref(), Some("kitchen"));
    assert!(matches!(room("lecture hall").as_deref(), Some("gallery" | "meetingroom")));
    for word in ["kitten", "forest"] {
        assert_eq!(room(word), None, "{word}: {:?}", &r.rank_rooms(word).unwrap()[..3]);
    }
    for w in ["sofa bed", "footrest", "microwave", "candle", "cello", "tablet", "pencil", "kitten", "dog", "democracy"]
    {
        let top: Vec<String> = r.rank(w).unwrap().into_iter().take(2).map(|(n, s)| format!("{n} {s:.2}")).collect();
        println!("object {w:>12}: {}", top.join(", "));
    }
    for w in ["dining room", "lecture hall", "bathroom", "forest", "kitten"] {
        let top: Vec<String> =
            r.rank_rooms(w).unwrap().into_iter().take(2).map(|(n, s)| format!("{n} {s:.2}")).collect();
        println!("room   {w:>12}: {}", top.join(", "));
    }
}

/// With "armchair" and "loveseat" taken out of the tables, the model still puts them among seats.
#[test]
fn armchair_and_loveseat_without_the_tables() {
    if model_dir().is_none() {
        skipped();
        return;
    }
    let full = builtin();
    let categories: Vec<Category> = full
        .categories()
        .iter()
        .filter(|c| c.name != "armchair")
        .cloned()
        .map(|mut c| {
            c.synonyms.retain(|s| s != "loveseat");
            c
        })
        .collect();
    let cat = Catalogue::new(categories, full.rooms().to_vec());
    assert!(cat.resolve("armchair").is_none() && cat.resolve("loveseat").is_none());
    let r = SemanticResolver::new(Embedder::load_default().unwrap(), &cat).unwrap();
    for word in ["armchair", "loveseat"] {
        let hit = r.nearest(word).unwrap();
        println!("{word} → {hit:?}");
        let (c, _) = hit.unwrap_or_else(|| panic!("{word}: {:?}", &r.rank(word).unwrap()[..3]));
        assert!(["sofa", "chair", "officechair"].contains(&c.as_str()), "{word} → {c}");
    }
}

#[test]
fn batches_give_the_same_vectors_as_single_texts() {
    let Some(r) = resolver() else { return };
    let e = r.embedder();
    let texts = ["sofa", "grand piano", "couch", "a desk near a bed", "lamp", "office chair"];
    let batch = e.embed_batch(&texts).unwrap();
    for (t, b) in texts.iter().zip(&batch) {
        let single = e.embed(t).unwrap();
        let diff = single.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0f32, f32::max);
        assert!(diff < 1e-4, "{t}: batch and single differ by {diff}");
    }
}
