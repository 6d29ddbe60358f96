//! Issue 27: what a 3D client shows holds on every built-in story and on random stories (see
//! `inbetween_script::invariants`): no joint under the floor, planted feet flat, hips up while
//! walking, the camera sees whom it frames, every object rests on something, seats in front of
//! something face it; and a story's outputs all show one (the optimised) layout.

mod common;
use common::run_job;

use inbetween_script::animate::AnimateConfig;
use inbetween_script::builtin_scripts::{all, random_story};
use inbetween_script::catalogue::builtin::builtin;
use inbetween_script::compose::ComposeConfig;
use inbetween_script::database::SceneDatabase;
use inbetween_script::invariants::{check, Report};
use inbetween_script::jobs::{run_story, RunJob, DEFAULT_VARIATIONS};
use inbetween_script::motion::MotionLibrary;
use inbetween_script::optimize::OptimizeConfig;
use inbetween_script::story_session::StorySession;

fn job(out: &std::path::Path) -> RunJob {
    run_job(out, true)
}

/// A session as `script run` makes it, with a shorter annealing (the invariants must hold after
/// it as before).
fn session(iterations: usize) -> StorySession {
    let cat = builtin();
    let db = SceneDatabase::builtin(&cat, DEFAULT_VARIATIONS, 1);
    let ocfg = OptimizeConfig { seed: 1, iterations, ..OptimizeConfig::default() };
    let compose = ComposeConfig { seed: 1, ..ComposeConfig::default() };
    StorySession::new(cat, db, compose, MotionLibrary::procedural(1), AnimateConfig::default(), Some(ocfg))
}

fn report(text: &str, iterations: usize) -> Report {
    let mut s = session(iterations);
    let u = s.update(text);
    check(&u.animation, s.catalogue(), &u.scene.composition.relations)
}

fn assert_clean(name: &str, text: &str, r: &Report) {
    let problems = r.problems();
    assert!(problems.is_empty(), "{name}: {problems:#?}\n{text}");
    assert!(r.frames > 0 && r.planted > 0, "{name}: nothing measured ({r:?})");
}

#[test]
fn every_builtin_story_keeps_the_invariants() {
    for (name, text) in all() {
        let r = report(text, 20);
        eprintln!("{name}: {:?}, blocked {} of {} frames", r.counts(), r.blocked, r.frames);
        assert_clean(name, text, &r);
    }
}

#[test]
fn random_stories_keep_the_invariants() {
    for seed in 0..8 {
        let text = random_story(seed);
        let r = report(&text, 10);
        eprintln!("random {seed}: {:?}, blocked {} of {} frames", r.counts(), r.blocked, r.frames);
        assert_clean(&format!("random story {seed}"), &text, &r);
    }
}

#[test]
fn random_stories_are_deterministic_and_differ() {
    assert_eq!(random_story(3), random_story(3));
    assert_ne!(random_story(3), random_story(4));
}

/// The example: scene.json, scene.gltf and story.gltf show the optimised layout.
#[test]
fn a_story_run_writes_one_layout() {
    let text = "In the bedroom, a bed is next to a wardrobe$. A desk is near the window$. \
                A chair is in front of the desk$.\nTom walks to the desk and sits on the chair. \
                Tom gets up and walks to the bed. camera front.\n";
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let rep = run_story(text, std::path::Path::new("story.txt"), &job(&out)).expect("the story runs");
    let scene: serde_json::Value = serde_json::from_slice(&std::fs::read(out.join("scene.json")).unwrap()).unwrap();
    let objects = scene["objects"].as_array().unwrap();
    let anim = &rep.animation.scene;
    assert_eq!(objects.len(), anim.objects.len());
    let mut moved_by_optimisation = 0;
    for (j, o) in objects.iter().zip(&anim.objects) {
        let f = |v: &serde_json::Value| {
            v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap() as f32).collect::<Vec<_>>()
        };
        assert_eq!(j["label"].as_str(), Some(o.label.as_str()));
        assert_eq!(f(&j["position"]), o.position.to_vec(), "{}", o.label);
        assert_eq!(f(&j["size"]), o.size.to_vec(), "{}", o.label);
        assert!(j["mount"].is_string(), "{}: no mount", o.label);
        let before = rep.scene.composition.scene.find(&o.label).unwrap();
        if before.position != o.position || before.size != o.size {
            moved_by_optimisation += 1;
        }
    }
    // The optimisation did move something, so the check above is not vacuous.
    assert!(moved_by_optimisation > 0);
    // scene.gltf's object nodes stand where the animation's objects do.
    let gltf: serde_json::Value = serde_json::from_slice(&std::fs::read(out.join("scene.gltf")).unwrap()).unwrap();
    for o in &anim.objects {
        let node = gltf["nodes"].as_array().unwrap().iter().find(|n| n["name"].as_str() == Some(o.label.as_str()));
        let node = node.unwrap_or_else(|| panic!("scene.gltf has no node {}", o.label));
        let t: Vec<f32> = node["translation"].as_array().unwrap().iter().map(|x| x.as_f64().unwrap() as f32).collect();
        assert!(
            (t[0] - o.position[0]).abs() < 1e-4 && (t[2] - o.position[2]).abs() < 1e-4,
            "{}: {t:?} vs {:?}",
            o.label,
            o.position
        );
    }
    // The chair the story puts in front of the desk faces it, and no invariant is broken.
    let r = check(&rep.animation, &builtin(), &rep.scene.composition.relations);
    assert_clean("issue 27 example", text, &r);
}

/// "A small table", "a tall bookshelf": size adjectives scale the object within its category's
/// range (issue 27: "a small table" used to get the default 1.2 m table).
#[test]
fn size_words_scale_the_object() {
    use inbetween_script::compose::{compose, ComposeInput};
    use inbetween_script::parse::parse_script;
    let cat = builtin();
    let db = SceneDatabase::builtin(&cat, 2, 1);
    let text = "In the room, a small table is near a tall bookshelf$\nA low cabinet is next to the bookshelf$\n";
    let parsed = parse_script(text, &cat);
    let c = compose(
        &ComposeInput { parsed: &parsed, catalogue: &cat, database: &db, pins: &Default::default() },
        &ComposeConfig::default(),
    );
    let default = |name: &str| cat.get(name).unwrap().size;
    let find = |cat: &str| c.scene.objects.iter().find(|o| o.category == cat).unwrap_or_else(|| panic!("no {cat}"));
    let (small, low) = (find("table"), find("cabinet"));
    assert!(small.size[0] < default("table")[0] * 0.8 && small.size[0] > default("table")[0] * 0.6, "{:?}", small.size);
    assert!(
        low.size[1] < default("cabinet")[1] * 0.8 && (low.size[0] - default("cabinet")[0]).abs() < 1e-6,
        "{:?}",
        low.size
    );
    let shelf = find("bookshelf");
    assert!(shelf.size[1] > default("bookshelf")[1] * 1.2, "{:?}", shelf.size);
}

/// "A chair is at the desk": the chair stands in front of the desk, turned to it (issue 27: "at"
/// was an unknown relation).
#[test]
fn a_chair_at_the_desk_faces_it() {
    use inbetween_script::compose::{compose, ComposeInput};
    use inbetween_script::layout::geom::{facing_angle, FACING_TOLERANCE_DEG};
    use inbetween_script::parse::parse_script;
    use inbetween_script::ssg::Relation;
    let cat = builtin();
    let db = SceneDatabase::builtin(&cat, 2, 1);
    let text = "In the office, a desk is near the window$. A chair is at the desk$.\nTom looks at the window.\n";
    let parsed = parse_script(text, &cat);
    assert!(parsed.diagnostics.is_empty(), "{:?}", parsed.diagnostics);
    let rel = parsed.sentences.iter().flat_map(|s| &s.ssg.relations).find(|r| r.sentence == 1).expect("a relation");
    assert_eq!(rel.relation, Relation::InFrontOf);
    // "looks at" keeps its preposition.
    let look = parsed.sentences.iter().flat_map(|s| &s.ssg.characters).flat_map(|c| &c.actions).next().unwrap();
    assert_eq!(look.preposition.as_deref(), Some("at"));
    let c = compose(
        &ComposeInput { parsed: &parsed, catalogue: &cat, database: &db, pins: &Default::default() },
        &ComposeConfig::default(),
    );
    let (chair, desk) = (c.scene.find("chair").unwrap(), c.scene.find("desk").unwrap());
    assert!(facing_angle(chair, desk) <= FACING_TOLERANCE_DEG, "{chair:?}\n{desk:?}");
    assert!(inbetween_script::layout::relation_holds(Relation::InFrontOf, chair, desk));
}

#[test]
fn a_chair_in_front_of_a_desk_is_tucked_and_pulled_out_to_sit_on() {
    use inbetween_core::fk::forward;
    use inbetween_script::animate::object_pose;
    use inbetween_script::layout::geom::{facing_angle, local_box, FACING_TOLERANCE_DEG};
    use inbetween_script::motion::Rig;
    let text = "In the bedroom, a bed is next to a wardrobe$. A desk is near the window$. \
                A chair is in front of the desk$.\nTom walks to the desk and sits on the chair. \
                Tom gets up and walks to the bed. camera front.\n";
    let mut session = session(10);
    let u = session.update(text);
    let anim = &u.animation;
    let objs = &anim.scene.objects;
    let chair = objs.iter().position(|o| o.category == "chair").expect("a chair");
    let desk = objs.iter().position(|o| o.category == "desk").expect("a desk");
    // Tucked: facing the desk, centred, its front in under the desk's top, its centre in front.
    let (c, h) = local_box(&objs[chair], &objs[desk]);
    let ad = objs[desk].size[2] / 2.0;
    eprintln!("chair centre {c:?} (half {h:?}) in the desk's frame, desk half depth {ad}");
    assert!(facing_angle(&objs[chair], &objs[desk]) <= FACING_TOLERANCE_DEG);
    assert!(c[1] > ad && c[1] - h[1] < ad - 0.05, "not tucked: {c:?} {h:?}");
    assert!(c[0].abs() < 0.1, "not centred: {c:?}");
    // Tom pulls it out, sits, stands up and pushes it back in.
    let tom = &anim.characters[0];
    let verbs: Vec<&str> = tom.segments.iter().map(|s| s.verb.as_str()).collect();
    eprintln!("segments {verbs:?}, notes {:?}", anim.notes);
    let at = |v: &str| verbs.iter().position(|x| *x == v).unwrap_or_else(|| panic!("no {v} in {verbs:?}"));
    let (pull, sit, stand, push) = (at("pull out"), at("sit"), at("stand_up"), at("push in"));
    assert!(pull < sit && sit < stand && stand < push, "{verbs:?}");
    // Pulled out, scooted in seated, scooted out seated, pushed back in.
    assert_eq!(tom.slides.len(), 4, "{:?}", tom.slides);
    let out = &tom.slides[0];
    // Out from under the desk far enough for the stand point in front of the seat to keep 0.22 m
    // from the desk's edge.
    let pulled = out.to[0].hypot(out.to[1]) as f64;
    assert!((0.4..0.7).contains(&pulled) && out.object == chair, "{out:?}");
    let inside = tom.slides[1].to[0].hypot(tom.slides[1].to[1]) as f64;
    assert!((pulled - inside - 0.30).abs() < 1e-3, "scooted in 0.30 m: {:?}", tom.slides[1]);
    assert_eq!((tom.slides[1].from, tom.slides[2].from, tom.slides[2].to), (out.to, tom.slides[1].to, out.to));
    assert_eq!(tom.slides[3].to, [0.0, 0.0]);
    let in_segment = |sl: &inbetween_script::animate::Slide, verb: &str| {
        tom.segments.iter().any(|s| s.verb == verb && s.start <= sl.start && sl.end <= s.end)
    };
    assert!(in_segment(&tom.slides[1], "sit") && in_segment(&tom.slides[2], "stand_up"));
    // A hand holds the top of the backrest while the chair slides, out and back in.
    for sl in held_slides(tom) {
        let gap = hand_gap(anim, tom, sl);
        eprintln!("slide {sl:?}: hand within {gap:.3} m of the backrest's top");
        assert!(gap < 0.05, "the hand is {gap:.3} m from the backrest while the chair slides");
    }
    let rig = Rig::standard();
    // Seated on the pulled-out chair: the hips above its seat, the chair where it was pulled to.
    let seg = &tom.segments[sit];
    let rest = &objs[chair].position;
    for f in [tom.slides[1].start + 10, seg.end - 1] {
        let hips = forward(tom.clip.skeleton(), &tom.clip.pose(f)).positions[rig.hips];
        let (seat, _) = object_pose(anim, chair, f);
        let off = (hips.x - seat.x).hypot(hips.z - seat.z);
        assert!(off < 0.15, "frame {f}: hips {off:.3} m from the seat");
    }
    let (seat, _) = object_pose(anim, chair, seg.end - 1);
    assert!(((seat.x - rest[0] as f64).hypot(seat.z - rest[2] as f64) - inside).abs() < 1e-3, "scooted in");
    // Pushed back in by the end.
    let (end, _) = object_pose(anim, chair, anim.frames() - 1);
    assert!((end.x - rest[0] as f64).hypot(end.z - rest[2] as f64) < 1e-4);
    // The hips and head never go into the desk (the knees may go under its top).
    let d = &objs[desk];
    let (s, co) = (d.yaw as f64).sin_cos();
    for f in 0..tom.clip.num_frames() {
        let g = forward(tom.clip.skeleton(), &tom.clip.pose(f));
        for j in [rig.hips, rig.head] {
            let p = g.positions[j];
            let (dx, dz) = (p.x - d.position[0] as f64, p.z - d.position[2] as f64);
            let (lx, lz) = (dx * co - dz * s, dx * s + dz * co);
            let inside = lx.abs() < d.size[0] as f64 / 2.0 && lz.abs() < d.size[2] as f64 / 2.0;
            assert!(!inside || p.y > d.top() as f64, "frame {f}: joint {j} inside the desk");
        }
    }
    assert_clean("tucked chair", text, &check(anim, session.catalogue(), &u.scene.composition.relations));
}

/// The slides a character makes standing, by hand ("pull out", "push in"), not seated scoots.
fn held_slides(
    c: &inbetween_script::animate::CharacterTrack,
) -> impl Iterator<Item = &inbetween_script::animate::Slide> {
    c.slides.iter().filter(|sl| {
        c.segments
            .iter()
            .any(|s| matches!(s.verb.as_str(), "pull out" | "push in") && s.start <= sl.start && sl.end <= s.end)
    })
}

/// While `slide` moves its seat at full grip (all but its first 7 and last 4 frames), the largest
/// distance from the nearer wrist to where it holds the seat: [`GRIP_ABOVE`] over the top of a
/// chair's backrest, or over the rim of a stool's seat (metres).
///
/// [`GRIP_ABOVE`]: inbetween_script::animate::GRIP_ABOVE
fn hand_gap(
    anim: &inbetween_script::animate::Animation,
    c: &inbetween_script::animate::CharacterTrack,
    sl: &inbetween_script::animate::Slide,
) -> f64 {
    use glam::DVec3;
    let rig = inbetween_script::motion::Rig::standard();
    let ch = &anim.scene.objects[sl.object];
    let (yaw, hw, hd) = (ch.yaw as f64, ch.size[0] as f64 / 2.0 - 0.04, ch.size[2] as f64 / 2.0 - 0.03);
    let (fw, side) = (DVec3::new(yaw.sin(), 0.0, yaw.cos()), DVec3::new(yaw.cos(), 0.0, -yaw.sin()));
    let stool = ch.category.contains("stool");
    let mut worst: f64 = 0.0;
    for f in sl.start + 7..sl.end - 4 {
        let (base, _) = inbetween_script::animate::object_pose(anim, sl.object, f);
        let top = base + DVec3::Y * (ch.size[1] as f64 + inbetween_script::animate::GRIP_ABOVE);
        let g = inbetween_core::fk::forward(c.clip.skeleton(), &c.clip.pose(f));
        let near = rig
            .arms
            .iter()
            .map(|a| {
                let w = g.positions[a[3]];
                let x = (w - top).dot(side).clamp(-hw, hw);
                let z = if stool { (w - top).dot(fw).clamp(-hd, hd) } else { -hd };
                (w - (top + side * x + fw * z)).length()
            })
            .fold(f64::INFINITY, f64::min);
        worst = worst.max(near);
    }
    worst
}

/// Stories around a seat tucked at a table (the random stories rarely sit on one): a room, a desk
/// or table, a chair or stool in front of it, other furniture related at random, one or two
/// characters of whom the first sits on the tucked seat, then gets up and walks away or stays.
fn tucked_story(seed: u64) -> String {
    use rand::seq::IndexedRandom;
    use rand::Rng;
    let mut rng = inbetween_core::seed::rng(seed);
    let room = *["office", "bedroom", "living room", "kitchen"].choose(&mut rng).unwrap();
    let table = *["desk", "table"].choose(&mut rng).unwrap();
    let seat = *["chair", "stool"].choose(&mut rng).unwrap();
    let mut lines = vec![format!(
        "In the {room}, a {table} is {} a {}$",
        ["near", "next to"].choose(&mut rng).unwrap(),
        ["bookcase", "wardrobe", "sofa", "bed", "cabinet"].choose(&mut rng).unwrap()
    )];
    lines.push(format!("A {seat} is in front of the {table}$"));
    if rng.random_bool(0.5) {
        lines.push(format!("An armchair is {} the {seat}$", ["near", "next to", "behind"].choose(&mut rng).unwrap()));
    }
    lines.push(format!("camera {}", ["front", "left", "right", "wide"].choose(&mut rng).unwrap()));
    lines.push(format!("Tom walks to the {table} and sits on the {seat}."));
    if rng.random_bool(0.7) {
        lines.push(format!(
            "Tom gets up and walks to the {}.",
            ["door", "window", "armchair", table].choose(&mut rng).unwrap()
        ));
    }
    if rng.random_bool(0.5) {
        lines.push("Eve walks to the window.".to_string());
    }
    lines.join("\n") + "\n"
}

#[test]
fn tucked_seats_keep_the_invariants_and_stay_out_of_the_table() {
    use inbetween_core::fk::forward;
    use inbetween_script::motion::Rig;
    let rig = Rig::standard();
    let mut pulled = 0;
    for seed in 0..10 {
        let text = tucked_story(seed);
        let mut s = session(5);
        let u = s.update(&text);
        let anim = &u.animation;
        let slides: usize = anim.characters.iter().map(|c| c.slides.len()).sum();
        pulled += usize::from(slides > 0);
        let r = check(anim, s.catalogue(), &u.scene.composition.relations);
        eprintln!("tucked {seed}: {} slides, {:?}\n{text}", slides, r.counts());
        assert_clean(&format!("tucked story {seed}"), &text, &r);
        for c in &anim.characters {
            for sl in held_slides(c) {
                let gap = hand_gap(anim, c, sl);
                assert!(gap < 0.05, "story {seed}, {}: the hand is {gap:.3} m from the sliding seat\n{text}", c.name);
            }
        }
        // No hips or head inside a table with leg room at any frame, where the seat was tucked
        // (a seat the layout could not tuck stands just in front, and the stand point in front of
        // it reaches in under the table's edge: not done).
        for c in anim.characters.iter().filter(|_| slides > 0) {
            for f in 0..c.clip.num_frames() {
                let g = forward(c.clip.skeleton(), &c.clip.pose(f));
                for d in anim.scene.objects.iter().filter(|o| matches!(o.category.as_str(), "desk" | "table")) {
                    let (sn, co) = (d.yaw as f64).sin_cos();
                    for j in [rig.hips, rig.head] {
                        let p = g.positions[j];
                        let (dx, dz) = (p.x - d.position[0] as f64, p.z - d.position[2] as f64);
                        let (lx, lz) = (dx * co - dz * sn, dx * sn + dz * co);
                        let inside = lx.abs() < d.size[0] as f64 / 2.0 && lz.abs() < d.size[2] as f64 / 2.0;
                        assert!(
                            !inside || p.y > d.top() as f64,
                            "story {seed}, {} frame {f}: joint {j} inside the {}\n{text}",
                            c.name,
                            d.label
                        );
                    }
                }
            }
        }
    }
    assert!(pulled >= 6, "only {pulled} of 10 stories pulled a seat out");
}
