//! Splitting a script into sentences (§3.2): `$` scenes, commands, directions, line numbers.

use inbetween_script::sentences::{command_parts, split, SentenceKind};

#[test]
fn empty_and_comment_only_scripts_have_no_sentences() {
    assert!(split("").is_empty());
    assert!(split("\n\r\n   \n").is_empty());
    assert!(split("# just a comment\n# another\n").is_empty());
    assert!(split("...... $ .").is_empty());
}

#[test]
fn crlf_and_lf_line_numbers() {
    let text =
        "# comment\r\nIn the room, a desk is near a bed$\r\n\r\ncamera left\r\nEve walks to the desk. Eve sits.\r\n";
    let s = split(text);
    let got: Vec<(usize, usize, &str, SentenceKind)> =
        s.iter().map(|r| (r.at.line, r.at.sentence, r.at.text.as_str(), r.kind)).collect();
    assert_eq!(
        got,
        [
            (2, 1, "In the room, a desk is near a bed", SentenceKind::Scene),
            (4, 2, "camera left", SentenceKind::Command),
            (5, 3, "Eve walks to the desk", SentenceKind::Direction),
            (5, 4, "Eve sits", SentenceKind::Direction),
        ]
    );
    let lf = split(&text.replace("\r\n", "\n"));
    assert_eq!(lf, s, "CRLF and LF give the same sentences");
}

#[test]
fn a_sentence_starts_on_the_line_of_its_first_word() {
    let s = split("A desk is near\n\nand a lamp is on it$\n   Tom sits");
    // The second line starts with "and": it continues the first sentence.
    assert_eq!(s.len(), 2);
    assert_eq!((s[0].at.line, s[0].kind), (1, SentenceKind::Scene));
    assert_eq!(s[0].at.text, "A desk is near and a lamp is on it");
    assert_eq!((s[1].at.line, s[1].at.text.as_str()), (4, "Tom sits"));
}

#[test]
fn scene_markers_as_in_the_captions() {
    for text in
        ["A desk is near a bed$", "A desk is near a bed\\$", "A desk is near a bed$.", "\"A desk is near a bed\\$.\""]
    {
        let s = split(text);
        assert_eq!(s.len(), 1, "{text}");
        assert_eq!(s[0].kind, SentenceKind::Scene, "{text}");
        assert_eq!(s[0].at.text, "A desk is near a bed", "{text}");
    }
    // `".` after a sentence, and after `.` (Fig. 7 boxing caption).
    let s = split("\"There is a ring above which a bag hangs\". There is a stool and a desk.\". There is a bottle\"");
    let kinds: Vec<SentenceKind> = s.iter().map(|r| r.kind).collect();
    assert_eq!(kinds, [SentenceKind::Scene, SentenceKind::Scene, SentenceKind::Direction]);
    assert_eq!(s[2].at.text, "There is a bottle");
}

#[test]
fn terminators_and_quotes() {
    let s = split("Eve walks! Does Tom sit? 'Tom sits.' Eve's desk is near a bed$");
    let texts: Vec<&str> = s.iter().map(|r| r.at.text.as_str()).collect();
    assert_eq!(texts, ["Eve walks", "Does Tom sit", "Tom sits", "Eve's desk is near a bed"]);
    assert_eq!(s.iter().map(|r| r.at.sentence).collect::<Vec<_>>(), [1, 2, 3, 4]);
}

#[test]
fn commands() {
    for (text, what, value) in [
        ("camera left", "camera", "left"),
        ("Camera Front", "camera", "front"),
        ("weather rainy", "weather", "rainy"),
        ("time night", "time", "night"),
        ("camera: top", "camera", "top"),
    ] {
        assert_eq!(command_parts(text), Some((what.to_string(), value.to_string())), "{text}");
        assert_eq!(split(text)[0].kind, SentenceKind::Command, "{text}");
    }
    // "time" only with a time of day; three words are no command.
    assert_eq!(command_parts("time flies"), None);
    assert_eq!(command_parts("camera moves left"), None);
    assert_eq!(split("the camera watches").first().map(|r| r.kind), Some(SentenceKind::Direction));
    assert_eq!(split("camera left$")[0].kind, SentenceKind::Command);
}

mod never_panics {
    use inbetween_script::parse::parse_script;
    use inbetween_script::sentences::split;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig { cases: 200, rng_seed: proptest::test_runner::RngSeed::Fixed(inbetween_core::seed::PROPTEST_SEED), ..ProptestConfig::default() })]
        /// Any text splits into consecutive sentence numbers with valid lines, and parses.
        #[test]
        fn any_text(text in "(\\PC|[\\$\\.\\n\\r\"'#]){0,120}") {
            let lines = text.split('\n').count();
            let s = split(&text);
            for (i, r) in s.iter().enumerate() {
                prop_assert_eq!(r.at.sentence, i + 1);
                prop_assert!(r.at.line >= 1 && r.at.line <= lines);
                prop_assert!(!r.at.text.is_empty());
            }
            let cat = inbetween_script::catalogue::Catalogue::default();
            let p = parse_script(&text, &cat);
            prop_assert_eq!(p.sentences.len(), s.len());
        }

        /// Word-like scripts with the paper's vocabulary parse without panics.
        #[test]
        fn wordy_text(words in proptest::collection::vec(
            "(a|the|two|chair|chairs|desk|is|are|on|in|front|of|near|Eve|walks|sits|and|it|which|above|there|camera|left|\\$|\\.|,)",
            0..30)) {
            let text = words.join(" ");
            let p = parse_script(&text, &crate::cat());
            for s in &p.sentences {
                for r in &s.ssg.relations {
                    prop_assert!(r.active < s.ssg.objects.len() && r.anchor < s.ssg.objects.len());
                }
                for c in &s.ssg.characters {
                    for a in &c.actions {
                        prop_assert!(a.target.is_none_or(|t| t < s.ssg.objects.len()));
                    }
                }
            }
        }
    }
}

fn cat() -> inbetween_script::catalogue::Catalogue {
    use inbetween_script::catalogue::{Catalogue, Category, RoomKind, Support};
    let c = |name: &str| Category {
        name: name.into(),
        synonyms: vec![],
        size: [1.0; 3],
        support: Support::Floor,
        surface: true,
        contacts: vec![],
        color: [0; 3],
        model: None,
    };
    Catalogue::new(
        vec![c("chair"), c("desk")],
        vec![RoomKind { name: "room".into(), synonyms: vec![], size: [5.0, 2.8, 4.0] }],
    )
}
