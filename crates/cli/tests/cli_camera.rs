//! End-to-end checks of `inbetween camera …` with the committed weights.

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

fn generate(scene: &Path, keys: &Path, out: &Path, extra: &[&str]) -> std::process::Output {
    let mut args = vec!["camera", "generate", "--scene", s(scene), "--keys", s(keys), "-o", s(out)];
    args.extend_from_slice(extra);
    inbetween(&args)
}

#[test]
fn scenes_with_coinciding_or_same_named_characters_blame_the_scene() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    assert!(inbetween(&["camera", "scene", "-o", s(d), "--frames", "60"]).status.success());
    let scene: serde_json::Value = serde_json::from_slice(&std::fs::read(d.join("scene.json")).unwrap()).unwrap();
    let (keys, cam) = (d.join("keys.json"), d.join("cam.json"));
    // Both characters at the same place.
    let mut same_place = scene.clone();
    let name = same_place["characters"][1]["name"].clone();
    same_place["characters"][1] = same_place["characters"][0].clone();
    same_place["characters"][1]["name"] = name;
    let bad = d.join("same-place.json");
    std::fs::write(&bad, serde_json::to_vec(&same_place).unwrap()).unwrap();
    let err = fails(&generate(&bad, &keys, &cam, &[]));
    assert!(
        err.contains(&format!("{}: characters", bad.display()))
            && err.contains("stand at the same position at frame 0"),
        "{err}"
    );
    assert!(!err.contains("keys.json"), "the keys are not at fault: {err}");
    // Two characters with one name.
    let mut same_name = scene.clone();
    same_name["characters"][1]["name"] = same_name["characters"][0]["name"].clone();
    let bad = d.join("same-name.json");
    std::fs::write(&bad, serde_json::to_vec(&same_name).unwrap()).unwrap();
    let err = fails(&generate(&bad, &keys, &cam, &[]));
    assert!(err.contains(&format!("{}: characters 0 and 1 are both named", bad.display())), "{err}");
    assert!(!cam.exists());
}

#[test]
fn camera_limits_and_time_limits_name_their_flags_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    assert!(inbetween(&["camera", "scene", "-o", s(d), "--frames", "60"]).status.success());
    let before = listing(d);
    let (scene, keys, cam) = (d.join("scene.json"), d.join("keys.json"), d.join("cam.json"));
    let gif = d.join("cam.gif");
    let err = fails(&generate(&scene, &keys, &cam, &["--max-frames", "50"]));
    assert!(
        err.contains("60 frames, more than the limit of 50 frames (max_frames); raise it with --max-frames"),
        "{err}"
    );
    let err = fails(&generate(&scene, &keys, &cam, &["--max-keys", "2"]));
    assert!(
        err.contains("keys.json: 3 keys, more than the limit of 2 keys (max_keys); raise it with --max-keys"),
        "{err}"
    );
    let err = fails(&generate(&scene, &keys, &cam, &["--all-styles", "--gif", s(&gif), "--time-limit", "0.000001"]));
    assert!(err.contains("time limit of 0.000001 s reached; raise it with --time-limit"), "{err}");
    assert_eq!(listing(d), before, "no track, glTF or preview of any style, and no staging folder");
    let err =
        fails(&inbetween(&["camera", "scene", "-o", s(&d.join("big")), "--frames", "200", "--max-frames", "100"]));
    assert!(err.contains("raise it with --max-frames"), "{err}");
    assert!(!d.join("big").exists());
}

#[test]
fn generate_takes_two_bvh_takes_as_the_characters() {
    use inbetween_core::procedural::{gait, GaitParams};
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (a, b) = (d.join("a.bvh"), d.join("b.bvh"));
    std::fs::write(&a, inbetween_io::to_bvh_string(&gait(&GaitParams { frames: 90, ..GaitParams::walk() }))).unwrap();
    std::fs::write(&b, inbetween_io::to_bvh_string(&gait(&GaitParams { frames: 120, ..GaitParams::walk() }))).unwrap();
    let keys = d.join("keys.json");
    std::fs::write(
        &keys,
        r#"{"keys":[{"frame":0,"camera":{"pa":[-0.3,0.0],"pb":[0.3,0.0],"theta":1.0,"phi":0.2}},
                    {"frame":80,"camera":{"pa":[-0.2,0.1],"pb":[0.35,0.0],"theta":1.5,"phi":0.3}}]}"#,
    )
    .unwrap();
    let cam = d.join("cam.json");
    // `camera generate` on the two takes with the keys, then `extra`.
    let generate = |extra: &[&str]| {
        let mut args = vec!["camera", "generate", "--characters", s(&a), s(&b), "--keys", s(&keys)];
        args.extend_from_slice(extra);
        inbetween(&args)
    };
    let out = generate(&["--style", "orbit", "-o", s(&cam)]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(text.contains("a.bvh: root Hips, shoulders LeftArm / RightArm"), "{text}");
    assert!(text.contains("moved 1.5 m"), "two takes at one spot are set apart: {text}");
    let track: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&cam).unwrap()).unwrap();
    assert_eq!(track["frames"].as_array().unwrap().len(), 81);
    // The glTF written beside it is a style reference: its camera animation over the same takes.
    let again = d.join("again.json");
    let reference = cam.with_extension("gltf");
    let out = generate(&["--reference", s(&reference), "-o", s(&again)]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let track: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&again).unwrap()).unwrap();
    assert!(track["style"].as_str().unwrap().starts_with("reference:"), "{}", track["style"]);
    assert_eq!(track["frames"].as_array().unwrap().len(), 81);
    // Joints no scheme names are found by the skeleton's shape (issue 42) ...
    std::fs::write(&b, std::fs::read_to_string(&a).unwrap().replace("LeftArm", "Wing").replace("LeftShoulder", "Fin"))
        .unwrap();
    let out = generate(&["--style", "orbit", "-o", s(&cam)]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(text.contains("b.bvh: root Hips, shoulders Wing / RightArm (by shape)"), "{text}");
    // ... every scheme by name (Daz Genesis: `lShldrBend`) ...
    use inbetween_core::roles::fixtures::{chain, renamed, with_skeleton};
    let walk = gait(&GaitParams { frames: 90, ..GaitParams::walk() });
    let daz = with_skeleton(&walk, renamed(&walk.skeleton, inbetween_core::roles::Scheme::Daz));
    std::fs::write(&b, inbetween_io::to_bvh_string(&daz)).unwrap();
    let out = generate(&["--style", "orbit", "-o", s(&cam)]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(text.contains("shoulders lShldrBend / rShldrBend (by name (Daz Genesis))"), "{text}");
    // ... a roles file wins (it applies to both takes: both on the Daz rig here) ...
    std::fs::write(&a, inbetween_io::to_bvh_string(&daz)).unwrap();
    let roles = d.join("roles.json");
    std::fs::write(
        &roles,
        r#"{"left_clavicle": "rCollar", "left_upper_arm": "rShldrBend", "left_forearm": "rForearmBend",
            "left_hand": "rHand", "right_clavicle": "lCollar", "right_upper_arm": "lShldrBend",
            "right_forearm": "lForearmBend", "right_hand": "lHand"}"#,
    )
    .unwrap();
    let out = generate(&["--style", "orbit", "-o", s(&cam), "--roles", s(&roles)]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(text.contains("shoulders rShldrBend / lShldrBend (by roles file)"), "{text}");
    std::fs::write(&roles, r#"{"left_hand": "Wrist"}"#).unwrap();
    let err = fails(&generate(&["--style", "orbit", "-o", s(&cam), "--roles", s(&roles)]));
    assert!(err.contains("the roles file gives 'Wrist' for left_hand"), "{err}");
    std::fs::write(&roles, r#"{"lefthand": "lHand"}"#).unwrap();
    let err = fails(&generate(&["--style", "orbit", "-o", s(&cam), "--roles", s(&roles)]));
    assert!(err.contains("roles.json") && err.contains("unknown role 'lefthand'"), "{err}");
    // ... and a take that is no humanoid is refused, naming it, what is missing and --roles.
    let tail = inbetween_core::Motion::new(chain(), 1.0 / 30.0, vec![0.0; 90 * chain().num_channels()]).unwrap();
    std::fs::write(&b, inbetween_io::to_bvh_string(&tail)).unwrap();
    let err = fails(&generate(&["--style", "orbit", "-o", s(&cam)]));
    assert!(err.contains("b.bvh: not a humanoid skeleton") && err.contains("--roles"), "{err}");
    // --scene and --characters exclude each other.
    let err = fails(&inbetween(&["camera", "generate", "--keys", s(&keys), "-o", s(&cam)]));
    assert!(err.contains("--scene") || err.contains("--characters"), "{err}");
}
