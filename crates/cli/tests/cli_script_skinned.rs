//! `inbetween script run builtin:demo --skinned` from the command line: with the Kenney blocky
//! characters of the shared data, story_skinned.gltf (valid JSON, one skin per character) and
//! story_skinned.png are written next to story.gltf; without them the stick-figure outputs are
//! still written and the error names where it looked.

use std::path::Path;
use std::process::Command;

fn inbetween() -> Command {
    Command::new(env!("CARGO_BIN_EXE_inbetween"))
}

fn run_skinned(out: &Path, data: &Path) -> std::process::Output {
    inbetween()
        .args(["script", "run", "builtin:demo", "-o"])
        .arg(out)
        .args(["--skinned", "--gif-width", "160"])
        .env("INBETWEEN_DATA", data)
        .output()
        .unwrap()
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(path).unwrap())
        .unwrap_or_else(|e| panic!("{}: not JSON: {e}", path.display()))
}

#[test]
fn run_skinned_writes_kenney_characters_from_the_shared_data() {
    let Some(data) = inbetween_io::data::with_shared_data("script run --skinned", |p| p) else { return };
    if !data.join("assets/kenney_blocky_characters/character-a.glb").is_file() {
        println!(
            "skipped: no data at {} (assets/kenney_blocky_characters)",
            data.join("assets/kenney_blocky_characters").display()
        );
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("story");
    let o = run_skinned(&out, &data);
    let (stdout, stderr) = (String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
    assert!(o.status.success(), "{stdout}\n{stderr}");
    assert!(stdout.contains("wears") && stdout.contains("character-a.glb"), "{stdout}");
    let doc = json(&out.join("story_skinned.gltf"));
    assert_eq!(doc["asset"]["version"], "2.0");
    // The demo has two characters (Eve, Tom): one skin and one skinned mesh node each.
    let skins = doc["skins"].as_array().expect("skins");
    assert_eq!(skins.len(), 2, "{skins:?}");
    let skinned_nodes = doc["nodes"].as_array().unwrap().iter().filter(|n| n.get("skin").is_some()).count();
    assert_eq!(skinned_nodes, 2);
    assert!(!doc["animations"].as_array().unwrap().is_empty());
    assert!(doc["images"].as_array().is_some_and(|i| !i.is_empty()), "the Kenney texture is embedded");
    let png = std::fs::read(out.join("story_skinned.png")).unwrap();
    assert!(png.starts_with(b"\x89PNG\r\n\x1a\n"), "story_skinned.png is not a PNG");
    // The stick-figure document is still there and still parses.
    assert_eq!(json(&out.join("story.gltf"))["asset"]["version"], "2.0");
}

#[test]
fn run_skinned_without_the_kenney_files_names_where_it_looked() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("story");
    let o = run_skinned(&out, Path::new("/tmp/no-such-data-xyz"));
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success());
    assert!(
        stderr.contains("error:")
            && stderr.contains("/tmp/no-such-data-xyz")
            && stderr.contains("kenney_blocky_characters"),
        "{stderr}"
    );
    assert!(!stderr.contains("panicked"), "{stderr}");
    // The usual outputs come first and stay; the skinned ones are not written.
    assert_eq!(json(&out.join("story.gltf"))["asset"]["version"], "2.0");
    assert!(!out.join("story_skinned.gltf").exists() && !out.join("story_skinned.png").exists());
}
