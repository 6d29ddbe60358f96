//! Algorithm 2 (§4.3): the optimiser never returns a worse state, is deterministic for a seed,
//! keeps base heights, closes a hand–keyboard gap; the demo's before/after costs.

use std::collections::HashMap;

use inbetween_script::animate::{animate_scene, AnimateConfig};
use inbetween_script::builtin_scripts;
use inbetween_script::catalogue::builtin::builtin;
use inbetween_script::compose::{compose, ComposeConfig, ComposeInput, Composition};
use inbetween_script::database::SceneDatabase;
use inbetween_script::motion::MotionLibrary;
use inbetween_script::optimize::{costs, optimize, optimize_scene, plot_costs, OptimizeConfig};
use inbetween_script::parse::parse_script;
use inbetween_script::scene::{Origin, PlacedObject, Room, Scene};
use inbetween_script::ssg::{Action, CharacterNode, ObjectNode, Relation, Ssg};

fn demo() -> Composition {
    let cat = builtin();
    let db = SceneDatabase::builtin(&cat, 2, 7);
    let parsed = parse_script(builtin_scripts::DEMO, &cat);
    compose(
        &ComposeInput { parsed: &parsed, catalogue: &cat, database: &db, pins: &HashMap::new() },
        &ComposeConfig::default(),
    )
}

#[test]
fn demo_optimisation_never_increases_the_cost_and_is_deterministic() {
    let comp = demo();
    let cat = builtin();
    let lib = MotionLibrary::procedural(0);
    let cfg = OptimizeConfig { iterations: 30, seed: 5, ..OptimizeConfig::default() };
    let a = optimize(&comp, &cat, &lib, &AnimateConfig::default(), &cfg);
    eprintln!("before {:?}\nafter  {:?}\nmovable {:?} rejected {}", a.before, a.after, a.movable, a.rejected_layout);
    assert!(a.after.total <= a.before.total + 1e-12);
    assert!(a.before.contact_pairs >= 3, "seats and keys: {:?}", a.before);
    assert_eq!(a.curves.total.len(), cfg.iterations + 1);
    assert!(a.curves.total.iter().all(|&c| c >= a.after.total - 1e-12), "the best state is returned");
    assert!(a.curves.best.windows(2).all(|w| w[1] <= w[0]), "best C never increases");
    assert_eq!(*a.curves.best.last().unwrap(), a.after.total);
    let b = optimize(&comp, &cat, &lib, &AnimateConfig::default(), &cfg);
    assert_eq!(a.curves, b.curves);
    assert_eq!(serde_json::to_string(&a.scene).unwrap(), serde_json::to_string(&b.scene).unwrap());
    // Base heights stay: floor objects on the floor, the rest on their support's top (or shelf).
    for (o, o0) in a.scene.objects.iter().zip(&comp.scene.objects) {
        match o.support {
            None => assert_eq!(o.position[1], o0.position[1], "{}", o.label),
            Some(s) => assert!(inbetween_script::layout::rests_on(o, &a.scene.objects[s]), "{}", o.label),
        }
    }
    // The returned animation is the returned scene's.
    assert_eq!(a.animation.scene, a.scene);
    let again = costs(&a.animation, &cfg);
    assert!((again.total - a.after.total).abs() < 1e-9);
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("costs.png");
    plot_costs(&png, &a.curves).unwrap();
    assert!(std::fs::metadata(&png).unwrap().len() > 1000);
}

fn object(
    label: &str,
    category: &str,
    size: [f32; 3],
    position: [f32; 3],
    support: Option<usize>,
    node: usize,
) -> PlacedObject {
    PlacedObject {
        label: label.into(),
        category: category.into(),
        attributes: vec![],
        position,
        yaw: 0.0,
        size,
        support,
        origin: Origin::Script { sentence: 0, node },
    }
}

/// A desk facing the door with a keyboard at its back edge: out of reach from the front.
fn keyboard_case() -> (Scene, Ssg, Vec<(Relation, usize, usize)>) {
    let scene = Scene {
        room: Room { name: "room".into(), width: 4.0, depth: 4.0, height: 2.8 },
        objects: vec![
            object("desk", "desk", [1.4, 0.75, 0.7], [2.0, 0.0, 2.0], None, 0),
            object("keyboard", "keyboard", [0.45, 0.03, 0.15], [2.0, 0.75, 1.74], Some(0), 1),
        ],
        camera: vec![],
        weather: None,
    };
    let node = |c: &str| ObjectNode { category: c.into(), attributes: vec![], count: 1, word: c.into(), sentence: 0 };
    let act = |verb: &str, target: usize| Action {
        verb: verb.into(),
        preposition: None,
        target: Some(target),
        manner: vec![],
        destination: None,
        person: None,
    };
    let query = Ssg {
        room: None,
        objects: vec![node("desk"), node("keyboard")],
        relations: vec![],
        places: vec![],
        characters: vec![CharacterNode {
            name: "Ann".into(),
            actions: vec![act("walk", 0), act("type", 1)],
            sentence: 1,
        }],
        commands: vec![],
    };
    (scene, query, vec![(Relation::On, 1, 0)])
}

#[test]
fn a_gap_between_hands_and_keyboard_shrinks() {
    let (scene, query, rels) = keyboard_case();
    let cat = builtin();
    let lib = MotionLibrary::procedural(0);
    let acfg = AnimateConfig::default();
    let anim = animate_scene(&scene, &query, &cat, &lib, &acfg);
    assert!(anim.notes.is_empty(), "{:?}", anim.notes);
    let cfg = OptimizeConfig { seed: 3, ..OptimizeConfig::default() };
    let o = optimize_scene(&scene, &query, &rels, &cat, &lib, &acfg, &cfg);
    eprintln!("before {:?}\nafter  {:?}\nmovable {:?}", o.before, o.after, o.movable);
    assert!(o.before.contact > 0.1, "the keyboard starts out of reach: {:?}", o.before);
    assert!(o.after.contact < o.before.contact - 0.02, "C_T {:.3} → {:.3}", o.before.contact, o.after.contact);
    assert!(o.after.total <= o.before.total);
    let kb = &o.scene.objects[1];
    assert!((kb.position[1] - o.scene.objects[0].top()).abs() < 1e-4, "the keyboard stays on the desk");
    assert_eq!(o.scene.objects[0].position[1], 0.0);
}

#[test]
fn collision_cost_counts_boxes_the_body_passes_through() {
    // Ann walks to a desk at the far wall; a box dropped on her route afterwards is walked into.
    let (mut scene, query, _) = keyboard_case();
    scene.objects.truncate(1);
    scene.objects[0].position = [2.0, 0.0, 0.5];
    let mut query = query;
    query.characters[0].actions.truncate(1);
    let cat = builtin();
    let anim = animate_scene(&scene, &query, &cat, &MotionLibrary::procedural(0), &AnimateConfig::default());
    let cfg = OptimizeConfig::default();
    let clear = costs(&anim, &cfg);
    assert_eq!(clear.collided_boxes, 0, "{clear:?}");
    assert_eq!(clear.collision, 0.0);
    assert_eq!(clear.contact_pairs, 0);
    let mut blocked = anim.clone();
    blocked.scene.objects.push(object("box", "box", [0.5, 0.5, 0.5], [2.0, 0.0, 2.4], None, 9));
    let hit = costs(&blocked, &cfg);
    // 2 × 2 × 2 boxes of 0.25 m; the body sweeps through the box.
    assert_eq!(hit.collided_objects, 1, "{hit:?}");
    assert!(hit.collided_boxes >= 4 && hit.collided_boxes <= 8, "{hit:?}");
    assert!((hit.collision - hit.collided_boxes as f64 / 8.0).abs() < 1e-9);
}
