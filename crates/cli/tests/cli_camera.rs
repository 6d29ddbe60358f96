//! End-to-end checks of `inbetween camera …` with the committed weights.

use std::path::Path;
use std::process::Command;

fn inbetween(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_inbetween")).args(args).output().expect("run inbetween")
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn scene_then_generate_writes_track_gltf_and_preview() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let out = inbetween(&["camera", "scene", "-o", s(d), "--frames", "120"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let cam = d.join("cam.json");
    let gif = d.join("cam.gif");
    let out = inbetween(&[
        "camera",
        "generate",
        "--scene",
        s(&d.join("scene.json")),
        "--keys",
        s(&d.join("keys.json")),
        "--style",
        "side",
        "-o",
        s(&cam),
        "--gif",
        s(&gif),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let track: serde_json::Value = serde_json::from_slice(&std::fs::read(&cam).unwrap()).unwrap();
    assert_eq!(track["frames"].as_array().unwrap().len(), 120);
    assert_eq!(track["style"], "side");
    assert!(track["max_corrected_residual"].as_f64().unwrap() < 1e-9, "keys are hit exactly");
    let gltf: serde_json::Value = serde_json::from_slice(&std::fs::read(d.join("cam.gltf")).unwrap()).unwrap();
    assert_eq!(gltf["asset"]["version"], "2.0");
    assert!(std::fs::read(&gif).unwrap().starts_with(b"GIF89a"));

    let out = inbetween(&[
        "camera",
        "generate",
        "--scene",
        s(&d.join("scene.json")),
        "--keys",
        s(&d.join("keys.json")),
        "--all-styles",
        "-o",
        s(&cam),
    ]);
    assert!(out.status.success());
    for b in ["direct", "relative", "side", "orbit"] {
        assert!(d.join(format!("cam-{b}.json")).exists(), "{b}");
    }
}

#[test]
fn bad_inputs_are_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    assert!(inbetween(&["camera", "scene", "-o", s(d), "--frames", "60"]).status.success());
    std::fs::write(d.join("bad.json"), "{\"keys\": [ {\"frame\": 0,\n \"camera\": 7} ]}").unwrap();
    let out = inbetween(&[
        "camera",
        "generate",
        "--scene",
        s(&d.join("scene.json")),
        "--keys",
        s(&d.join("bad.json")),
        "-o",
        s(&d.join("c.json")),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("bad.json:2"), "{err}");
    let out = inbetween(&[
        "camera",
        "generate",
        "--scene",
        s(&d.join("scene.json")),
        "--keys",
        s(&d.join("keys.json")),
        "--style",
        "dolly",
        "-o",
        s(&d.join("c.json")),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("unknown style `dolly`"), "{err}");
}

#[test]
fn train_resumes_from_its_checkpoint_and_can_restart_the_learning_rate() {
    let dir = tempfile::tempdir().unwrap();
    let (weights, ckpt) = (dir.path().join("w.bpk"), dir.path().join("ck"));
    let small = ["--iters-per-epoch", "2", "--batch", "4", "--scenes", "1", "--hidden", "16"];
    let run = |extra: &[&str]| {
        let mut args = vec!["camera", "train", "-o", s(&weights), "--checkpoints", s(&ckpt)];
        args.extend_from_slice(&small);
        args.extend_from_slice(extra);
        let out = inbetween(&args);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let text = std::fs::read_to_string(weights.with_extension("json")).unwrap();
        let card = serde_json::from_str::<serde_json::Value>(&text).unwrap();
        assert_eq!(card["kind"], "camera");
        assert_eq!(card["extra"]["style_codes"].as_array().unwrap().len(), 8, "4 behaviours × main left/right");
        card["training"].clone()
    };
    let first = run(&["--epochs", "1"]);
    assert_eq!(first["epochs_done"], 1);
    let resumed = run(&["--epochs", "2", "--lr", "5e-4", "--restart-lr"]);
    assert_eq!(resumed["epochs_done"], 2, "the second run continues the first");
    assert_eq!(resumed["iterations"], 4);
    assert_eq!(resumed["config"]["lr_decay_from"], 1);
    assert_eq!(resumed["lr"], 5e-4, "epoch 2 runs at the restarted rate, not 5e-4 × 0.97");
    // The trained weights load back for generation.
    let d = dir.path();
    assert!(inbetween(&["camera", "scene", "-o", s(d), "--frames", "60"]).status.success());
    let out = inbetween(&[
        "camera",
        "generate",
        "--scene",
        s(&d.join("scene.json")),
        "--keys",
        s(&d.join("keys.json")),
        "--weights",
        s(&weights),
        "-o",
        s(&d.join("c.json")),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
}

#[test]
fn train_refuses_to_overwrite_the_committed_weights() {
    let committed = Path::new(env!("CARGO_MANIFEST_DIR")).join("../camera/weights/camera.bpk");
    let before = std::fs::read(&committed).unwrap();
    let out = inbetween(&[
        "camera",
        "train",
        "-o",
        s(&committed),
        "--epochs",
        "1",
        "--iters-per-epoch",
        "1",
        "--batch",
        "2",
        "--scenes",
        "1",
        "--hidden",
        "8",
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("--overwrite-committed"), "{err}");
    assert_eq!(std::fs::read(&committed).unwrap(), before, "the committed weights are untouched");
}
