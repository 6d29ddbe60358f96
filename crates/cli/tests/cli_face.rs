//! End-to-end checks of `inbetween face …` with the committed weights.

use std::path::Path;
use std::process::Command;

mod common;
use common::{fails, listing};

fn inbetween(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_inbetween")).args(args).output().expect("run inbetween")
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn ok(out: &std::process::Output) {
    assert!(
        out.status.success(),
        "stdout {}\nstderr {}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn synth_then_edit_with_every_guidance_writes_clip_png_and_gif() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let input = d.join("take.csv");
    ok(&inbetween(&["face", "synth", "-o", s(&input), "--seconds", "8", "--live-link"]));
    let head = std::fs::read_to_string(&input).unwrap();
    assert!(head.starts_with("Timecode"), "Live Link layout");
    let keys = d.join("keys.json");
    std::fs::write(&keys, r#"{"keys":[{"time_s":3.0,"shapes":{"JawOpen":0.9}}]}"#).unwrap();
    let timing = d.join("take.phonemes.csv");
    assert!(timing.exists());
    let runs: [&[&str]; 5] = [
        &[],
        &["--keys", s(&keys)],
        &["--guide", s(&input)],
        &["--visemes", s(&timing)],
        &["--text", "our little brother"],
    ];
    let gif = d.join("edit.gif");
    for (i, extra) in runs.iter().enumerate() {
        let out = d.join(format!("out{i}.csv"));
        let mut args = vec!["face", "edit", s(&input), "--mask", "2.0s..4.0s", "-o", s(&out)];
        args.extend_from_slice(extra);
        if i == 0 {
            args.extend_from_slice(&["--gif", s(&gif)]);
        }
        ok(&inbetween(&args));
        let text = std::fs::read_to_string(&out).unwrap();
        assert_eq!(text.lines().count(), head.lines().count(), "same frames, run {i}");
        assert!(std::fs::read(out.with_extension("png")).unwrap().starts_with(b"\x89PNG"));
    }
    assert!(std::fs::read(d.join("edit.gif")).unwrap().starts_with(b"GIF89a"));
    // The key is hit exactly: JawOpen at 3.0 s (frame 75 of the 25 fps take) reads 0.9.
    let edited = std::fs::read_to_string(d.join("out1.csv")).unwrap();
    let header: Vec<&str> = edited.lines().next().unwrap().split(',').collect();
    let jaw = header.iter().position(|h| *h == "JawOpen").unwrap();
    let row: Vec<&str> = edited.lines().nth(1 + 75).unwrap().split(',').collect();
    assert!((row[jaw].parse::<f32>().unwrap() - 0.9).abs() < 1e-4, "{}", row[jaw]);
}

#[test]
fn bad_face_inputs_are_clear_errors_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let bad = d.join("bad.csv");
    std::fs::write(&bad, "time_s,JawOpen\n0,0.5\n").unwrap();
    let out_path = d.join("out.csv");
    let out = inbetween(&["face", "edit", s(&bad), "--mask", "0..1", "-o", s(&out_path)]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.starts_with("error: ") && err.contains("bad.csv"), "{err}");
    assert!(!err.contains("panicked") && !err.contains("stack backtrace"), "{err}");
    assert!(!out_path.exists());
    let input = d.join("take.json");
    ok(&inbetween(&["face", "synth", "-o", s(&input), "--seconds", "3"]));
    let out = inbetween(&["face", "edit", s(&input), "--mask", "5s..6s", "-o", s(&out_path)]);
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("outside the clip"),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let out = inbetween(&["face", "edit", s(&input), "--mask", "1s..2s", "--groups", "nose", "-o", s(&out_path)]);
    assert!(String::from_utf8_lossy(&out.stderr).contains("'nose'"));
    assert!(!out_path.exists());
}

#[test]
fn keys_json_of_the_wrong_shape_names_the_file_and_the_expected_form() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let input = d.join("take.csv");
    ok(&inbetween(&["face", "synth", "-o", s(&input), "--seconds", "6"]));
    let keys = d.join("keys.json");
    let out_path = d.join("out.csv");
    for (text, want) in [
        ("{}", "an object without \"keys\""),
        ("[1,2,3]", "key 0 is the number 1"),
        ("\"NaN\"", "the file holds the string \"NaN\""),
        ("{\"keys\": 5}", "\"keys\" is the number 5"),
        ("[{\"time_s\": \"3\", \"shapes\": {\"JawOpen\": 0.5}}]", "\"time_s\" is the string \"3\""),
        ("[{\"time_s\": 3, \"shapes\": {\"JawOpen\": 0.5}, \"x\": 1}]", "unknown field 'x'"),
    ] {
        std::fs::write(&keys, text).unwrap();
        let err = fails(&inbetween(&[
            "face",
            "edit",
            s(&input),
            "--mask",
            "2s..4s",
            "--keys",
            s(&keys),
            "--method",
            "linear",
            "-o",
            s(&out_path),
        ]));
        assert!(err.contains(&format!("{}: ", keys.display())) && err.contains(want), "{text}: {err}");
        assert!(!err.contains("untagged") && !err.contains("KeysJson") && !err.contains(":0:"), "{text}: {err}");
    }
    assert!(!out_path.exists());
}

#[test]
fn keys_masks_and_visemes_that_cannot_work_are_refused_naming_their_file() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let input = d.join("take.csv");
    ok(&inbetween(&["face", "synth", "-o", s(&input), "--seconds", "8"]));
    let out_path = d.join("out.csv");
    let edit = |extra: &[&str]| {
        let mut args = vec!["face", "edit", s(&input), "--method", "linear", "-o", s(&out_path)];
        args.extend_from_slice(extra);
        inbetween(&args)
    };
    let keys = d.join("keys.json");
    // A key outside the mask names the keys file, the key and the spans.
    std::fs::write(&keys, r#"{"keys":[{"time_s":6.0,"shapes":{"JawOpen":0.9}}]}"#).unwrap();
    let err = fails(&edit(&["--mask", "2s..4s", "--keys", s(&keys)]));
    assert!(err.contains(&format!("{}: key 0 at 6.000 s lies outside every edited span", keys.display())), "{err}");
    // Two keys on one frame with different weights are refused; the same weight twice is merged.
    std::fs::write(
        &keys,
        r#"{"keys":[{"time_s":3.0,"shapes":{"JawOpen":0.9}},{"time_s":3.01,"shapes":{"JawOpen":0.2}}]}"#,
    )
    .unwrap();
    let err = fails(&edit(&["--mask", "2s..4s", "--keys", s(&keys)]));
    assert!(
        err.contains(&keys.display().to_string()) && err.contains("same frame") && err.contains("JawOpen"),
        "{err}"
    );
    std::fs::write(
        &keys,
        r#"{"keys":[{"time_s":3.0,"shapes":{"JawOpen":0.9}},{"time_s":3.0,"shapes":{"JawOpen":0.9,"MouthClose":0.1}}]}"#,
    )
    .unwrap();
    ok(&edit(&["--mask", "2s..4s", "--keys", s(&keys)]));
    std::fs::remove_file(&out_path).unwrap();
    std::fs::remove_file(out_path.with_extension("png")).unwrap();
    // Visemes wholly past the clip's end.
    let late = d.join("late.csv");
    std::fs::write(&late, "start,end,phoneme\n100.0,100.2,AA1\n100.2,100.4,B\n").unwrap();
    let err = fails(&edit(&["--mask", "2s..4s", "--visemes", s(&late)]));
    assert!(err.contains("late.csv: every phoneme lies after the clip's end"), "{err}");
    // A mask running past the clip's end.
    let err = fails(&edit(&["--mask", "6s..20s"]));
    assert!(err.contains("mask '6s..20s' runs past the clip's end"), "{err}");
    // Retrieval has no phoneme labels to follow, and --library belongs to retrieval only.
    let phon = d.join("take.phonemes.csv");
    let base = ["face", "edit", s(&input), "--mask", "2s..4s", "-o", s(&out_path)];
    let err = fails(&inbetween(&[&base[..], &["--method", "retrieval", "--visemes", s(&phon)]].concat()));
    assert!(err.contains("retrieval cannot follow visemes"), "{err}");
    let err = fails(&inbetween(&[&base[..], &["--visemes", s(&phon), "--library", s(&input)]].concat()));
    assert!(err.contains("--library is read only by --method retrieval"), "{err}");
    assert!(!out_path.exists());
    assert_eq!(listing(d), ["keys.json", "late.csv", "take.csv", "take.phonemes.csv"], "no output, no staging left");
    // A library of the user's own takes is read (any clip format) and drawn from.
    ok(&inbetween(&[&base[..], &["--method", "retrieval", "--library", s(&input)]].concat()));
    assert!(out_path.exists());
}

#[test]
fn limits_and_time_limits_are_named_with_their_flags_and_nothing_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let input = d.join("take.csv");
    ok(&inbetween(&["face", "synth", "-o", s(&input), "--seconds", "8"]));
    let out_path = d.join("out.csv");
    let gif = d.join("out.gif");
    let edit = |extra: &[&str]| {
        let mut args = vec!["face", "edit", s(&input), "--mask", "2s..4s", "-o", s(&out_path), "--gif", s(&gif)];
        args.extend_from_slice(extra);
        inbetween(&args)
    };
    let err = fails(&edit(&["--max-rows", "100"]));
    assert!(
        err.contains("take.csv: 200 rows, more than the limit of 100 rows (max_rows); raise it with --max-rows"),
        "{err}"
    );
    let err = fails(&edit(&["--max-mask-seconds", "1.5"]));
    assert!(err.contains("more than the limit of 1.5 s (max_mask_s); raise it with --max-mask-seconds"), "{err}");
    let err = fails(&edit(&["--time-limit", "0.000001"]));
    assert!(err.contains("time limit of 0.000001 s reached; raise it with --time-limit"), "{err}");
    let err = fails(&edit(&["--time-limit", "0"]));
    assert!(err.contains("--time-limit") && err.contains("expected a number of seconds > 0"), "{err}");
    assert_eq!(listing(d), ["take.csv", "take.phonemes.csv"], "no clip, PNG or GIF, and no staging folder");
    ok(&edit(&[]));
    assert_eq!(listing(d), ["out.csv", "out.gif", "out.png", "take.csv", "take.phonemes.csv"]);
}

#[test]
fn variants_write_one_fill_per_seed_and_the_same_seed_gives_the_same_fill() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let input = d.join("take.csv");
    ok(&inbetween(&["face", "synth", "-o", s(&input), "--seconds", "6"]));
    let out = d.join("out.csv");
    let o =
        inbetween(&["face", "edit", s(&input), "--mask", "2s..4s", "--variants", "3", "--seed", "5", "-o", s(&out)]);
    ok(&o);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("variants 2..3: mean |difference| from variant 1 inside the spans"), "{text}");
    assert_eq!(
        listing(d),
        ["out-1.csv", "out-1.png", "out-2.csv", "out-2.png", "out-3.csv", "out-3.png", "take.csv", "take.phonemes.csv"]
    );
    // Variant 2 is seed 6: a single edit with --seed 6 writes the same bytes.
    let one = d.join("one.csv");
    ok(&inbetween(&["face", "edit", s(&input), "--mask", "2s..4s", "--seed", "6", "-o", s(&one)]));
    assert_eq!(std::fs::read(&one).unwrap(), std::fs::read(d.join("out-2.csv")).unwrap());
    // The seed reaches the fill: another seed gives another file, and the default (retrieval) fills
    // differ visibly (a mean of at least 0.005 in weight inside the span), not by noise the network ignores.
    assert_ne!(std::fs::read(d.join("out-1.csv")).unwrap(), std::fs::read(d.join("out-2.csv")).unwrap());
    assert!(text.contains("with retrieval (seed 5)"), "{text}");
    let spread = text.lines().find(|l| l.starts_with("variants 2..3")).unwrap();
    for v in spread.rsplit(':').next().unwrap().split(',') {
        let v: f64 = v.trim().parse().unwrap();
        assert!(v >= 0.005, "variants too alike: {spread}");
    }
    let bad = inbetween(&["face", "edit", s(&input), "--mask", "2s..4s", "--variants", "0", "-o", s(&out)]);
    assert!(!bad.status.success());
}
