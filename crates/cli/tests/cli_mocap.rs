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
    let o = inbetween(&["mocap", "compress", &bvh, "--max-error", "1cm", "-o", &ibk]);
    assert!(o.status.success(), "{}", text(&o));
    assert!(text(&o).contains("bytes per key"), "{}", text(&o));
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
    assert!(text(&r).contains("complete") && text(&r).contains("emitted 90 frames"), "{}", text(&r));
}

#[test]
fn train_on_procedural_gaits_then_bench_a_folder_with_the_policy() {
    let dir = tempfile::tempdir().unwrap();
    let policy = dir.path().join("p.bpk").to_string_lossy().into_owned();
    let o = inbetween(&[
        "mocap", "train", "--procedural", "--preset", "quick", "--episodes", "8", "--stride", "60", "-o", &policy,
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let info = std::fs::read_to_string(dir.path().join("p.json")).unwrap();
    assert!(info.contains("procedural gaits"), "the sidecar says what it was trained on: {info}");
    // A plain folder of clips: two procedural walks, different lengths and speeds.
    let data = dir.path().join("clips");
    std::fs::create_dir_all(&data).unwrap();
    for (i, frames) in [(0, 250), (1, 190)] {
        let mut p = inbetween_core::procedural::GaitParams::walk();
        p.frames = frames;
        p.speed *= 1.0 + 0.2 * i as f64;
        inbetween_io::write_bvh(&data.join(format!("walk{i}.bvh")), &inbetween_core::procedural::gait(&p)).unwrap();
    }
    let csv = dir.path().join("bench.csv").to_string_lossy().into_owned();
    let o = inbetween(&[
        "mocap", "bench", "--data", data.to_str().unwrap(), "--model", &policy, "--csv", &csv, "--codec-bounds", "1",
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let table = std::fs::read_to_string(&csv).unwrap();
    for method in ["rc", "uc", "greedy", "sidql", "optimal"] {
        assert!(table.lines().any(|l| l.starts_with(&format!("{method},5,"))), "{method} missing:\n{table}");
    }
    // Without --model the bench uses the committed policy (trained on our procedural gaits).
    let o = inbetween(&["mocap", "bench", "--data", data.to_str().unwrap(), "--codec-bounds", "1"]);
    assert!(o.status.success(), "{}", text(&o));
    assert!(text(&o).contains("committed policy (trained on: 24 procedural gaits"), "{}", text(&o));
    let o = inbetween(&["mocap", "bench", "--data", dir.path().join("none").to_str().unwrap()]);
    assert!(!o.status.success(), "{}", text(&o));
    // One clip: no test split, so the table and the chart use all windows.
    std::fs::remove_file(data.join("walk1.bvh")).unwrap();
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
