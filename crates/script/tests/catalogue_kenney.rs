//! Kenney CC0 furniture models: measured sizes and model paths (when ../shared/data is present),
//! and a tiny GLB this test writes itself.

use inbetween_script::catalogue::builtin::builtin;
use inbetween_script::catalogue::kenney::{glb_bounds, with_models, MODELS};
use inbetween_script::ScriptError;

/// A GLB: one node translated (1, 0, 0) with a child scaled ×2 holding a mesh spanning
/// [0,1]×[0,1]×[-1,0] → bounds [1,3]×[0,2]×[-2,0] in model units.
fn tiny_glb() -> Vec<u8> {
    let json = serde_json::json!({
        "asset": {"version": "2.0"},
        "scenes": [{"nodes": [0]}],
        "nodes": [{"children": [1], "translation": [1.0, 0.0, 0.0]}, {"mesh": 0, "scale": [2.0, 2.0, 2.0]}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
        "accessors": [{"componentType": 5126, "count": 8, "type": "VEC3", "min": [0.0, 0.0, -1.0], "max": [1.0, 1.0, 0.0]}]
    });
    let mut text = serde_json::to_vec(&json).unwrap();
    while !text.len().is_multiple_of(4) {
        text.push(b' ');
    }
    let mut out = b"glTF".to_vec();
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&((20 + text.len()) as u32).to_le_bytes());
    out.extend_from_slice(&(text.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&text);
    out
}

#[test]
fn a_tiny_glb_sets_size_and_model() {
    assert_eq!(glb_bounds(&tiny_glb()).unwrap(), ([1.0, 0.0, -2.0], [3.0, 2.0, 0.0]));
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("desk.glb"), tiny_glb()).unwrap();
    let cat = with_models(builtin(), dir.path()).unwrap();
    let desk = cat.get("desk").unwrap();
    // Height kept (0.75 m); the model's 2 × 2 × 2 proportions give width and depth.
    assert_eq!(desk.model.as_deref(), Some("desk"));
    for (got, want) in desk.size.iter().zip([0.75, 0.75, 0.75]) {
        assert!((got - want).abs() < 1e-6, "{:?}", desk.size);
    }
    assert_eq!(cat.model_path("desk").unwrap(), dir.path().join("desk.glb"));
    assert!((cat.model("desk").unwrap().scale - 0.375).abs() < 1e-6);
    // Categories without a file keep their box.
    assert_eq!(cat.get("bed").unwrap(), builtin().get("bed").unwrap());
}

#[test]
fn a_broken_glb_is_an_error_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let mut g = tiny_glb();
    g.truncate(30);
    std::fs::write(dir.path().join("bedSingle.glb"), g).unwrap();
    let err = with_models(builtin(), dir.path()).unwrap_err();
    assert!(matches!(err, ScriptError::Asset { .. }));
    let msg = err.to_string();
    assert!(msg.contains("bedSingle.glb") && msg.contains("past the file end"), "{msg}");
    assert!(with_models(builtin(), &dir.path().join("missing")).is_err());
}

#[test]
fn kenney_furniture_from_shared_data() {
    inbetween_io::data::with_shared_data("Kenney furniture models", |data| {
        let dir = data.join("assets/kenney_furniture");
        if !dir.is_dir() {
            println!("skipped: no data at {}", dir.display());
            return;
        }
        let base = builtin();
        let cat = with_models(base.clone(), &dir).unwrap();
        let mut measured = 0;
        for &(stem, names) in MODELS {
            if !dir.join(format!("{stem}.glb")).is_file() {
                continue;
            }
            for &name in names {
                let (c, b) = (cat.get(name).unwrap(), base.get(name).unwrap());
                assert_eq!(c.model.as_deref(), Some(stem));
                let m = cat.model(name).unwrap();
                // Kenney furniture is built at roughly half scale.
                assert!(m.scale > 0.8 && m.scale < 4.0, "{stem}: scale {}", m.scale);
                if b.size[1] >= 0.05 {
                    assert!((c.size[1] - b.size[1]).abs() < 1e-4, "{name}: height kept");
                }
                // Measured footprints stay plausible next to the box guesses (a vintage TV is deep).
                for k in [0, 2] {
                    let ratio = c.size[k] / b.size[k];
                    assert!(ratio > 0.25 && ratio < 5.0, "{name} ({stem}): {:?} vs {:?}", c.size, b.size);
                }
                println!(
                    "{name:12} {stem:20} ×{:.2} {:?} (box {:?})",
                    m.scale,
                    c.size.map(|x| (x * 100.0).round() / 100.0),
                    b.size
                );
                measured += 1;
            }
        }
        assert!(measured >= 20, "{measured}");
        // The scene database does not depend on the installed models.
        use inbetween_script::database::SceneDatabase;
        assert_eq!(SceneDatabase::builtin(&cat, 2, 3).scenes, SceneDatabase::builtin(&base, 2, 3).scenes);
    });
}
