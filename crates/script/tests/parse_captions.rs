//! Every figure text of the paper (Fig. 1, 5, 6, 7) parses into the SSG facts it states (§3.2).

mod parse_common;

use inbetween_script::builtin_scripts;
use inbetween_script::parse::{parse_script, ParsedScript};
use inbetween_script::sentences::SentenceKind;
use inbetween_script::ssg::{Action, Command, Relation, Ssg};
use parse_common::paper_catalogue;

fn parse(text: &str) -> ParsedScript {
    parse_script(text, &paper_catalogue())
}

/// The SSG of the sentence with this text.
fn ssg<'a>(p: &'a ParsedScript, text: &str) -> &'a Ssg {
    &p.sentences.iter().find(|s| s.raw.at.text == text).unwrap_or_else(|| panic!("no sentence {text:?}")).ssg
}

fn cats(g: &Ssg) -> Vec<&str> {
    g.objects.iter().map(|o| o.category.as_str()).collect()
}

/// (relation, active category, anchor category) triples.
fn rels(g: &Ssg) -> Vec<(Relation, &str, &str)> {
    g.relations
        .iter()
        .map(|r| (r.relation, g.objects[r.active].category.as_str(), g.objects[r.anchor].category.as_str()))
        .collect()
}

/// (verb, preposition, target category, manner) of one action.
type Act = (String, Option<String>, Option<String>, Vec<String>);

/// The actions of a character.
fn acts(g: &Ssg, name: &str) -> Vec<Act> {
    let c = g.characters.iter().find(|c| c.name == name).unwrap_or_else(|| panic!("no character {name}: {g:?}"));
    c.actions
        .iter()
        .map(|a: &Action| {
            (a.verb.clone(), a.preposition.clone(), a.target.map(|t| g.objects[t].category.clone()), a.manner.clone())
        })
        .collect()
}

fn act(verb: &str, prep: Option<&str>, target: Option<&str>, manner: &[&str]) -> Act {
    (verb.into(), prep.map(Into::into), target.map(Into::into), manner.iter().map(|s| s.to_string()).collect())
}

#[test]
fn fig1_interface_example() {
    let p = parse(builtin_scripts::FIG1);
    let kinds: Vec<SentenceKind> = p.sentences.iter().map(|s| s.raw.kind).collect();
    use SentenceKind as K;
    assert_eq!(kinds, [K::Direction, K::Scene, K::Command, K::Direction]);
    assert!(p.diagnostics.is_empty(), "{:?}", p.diagnostics);

    let g = ssg(&p, "Eve walks to the house");
    assert_eq!(acts(g, "Eve"), [act("walk", Some("to"), Some("house"), &[])]);

    let g = ssg(&p, "In the room, an organized office desk is near a bed");
    assert_eq!(g.room.as_deref(), Some("room"));
    assert_eq!(cats(g), ["desk", "bed"]);
    assert_eq!(g.objects[0].attributes, ["organized", "office"]);
    assert_eq!(g.objects[0].count, 1);
    assert_eq!(rels(g), [(Relation::Near, "desk", "bed")]);
    assert!(g.objects.iter().all(|o| o.sentence == 1), "nodes carry the 0-based sentence index");

    let g = ssg(&p, "camera front");
    assert_eq!(g.commands, [Command::Camera { view: "front".into(), sentence: 2 }]);

    // "Eve sits on the couch. and sings with the microphone": the stray period does not split.
    let g = ssg(&p, "Eve sits on the couch and sings with the microphone");
    assert_eq!(
        acts(g, "Eve"),
        [act("sit", Some("on"), Some("sofa"), &[]), act("sing", Some("with"), Some("microphone"), &[])]
    );
    assert_eq!(g.objects[0].word, "couch");
}

#[test]
fn fig5_gallery_and_meeting_room_scenes() {
    let p = parse(builtin_scripts::FIG5);
    let g = ssg(&p, "In a gallery there is a horsesculpture and a oilpainting");
    assert_eq!(g.room.as_deref(), Some("gallery"));
    assert_eq!(cats(g), ["horsesculpture", "oilpainting"]);
    assert!(g.relations.is_empty());
    let g = ssg(&p, "There is also a sculpture and a picture");
    assert_eq!(cats(g), ["sculpture", "picture"]);
    let g = ssg(&p, "There is a blackboard in a meetingroom");
    assert_eq!((g.room.as_deref(), cats(g)), (Some("meetingroom"), vec!["blackboard"]));
    let g = ssg(&p, "There is an arranged table in the meetingroom");
    assert_eq!(g.room.as_deref(), Some("meetingroom"));
    assert_eq!(g.objects[0].attributes, ["arranged"]);
    let scenes = p.sentences.iter().filter(|s| s.raw.kind == SentenceKind::Scene).count();
    assert_eq!(scenes, 4);
    assert!(p.diagnostics.is_empty(), "{:?}", p.diagnostics);
}

#[test]
fn fig5_susan_and_tom_directions() {
    let p = parse(builtin_scripts::FIG5);
    let g = ssg(&p, "Susan stands in the front of oilpainting and is looking at it");
    assert_eq!(
        acts(g, "Susan"),
        [
            act("stand", Some("in front of"), Some("oilpainting"), &[]),
            act("look", Some("at"), Some("oilpainting"), &[])
        ]
    );
    // "it" is the same node, not a second painting.
    assert_eq!(g.objects.len(), 1);
    let g = ssg(&p, "Susan walks to the picture and plays with the phone");
    assert_eq!(
        acts(g, "Susan"),
        [act("walk", Some("to"), Some("picture"), &[]), act("play", Some("with"), Some("phone"), &[])]
    );
    let g = ssg(&p, "Susan is thinking before the horsesculpture");
    assert_eq!(acts(g, "Susan"), [act("think", Some("in front of"), Some("horsesculpture"), &[])]);
    let g = ssg(&p, "Tom sits on a modernchair");
    assert_eq!(acts(g, "Tom"), [act("sit", Some("on"), Some("chair"), &[])]);
    assert_eq!(g.objects[0].word, "modernchair");
    let g = ssg(&p, "Tom sits and calls with phone");
    assert_eq!(acts(g, "Tom"), [act("sit", None, None, &[]), act("call", Some("with"), Some("phone"), &[])]);
    assert_eq!(acts(ssg(&p, "Tom sits madly"), "Tom"), [act("sit", None, None, &["madly"])]);
    assert_eq!(acts(ssg(&p, "Tom stands"), "Tom"), [act("stand", None, None, &[])]);
    assert_eq!(acts(ssg(&p, "Tom turns right"), "Tom"), [act("turn", None, None, &["right"])]);
    let g = ssg(&p, "Tom stands and writes on the blackboard");
    assert_eq!(acts(g, "Tom"), [act("stand", None, None, &[]), act("write", Some("on"), Some("blackboard"), &[])]);
}

#[test]
fn fig6_film_line() {
    let p = parse(builtin_scripts::FIG6);
    let g = ssg(&p, "The man walks unbelievably to the road");
    assert_eq!(acts(g, "the man"), [act("walk", Some("to"), Some("road"), &["unbelievably"])]);
}

#[test]
fn fig7_boxing_workshop_music_scenes() {
    let p = parse(builtin_scripts::FIG7);
    let g = ssg(&p, "There is a boxing ring above which a boxingbag hangs");
    assert_eq!(cats(g), ["boxingring", "boxingbag"]);
    assert_eq!(rels(g), [(Relation::Above, "boxingbag", "boxingring")]);
    assert_eq!(g.objects[0].word, "boxing ring");
    // `".` stands for `$` in this caption.
    let s = p.sentences.iter().find(|s| s.raw.at.text == "There is a stool and a desk").unwrap();
    assert_eq!(s.raw.kind, SentenceKind::Scene);
    assert_eq!(cats(&s.ssg), ["stool", "desk"]);
    let g = ssg(&p, "There is an organized working shop");
    assert_eq!(g.room.as_deref(), Some("workshop"));
    let g = ssg(&p, "A hammer and a wood is on the table");
    assert_eq!(rels(g), [(Relation::On, "hammer", "table"), (Relation::On, "wood", "table")]);
    let g = ssg(&p, "There is a music room");
    assert_eq!(g.room.as_deref(), Some("musicroom"));
    let g = ssg(&p, "A computer and a recorder are on a desk");
    assert_eq!(rels(g), [(Relation::On, "computer", "desk"), (Relation::On, "recorder", "desk")]);
    // Written without `$` in the caption: read as scenes, with a note each.
    for text in ["There is a bottle", "A shelf and a sofa are in the front", "There is a piano and a chair in front"] {
        let s = p.sentences.iter().find(|s| s.raw.at.text == text).unwrap();
        assert_eq!(s.raw.kind, SentenceKind::Scene, "{text}");
        assert!(s.ssg.characters.is_empty());
        assert!(p.diagnostics.iter().any(|d| d.at.text == text && d.message.contains('$')), "{text}");
    }
    assert_eq!(cats(ssg(&p, "There is a piano and a chair in front")), ["piano", "chair"]);
    assert_eq!(p.diagnostics.len(), 3, "{:?}", p.diagnostics);
}

#[test]
fn fig7_actions() {
    let p = parse(builtin_scripts::FIG7);
    assert_eq!(acts(ssg(&p, "Mary is punching boxingbag"), "Mary"), [act("punch", None, Some("boxingbag"), &[])]);
    assert_eq!(acts(ssg(&p, "Mary is drinking soda"), "Mary"), [act("drink", None, Some("soda"), &[])]);
    assert_eq!(acts(ssg(&p, "Worker is sawing the wood"), "Worker"), [act("saw", None, Some("wood"), &[])]);
    assert_eq!(acts(ssg(&p, "Worker is serving the wood"), "Worker"), [act("serve", None, Some("wood"), &[])]);
    let g = ssg(&p, "Worker is hammering the nail into the wood");
    assert_eq!(acts(g, "Worker"), [act("hammer", None, Some("nail"), &[])]);
    assert_eq!(cats(g), ["nail", "wood"], "the second object still enters the scene");
    // Broken over lines in the caption; the button is the recorder's.
    let g = ssg(&p, "Anny walks to the recorder and pushes the record button");
    assert_eq!(
        acts(g, "Anny"),
        [act("walk", Some("to"), Some("recorder"), &[]), act("push", None, Some("recorder"), &[])]
    );
    let g = ssg(&p, "Anny sits on the chair and sings with microphone");
    assert_eq!(
        acts(g, "Anny"),
        [act("sit", Some("on"), Some("chair"), &[]), act("sing", Some("with"), Some("microphone"), &[])]
    );
    let g = ssg(&p, "Anny stands and is listening to music with the headphones");
    assert_eq!(acts(g, "Anny"), [act("stand", None, None, &[]), act("listen", Some("with"), Some("headphones"), &[])]);
    assert_eq!(g.objects[0].count, 1, "headphones are one object");
    assert_eq!(acts(ssg(&p, "Worker draws the design diagram"), "Worker")[0].0, "draw");
}

#[test]
fn every_builtin_text_parses() {
    for (name, text) in builtin_scripts::all() {
        let p = parse(text);
        assert!(!p.sentences.is_empty(), "{name}");
        for s in &p.sentences {
            let g = &s.ssg;
            let used = !g.objects.is_empty() || g.room.is_some() || !g.characters.is_empty() || !g.commands.is_empty();
            assert!(used, "{name}: {:?} gave nothing", s.raw.at.text);
            for o in &g.objects {
                assert_eq!(o.sentence + 1, s.raw.at.sentence);
                assert!(o.count >= 1);
            }
        }
    }
}

#[test]
fn demo_and_film_script() {
    let p = parse(builtin_scripts::DEMO);
    assert!(p.diagnostics.is_empty(), "{:?}", p.diagnostics);
    let scenes = p.sentences.iter().filter(|s| s.raw.kind == SentenceKind::Scene).count();
    assert!((2..=3).contains(&scenes));
    assert!(p.sentences.iter().any(|s| s.raw.kind == SentenceKind::Command));
    let g = ssg(&p, "A sofa is in front of a table, and a chair is next to the desk");
    assert_eq!(rels(g), [(Relation::InFrontOf, "sofa", "table"), (Relation::NextTo, "chair", "desk")]);
    let g = ssg(&p, "Tom walks slowly to the sofa and sits on it");
    assert_eq!(
        acts(g, "Tom"),
        [act("walk", Some("to"), Some("sofa"), &["slowly"]), act("sit", Some("on"), Some("sofa"), &[])]
    );

    let p = parse(builtin_scripts::NIGHT_OF_THE_LIVING_DEAD);
    assert!(p.diagnostics.is_empty(), "{:?}", p.diagnostics);
    let merged = p.merged();
    assert!(merged.commands.contains(&Command::Time { time: "night".into(), sentence: 3 }));
    assert!(merged.commands.contains(&Command::Weather { weather: "rainy".into(), sentence: 4 }));
    let g = ssg(&p, "There is a shelf behind the sofa and a lamp is on the shelf");
    assert_eq!(rels(g), [(Relation::Behind, "shelf", "sofa"), (Relation::On, "lamp", "shelf")]);
    let g = ssg(&p, "Ben walks quickly to the table and picks up the phone");
    assert_eq!(
        acts(g, "Ben"),
        [act("walk", Some("to"), Some("table"), &["quickly"]), act("pick", None, Some("phone"), &["up"])]
    );
}
