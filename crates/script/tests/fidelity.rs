//! The fidelity corpus (issue 39): each story composed and animated, its checks measured. One
//! test per phrase type; each keeps at least the share of checks met when the phrase was taught
//! (the floors below come from `inbetween script bench`, `bench/script-bench.md`), and every story
//! keeps round 3's invariants.

use inbetween_script::catalogue::builtin::builtin;
use inbetween_script::database::SceneDatabase;
use inbetween_script::fidelity::{corpus, run, scores};
use inbetween_script::jobs::DEFAULT_VARIATIONS;
use inbetween_script::motion::MotionLibrary;

/// Runs the corpus stories of one phrase type; asserts at least `floor` percent of their checks
/// met and no invariant violated.
fn phrase(name: &str, floor: f64) {
    let cat = builtin();
    let db = SceneDatabase::builtin(&cat, DEFAULT_VARIATIONS, 1);
    let lib = MotionLibrary::procedural(1);
    let stories: Vec<_> = corpus().into_iter().filter(|s| s.phrase == name).collect();
    assert!(!stories.is_empty(), "no story for {name}");
    let results = run(&stories, &cat, &db, &lib, 1);
    for r in &results {
        for c in r.checks.iter().filter(|c| !c.met) {
            println!("not met: {} {:?}: {}", r.name, c.check, c.measured);
        }
        assert_eq!(r.invariant_violations, 0, "{}: round 3 invariants violated", r.name);
    }
    let s = &scores(&results)[0].1;
    println!("{name}: {}/{} checks met ({:.1} %)", s.met, s.checks, s.percent());
    assert!(s.percent() >= floor - 1e-9, "{name}: {:.1} % met, floor {floor} %", s.percent());
}

macro_rules! phrase_tests {
    ($($test:ident: $name:expr => $floor:expr,)*) => {
        $(#[test]
        fn $test() {
            phrase($name, $floor);
        })*

        /// Every phrase type of the corpus has its test, and the corpus has at least 60 stories.
        #[test]
        fn every_phrase_type_is_tested() {
            let stories = corpus();
            assert!(stories.len() >= 60, "{} stories", stories.len());
            let tested = [$($name),*];
            for s in &stories {
                assert!(tested.contains(&s.phrase), "no test for phrase type {}", s.phrase);
            }
        }
    };
}

phrase_tests! {
    between: "between" => 100.0,
    against_a_wall: "against a wall" => 100.0,
    against_an_object: "against an object" => 100.0,
    in_the_middle_of_the_room: "in the middle of the room" => 100.0,
    in_a_corner: "in a corner" => 100.0,
    opposite_across_from: "opposite / across from" => 100.0,
    facing: "facing" => 100.0,
    left_right_of: "left / right of" => 100.0,
    on_either_side_of: "on either side of" => 100.0,
    around: "around" => 100.0,
    at_a_table: "at (a table)" => 100.0,
    along_a_wall: "along a wall" => 100.0,
    beside: "beside" => 100.0,
    near: "near" => 100.0,
    by_the_window_door: "by the window / door" => 100.0,
    in_front_of_behind: "in front of / behind" => 100.0,
    held_out: "held out" => 100.0,
    whole_rooms: "whole rooms" => 95.0,
    counts: "counts" => 100.0,
    attributes: "attributes" => 100.0,
    pronouns: "pronouns" => 87.5,
    plural_subjects: "plural subjects" => 90.0,
    sit_next_to_someone: "sit next to someone" => 100.0,
    walk_to_someone: "walk to someone" => 100.0,
    stand_behind_in_front_of_beside_someone: "stand behind / in front of / beside someone" => 100.0,
    face_follow_someone: "face / follow someone" => 100.0,
    walk_in_out: "walk in / out" => 100.0,
    talk_look_wave_at_someone: "talk / look / wave at someone" => 100.0,
    sit_down_no_seat_named: "sit down (no seat named)" => 100.0,
}

/// The whole corpus, printed as the bench's table (run with `--nocapture` to see it).
#[test]
fn fidelity_table() {
    let cat = builtin();
    let db = SceneDatabase::builtin(&cat, DEFAULT_VARIATIONS, 1);
    let lib = MotionLibrary::procedural(1);
    let results = run(&corpus(), &cat, &db, &lib, 1);
    for r in &results {
        for c in r.checks.iter().filter(|c| !c.met) {
            println!("FAIL {} [{}] {:?}: {}", r.name, r.phrase, c.check, c.measured);
        }
        if r.invariant_violations > 0 {
            println!("INVARIANTS {}: {}", r.name, r.invariant_violations);
        }
    }
    let (mut checks, mut met) = (0, 0);
    for (p, s) in scores(&results) {
        println!("| {p} | {} | {} | {:.0} |", s.stories, s.checks, s.percent());
        checks += s.checks;
        met += s.met;
    }
    println!("| all | {} | {checks} | {:.1} |", results.len(), 100.0 * met as f64 / checks.max(1) as f64);
    assert!(checks > 0);
}
