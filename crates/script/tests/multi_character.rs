//! Several characters in one room: every pair of roots keeps the passing distance at every frame
//! (walking, waiting, standing, sitting), crossing routes included, and a character standing
//! still is not walked through.

use std::collections::HashMap;

use inbetween_script::animate::crowd::root_track;
use inbetween_script::animate::{animate, animate_scene, min_clearance, AnimateConfig, Animation, PASSING_DISTANCE};
use inbetween_script::builtin_scripts;
use inbetween_script::catalogue::builtin::builtin;
use inbetween_script::compose::{compose, query_graph, ComposeConfig, ComposeInput};
use inbetween_script::database::SceneDatabase;
use inbetween_script::motion::MotionLibrary;
use inbetween_script::optimize::{optimize, OptimizeConfig};
use inbetween_script::parse::parse_script;
use inbetween_script::scene::{Origin, PlacedObject, Room, Scene};

/// An object of a catalogue category at (x, z) turned by `yaw`, on the floor.
fn object(label: &str, category: &str, x: f32, z: f32, yaw: f32) -> PlacedObject {
    let size = builtin().get(category).expect("a catalogue category").size;
    PlacedObject {
        label: label.into(),
        category: category.into(),
        attributes: Vec::new(),
        position: [x, 0.0, z],
        yaw,
        size,
        support: None,
        origin: Origin::Database { scene: "test".into(), node: 0 },
    }
}

/// A 6 m × 5 m room (door at (3, 5)) with the given objects, animated from the script's
/// character lines.
fn animate_in(objects: Vec<PlacedObject>, text: &str) -> Animation {
    let cat = builtin();
    let parsed = parse_script(text, &cat);
    let query = query_graph(&parsed);
    let scene = Scene {
        room: Room { name: "room".into(), width: 6.0, depth: 5.0, height: 2.8 },
        objects,
        camera: Vec::new(),
        weather: None,
    };
    animate_scene(&scene, &query, &cat, &MotionLibrary::procedural(0), &AnimateConfig::default())
}

fn dist(a: [f32; 2], b: [f32; 2]) -> f32 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// The smallest root distance over every frame, every pair (each holds its last position).
fn closest(anim: &Animation) -> f32 {
    let trajs: Vec<Vec<[f32; 2]>> = anim.characters.iter().map(|c| root_track(&c.clip).unwrap()).collect();
    let frames = trajs.iter().map(Vec::len).max().unwrap();
    let at = |t: &Vec<[f32; 2]>, f: usize| t[f.min(t.len() - 1)];
    let mut best = f32::INFINITY;
    for f in 0..frames {
        for a in 0..trajs.len() {
            for b in a + 1..trajs.len() {
                best = best.min(dist(at(&trajs[a], f), at(&trajs[b], f)));
            }
        }
    }
    best
}

#[test]
fn three_characters_crossing_the_room_keep_their_distance_at_every_frame() {
    // Tom starts left of the door and goes to the desk on the right wall, Anny starts right of it
    // and goes to the bookshelf on the left wall: their routes cross in front of Eve's table.
    let objects = vec![
        object("bookshelf", "bookshelf", 0.4, 1.5, std::f32::consts::FRAC_PI_2),
        object("desk", "desk", 5.5, 1.5, -std::f32::consts::FRAC_PI_2),
        object("table", "table", 3.0, 0.8, 0.0),
    ];
    let anim = animate_in(objects, "Eve walks to the table.\nTom walks to the desk.\nAnny walks to the bookshelf.\n");
    eprintln!("notes: {:?}", anim.notes);
    let names: Vec<&str> = anim.characters.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names, ["Eve", "Tom", "Anny"]);
    let c = min_clearance(&anim).expect("three characters");
    eprintln!("closest: {:.3} m at frame {} ({} and {})", c.metres, c.frame, names[c.a], names[c.b]);
    assert!(
        c.metres >= PASSING_DISTANCE,
        "{} and {} come {:.3} m close at frame {}",
        names[c.a],
        names[c.b],
        c.metres,
        c.frame
    );
    assert!((closest(&anim) - c.metres).abs() < 1e-6, "min_clearance is the smallest distance over all frames");
    assert!(anim.notes.iter().all(|n| !n.contains("close")), "{:?}", anim.notes);
    // Everyone still gets where they were sent.
    for (ch, target) in anim.characters.iter().zip(["table", "desk", "bookshelf"]) {
        let o = anim.scene.find(target).unwrap();
        let end = *root_track(&ch.clip).unwrap().last().unwrap();
        let gap = dist(end, [o.position[0], o.position[2]]);
        assert!(gap < 1.2, "{} ends {gap:.2} m from the {target}", ch.name);
    }
}

#[test]
fn a_character_standing_still_is_not_walked_through() {
    // Tom (second, started left of the door) only waves and stands there for good; Eve (first,
    // started at the door) walks to the bookshelf by the door wall on Tom's side: her shortest
    // route passes within 0.2 m of Tom.
    let objects =
        vec![object("bookshelf", "bookshelf", 0.8, 4.6, std::f32::consts::PI), object("table", "table", 4.5, 1.5, 0.0)];
    let anim = animate_in(objects, "Eve walks to the bookshelf.\nTom waves.\n");
    eprintln!("notes: {:?}", anim.notes);
    let eve = root_track(&anim.characters[0].clip).unwrap();
    let tom = root_track(&anim.characters[1].clip).unwrap();
    let tom_spot = tom[0];
    // Tom never moves from his spot (the wave is in place).
    assert!(tom.iter().all(|p| dist(*p, tom_spot) < 0.1), "Tom stays where he started");
    // Eve's straight line would pass him closely.
    let (a, b) = (eve[0], *eve.last().unwrap());
    let t = (((tom_spot[0] - a[0]) * (b[0] - a[0]) + (tom_spot[1] - a[1]) * (b[1] - a[1]))
        / ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)))
    .clamp(0.0, 1.0);
    let on_line = [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])];
    eprintln!(
        "Tom at ({:.2}, {:.2}), {:.2} m from Eve's straight line",
        tom_spot[0],
        tom_spot[1],
        dist(on_line, tom_spot)
    );
    assert!(dist(on_line, tom_spot) < PASSING_DISTANCE, "the test needs Tom in Eve's way");
    let frames = eve.len().max(tom.len());
    for f in 0..frames {
        let d = dist(eve[f.min(eve.len() - 1)], tom[f.min(tom.len() - 1)]);
        assert!(d >= PASSING_DISTANCE, "Eve passes {d:.2} m from Tom at frame {f}");
    }
    let o = anim.scene.find("bookshelf").unwrap();
    assert!(dist(*eve.last().unwrap(), [o.position[0], o.position[2]]) < 1.2, "Eve reaches the bookshelf");
}

#[test]
fn every_builtin_story_keeps_its_characters_apart() {
    // Night of the Living Dead: Ben's spot at the table used to lie beside Barbra's sofa (0.008 m
    // at frame 269); stand points and seats now keep clear of where earlier characters stand or
    // sit, so every pair keeps the passing distance on every built-in text.
    let cat = builtin();
    let db = SceneDatabase::builtin(&cat, 2, 7);
    let lib = MotionLibrary::procedural(0);
    let mut pairs = 0;
    for (name, text) in builtin_scripts::all() {
        let parsed = parse_script(text, &cat);
        let comp = compose(
            &ComposeInput { parsed: &parsed, catalogue: &cat, database: &db, pins: &HashMap::new() },
            &ComposeConfig::default(),
        );
        let anim = animate(&comp, &cat, &lib, &AnimateConfig::default());
        let Some(c) = min_clearance(&anim) else { continue };
        pairs += 1;
        eprintln!("{name}: closest {:.3} m at frame {}; notes {:?}", c.metres, c.frame, anim.notes);
        assert!(
            c.metres >= PASSING_DISTANCE,
            "{name}: {} and {} come {:.3} m close at frame {}",
            anim.characters[c.a].name,
            anim.characters[c.b].name,
            c.metres,
            c.frame
        );
        assert!((closest(&anim) - c.metres).abs() < 1e-6);
        assert!(anim.notes.iter().all(|n| !n.contains(" m close")), "{name}: {:?}", anim.notes);
    }
    assert!(pairs >= 2, "the demo and the film lines have two characters each");
}

#[test]
fn night_of_the_living_dead_keeps_its_characters_apart_after_the_optimisation() {
    // The bench's setting (seed 1, the annealing re-animates every state it tries).
    let cat = builtin();
    let db = SceneDatabase::builtin(&cat, inbetween_script::jobs::DEFAULT_VARIATIONS, 1);
    let parsed = parse_script(builtin_scripts::NIGHT_OF_THE_LIVING_DEAD, &cat);
    let comp = compose(
        &ComposeInput { parsed: &parsed, catalogue: &cat, database: &db, pins: &HashMap::new() },
        &ComposeConfig { seed: 1, ..ComposeConfig::default() },
    );
    let o = optimize(
        &comp,
        &cat,
        &MotionLibrary::procedural(1),
        &AnimateConfig::default(),
        &OptimizeConfig { iterations: 30, ..OptimizeConfig::default() },
    );
    let c = min_clearance(&o.animation).expect("two characters");
    eprintln!(
        "closest {:.3} m at frame {}; C {:.3} -> {:.3}; notes {:?}",
        c.metres, c.frame, o.before.total, o.after.total, o.animation.notes
    );
    assert!(c.metres >= PASSING_DISTANCE, "{:.3} m at frame {}", c.metres, c.frame);
}
