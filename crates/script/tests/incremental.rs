//! Incremental story editing: editing one character's sentence re-solves only that character and
//! the objects it touches; the other character's motion is reused bit for bit, untouched objects
//! keep their exact poses, and an unchanged text re-solves nothing and gives an equal `Animation`.

use std::collections::HashMap;

use inbetween_script::animate::AnimateConfig;
use inbetween_script::builtin_scripts::DEMO;
use inbetween_script::catalogue::builtin::builtin;
use inbetween_script::compose::{compose, ComposeConfig, ComposeInput};
use inbetween_script::database::SceneDatabase;
use inbetween_script::motion::MotionLibrary;
use inbetween_script::optimize::{optimize, OptimizeConfig};
use inbetween_script::parse::parse_script;
use inbetween_script::story_session::StorySession;

const ITERATIONS: usize = 20;

fn session() -> StorySession {
    let cat = builtin();
    let db = SceneDatabase::builtin(&cat, 2, 7);
    let ocfg = OptimizeConfig { iterations: ITERATIONS, ..OptimizeConfig::default() };
    StorySession::new(
        cat,
        db,
        ComposeConfig::default(),
        MotionLibrary::procedural(0),
        AnimateConfig::default(),
        Some(ocfg),
    )
}

/// The demo with Tom's sentence changed: he walks to the bookshelf first, then sits on the sofa.
/// (Walking to the table instead puts him on Eve's way to her chair in this layout for longer
/// than he may wait, a conflict only Eve can solve, and the crowd repair then rightly changes her
/// too.)
fn edited() -> String {
    let old = "Tom walks slowly to the sofa and sits on it.";
    assert!(DEMO.contains(old));
    DEMO.replace(old, "Tom walks to the bookshelf and sits on the sofa.")
}

#[test]
fn the_first_version_is_the_full_run() {
    let mut s = session();
    let first = s.update(DEMO);
    assert!(first.full);
    assert_eq!(first.resolved_characters, ["Eve", "Tom"]);
    // The same as composing and optimising in one go (what `inbetween script run` does).
    let cat = builtin();
    let db = SceneDatabase::builtin(&cat, 2, 7);
    let parsed = parse_script(DEMO, &cat);
    let comp = compose(
        &ComposeInput { parsed: &parsed, catalogue: &cat, database: &db, pins: &HashMap::new() },
        &ComposeConfig::default(),
    );
    let o = optimize(
        &comp,
        &cat,
        &MotionLibrary::procedural(0),
        &AnimateConfig::default(),
        &OptimizeConfig { iterations: ITERATIONS, ..OptimizeConfig::default() },
    );
    assert!(o.animation == first.animation, "the session's first run differs from optimize");
    assert_eq!(o.after, first.after);
}

#[test]
fn editing_one_characters_sentence_re_solves_only_that_character_and_its_objects() {
    let mut s = session();
    let first = s.update(DEMO);
    let second = s.update(&edited());
    eprintln!(
        "re-solved {:?}, kept {:?}, objects {:?}, builds {:?}, {:.3} s (full {:.3} s); notes {:?}",
        second.resolved_characters,
        second.kept_characters,
        second.resolved_objects,
        second.character_builds,
        second.seconds,
        first.seconds,
        second.animation.notes
    );
    assert!(!second.full);
    assert_eq!(second.scene.changed_sentences.len(), 1);
    assert_eq!(second.resolved_characters, ["Tom"]);
    assert_eq!(second.kept_characters, ["Eve"]);
    // Eve was not rebuilt at all, and her motion is the same to the bit.
    let builds: HashMap<&str, usize> = second.character_builds.iter().map(|(n, b)| (n.as_str(), *b)).collect();
    assert_eq!(builds["Eve"], 0);
    assert!(builds["Tom"] >= 1);
    let eve = |u: &inbetween_script::story_session::StoryUpdate| {
        u.animation.characters.iter().find(|c| c.name == "Eve").unwrap().clone()
    };
    assert!(eve(&first).clip == eve(&second).clip, "Eve's motion changed");
    // Tom now walks to the bookshelf first.
    let tom = second.animation.characters.iter().find(|c| c.name == "Tom").unwrap();
    assert_eq!(tom.segments.first().and_then(|s| s.target.as_deref()), Some("bookshelf"));
    // The optimisation ran only over Tom's objects: the sofa he sits on (and what relates to it),
    // none of Eve's.
    assert!(second.resolved_objects.iter().any(|l| l == "sofa"), "{:?}", second.resolved_objects);
    for l in ["desk", "chair", "laptop"] {
        assert!(!second.resolved_objects.iter().any(|r| r == l), "{l} is Eve's, yet re-optimised");
    }
    // Every other object keeps its exact pose from the previous run, but what rests on a
    // re-optimised object, which moves with it.
    let objects = &second.animation.scene.objects;
    let rests_on_resolved = |mut i: usize| {
        while let Some(s) = objects[i].support {
            if second.resolved_objects.contains(&objects[s].label) {
                return true;
            }
            i = s;
        }
        false
    };
    let mut kept = 0;
    for (i, o) in objects.iter().enumerate() {
        if second.resolved_objects.contains(&o.label) || rests_on_resolved(i) {
            continue;
        }
        let before = first.animation.scene.find(&o.label).expect("no object was added");
        assert_eq!((o.position, o.yaw, o.size), (before.position, before.yaw, before.size), "{} moved", o.label);
        kept += 1;
    }
    let carried = (0..objects.len()).filter(|&i| rests_on_resolved(i)).count();
    assert!(kept >= first.animation.scene.objects.len() - second.resolved_objects.len() - carried);
}

#[test]
fn an_unchanged_text_re_solves_nothing() {
    let mut s = session();
    let first = s.update(DEMO);
    let again = s.update(DEMO);
    assert!(!again.full);
    assert!(again.resolved_characters.is_empty(), "{:?}", again.resolved_characters);
    assert!(again.resolved_objects.is_empty(), "{:?}", again.resolved_objects);
    assert!(again.character_builds.iter().all(|(_, b)| *b == 0), "{:?}", again.character_builds);
    for (a, b) in again.animation.characters.iter().zip(&first.animation.characters) {
        assert!(a.clip == b.clip, "{}'s motion changed", a.name);
    }
    let moved: Vec<&str> = again
        .animation
        .scene
        .objects
        .iter()
        .filter(|o| {
            first
                .animation
                .scene
                .find(&o.label)
                .is_none_or(|p| (p.position, p.size, p.yaw) != (o.position, o.size, o.yaw))
        })
        .map(|o| o.label.as_str())
        .collect();
    assert!(moved.is_empty(), "objects not at their previous pose: {moved:?}");
    // The whole value: scene (supports included), tracks, segments, camera, notes.
    assert!(again.animation == first.animation, "an unchanged re-run gives another Animation");
    // Also after an edit: the edited version, saved again, stays as it was.
    let second = s.update(&edited());
    let third = s.update(&edited());
    assert!(
        third.resolved_characters.is_empty() && third.resolved_objects.is_empty(),
        "{:?} {:?}",
        third.resolved_characters,
        third.resolved_objects
    );
    assert!(third.scene.changed_sentences.is_empty());
    for (a, b) in third.animation.characters.iter().zip(&second.animation.characters) {
        assert!(a.clip == b.clip, "{}'s motion changed", a.name);
    }
    assert!(third.animation == second.animation, "saving the edit again gives another Animation");
}

/// A cancelled update stops early, says why, and leaves the session as it was: the next update
/// gives exactly what it would have given had the cancelled one never been asked for.
#[test]
fn a_cancelled_update_leaves_the_session_as_it_was() {
    use inbetween_core::cancel::{Cancel, Cancelled};
    let mut s = session();
    let first = s.update(DEMO);
    // Cancelled before it starts: refused at once.
    let stopped = Cancel::new();
    stopped.cancel();
    assert_eq!(s.update_with(&edited(), &stopped).unwrap_err(), Cancelled::Requested);
    // Cancelled part way (a time limit far shorter than the edit takes).
    let short = Cancel::with_time_limit(std::time::Duration::from_millis(5));
    let t0 = std::time::Instant::now();
    let e = s.update_with(&edited(), &short).unwrap_err();
    assert!(matches!(e, Cancelled::TimeLimit { .. }), "{e}");
    let stop_ms = t0.elapsed().as_secs_f64() * 1e3;
    // The same edit afterwards equals the edit in a session that never saw the cancelled ones.
    let after = s.update(&edited());
    let mut clean = session();
    assert!(clean.update(DEMO).animation == first.animation);
    let expected = clean.update(&edited());
    assert!(after.animation == expected.animation, "the cancelled update left a trace");
    assert_eq!(after.resolved_characters, expected.resolved_characters);
    let full_ms = after.seconds * 1e3;
    eprintln!("stopped after {stop_ms:.0} ms; the whole edit takes {full_ms:.0} ms");
}
