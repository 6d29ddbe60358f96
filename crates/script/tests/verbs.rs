//! Issue 27: every verb of the parser's lexicon either has motion or is refused before anything
//! is written; "lie down" lies on the bed and "gets up" gets up again.

mod common;
use common::run_job;

use inbetween_core::fk::forward;
use inbetween_script::animate::verb_has_motion;
use inbetween_script::jobs::{run_story, RunJob};
use inbetween_script::motion::rig::Rig;
use inbetween_script::motion::MotionLibrary;
use inbetween_script::parse::lexicon::VERBS;

fn job(out: &std::path::Path) -> RunJob {
    run_job(out, false)
}

#[test]
fn the_verbs_the_issue_names_all_have_motion() {
    let lib = MotionLibrary::procedural(1);
    let none: Vec<String> = Vec::new();
    let up = vec!["up".to_string()];
    let down = vec!["down".to_string()];
    for (verb, manner) in [
        ("get", &up),
        ("stand", &up),
        ("lie", &down),
        ("open", &none),
        ("close", &none),
        ("pick", &up),
        ("put", &down),
        ("give", &none),
        ("look", &none),
        ("wave", &none),
        ("point", &none),
        ("sit", &none),
        ("walk", &none),
        ("run", &none),
        ("turn", &none),
        ("sleep", &none),
        ("wake", &up),
    ] {
        assert!(verb_has_motion(verb, manner, &lib), "{verb} {manner:?} has no motion");
    }
    // Most of the lexicon plays with the built-in clips; the rest is refused (next test).
    let plays = VERBS.iter().filter(|v| verb_has_motion(v, &[], &lib)).count();
    eprintln!("{plays} of {} lexicon verbs have motion with the procedural library", VERBS.len());
    assert!(plays * 10 >= VERBS.len() * 8, "{plays} of {}", VERBS.len());
}

#[test]
fn a_verb_without_motion_is_refused_before_anything_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let text = "In the bedroom, a bed is near a desk$\nTom walks to the desk.\nTom swims to the bed.\n";
    let err = run_story(text, std::path::Path::new("story.txt"), &job(&out)).unwrap_err().to_string();
    assert!(err.contains("story.txt:3:"), "{err}");
    assert!(err.contains("\"swim\""), "{err}");
    assert!(err.contains("nothing was written"), "{err}");
    assert!(!out.exists(), "an output folder was made");
}

#[test]
fn lying_down_on_the_bed_and_getting_up() {
    let dir = tempfile::tempdir().unwrap();
    let text = "In the bedroom, a bed is near a desk$\nTom lies down on the bed.\nTom gets up and walks to the desk.\n";
    let rep = run_story(text, std::path::Path::new("story.txt"), &job(&dir.path().join("out"))).expect("runs");
    assert!(rep.animation.notes.iter().all(|n| !n.contains("instead")), "{:?}", rep.animation.notes);
    let tom = &rep.animation.characters[0];
    let verbs: Vec<&str> = tom.segments.iter().map(|s| s.verb.as_str()).collect();
    assert!(verbs.contains(&"lie") && verbs.contains(&"get_up"), "{verbs:?}");
    let lie = tom.segments.iter().find(|s| s.verb == "lie").unwrap();
    let bed = rep.animation.scene.objects.iter().find(|o| o.category == "bed").unwrap();
    let rig = Rig::standard();
    let g = forward(&rig.skeleton, &tom.clip.pose(lie.end - 1));
    let (hips, head) = (g.positions[rig.hips], g.positions[rig.head]);
    // Lying: head and hips at about the same height, just above the bed's top, over the bed.
    assert!((head.y - hips.y).abs() < 0.2, "not lying: hips {hips:?}, head {head:?}");
    assert!(hips.y > bed.top() as f64 && hips.y < bed.top() as f64 + 0.3, "hips {hips:?}, bed top {}", bed.top());
    let over = |p: glam::DVec3| {
        let l = inbetween_script::layout::geom::to_local(
            [bed.position[0], bed.position[2]],
            bed.yaw,
            [p.x as f32, p.z as f32],
        );
        l[0].abs() <= bed.size[0] / 2.0 && l[1].abs() <= bed.size[2] / 2.0
    };
    assert!(over(hips) && over(head), "hips {hips:?}, head {head:?} not over the bed");
    // Standing again at the end, at the desk.
    let end = forward(&rig.skeleton, &tom.clip.pose(tom.clip.num_frames() - 1));
    assert!(end.positions[rig.head].y > 1.4, "{:?}", end.positions[rig.head]);
}
