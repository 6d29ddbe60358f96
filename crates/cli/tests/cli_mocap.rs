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
