//! End-to-end runs of `inbetween mocap …` on a procedural clip.

use std::path::Path;
use std::process::{Command, Output};

fn inbetween(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_inbetween"))
        .args(args)
        .env("RUST_BACKTRACE", "0")
        .output()
        .expect("runs the binary")
}

fn text(o: &Output) -> String {
    format!("{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr))
}

fn walk_bvh(dir: &Path) -> String {
    let mut p = inbetween_core::procedural::GaitParams::walk();
    p.frames = 90;
    let path = dir.join("walk.bvh");
    inbetween_io::write_bvh(&path, &inbetween_core::procedural::gait(&p)).unwrap();
    path.to_string_lossy().into_owned()
}

#[test]
fn compress_decompress_preview_and_corrupt_input() {
    let dir = tempfile::tempdir().unwrap();
    let bvh = walk_bvh(dir.path());
    let ibk = dir.path().join("walk.ibk").to_string_lossy().into_owned();
    // Version 4 (the default with --max-error): every frame, fixed-width values per segment; the
    // bound holds on virtual vertices.
    let v4 = dir.path().join("walk4.ibk").to_string_lossy().into_owned();
    let o = inbetween(&["mocap", "compress", &bvh, "--max-error", "1cm", "-o", &v4]);
    assert!(o.status.success() && text(&o).contains("version 4"), "{}", text(&o));
    assert!(max_cm(&text(&o)) <= 1.0, "{}", text(&o));
    let out4 = dir.path().join("rec4.bvh").to_string_lossy().into_owned();
    let o = inbetween(&["mocap", "decompress", &v4, "-o", &out4]);
    assert!(o.status.success(), "{}", text(&o));
    assert_eq!(inbetween_io::read_bvh(Path::new(&out4)).unwrap().num_frames(), 90);
    // Version 3 on request: every frame, a variable-length stream (smaller, slower to sample).
    let v3 = dir.path().join("walk3.ibk").to_string_lossy().into_owned();
    let o = inbetween(&["mocap", "compress", &bvh, "--max-error", "1cm", "--format", "v3", "-o", &v3]);
    assert!(o.status.success() && text(&o).contains("version 3"), "{}", text(&o));
    assert!(max_cm(&text(&o)) <= 1.0, "{}", text(&o));
    let out3 = dir.path().join("rec3.bvh").to_string_lossy().into_owned();
    let o = inbetween(&["mocap", "decompress", &v3, "-o", &out3]);
    assert!(o.status.success(), "{}", text(&o));
    assert_eq!(inbetween_io::read_bvh(Path::new(&out3)).unwrap().num_frames(), 90);
    // Version 2 keeps keyframes.
    let o = inbetween(&["mocap", "compress", &bvh, "--max-error", "1cm", "--format", "v2", "-o", &ibk]);
    assert!(o.status.success(), "{}", text(&o));
    assert!(text(&o).contains("bytes per key"), "{}", text(&o));
    assert!(text(&o).contains("length unit: CMU units (5.6444 cm) (rest-pose height 26.7 units"), "{}", text(&o));
    assert!(max_cm(&text(&o)) <= 1.0, "{}", text(&o));
    let out = dir.path().join("rec.bvh").to_string_lossy().into_owned();
    let o = inbetween(&["mocap", "decompress", &ibk, "-o", &out]);
    assert!(o.status.success(), "{}", text(&o));
    let rec = inbetween_io::read_bvh(Path::new(&out)).unwrap();
    assert_eq!(rec.num_frames(), 90);
    let gif = dir.path().join("overlay.gif").to_string_lossy().into_owned();
    let o = inbetween(&["mocap", "preview", &bvh, "--ibk", &ibk, "-o", &gif]);
    assert!(o.status.success(), "{}", text(&o));
    assert!(std::fs::metadata(&gif).unwrap().len() > 1000);
    // A truncated file is refused with a clear message, and no output is written.
    let bytes = std::fs::read(&ibk).unwrap();
    let bad = dir.path().join("bad.ibk");
    std::fs::write(&bad, &bytes[..bytes.len() - 10]).unwrap();
    let none = dir.path().join("none.bvh").to_string_lossy().into_owned();
    let o = inbetween(&["mocap", "decompress", bad.to_str().unwrap(), "-o", &none]);
    assert!(!o.status.success());
    assert!(text(&o).contains("checksum"), "{}", text(&o));
    assert!(!Path::new(&none).exists());
    let o = inbetween(&["mocap", "compress", &bvh, "-o", &ibk]);
    assert!(!o.status.success() && text(&o).contains("-k"), "{}", text(&o));
}

/// The "max X cm" of a report line.
fn max_cm(report: &str) -> f64 {
    let at = report.find("max ").expect("a max error in the report") + 4;
    report[at..].split_whitespace().next().unwrap().parse().unwrap()
}

/// Keys in a compress report ("…, 12 keys; …").
fn keys(report: &str) -> usize {
    let before = &report[..report.find(" keys;").expect("a key count")];
    before.rsplit(' ').next().unwrap().parse().unwrap()
}

/// The same walk written in CMU units, centimetres and metres compresses to the same keys and the
/// same cm error at the same bound; each report says which unit it inferred, and --unit overrides.
#[test]
fn compress_infers_the_unit_of_any_rig_and_accepts_an_override() {
    let dir = tempfile::tempdir().unwrap();
    let mut p = inbetween_core::procedural::GaitParams::walk();
    p.frames = 90;
    let walk = inbetween_core::procedural::gait(&p);
    let mut reports = Vec::new();
    for (name, unit) in [("cmu", "CMU units (5.6444 cm)"), ("cm", "cm"), ("m", "m")] {
        let u: inbetween_core::units::LengthUnit = name.parse().unwrap();
        let scaled = inbetween_core::units::scale_motion(&walk, 5.6444 / u.cm_per_unit());
        let bvh = dir.path().join(format!("{name}.bvh"));
        inbetween_io::write_bvh(&bvh, &scaled).unwrap();
        let ibk = dir.path().join(format!("{name}.ibk")).to_string_lossy().into_owned();
        let o = inbetween(&[
            "mocap",
            "compress",
            bvh.to_str().unwrap(),
            "--max-error",
            "0.5cm",
            "--format",
            "v2",
            "-o",
            &ibk,
        ]);
        assert!(o.status.success(), "{}", text(&o));
        assert!(text(&o).contains(&format!("length unit: {unit} (rest-pose height")), "{}", text(&o));
        reports.push(text(&o));
    }
    for r in &reports[1..] {
        assert_eq!(keys(r), keys(&reports[0]), "{r}");
        assert!((max_cm(r) - max_cm(&reports[0])).abs() < 2e-3, "{r}");
    }
    // Told the CMU clip is in cm, the bound is 5.6 times looser: fewer keys.
    let bvh = dir.path().join("cmu.bvh");
    let out = dir.path().join("o.ibk").to_string_lossy().into_owned();
    let o = inbetween(&[
        "mocap",
        "compress",
        bvh.to_str().unwrap(),
        "--max-error",
        "0.5cm",
        "--unit",
        "cm",
        "--format",
        "v2",
        "-o",
        &out,
    ]);
    assert!(o.status.success() && text(&o).contains("length unit: cm (given with --unit)"), "{}", text(&o));
    assert!(keys(&text(&o)) < keys(&reports[0]), "{}", text(&o));
    let o =
        inbetween(&["mocap", "compress", bvh.to_str().unwrap(), "--max-error", "1cm", "--unit", "feet", "-o", &out]);
    assert!(!o.status.success() && text(&o).contains("expected cm, m, mm, in, cmu"), "{}", text(&o));
}

/// A receiver is killed mid-stream and a new one started on the same address: the sender
/// reconnects, and the new receiver says which frame it starts at and compares from there.
#[test]
fn stream_receiver_joining_mid_stream_compares_at_its_offset() {
    let dir = tempfile::tempdir().unwrap();
    let bvh = walk_bvh(dir.path());
    let port = std::net::TcpListener::bind("127.0.0.1:0").unwrap().local_addr().unwrap().port();
    let addr = format!("127.0.0.1:{port}");
    let first = dir.path().join("first.bvh").to_string_lossy().into_owned();
    let out = dir.path().join("second.bvh").to_string_lossy().into_owned();
    let exe = env!("CARGO_BIN_EXE_inbetween");
    let mut recv1 = Command::new(exe)
        .args(["mocap", "stream", "recv", "--addr", &addr, "-o", &first, "--timeout-s", "20"])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(300));
    // Real time: 90 frames at 30 fps take 3 s.
    let sender = Command::new(exe)
        .args(["mocap", "stream", "send", &bvh, "--addr", &addr, "--max-error", "1cm", "--retries", "25"])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(1200));
    recv1.kill().unwrap();
    recv1.wait().unwrap();
    let o =
        inbetween(&["mocap", "stream", "recv", "--addr", &addr, "-o", &out, "--reference", &bvh, "--timeout-s", "20"]);
    let s = sender.wait_with_output().unwrap();
    assert!(s.status.success(), "{}", text(&s));
    assert!(text(&s).contains("1 reconnects"), "{}", text(&s));
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    assert!(t.contains("joined mid-stream"), "{t}");
    let start: usize = t.split("frame 0 is frame ").nth(1).unwrap().split_whitespace().next().unwrap().parse().unwrap();
    assert!(start > 10 && start < 80, "{t}");
    assert!(
        t.contains(&format!("emitted {} frames (frames {start}..90 of the sender's 90-frame clip)", 90 - start)),
        "{t}"
    );
    assert!(t.contains(&format!("frames {start}..90: mean")), "{t}");
    assert!(max_cm(&t[t.find("error vs").unwrap()..]) <= 1.0, "{t}");
    assert_eq!(inbetween_io::read_bvh(Path::new(&out)).unwrap().num_frames(), 90 - start);
}

#[test]
fn stream_over_loopback() {
    let dir = tempfile::tempdir().unwrap();
    let bvh = walk_bvh(dir.path());
    let port = std::net::TcpListener::bind("127.0.0.1:0").unwrap().local_addr().unwrap().port();
    let addr = format!("127.0.0.1:{port}");
    let out = dir.path().join("streamed.bvh").to_string_lossy().into_owned();
    let recv = {
        let (addr, out, bvh) = (addr.clone(), out.clone(), bvh.clone());
        std::thread::spawn(move || {
            inbetween(&[
                "mocap",
                "stream",
                "recv",
                "--addr",
                &addr,
                "-o",
                &out,
                "--reference",
                &bvh,
                "--timeout-s",
                "20",
            ])
        })
    };
    std::thread::sleep(std::time::Duration::from_millis(300));
    let o = inbetween(&["mocap", "stream", "send", &bvh, "--addr", &addr, "--fast", "--max-error", "1cm"]);
    assert!(o.status.success(), "{}", text(&o));
    assert!(text(&o).contains("added latency"), "{}", text(&o));
    let r = recv.join().unwrap();
    assert!(r.status.success(), "{}", text(&r));
    assert!(text(&r).contains("complete") && text(&r).contains("emitted 90 frames (frames 0..90"), "{}", text(&r));
    assert!(max_cm(&text(&r)[text(&r).find("error vs").unwrap()..]) <= 1.0, "{}", text(&r));
}

#[test]
fn train_on_procedural_gaits_then_bench_a_folder_with_the_policy() {
    let dir = tempfile::tempdir().unwrap();
    let policy = dir.path().join("p.bpk").to_string_lossy().into_owned();
    let o = inbetween(&[
        "mocap",
        "train",
        "--procedural",
        "--preset",
        "quick",
        "--episodes",
        "8",
        "--stride",
        "60",
        "-o",
        &policy,
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let info = std::fs::read_to_string(dir.path().join("p.json")).unwrap();
    assert!(info.contains("procedural gaits"), "the sidecar says what it was trained on: {info}");
    // A plain folder of clips: two procedural walks, different lengths and speeds.
    let data = dir.path().join("clips");
    std::fs::create_dir_all(&data).unwrap();
    // The second one in a sub-folder: --data searches below the folder too.
    std::fs::create_dir_all(data.join("more")).unwrap();
    for (i, frames, path) in [(0, 250, "walk0.bvh"), (1, 190, "more/walk1.bvh")] {
        let mut p = inbetween_core::procedural::GaitParams::walk();
        p.frames = frames;
        p.speed *= 1.0 + 0.2 * i as f64;
        inbetween_io::write_bvh(&data.join(path), &inbetween_core::procedural::gait(&p)).unwrap();
    }
    let csv = dir.path().join("bench.csv").to_string_lossy().into_owned();
    let o = inbetween(&[
        "mocap",
        "bench",
        "--data",
        data.to_str().unwrap(),
        "--model",
        &policy,
        "--csv",
        &csv,
        "--codec-bounds",
        "1",
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let table = std::fs::read_to_string(&csv).unwrap();
    for method in ["rc", "uc", "greedy", "sidql", "optimal"] {
        assert!(table.lines().any(|l| l.starts_with(&format!("{method},5,"))), "{method} missing:\n{table}");
    }
    // Without --model the bench uses the committed policy (trained on the CMU takes).
    let o = inbetween(&["mocap", "bench", "--data", data.to_str().unwrap(), "--codec-bounds", "1"]);
    assert!(o.status.success(), "{}", text(&o));
    assert!(text(&o).contains("committed policy (trained on: every CMU take"), "{}", text(&o));
    let o = inbetween(&["mocap", "bench", "--data", dir.path().join("none").to_str().unwrap()]);
    assert!(!o.status.success(), "{}", text(&o));
    // One clip: no test split, so the table and the chart use all windows.
    std::fs::remove_file(data.join("more/walk1.bvh")).unwrap();
    let png = dir.path().join("bench.png").to_string_lossy().into_owned();
    let o = inbetween(&["mocap", "bench", "--data", data.to_str().unwrap(), "--plot", &png, "--codec-bounds", "1"]);
    assert!(o.status.success(), "{}", text(&o));
    assert!(text(&o).contains("test split has no windows"), "{}", text(&o));
    assert!(std::fs::metadata(&png).unwrap().len() > 1000);
    // A clip shorter than one window is refused with a reason, not a table of zeros.
    let mut p = inbetween_core::procedural::GaitParams::walk();
    p.frames = 40;
    inbetween_io::write_bvh(&data.join("walk0.bvh"), &inbetween_core::procedural::gait(&p)).unwrap();
    let o = inbetween(&["mocap", "bench", "--data", data.to_str().unwrap()]);
    assert!(!o.status.success() && text(&o).contains("long enough"), "{}", text(&o));
}

/// A sender killed mid-stream: the receiver keeps the frames it rebuilt (written whole), says
/// what it lost and exits non-zero.
#[test]
fn stream_receiver_of_a_killed_sender_keeps_its_frames_and_fails() {
    let dir = tempfile::tempdir().unwrap();
    let bvh = walk_bvh(dir.path());
    let port = std::net::TcpListener::bind("127.0.0.1:0").unwrap().local_addr().unwrap().port();
    let addr = format!("127.0.0.1:{port}");
    let out = dir.path().join("cut.bvh").to_string_lossy().into_owned();
    let exe = env!("CARGO_BIN_EXE_inbetween");
    let recv = Command::new(exe)
        .args(["mocap", "stream", "recv", "--addr", &addr, "-o", &out, "--timeout-s", "2"])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(300));
    // Real time: 90 frames at 30 fps take 3 s; killed after about 1.2 s.
    let mut sender = Command::new(exe)
        .args(["mocap", "stream", "send", &bvh, "--addr", &addr, "--max-error", "1cm", "--retries", "0"])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(1200));
    sender.kill().unwrap();
    sender.wait().unwrap();
    let r = recv.wait_with_output().unwrap();
    let t = text(&r);
    assert!(!r.status.success(), "{t}");
    assert!(t.contains("without the sender's End") && t.contains("lost after them"), "{t}");
    let kept = inbetween_io::read_bvh(Path::new(&out)).unwrap().num_frames();
    assert!(kept > 0 && kept < 90, "{kept} frames kept; {t}");
    assert!(t.contains(&format!("the {kept} frames received were kept")), "{t}");
}

/// `--max-error` without a unit is refused, showing the number with each unit.
#[test]
fn a_bound_without_a_unit_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let bvh = walk_bvh(dir.path());
    let out = dir.path().join("x.ibk").to_string_lossy().into_owned();
    let o = inbetween(&["mocap", "compress", &bvh, "--max-error", "1e9", "-o", &out]);
    assert!(!o.status.success());
    assert!(text(&o).contains("'1e9' has no length unit") && text(&o).contains("1e9cm"), "{}", text(&o));
    assert!(!Path::new(&out).exists());
}

#[test]
fn scale_measures_compress_on_the_demo_walk_and_writes_its_table() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("scale");
    let o = inbetween(&["mocap", "scale", "--scales", "1,2", "-o", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", text(&o));
    let csv = std::fs::read_to_string(out.join("mocap_scale.csv")).unwrap();
    let rows: Vec<&str> = csv.lines().skip(1).collect();
    assert_eq!(rows.len(), 2, "{csv}");
    assert!(rows[0].contains("60 frames × 31 joints") && rows[1].contains("120 frames × 31 joints"), "{csv}");
    assert!(rows.iter().all(|r| r.ends_with("ok")), "{csv}");
}
