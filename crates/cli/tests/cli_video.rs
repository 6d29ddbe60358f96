//! End-to-end checks of `inbetween video …` on a procedural clip (no files needed).

use std::path::Path;
use std::process::Command;

fn inbetween(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_inbetween")).args(args).output().expect("run inbetween")
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn ok(out: &std::process::Output) -> String {
    assert!(
        out.status.success(),
        "stdout {}\nstderr {}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn fails_with(out: &std::process::Output, needle: &str) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "should fail: {err}");
    assert!(err.starts_with("error: ") && err.contains(needle), "stderr: {err}");
    assert!(!err.contains("stack backtrace"), "{err}");
}

#[test]
fn synth_then_resequence_writes_clips_sheets_and_explains() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let clip = d.join("clip.gif");
    ok(&inbetween(&[
        "video",
        "synth",
        "-o",
        s(&clip),
        "--kind",
        "pendulum",
        "--frames",
        "24",
        "--width",
        "96",
        "--height",
        "64",
    ]));
    let out = d.join("new.gif");
    let cache = d.join("cache");
    let args = [
        "video",
        "resequence",
        s(&clip),
        "--start",
        "3",
        "--count",
        "2",
        "--steps",
        "10",
        "--explain",
        "--cache-dir",
        s(&cache),
        "-o",
        s(&out),
    ];
    let text = ok(&inbetween(&args));
    assert!(text.contains("S1 (content, Eq. 8)"), "{text}");
    assert!(text.contains("C_r (reverse, beyond the paper)"), "{text}");
    assert!(text.contains("shot 0 (24 frames): motion judged"), "{text}");
    // The default length is the source's: 24 frames.
    assert!(text.contains("new-1.gif: 24 frames"), "{text}");
    assert!(text.contains("SDPF walks"), "{text}");
    for f in ["new-1.gif", "new-1.sheet.png"] {
        assert!(d.join(f).exists(), "{f} missing: {text}");
    }
    // Same seed, same clip: the cached metric and the same first order.
    let again = ok(&inbetween(&args));
    assert!(again.contains("read from the cache"), "{again}");
    let first_line = |t: &str| t.lines().find(|l| l.contains("new-1.gif:")).map(str::to_string);
    assert_eq!(first_line(&text), first_line(&again));
}

#[test]
fn bad_inputs_name_the_problem() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let missing = d.join("nope.mp4");
    fails_with(&inbetween(&["video", "resequence", s(&missing), "-o", s(&d.join("o.gif"))]), "nope.mp4");
    let clip = d.join("clip.gif");
    ok(&inbetween(&["video", "synth", "-o", s(&clip), "--frames", "6", "--width", "32", "--height", "32"]));
    fails_with(&inbetween(&["video", "resequence", s(&clip), "-o", s(&d.join("o.avi"))]), ".mp4 or .gif");
    fails_with(
        &inbetween(&["video", "resequence", s(&clip), "--start", "99", "-o", s(&d.join("o.gif"))]),
        "start frame 99 is outside the clip (frames 0..5)",
    );
    let o = d.join("o.gif");
    fails_with(
        &inbetween(&["video", "resequence", s(&clip), "--length", "0", "-o", s(&o)]),
        "length of 0 frames asks for nothing",
    );
    fails_with(
        &inbetween(&["video", "resequence", s(&clip), "--count", "0", "-o", s(&o)]),
        "count of 0 sequences asks for nothing",
    );
    fails_with(
        &inbetween(&["video", "resequence", s(&clip), "--limit-frames", "5", "-o", s(&o)]),
        "raise it with --limit-frames; or read only",
    );
    fails_with(
        &inbetween(&["video", "resequence", s(&clip), "--limit-resolution", "16x16", "-o", s(&o)]),
        "raise it with --limit-resolution",
    );
    fails_with(
        &inbetween(&["video", "resequence", s(&clip), "--length", "50000", "-o", s(&o)]),
        "raise it with --limit-length",
    );
    fails_with(&inbetween(&["video", "resequence", s(&clip), "--count", "99", "-o", s(&o)]), "--limit-count");
    fails_with(
        &inbetween(&["video", "resequence", s(&clip), "--limit-resolution", "wide", "-o", s(&o)]),
        "WIDTHxHEIGHT",
    );
    fails_with(&inbetween(&["video", "resequence", s(&clip), "--time-limit=-1", "-o", s(&o)]), "--time-limit");
    // A time limit too short for the work: a clear error and no output at all (no clip, no sheet).
    let cache = d.join("cache-limit");
    fails_with(
        &inbetween(&["video", "resequence", s(&clip), "--time-limit", "0.001", "--cache-dir", s(&cache), "-o", s(&o)]),
        "time limit of 0.001 s reached",
    );
    assert!(!o.exists(), "no output for a refused request");
    assert!(!d.join("o.sheet.png").exists());
    let junk = d.join("junk.gif");
    std::fs::write(&junk, b"GIF89a not really").unwrap();
    fails_with(&inbetween(&["video", "resequence", s(&junk), "-o", s(&d.join("o.gif"))]), "junk.gif");
}

#[test]
fn scale_measures_resequence_on_the_demo_clip_and_writes_its_table() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("scale");
    ok(&inbetween(&["video", "scale", "--scales", "1", "-o", s(&out)]));
    let csv = std::fs::read_to_string(out.join("video_scale.csv")).unwrap();
    let rows: Vec<&str> = csv.lines().skip(1).collect();
    assert_eq!(rows.len(), 1, "{csv}");
    assert!(rows[0].contains("48 frames of 192×108 px") && rows[0].ends_with("ok"), "{csv}");
}
