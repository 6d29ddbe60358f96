//! End-to-end checks of `inbetween face …` with the committed weights.

use std::path::Path;
use std::process::Command;

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
