//! Issue 39's words on parsed SSGs: spatial phrases become relations or places, pronouns and
//! plural subjects resolve to the characters they stand for, and every relation phrase of a
//! generated story is realised in the layout or named in a warning (property test).

use std::collections::HashMap;

use inbetween_script::catalogue::builtin::builtin;
use inbetween_script::compose::{compose, ComposeConfig, ComposeInput};
use inbetween_script::database::SceneDatabase;
use inbetween_script::parse::parse_script;
use inbetween_script::ssg::{Place, Relation, Ssg};

fn merged(text: &str) -> (Ssg, Vec<String>) {
    let p = parse_script(text, &builtin());
    (p.merged(), p.diagnostics.iter().map(|d| d.to_string()).collect())
}

fn relation(s: &Ssg) -> Vec<(Relation, String, String)> {
    s.relations
        .iter()
        .map(|r| (r.relation, s.objects[r.active].category.clone(), s.objects[r.anchor].category.clone()))
        .collect()
}

#[test]
fn spatial_phrases_become_relations() {
    let cases: &[(&str, Relation)] = &[
        ("A desk is opposite the bed$", Relation::Opposite),
        ("A sofa is across from the armchair$", Relation::Opposite),
        ("An armchair is facing the TV$", Relation::Facing),
        ("A chair faces the window$", Relation::Facing),
        ("A lamp is to the left of the sofa$", Relation::LeftOf),
        ("A plant is on the right of the desk$", Relation::RightOf),
        ("A cabinet is against the desk$", Relation::Against),
        ("Two nightstands are on either side of the bed$", Relation::EitherSide),
        ("Four chairs are around the table$", Relation::Around),
        ("Two chairs are at the table$", Relation::At),
        ("A chair is at the desk$", Relation::InFrontOf),
        ("A plant is beside the sofa$", Relation::NextTo),
        ("A trash can is near the fridge$", Relation::Near),
    ];
    for (text, want) in cases {
        let (s, d) = merged(text);
        let r = relation(&s);
        assert_eq!(r.len(), 1, "{text}: {r:?} {d:?}");
        assert_eq!(r[0].0, *want, "{text}");
    }
    // Two things on either side: one each side.
    let (s, _) = merged("A lamp and a plant are on either side of the sofa$");
    let r = relation(&s);
    assert_eq!(r.iter().map(|x| x.0).collect::<Vec<_>>(), vec![Relation::LeftOf, Relation::RightOf]);
}

#[test]
fn room_places_and_between() {
    let place = |text: &str| {
        let (s, d) = merged(text);
        assert!(s.relations.is_empty(), "{text}: {:?}", s.relations);
        assert_eq!(s.places.len(), 1, "{text}: {d:?}");
        s.places[0].place
    };
    assert_eq!(place("A table is in the middle of the room$"), Place::Middle);
    assert_eq!(place("A rug lies in the centre of the room$"), Place::Middle);
    assert_eq!(place("A bed is in the corner$"), Place::Corner);
    assert_eq!(place("There is a plant in a corner of the room$"), Place::Corner);
    assert_eq!(place("A bookshelf stands against the wall$"), Place::Wall);
    assert_eq!(place("A long bench runs along the wall$"), Place::Wall);
    assert_eq!(place("The cabinet is by the door$"), Place::Door);
    assert_eq!(place("A painting hangs in the middle of the wall$"), Place::Wall);
    let (s, _) = merged("A rug is between the sofa and the TV$");
    assert_eq!(s.places.len(), 1);
    let Place::Between { first, second } = s.places[0].place else { panic!("{:?}", s.places) };
    assert_eq!((s.objects[first].category.as_str(), s.objects[second].category.as_str()), ("sofa", "tv"));
    assert_eq!(s.objects[s.places[0].active].category, "rug");
    // "in the middle of the table" is on it.
    let (s, _) = merged("A vase is in the middle of the table$");
    assert_eq!(relation(&s), vec![(Relation::On, "vase".into(), "table".into())]);
}

#[test]
fn a_relation_to_nothing_is_warned() {
    let (s, d) = merged("A chair is against the fireplace$");
    assert!(s.relations.is_empty());
    assert!(d.iter().any(|d| d.contains("against")), "{d:?}");
}

/// A character's name and its actions as (verb, person acted towards).
type Acts = (String, Vec<(String, Option<String>)>);

fn people(s: &Ssg) -> Vec<Acts> {
    s.characters
        .iter()
        .map(|c| (c.name.clone(), c.actions.iter().map(|a| (a.verb.clone(), a.person.clone())).collect()))
        .collect()
}

#[test]
fn pronouns_resolve_to_the_last_fitting_name() {
    let (s, _) = merged("An armchair is in the room$\nMax sits on the armchair and Lena stands behind him.");
    assert_eq!(
        people(&s),
        vec![("Max".into(), vec![("sit".into(), None)]), ("Lena".into(), vec![("stand".into(), Some("Max".into()))]),]
    );
    let (s, _) = merged("Tom walks to the sofa. He sits on it.");
    assert_eq!(s.characters[1].name, "Tom");
    assert_eq!(s.objects[s.characters[1].actions[0].target.unwrap()].category, "sofa");
    let (s, _) = merged("Ben walks in. Anna waves at him. She talks to Ben.");
    assert_eq!(people(&s)[1], ("Anna".into(), vec![("wave".into(), Some("Ben".into()))]));
    assert_eq!(people(&s)[2], ("Anna".into(), vec![("talk".into(), Some("Ben".into()))]));
}

#[test]
fn plural_subjects_act_together() {
    let (s, _) = merged("A window is in the room$\nAnna and Ben walk to the window. They sit down. They talk.");
    let p = people(&s);
    let names: Vec<&str> = p.iter().map(|c| c.0.as_str()).collect();
    assert_eq!(names, vec!["Anna", "Ben", "Anna", "Ben", "Anna", "Ben"]);
    assert_eq!(s.objects[s.characters[1].actions[0].target.unwrap()].category, "window");
    assert_eq!(p[4].1, vec![("talk".to_string(), Some("Ben".to_string()))]);
    assert_eq!(p[5].1, vec![("talk".to_string(), Some("Anna".to_string()))]);
}

#[test]
fn they_without_a_plural_subject_is_the_last_two_named() {
    let (s, _) = merged("A sofa is in the room$\nAnna sits on the sofa. Ben sits next to her. They talk.");
    let p = people(&s);
    assert_eq!(p[1], ("Ben".into(), vec![("sit".into(), Some("Anna".into()))]));
    assert_eq!(p[2], ("Anna".into(), vec![("talk".into(), Some("Ben".into()))]));
    assert_eq!(p[3], ("Ben".into(), vec![("talk".into(), Some("Anna".into()))]));
}

#[test]
fn relations_to_characters() {
    let (s, _) = merged("Mia walks to the TV, turns around and walks to Tom. Tom follows Mia. Ben faces Anna.");
    let p = people(&s);
    assert_eq!(p[0].1.last().unwrap(), &("walk".to_string(), Some("Tom".to_string())));
    assert_eq!(p[1], ("Tom".into(), vec![("follow".into(), Some("Mia".into()))]));
    assert_eq!(p[2], ("Ben".into(), vec![("face".into(), Some("Anna".into()))]));
    let (s, _) = merged("Mia sits down next to Tom.");
    let a = &s.characters[0].actions[0];
    assert_eq!((a.verb.as_str(), a.person.as_deref(), a.preposition.as_deref()), ("sit", Some("Tom"), Some("next to")));
}

mod property {
    use super::*;
    use proptest::prelude::*;

    const THINGS: &[&str] = &["sofa", "table", "chair", "bed", "desk", "bookshelf", "plant", "cabinet", "armchair"];
    const PHRASES: &[&str] = &[
        "next to",
        "near",
        "beside",
        "in front of",
        "behind",
        "against",
        "opposite",
        "facing",
        "to the left of",
        "to the right of",
        "across from",
        "at",
        "by",
    ];
    const PLACES: &[&str] = &["in the middle of the room", "in the corner", "against the wall", "by the door"];

    proptest! {
        #![proptest_config(ProptestConfig { cases: 24, rng_seed: proptest::test_runner::RngSeed::Fixed(inbetween_core::seed::PROPTEST_SEED), ..ProptestConfig::default() })]

        /// Every relation phrase of a generated story becomes a relation or place node, and every
        /// one of those the layout does not keep is named in a warning.
        #[test]
        fn every_relation_is_realised_or_warned(
            picks in proptest::collection::vec((0..THINGS.len(), 0..PHRASES.len() + PLACES.len(), 0..THINGS.len()), 1..5)
        ) {
            let mut text = String::new();
            let mut phrases = 0;
            for (k, &(a, p, b)) in picks.iter().enumerate() {
                let (a, b) = (THINGS[a], THINGS[(b + usize::from(a == b)) % THINGS.len()]);
                let (a, b) = if a == b { (a, THINGS[(k + 3) % THINGS.len()]) } else { (a, b) };
                if p < PHRASES.len() {
                    text += &format!("A {a} is {} the {b}$\n", PHRASES[p]);
                } else {
                    text += &format!("A {a} is {}$\n", PLACES[p - PHRASES.len()]);
                }
                phrases += 1;
            }
            let cat = builtin();
            let db = SceneDatabase::builtin(&cat, 1, 1);
            let parsed = parse_script(&text, &cat);
            let nodes: usize = parsed.sentences.iter().map(|s| s.ssg.relations.len() + s.ssg.places.len()).sum();
            let parse_warnings = parsed.diagnostics.iter().filter(|d| d.message.contains("left out")).count();
            prop_assert_eq!(nodes + parse_warnings, phrases, "{}: {:?}", text, parsed.diagnostics);
            let c = compose(&ComposeInput { parsed: &parsed, catalogue: &cat, database: &db, pins: &HashMap::new() }, &ComposeConfig::default());
            // Each relation and place of the script's objects holds, or a warning names it.
            let warned = c.diagnostics.iter().filter(|d| d.message.contains("not kept")).count();
            let script = |o: &inbetween_script::scene::PlacedObject| matches!(o.origin, inbetween_script::scene::Origin::Script { .. });
            let unmet = c.relations.iter().filter(|&&(r, a, b)| {
                let (a, b) = (&c.scene.objects[a], &c.scene.objects[b]);
                script(a) && script(b) && !inbetween_script::layout::relation_holds(r, a, b)
            }).count() + c.violations.unmet_places.len();
            prop_assert_eq!(warned, unmet, "{}: {:?}", text, c.diagnostics);
        }
    }
}
