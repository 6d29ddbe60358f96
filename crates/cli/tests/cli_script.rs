//! `inbetween script …` end to end: outputs written, clear errors naming the file.

use std::process::Command;

fn inbetween() -> Command {
    Command::new(env!("CARGO_BIN_EXE_inbetween"))
}

#[test]
fn scene_writes_json_gltf_and_previews() {
    let dir = tempfile::tempdir().unwrap();
    let script = dir.path().join("story.txt");
    std::fs::write(&script, "In the room, an organized office desk is near a bed$.\nA lamp is on the desk$.\ncamera left\nEve sits on the bed.\n").unwrap();
    let out = dir.path().join("out");
    let o = inbetween().args(["script", "scene"]).arg(&script).arg("-o").arg(&out).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for f in ["scene.json", "scene.gltf", "ssg.json", "top.png", "view.png"] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    let scene: serde_json::Value = serde_json::from_slice(&std::fs::read(out.join("scene.json")).unwrap()).unwrap();
    let cats: Vec<&str> =
        scene["objects"].as_array().unwrap().iter().map(|o| o["category"].as_str().unwrap()).collect();
    for c in ["desk", "bed", "lamp"] {
        assert!(cats.contains(&c), "{c} not in {cats:?}");
    }
    assert_eq!(scene["camera"][0], "left");
}

#[test]
fn an_empty_script_is_an_error_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let script = dir.path().join("empty.txt");
    std::fs::write(&script, "\n  \n# only a comment\n").unwrap();
    let o = inbetween().args(["script", "scene"]).arg(&script).arg("-o").arg(dir.path().join("out")).output().unwrap();
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("error:") && err.contains("empty.txt") && err.contains("empty"), "{err}");
    assert!(!err.contains("panicked") && !err.contains("stack backtrace"), "{err}");
    assert!(!dir.path().join("out").join("scene.json").exists());
}

#[test]
fn an_unknown_word_warns_with_suggestions_and_the_rest_runs() {
    let dir = tempfile::tempdir().unwrap();
    let script = dir.path().join("typo.txt");
    std::fs::write(&script, "A desk is near a bedd$.\nA sofa is in front of a tv$.\n").unwrap();
    let out = dir.path().join("out");
    let o = inbetween().args(["script", "scene"]).arg(&script).arg("-o").arg(&out).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("typo.txt") && err.contains("bedd") && err.contains("bed"), "{err}");
    assert!(err.contains("line 1"), "{err}");
    assert!(out.join("scene.json").is_file());
}

#[test]
fn builtin_stories_are_listed_and_parsed() {
    let o = inbetween().args(["script", "stories"]).output().unwrap();
    assert!(o.status.success());
    assert!(String::from_utf8_lossy(&o.stdout).contains("demo"));
    let o = inbetween().args(["script", "parse", "builtin:demo"]).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(String::from_utf8_lossy(&o.stdout).contains("\"objects\""));
}

#[test]
fn the_quick_bench_writes_its_tables_and_box_plot() {
    let dir = tempfile::tempdir().unwrap();
    let o = inbetween().args(["script", "bench", "--quick", "-o"]).arg(dir.path()).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for f in ["speed.csv", "layout.csv", "fig8.csv", "incremental.csv", "stories.csv", "fig8.png", "fig12_costs.png"] {
        assert!(dir.path().join(f).is_file(), "{f} missing");
    }
}

#[test]
fn run_writes_the_animated_story_and_watch_reruns_on_save() {
    let dir = tempfile::tempdir().unwrap();
    let script = dir.path().join("story.txt");
    std::fs::write(&script, "A chair is near a desk$.\ncamera left\nEve walks to the desk and sits on the chair.\n")
        .unwrap();
    let out = dir.path().join("out");
    let o = inbetween()
        .args(["script", "run"])
        .arg(&script)
        .arg("-o")
        .arg(&out)
        .arg("--no-optimize")
        .arg("--gif-width")
        .arg("160")
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for f in ["story.gltf", "Eve.bvh", "Eve.bvh.json", "story.gif", "routes.png", "scene.json"] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(stdout.contains("1 characters") && stdout.contains("frames"), "{stdout}");
    let o = inbetween()
        .args(["script", "watch"])
        .arg(&script)
        .arg("-o")
        .arg(dir.path().join("w"))
        .args(["--no-optimize", "--gif-width", "160", "--max-runs", "1"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(dir.path().join("w").join("story.gltf").is_file());
}

#[test]
fn an_oversized_story_is_refused_at_once_naming_the_limit_and_its_flag_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let script = dir.path().join("long.txt");
    let mut text = String::from("In the office, a desk is near a bookshelf$\n");
    for _ in 0..300 {
        text.push_str("Eve walks to the desk.\n");
    }
    std::fs::write(&script, &text).unwrap();
    let out = dir.path().join("out");
    let t = std::time::Instant::now();
    let o = inbetween().args(["script", "run"]).arg(&script).arg("-o").arg(&out).output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success());
    assert!(err.contains("long.txt: 301 sentences, more than the limit of 200 sentences"), "{err}");
    assert!(err.contains("raise it with --max-sentences"), "{err}");
    assert!(!out.exists(), "nothing is written");
    assert!(t.elapsed().as_secs_f64() < 20.0, "refused before any work: {:?}", t.elapsed());
    // Raised, the sentence limit passes and the next one (actions) is named.
    let o = inbetween()
        .args(["script", "scene"])
        .arg(&script)
        .args(["--max-sentences", "400", "-o"])
        .arg(&out)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("300 character actions") && err.contains("raise it with --max-actions"), "{err}");
    // One endless sentence is bounded by its words.
    let line = vec!["Eve walks to the desk"; 2000].join(" and ");
    std::fs::write(&script, format!("In the office, a desk is near a bookshelf$\n{line}.\n")).unwrap();
    let o = inbetween().args(["script", "run"]).arg(&script).arg("-o").arg(&out).output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("words") && err.contains("raise it with --max-words"), "{err}");
}

#[test]
fn scale_measures_the_demo_story_and_writes_its_table() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("scale");
    let o = inbetween().args(["script", "scale", "--scales", "1,2", "-o"]).arg(&out).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let csv = std::fs::read_to_string(out.join("script_scale.csv")).unwrap();
    let rows: Vec<&str> = csv.lines().skip(1).collect();
    assert_eq!(rows.len(), 2, "{csv}");
    // The demo's 4 scene lines plus 3 direction sentences per copy.
    assert!(rows[0].contains("7 sentences, 5 actions") && rows[1].contains("10 sentences, 10 actions"), "{csv}");
}

#[test]
fn a_run_past_its_time_limit_says_so_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let o = inbetween()
        .args(["script", "run", "builtin:demo", "--gif-width", "120", "--time-limit", "0.05", "-o"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("time limit of 0.05 s reached; raise it with --time-limit"), "{err}");
    let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().filter_map(|e| e.ok()).map(|e| e.file_name()).collect();
    assert!(!out.join("story.gltf").exists() && !out.join("scene.json").exists(), "partial outputs: {left:?}");
    assert!(left.iter().all(|n| !n.to_string_lossy().starts_with(".inbetween-staging")), "staging left: {left:?}");
    // Within the limit, the whole set lands in --out.
    let o = inbetween().args(["script", "run", "builtin:demo", "--gif-width", "120", "-o"]).arg(&out).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for f in ["story.gltf", "scene.json", "Eve.bvh", "story.gif"] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    assert!(String::from_utf8_lossy(&o.stdout).contains(&format!("wrote {}", out.join("story.gltf").display())));
}
