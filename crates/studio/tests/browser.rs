//! Real-browser test (issue 23): headless Chromium drives the page through its `data-testid`
//! hooks and `window.inbetweenStudio`. Prints `skipped: no chromium` when Chromium is absent, and
//! `skipped: no data at …` for the real-BVH part when the shared corpus is absent.

use std::path::Path;

use inbetween_studio::browser::{available, Browser};
use inbetween_studio::{Studio, StudioConfig};
use serde_json::Value;

/// The visible panel's element with `testid`.
fn sel(testid: &str) -> String {
    format!("section.panel:not([hidden]) [data-testid={testid}], header [data-testid={testid}], .view [data-testid={testid}]")
}

fn js_sel(testid: &str) -> String {
    format!("document.querySelector({:?})", sel(testid))
}

fn state(b: &Browser) -> Value {
    b.eval("window.inbetweenStudio.state()").expect("state()")
}

fn click_and_wait(b: &Browser, testid: &str) -> Value {
    b.eval(&format!("({}.click(), window.inbetweenStudio.ready())", js_sel(testid))).expect("click");
    state(b)
}

/// Sets the visible panel's file input and waits for the job its change event starts.
fn open_files(b: &Browser, files: &[&Path]) {
    let n = b.eval("window.inbetweenStudio.started()").unwrap().as_u64().unwrap();
    b.set_files(&sel("file-input"), files).unwrap();
    b.eval(&format!(
        "new Promise((ok, fail) => {{ const t0 = Date.now(); const poll = () => \
           window.inbetweenStudio.started() > {n} ? ok(window.inbetweenStudio.ready()) \
           : Date.now() - t0 > 20000 ? fail(new Error('no job started')) : setTimeout(poll, 20); poll(); }})"
    ))
    .unwrap();
}

fn error_text(b: &Browser) -> String {
    b.eval("document.querySelector('[data-testid=error]').textContent").unwrap().as_str().unwrap_or("").to_string()
}

/// Share of the viewport's pixels that differ from its background colour, from a screenshot.
fn viewport_coverage(b: &Browser) -> f64 {
    let rect = b
        .eval("(r => [r.left, r.top, r.width, r.height])(document.querySelector('[data-testid=viewport]').getBoundingClientRect())")
        .unwrap();
    let r: Vec<u32> = rect.as_array().unwrap().iter().map(|v| v.as_f64().unwrap().round() as u32).collect();
    let png = b.screenshot().unwrap();
    let img = image::load_from_memory(&png).unwrap().to_rgb8();
    let bg = [0x2b, 0x2f, 0x37];
    let (mut differ, mut total) = (0u64, 0u64);
    for y in r[1]..(r[1] + r[3]).min(img.height()) {
        for x in r[0]..(r[0] + r[2]).min(img.width()) {
            let p = img.get_pixel(x, y).0;
            total += 1;
            if p.iter().zip(bg).any(|(a, b)| (*a as i32 - b).abs() > 12) {
                differ += 1;
            }
        }
    }
    differ as f64 / total.max(1) as f64
}

fn object_positions(st: &Value) -> Vec<(String, Vec<f64>)> {
    st["objects"]
        .as_array()
        .unwrap()
        .iter()
        .map(|o| {
            (
                o["label"].as_str().unwrap().to_string(),
                o["position"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect(),
            )
        })
        .collect()
}

#[test]
fn studio_in_headless_chromium() {
    let (chromium, driver) = match available() {
        Ok(found) => found,
        Err(why) => {
            println!("skipped: {why}");
            return;
        }
    };
    if inbetween_studio::assets::missing().is_some() {
        println!("skipped: the studio was built without three.js (no Node at build time)");
        return;
    }
    let data = inbetween_io::shared_data_dir();
    let studio =
        Studio::start(StudioConfig { port: 0, root: data.clone().ok(), ..StudioConfig::default() }).expect("start");
    let b = Browser::launch(&chromium, &driver, 1280, 800).expect("launch chromium");
    b.goto(&studio.url()).unwrap();
    b.eval("window.inbetweenStudio.ready()").unwrap();
    let st = state(&b);
    assert_eq!(st["panel"], "script", "{st}");
    assert_eq!(error_text(&b), "");

    // The demo story: the furnished room, the characters, the camera.
    let st = click_and_wait(&b, "script-run");
    assert_eq!(error_text(&b), "");
    assert_eq!(st["lastJob"]["ok"], true, "{st}");
    assert_eq!(st["lastJob"]["kind"], "script", "{st}");
    assert!(st["objects"].as_array().unwrap().len() >= 5, "{st}");
    let chars: Vec<&str> = st["characters"].as_array().unwrap().iter().map(|c| c["name"].as_str().unwrap()).collect();
    assert_eq!(chars, ["Eve", "Tom"], "{st}");
    assert!(st["frames"].as_u64().unwrap() > 30, "{st}");
    assert!(st["camera"]["eye"].as_array().unwrap().len() == 3, "{st}");
    let status = b.eval("document.querySelector('[data-testid=status]').textContent").unwrap();
    assert!(status.as_str().unwrap().contains("story:"), "{status}");
    b.eval("window.inbetweenStudio.seek(60)").unwrap();
    assert_eq!(state(&b)["frame"], 60);
    let frame_text = b.eval("document.querySelector('[data-testid=frame]').textContent").unwrap();
    assert!(frame_text.as_str().unwrap().starts_with("60 /"), "{frame_text}");
    let covered = viewport_coverage(&b);
    assert!(covered > 0.05, "the 3D view looks blank: {:.3} of its pixels differ from the background", covered);

    // Edit one scene sentence: the objects of the unchanged sentences keep their places.
    let before = object_positions(&st);
    b.eval(&format!(
        "(t => {{ t.value = t.value.replace('A laptop and a lamp are on the desk$', 'A laptop and a plant are on the desk$'); t.dispatchEvent(new Event('input')); return t.value.includes('plant'); }})({})",
        js_sel("script-text")
    ))
    .unwrap();
    let st = click_and_wait(&b, "script-run");
    assert_eq!(st["lastJob"]["ok"], true, "{st}");
    let after = object_positions(&st);
    assert!(after.iter().any(|(l, _)| l.contains("plant")), "{after:?}");
    let mut kept = 0;
    for cat in ["desk", "bookshelf", "sofa", "table", "chair", "laptop"] {
        let find = |v: &[(String, Vec<f64>)]| v.iter().find(|(l, _)| l == cat).map(|x| x.1.clone());
        let (p0, p1) = (find(&before), find(&after));
        assert!(p0.is_some() && p1.is_some(), "'{cat}' missing: {before:?} / {after:?}");
        assert_eq!(p0, p1, "'{cat}' moved although its sentence did not change");
        kept += 1;
    }
    assert_eq!(kept, 6);

    // Mocap panel: a real take from the corpus (or the built-in walk without data).
    b.eval("(document.querySelector('[data-testid=nav-mocap]').click(), true)").unwrap();
    assert_eq!(state(&b)["panel"], "mocap");
    let real = data.as_ref().ok().map(|d| d.join("mocap/cmu/iclone_cc/007_12.bvh")).filter(|p| p.is_file());
    match &real {
        Some(p) => {
            open_files(&b, &[p.as_path()]);
        }
        None => {
            println!("skipped: no data at {} (real BVH; using the built-in walk)", data.unwrap_err().display());
            b.eval("(s => { s.value = 'builtin:walk'; s.dispatchEvent(new Event('change')); return window.inbetweenStudio.ready(); })(document.getElementById('mocap-corpus'))").unwrap();
        }
    }
    let st = state(&b);
    assert_eq!(error_text(&b), "", "{st}");
    assert_eq!(st["lastJob"]["kind"], "open", "{st}");
    let frames = st["frames"].as_u64().unwrap();
    assert_eq!(frames, if real.is_some() { 132 } else { 240 }, "{st}");
    assert!(st["characters"][0]["joints"].as_u64().unwrap() > 10, "{st}");

    // Change K: the keys follow at once.
    for k in [8u64, 12] {
        b.eval(&format!(
            "(i => {{ i.value = {k}; i.dispatchEvent(new Event('change')); return window.inbetweenStudio.ready(); }})({})",
            js_sel("mocap-k")
        ))
        .unwrap();
        let st = state(&b);
        assert_eq!(st["lastJob"]["kind"], "keys", "{st}");
        let keys = st["keys"].as_array().unwrap();
        assert_eq!(keys.len() as u64, k, "{st}");
        assert_eq!(keys[0], 0);
        assert_eq!(keys[keys.len() - 1].as_u64().unwrap(), frames - 1);
        assert!(st["lastJob"]["error_cm"].as_f64().unwrap() > 0.0, "{st}");
        assert!(st["lastJob"]["message"].as_str().unwrap().contains("cm"), "{st}");
    }
    // SIDQL on a take longer than its 64-frame windows.
    let st = b
        .eval(&format!(
            "(m => {{ m.value = 'sidql'; m.dispatchEvent(new Event('change')); return window.inbetweenStudio.ready(); }})({})",
            js_sel("mocap-method")
        ))
        .map(|_| state(&b))
        .unwrap();
    assert_eq!(st["lastJob"]["ok"], true, "{st}");
    assert_eq!(st["keys"].as_array().unwrap().len(), 12, "{st}");
    assert!(st["lastJob"]["message"].as_str().unwrap().starts_with("SIDQL K=12"), "{st}");
    let covered = viewport_coverage(&b);
    assert!(covered > 0.002, "the mocap view looks blank: {covered:.4}");

    // Compress: ratio and decoded error.
    let st = click_and_wait(&b, "mocap-compress");
    assert_eq!(st["lastJob"]["kind"], "compress", "{st}");
    assert!(st["lastJob"]["ratio"].as_f64().unwrap() > 1.0, "{st}");
    assert!(st["lastJob"]["bytes"].as_u64().unwrap() > 0, "{st}");
    let bound = b.eval(&format!("parseFloat({}.value)", js_sel("mocap-bound"))).unwrap().as_f64().unwrap();
    assert!(st["lastJob"]["error_cm"].as_f64().unwrap() <= bound + 1e-9, "{st}");

    // A garbage file: its error in the page, and the server keeps serving.
    let dir = tempfile::tempdir().unwrap();
    let junk = dir.path().join("garbage.bvh");
    std::fs::write(&junk, "HIERARCHY\nROOT Hips\n{\n  OFFSET nope\n").unwrap();
    open_files(&b, &[Path::new(&junk)]);
    let err = error_text(&b);
    assert!(err.contains("garbage.bvh:"), "the error should name the file and line: {err:?}");
    assert_eq!(state(&b)["lastJob"]["ok"], false);
    // The next successful job clears the error.
    let st = click_and_wait(&b, "mocap-run");
    assert_eq!(st["lastJob"]["ok"], true, "{st}");
    assert_eq!(error_text(&b), "");
}
