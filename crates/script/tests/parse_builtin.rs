//! The paper's captions against the built-in catalogue (synonyms such as couch → sofa,
//! modernchair → chair, compounds such as "boxing ring", room names).

use inbetween_script::builtin_scripts;
use inbetween_script::catalogue::builtin::builtin;
use inbetween_script::parse::parse_script;
use inbetween_script::ssg::{Relation, Ssg};

fn find<'a>(p: &'a inbetween_script::parse::ParsedScript, text: &str) -> &'a Ssg {
    &p.sentences.iter().find(|s| s.raw.at.text == text).unwrap_or_else(|| panic!("{text}")).ssg
}

#[test]
fn fig1_with_builtin_catalogue() {
    let cat = builtin();
    let p = parse_script(builtin_scripts::FIG1, &cat);
    assert!(p.diagnostics.is_empty(), "{:?}", p.diagnostics);
    let g = find(&p, "In the room, an organized office desk is near a bed");
    assert_eq!(g.room.as_deref(), Some("room"));
    assert_eq!(g.objects[0].category, "desk");
    assert_eq!(g.objects[0].attributes, ["organized", "office"]);
    assert_eq!(g.objects[1].category, "bed");
    assert_eq!(g.relations[0].relation, Relation::Near);
    let g = find(&p, "Eve sits on the couch and sings with the microphone");
    let eve = &g.characters[0];
    assert_eq!(g.objects[eve.actions[0].target.unwrap()].category, "sofa");
    assert_eq!(eve.actions[1].verb, "sing");
}

#[test]
fn figure_scenes_with_builtin_catalogue() {
    let cat = builtin();
    let p = parse_script(builtin_scripts::FIG5, &cat);
    let g = find(&p, "Tom sits on a modernchair");
    let target = g.characters[0].actions[0].target.unwrap();
    assert_eq!(g.objects[target].category, cat.resolve("modernchair").unwrap().name);
    assert_eq!(find(&p, "In a gallery there is a horsesculpture and a oilpainting").room.as_deref(), Some("gallery"));

    let p = parse_script(builtin_scripts::FIG7, &cat);
    let g = find(&p, "There is a boxing ring above which a boxingbag hangs");
    assert_eq!(g.relations.len(), 1);
    assert_eq!(g.relations[0].relation, Relation::Above);
    assert_eq!(g.objects[g.relations[0].anchor].category, cat.resolve("boxingring").unwrap().name);
    assert!(g.objects[g.relations[0].anchor].attributes.is_empty());
    let room = |t: &str| find(&p, t).room.clone();
    assert_eq!(room("There is an organized working shop"), cat.resolve_room("workingshop").map(|r| r.name.clone()));
    assert_eq!(room("There is a music room"), cat.resolve_room("musicroom").map(|r| r.name.clone()));
    assert!(room("There is a music room").is_some());
    for text in ["A hammer and a wood is on the table", "A computer and a recorder are on a desk"] {
        let g = find(&p, text);
        assert_eq!(g.relations.len(), 2, "{text}");
        assert!(g.relations.iter().all(|r| r.relation == Relation::On));
    }
}
