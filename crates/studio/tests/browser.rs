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
    set_files_and_wait(b, "file-input", files);
}

/// Sets the visible panel's file input `testid` and waits for the job its change event starts.
fn set_files_and_wait(b: &Browser, testid: &str, files: &[&Path]) {
    let n = b.eval("window.inbetweenStudio.started()").unwrap().as_u64().unwrap();
    b.set_files(&sel(testid), files).unwrap();
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

/// Share of an element's pixels that differ from `bg`, from a screenshot.
fn coverage(b: &Browser, testid: &str, bg: [i32; 3]) -> f64 {
    let rect = b
        .eval(&format!(
            "(r => [r.left, r.top, r.width, r.height])(document.querySelector('[data-testid={testid}]').getBoundingClientRect())"
        ))
        .unwrap();
    let r: Vec<u32> = rect.as_array().unwrap().iter().map(|v| v.as_f64().unwrap().round() as u32).collect();
    let img = image::load_from_memory(&b.screenshot().unwrap()).unwrap().to_rgb8();
    let (mut differ, mut total) = (0u64, 0u64);
    for y in r[1]..(r[1] + r[3]).min(img.height()) {
        for x in r[0]..(r[0] + r[2]).min(img.width()) {
            total += 1;
            if img.get_pixel(x, y).0.iter().zip(bg).any(|(a, b)| (*a as i32 - b).abs() > 12) {
                differ += 1;
            }
        }
    }
    differ as f64 / total.max(1) as f64
}

/// Sets an input's value and fires its change event.
fn set_value(b: &Browser, testid: &str, value: &str) {
    b.eval(&format!(
        "(i => {{ i.value = {value:?}; i.dispatchEvent(new Event('change')); return true; }})({})",
        js_sel(testid)
    ))
    .unwrap();
}

/// The face panel's columns as `name -> values per input row`.
fn edited(st: &Value) -> serde_json::Map<String, Value> {
    st["face"]["edited"].as_object().unwrap().clone()
}

fn col(m: &serde_json::Map<String, Value>, name: &str) -> Vec<f64> {
    m[name].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect()
}

/// Rows whose time (from the first row) lies inside `[a, b]`, and the file's times.
fn rows_inside(times: &[f64], a: f64, b: f64) -> Vec<usize> {
    (0..times.len()).filter(|&i| times[i] >= a && times[i] <= b).collect()
}

/// A studio (files under the shared data when present) and headless Chromium on its page, showing
/// `panel`; None (after printing why) when Chromium or the built page is missing.
fn open_panel(panel: &str) -> Option<(Studio, Browser, Result<std::path::PathBuf, std::path::PathBuf>)> {
    let (chromium, driver) = match available() {
        Ok(found) => found,
        Err(why) => {
            println!("skipped: {why}");
            return None;
        }
    };
    if inbetween_studio::assets::missing().is_some() {
        println!("skipped: the studio was built without three.js (no Node at build time)");
        return None;
    }
    let data = inbetween_io::shared_data_dir();
    let studio =
        Studio::start(StudioConfig { port: 0, root: data.clone().ok(), ..StudioConfig::default() }).expect("start");
    let b = Browser::launch(&chromium, &driver, 1280, 800).expect("launch chromium");
    b.goto(&studio.url()).unwrap();
    b.eval("window.inbetweenStudio.ready()").unwrap();
    b.eval(&format!("(document.querySelector('[data-testid=nav-{panel}]').click(), true)")).unwrap();
    assert_eq!(state(&b)["panel"], panel);
    Some((studio, b, data))
}

/// Opens a garbage file `name` through the visible panel's file input: its error names the file and
/// the job fails; then `recover` (a button) succeeds and clears the error: the server kept serving.
fn garbage_then_recover(b: &Browser, name: &str, bytes: &[u8], recover: &str) {
    let dir = tempfile::tempdir().unwrap();
    let junk = dir.path().join(name);
    std::fs::write(&junk, bytes).unwrap();
    open_files(b, &[junk.as_path()]);
    let err = error_text(b);
    assert!(err.contains(name), "the error should name the file: {err:?}");
    assert_eq!(state(b)["lastJob"]["ok"], false);
    let st = click_and_wait(b, recover);
    assert_eq!(st["lastJob"]["ok"], true, "{}", st["lastJob"]);
    assert_eq!(error_text(b), "");
}

/// Without the shared data (`what` names what was missing): picks `value` in the select `select_id`
/// instead and waits for its job.
fn open_builtin(
    b: &Browser,
    data: &Result<std::path::PathBuf, std::path::PathBuf>,
    what: &str,
    select_id: &str,
    value: &str,
) {
    let at = data.as_ref().map_or_else(|e| e.display().to_string(), |d| d.display().to_string());
    println!("skipped: no data at {at} ({what}; using {value})");
    b.eval(&format!(
        "(s => {{ s.value = {value:?}; s.dispatchEvent(new Event('change')); return window.inbetweenStudio.ready(); }})(document.getElementById({select_id:?}))"
    ))
    .unwrap();
}

#[test]
fn face_panel_in_headless_chromium() {
    let Some((_studio, b, data)) = open_panel("face") else { return };

    // A real capture from the corpus (the built-in procedural take without data).
    let real = "face/neurosync/livelink/Fearful/MySlate_162_iPhone_cal.csv";
    let have_real = data.as_ref().map(|d| d.join(real).is_file()).unwrap_or(false);
    let path = if have_real {
        real
    } else {
        println!(
            "skipped: no data at {} (real face capture; using the built-in take)",
            data.as_ref().map_or_else(|e| e.display().to_string(), |d| d.display().to_string())
        );
        "builtin:procedural"
    };
    b.eval(&format!(
        "(s => {{ s.value = {path:?}; s.dispatchEvent(new Event('change')); return window.inbetweenStudio.ready(); }})(document.getElementById('face-corpus'))"
    ))
    .unwrap();
    let st = state(&b);
    assert_eq!(error_text(&b), "", "{}", st["lastJob"]);
    assert_eq!(st["lastJob"]["kind"], "face-open", "{}", st["lastJob"]);
    let frames = st["frames"].as_u64().unwrap() as usize;
    assert!(frames >= 300, "{}", st["lastJob"]);
    let original = edited(&st);
    assert_eq!(original.len(), 52);
    assert_eq!(col(&original, "JawOpen").len(), frames, "one value per input row");
    let times: Vec<f64> = serde_json::from_value(b.eval("window.inbetweenStudio.faceTimes()").unwrap()).unwrap();
    assert_eq!(times.len(), frames);
    let fps = (frames - 1) as f64 / times[frames - 1];

    // A 2 s unguided span: the frames inside change, the ones outside do not.
    set_value(&b, "face-mask-start", "4");
    set_value(&b, "face-mask-end", "6");
    set_value(&b, "face-constraint", "none");
    let st = click_and_wait(&b, "face-generate");
    assert_eq!(error_text(&b), "", "{}", st["lastJob"]);
    assert_eq!(st["lastJob"]["ok"], true, "{}", st["lastJob"]);
    let mask: Vec<f64> = serde_json::from_value(st["face"]["mask"].clone()).unwrap();
    assert_eq!(mask, [4.0, 6.0]);
    assert!(st["lastJob"]["message"].as_str().unwrap().starts_with("retrieval fill"), "{}", st["lastJob"]);
    assert!(st["lastJob"]["masked_mse"].as_f64().unwrap() > 0.0);
    let first = edited(&st);
    let inside = rows_inside(&times, 4.0 + 0.05, 6.0 - 0.05);
    let mut changed_inside = 0;
    for name in original.keys() {
        let (o, e) = (col(&original, name), col(&first, name));
        for i in 0..frames {
            let t = times[i];
            if !(4.0 - 0.02..=6.0 + 0.02).contains(&t) {
                assert_eq!(o[i], e[i], "{name} changed at row {i} ({t:.3} s), outside the span");
            }
        }
        changed_inside += inside.iter().filter(|&&i| (o[i] - e[i]).abs() > 1e-4).count();
    }
    assert!(changed_inside > inside.len(), "the fill changed only {changed_inside} values inside the span");
    let covered = coverage(&b, "face-curves", [0x1b, 0x1d, 0x22]);
    assert!(covered > 0.02, "the curves look blank: {covered:.3}");
    let covered = coverage(&b, "face-edited", [0x23, 0x26, 0x2d]);
    assert!(covered > 0.2, "the schematic face looks blank: {covered:.3}");

    // Undo brings the original back, redo the fill.
    let st = click_and_wait(&b, "face-undo");
    assert_eq!(edited(&st), original, "undo");
    let st = click_and_wait(&b, "face-redo");
    assert_eq!(edited(&st), first, "redo");

    // Variants: three fills with thumbnails, the first applied; a click on the second shows it.
    set_value(&b, "face-variants-count", "3");
    let st = click_and_wait(&b, "face-generate");
    assert_eq!(st["lastJob"]["ok"], true, "{}", st["lastJob"]);
    assert_eq!((st["face"]["variants"].as_u64(), st["face"]["picked"].as_u64()), (Some(3), Some(1)));
    let one = edited(&st);
    let covered = coverage(&b, "face-variant-2", [0x1b, 0x1d, 0x22]);
    assert!(covered > 0.03, "the second variant's thumbnail looks blank: {covered:.3}");
    let st = click_and_wait(&b, "face-variant-2");
    assert_eq!(error_text(&b), "", "{}", st["lastJob"]);
    assert_eq!(st["face"]["picked"].as_u64(), Some(2));
    assert_ne!(edited(&st), one, "picking the second variant changed nothing");
    set_value(&b, "face-variants-count", "1");

    // A drag on the timeline sets the span (seconds of the file's own time).
    b.eval(&format!("window.inbetweenStudio.dragTimeline({}, {})", (3.0 * fps).round(), (5.0 * fps).round())).unwrap();
    let mask: Vec<f64> = serde_json::from_value(state(&b)["face"]["mask"].clone()).unwrap();
    assert!((mask[0] - 3.0).abs() < 0.05 && (mask[1] - 5.0).abs() < 0.05, "{mask:?}");
    set_value(&b, "face-mask-start", "4");
    set_value(&b, "face-mask-end", "6");

    // Keyframes: a key inside the span is hit.
    set_value(&b, "face-constraint", "keys");
    b.eval("(window.inbetweenStudio.faceKey(5.0, 'JawOpen', 0.8), true)").unwrap();
    let st = click_and_wait(&b, "face-generate");
    assert_eq!(st["lastJob"]["ok"], true, "{}", st["lastJob"]);
    assert!(st["lastJob"]["message"].as_str().unwrap().starts_with("network fill"), "{}", st["lastJob"]);
    let jaw = col(&edited(&st), "JawOpen");
    let at = (0..frames).min_by(|&i, &j| (times[i] - 5.0).abs().total_cmp(&(times[j] - 5.0).abs())).unwrap();
    assert!((jaw[at] - 0.8).abs() < 0.03, "JawOpen at 5.0 s is {} (key 0.8)", jaw[at]);

    // Visemes from text, only the mouth and jaw: the eyes stay as they were.
    let before = edited(&st);
    set_value(&b, "face-constraint", "text");
    set_value(&b, "face-text", "our little brother");
    set_value(&b, "face-groups", "mouth,jaw");
    let st = click_and_wait(&b, "face-generate");
    assert_eq!(st["lastJob"]["ok"], true, "{}", st["lastJob"]);
    let after = edited(&st);
    assert_eq!(col(&before, "EyeBlinkLeft"), col(&after, "EyeBlinkLeft"), "the eyes changed under groups mouth,jaw");
    assert_ne!(col(&before, "JawOpen"), col(&after, "JawOpen"));

    // Phonemes from a TextGrid file (MFA's phones tier) guide the span.
    let tg_dir = tempfile::tempdir().unwrap();
    let tg = tg_dir.path().join("align.TextGrid");
    std::fs::write(
        &tg,
        "File type = \"ooTextFile\"\nObject class = \"TextGrid\"\n\nxmin = 0\nxmax = 6\ntiers? <exists>\nsize = 1\nitem []:\n\
         item [1]:\nclass = \"IntervalTier\"\nname = \"phones\"\nxmin = 0\nxmax = 6\nintervals: size = 4\n\
         intervals [1]:\nxmin = 0\nxmax = 4.2\ntext = \"\"\nintervals [2]:\nxmin = 4.2\nxmax = 4.8\ntext = \"HH\"\n\
         intervals [3]:\nxmin = 4.8\nxmax = 5.5\ntext = \"AA1\"\nintervals [4]:\nxmin = 5.5\nxmax = 6\ntext = \"\"\n",
    )
    .unwrap();
    set_files_and_wait(&b, "face-guide", &[tg.as_path()]);
    assert_eq!(error_text(&b), "");
    assert_eq!(b.eval(&format!("{}.value", js_sel("face-constraint"))).unwrap(), "visemes");
    let st = click_and_wait(&b, "face-generate");
    assert_eq!(st["lastJob"]["ok"], true, "{}", st["lastJob"]);
    assert!(st["lastJob"]["message"].as_str().unwrap().starts_with("network fill"), "{}", st["lastJob"]);

    // A noisy guide file: the take itself stands in for a second tracker's take.
    set_value(&b, "face-groups", "all");
    let guide = match &data {
        Ok(d) if have_real => d.join(real),
        _ => {
            let p = std::env::temp_dir().join(format!("inbetween-face-guide-{}.csv", std::process::id()));
            let f: String = b
                .eval("fetch(document.querySelector('#face-export a').href).then(r => r.text())")
                .unwrap()
                .as_str()
                .unwrap()
                .to_string();
            std::fs::write(&p, f).unwrap();
            p
        }
    };
    set_files_and_wait(&b, "face-guide", &[guide.as_path()]);
    assert_eq!(error_text(&b), "");
    assert_eq!(b.eval(&format!("{}.value", js_sel("face-constraint"))).unwrap(), "noisy");
    let st = click_and_wait(&b, "face-generate");
    assert_eq!(st["lastJob"]["ok"], true, "{}", st["lastJob"]);
    assert!(st["lastJob"]["message"].as_str().unwrap().starts_with("retrieval fill"), "{}", st["lastJob"]);

    // Export: the input's own layout, one row per input row.
    let text = b.eval("fetch(document.querySelector('#face-export a').href).then(r => r.text())").unwrap();
    let text = text.as_str().unwrap();
    if have_real {
        assert!(text.starts_with("Timecode,BlendshapeCount,EyeBlinkLeft"), "{}", &text[..80.min(text.len())]);
    }
    assert_eq!(text.lines().filter(|l| !l.starts_with('#')).count(), frames + 1);

    garbage_then_recover(
        &b,
        "garbage.csv",
        b"Timecode,BlendShapeCount,EyeBlinkLeft\n00:00:00:00.000,1,banana\n",
        "face-generate",
    );
}

#[test]
fn video_panel_in_headless_chromium() {
    let Some((_studio, b, data)) = open_panel("video") else { return };

    // Real footage with a scene cut: the corpus has no clip with one, so the test joins 40 frames of
    // two of its clips (Big Buck Bunny, then the carphone sequence) into one GIF and opens it as a
    // user would. Without the data, the built-in procedural clip (which has a cut) is opened.
    let dir = tempfile::tempdir().unwrap();
    let joined = dir.path().join("bunny-then-carphone.gif");
    let have_real = match &data {
        Ok(d) if d.join("video/bigbuckbunny.mp4").is_file() && d.join("video/carphone_pristine.mp4").is_file() => {
            use inbetween_video::frames::{read_clip, write_clip, Clip, ReadOptions};
            let opts = ReadOptions { max_frames: Some(40), ..ReadOptions::default() };
            let mut frames = Vec::new();
            for f in ["video/bigbuckbunny.mp4", "video/carphone_pristine.mp4"] {
                let (clip, _) = read_clip(&d.join(f), &opts).unwrap();
                frames.extend(
                    clip.frames
                        .iter()
                        .map(|im| image::imageops::resize(im, 192, 108, image::imageops::FilterType::Triangle)),
                );
            }
            write_clip(&joined, &Clip { frames, fps: 25.0, source: "joined".into() }).unwrap();
            true
        }
        _ => false,
    };
    if have_real {
        open_files(&b, &[joined.as_path()]);
    } else {
        open_builtin(&b, &data, "real clips", "video-corpus", "builtin:mixed");
    }
    let st = state(&b);
    assert_eq!(error_text(&b), "", "{}", st["lastJob"]);
    assert_eq!(st["lastJob"]["kind"], "video-open", "{}", st["lastJob"]);
    let frames = st["frames"].as_u64().unwrap() as usize;
    assert_eq!(frames, if have_real { 80 } else { 96 });
    let cuts = st["video"]["cuts"].as_array().unwrap().len();
    assert!(cuts >= 1, "the clip has a scene cut: {}", st["video"]);
    let covered = coverage(&b, "video-strip", [0x15, 0x17, 0x1c]);
    assert!(covered > 0.3, "the frame strip looks blank: {covered:.3}");

    // A new order of 60 frames from frame 10.
    set_value(&b, "video-start", "10");
    set_value(&b, "video-length", "60");
    let st = click_and_wait(&b, "video-generate");
    assert_eq!(error_text(&b), "", "{}", st["lastJob"]);
    assert_eq!(st["lastJob"]["ok"], true, "{}", st["lastJob"]);
    let order: Vec<usize> = serde_json::from_value(st["video"]["order"].clone()).unwrap();
    assert_eq!(order.len(), 60);
    assert_eq!(order[0], 10);
    assert!(order.iter().all(|&f| f < frames));
    assert_eq!(st["frames"].as_u64().unwrap(), 60, "the timeline spans the new order");
    let text = b.eval(&format!("{}.textContent", js_sel("video-order"))).unwrap();
    let shown: Vec<usize> = text.as_str().unwrap().split_whitespace().map(|t| t.parse().unwrap()).collect();
    assert_eq!(shown, order);
    let md = st["video"]["md"].as_f64().unwrap();
    assert!(md.is_finite() && md > 0.0, "{}", st["video"]);
    // Every jump the state lists is a step that is not the next source frame.
    for j in st["video"]["jumps"].as_array().unwrap() {
        let (p, to) = (j["position"].as_u64().unwrap() as usize, j["to"].as_u64().unwrap() as usize);
        assert_eq!(order[p], to, "{j}");
        assert_ne!(order[p], order[p - 1] + 1, "{j}");
    }
    let steps = order.windows(2).filter(|w| w[1] != w[0] + 1).count();
    assert_eq!(st["video"]["jumps"].as_array().unwrap().len(), steps, "one mark per jump");
    // Hovering a jump's mark shows its explanation.
    if let Some(j) = st["video"]["jumps"].as_array().unwrap().first() {
        let p = j["position"].as_u64().unwrap();
        let tip = b
            .eval(&format!(
                "(() => {{ const tl = document.querySelector('[data-testid=timeline]'); const r = tl.getBoundingClientRect(); \
                 const x = r.left + 40 + (r.width - 50) * Math.min({p}, 59) / 59; \
                 tl.dispatchEvent(new MouseEvent('mousemove', {{ clientX: x, clientY: r.top + 60, bubbles: true }})); \
                 const t = document.getElementById('video-tip'); return t.hidden ? '' : t.textContent; }})()"
            ))
            .unwrap();
        assert!(tip.as_str().unwrap().contains("S1"), "the tip should explain the step: {tip}");
    }

    // Regenerate with another seed and the loop on: the analysis is reused.
    set_value(&b, "video-seed", "3");
    b.eval(&format!("({}.checked = true, true)", js_sel("video-loop"))).unwrap();
    let st = click_and_wait(&b, "video-generate");
    assert_eq!(st["lastJob"]["ok"], true, "{}", st["lastJob"]);
    assert!(st["lastJob"]["ms"].as_f64().unwrap() < 30_000.0);

    // Export: a GIF of the new order.
    let gif = b
        .eval(
            "fetch([...document.querySelectorAll('#video-export a')].find(a => a.textContent.endsWith('.gif')).href)\
             .then(r => r.arrayBuffer()).then(b => { const u = new Uint8Array(b); return [u.length, String.fromCharCode(...u.slice(0, 4))]; })",
        )
        .unwrap();
    assert_eq!(gif[1], "GIF8", "{gif}");
    assert!(gif[0].as_u64().unwrap() > 1000, "{gif}");
    let mp4 = b
        .eval(
            "fetch([...document.querySelectorAll('#video-export a')].find(a => a.textContent.endsWith('.mp4')).href)\
             .then(r => r.arrayBuffer()).then(b => { const u = new Uint8Array(b); return [u.length, String.fromCharCode(...u.slice(4, 8))]; })",
        )
        .unwrap();
    assert_eq!(mp4[1], "ftyp", "{mp4}");
    assert!(mp4[0].as_u64().unwrap() > 1000, "{mp4}");

    garbage_then_recover(&b, "garbage.mp4", b"\0\0\0\x18ftypisom this is not a movie", "video-generate");

    // A folder of PNG frames from the corpus opens as one clip.
    if have_real {
        b.eval("(s => { s.value = 'video/bbb_png_seq/'; s.dispatchEvent(new Event('change')); return window.inbetweenStudio.ready(); })(document.getElementById('video-corpus'))").unwrap();
        let st = state(&b);
        assert_eq!(error_text(&b), "", "{}", st["lastJob"]);
        assert_eq!(st["frames"].as_u64().unwrap(), 24, "{}", st["lastJob"]);
    }
}

#[test]
fn camera_panel_in_headless_chromium() {
    let Some((_studio, b, data)) = open_panel("camera") else { return };

    // Two CMU takes as the characters (the built-in procedural pair without data).
    let takes = data.as_ref().ok().map(|d| {
        let dir = d.join("mocap/cmu/iclone_cc");
        (dir.join("007_12.bvh"), dir.join("002_01.bvh"))
    });
    let real = takes.as_ref().is_some_and(|(a, c)| a.is_file() && c.is_file());
    if real {
        let (a, c) = takes.as_ref().unwrap();
        set_files_and_wait(&b, "camera-characters", &[a.as_path(), c.as_path()]);
    } else {
        open_builtin(&b, &data, "CMU takes", "camera-scene", "builtin:pair");
    }
    let st = state(&b);
    assert_eq!(error_text(&b), "", "{}", st["lastJob"]);
    assert_eq!(st["lastJob"]["kind"], "camera-scene", "{}", st["lastJob"]);
    let frames = st["frames"].as_u64().unwrap();
    assert!(frames > 100, "{st}");
    assert_eq!(st["characters"].as_array().unwrap().len(), 2, "{st}");
    assert_eq!(st["camera"]["keys"].as_array().unwrap().len(), 3, "three starting keys: {}", st["camera"]);

    // Dragging a key's triangle on the timeline moves it in time.
    let mid = st["camera"]["keys"][1]["frame"].as_u64().unwrap();
    b.eval(&format!("window.inbetweenStudio.dragTimeline({mid}, {})", mid + 20)).unwrap();
    let moved: Vec<u64> =
        state(&b)["camera"]["keys"].as_array().unwrap().iter().map(|k| k["frame"].as_u64().unwrap()).collect();
    assert!(moved.contains(&(mid + 20)) && !moved.contains(&mid), "{moved:?} (dragged {mid} → {})", mid + 20);

    // A key at the playhead.
    b.eval("window.inbetweenStudio.seek(60)").unwrap();
    let st = click_and_wait(&b, "camera-add-key");
    assert_eq!(st["lastJob"]["ok"], true, "{}", st["lastJob"]);
    let key_frames: Vec<u64> =
        st["camera"]["keys"].as_array().unwrap().iter().map(|k| k["frame"].as_u64().unwrap()).collect();
    assert_eq!(key_frames.len(), 4);
    assert!(key_frames.contains(&60), "{key_frames:?}");
    assert!(key_frames.windows(2).all(|w| w[0] < w[1]), "keys in time order: {key_frames:?}");

    // Every style at once, each through every key.
    let st = click_and_wait(&b, "camera-generate");
    assert_eq!(error_text(&b), "", "{}", st["lastJob"]);
    assert_eq!(st["lastJob"]["ok"], true, "{}", st["lastJob"]);
    let trajectories = st["camera"]["trajectories"].as_array().unwrap();
    let styles: Vec<&str> = trajectories.iter().map(|t| t["style"].as_str().unwrap()).collect();
    assert_eq!(styles, ["direct", "relative", "side", "orbit"]);
    for t in trajectories {
        assert!(t["key_hit_error"].as_f64().unwrap() < 1e-6, "every key hit: {t}");
        assert_eq!(t["frames"].as_u64().unwrap(), key_frames[3] - key_frames[0] + 1, "{t}");
    }
    let children = b.eval(&format!("{}.children.length", js_sel("camera-trajectories"))).unwrap();
    assert_eq!(children, 4, "one listed trajectory per style");
    let status = st["lastJob"]["message"].as_str().unwrap().to_string();
    assert!(status.contains("key hit error"), "{status}");

    // Pick orbit and look through its camera: the view shows the scene.
    b.eval("(document.querySelector('#camera-trajectories [data-style=orbit]').click(), true)").unwrap();
    b.eval(&format!("({}.click(), true)", js_sel("camera-shot"))).unwrap();
    b.eval("window.inbetweenStudio.seek(80)").unwrap();
    let st = state(&b);
    assert_eq!(st["camera"]["selected"], "orbit");
    assert_eq!(st["camera"]["shot"], true);
    let covered = viewport_coverage(&b);
    assert!(covered > 0.02, "the shot camera's view looks blank: {covered:.3}");

    // The selected key takes the Toric pose of a camera placed in the viewport.
    b.eval(&format!("({}.click(), true)", js_sel("camera-shot"))).unwrap();
    let st = b
        .eval("(document.getElementById('camera-key-from-view').click(), window.inbetweenStudio.ready())")
        .map(|_| state(&b))
        .unwrap();
    assert_eq!(st["lastJob"]["ok"], true, "{}", st["lastJob"]);
    assert!(st["lastJob"]["message"].as_str().unwrap().contains("set from the view"), "{}", st["lastJob"]);

    // A velocity at the selected key shows as an arrow in the viewport; swapping A and B at a key
    // still generates through every key.
    b.eval("(() => { const v = document.getElementById('ck-vel'); v.checked = true; v.dispatchEvent(new Event('change')); return true; })()").unwrap();
    let st = b.eval("new Promise(ok => setTimeout(ok, 300)).then(() => window.inbetweenStudio.state())").unwrap();
    assert_eq!(st["camera"]["arrow"], true, "{}", st["camera"]);
    b.eval("(() => { const s = document.querySelector('[data-testid=camera-swap]'); s.checked = true; s.dispatchEvent(new Event('change')); return true; })()").unwrap();
    let st = click_and_wait(&b, "camera-generate");
    assert_eq!(st["lastJob"]["ok"], true, "{}", st["lastJob"]);
    let keys = st["camera"]["keys"].as_array().unwrap();
    assert!(keys.iter().any(|k| k["targets"].is_array() && !k["velocity"].is_null()), "{}", st["camera"]);
    for t in st["camera"]["trajectories"].as_array().unwrap() {
        assert!(t["key_hit_error"].as_f64().unwrap() < 1e-6, "every key hit: {t}");
    }

    // The gizmo: the selected key's camera dragged in the viewport gets new Toric coordinates.
    let before = st["camera"]["keys"].clone();
    let st = b
        .eval("window.inbetweenStudio.cameraGizmoMove(0.6, 0.4, 0.3).then(() => window.inbetweenStudio.ready())")
        .map(|_| state(&b))
        .unwrap();
    assert_eq!(st["lastJob"]["kind"], "camera-gizmo", "{}", st["lastJob"]);
    assert_eq!(st["lastJob"]["ok"], true, "{}", st["lastJob"]);
    assert_ne!(st["camera"]["keys"], before, "the dragged key changed");

    // The chosen trajectory's glTF, opened as the style reference: a fifth style is generated.
    let gltf = b
        .eval("fetch([...document.querySelectorAll('#camera-export a')].find(a => a.textContent.endsWith('.gltf')).href).then(r => r.text())")
        .unwrap();
    let dir0 = tempfile::tempdir().unwrap();
    let reference = dir0.path().join("orbit.gltf");
    std::fs::write(&reference, gltf.as_str().unwrap()).unwrap();
    set_files_and_wait(&b, "camera-reference", &[reference.as_path()]);
    assert_eq!(error_text(&b), "");
    let st = click_and_wait(&b, "camera-generate");
    assert_eq!(st["lastJob"]["ok"], true, "{}", st["lastJob"]);
    let styles: Vec<String> = st["camera"]["trajectories"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| t["style"].as_str().unwrap().to_string())
        .collect();
    assert_eq!(styles, ["reference orbit.gltf"], "the style select says reference: {styles:?}");

    // Delete the selected key.
    let before = state(&b)["camera"]["keys"].as_array().unwrap().len();
    b.eval("(document.getElementById('camera-delete-key').click(), true)").unwrap();
    assert_eq!(state(&b)["camera"]["keys"].as_array().unwrap().len(), before - 1);

    // Export: the track as JSON.
    let track = b.eval("fetch(document.querySelector('#camera-export a').href).then(r => r.json())").unwrap();
    assert!(
        track["frames"].as_array().is_some_and(|f| !f.is_empty()),
        "{}",
        &track.to_string()[..200.min(track.to_string().len())]
    );

    // A garbage take: its error names it; the next generation still works.
    let dir = tempfile::tempdir().unwrap();
    let (junk, good) = (dir.path().join("garbage.bvh"), dir.path().join("walk.bvh"));
    std::fs::write(&junk, "HIERARCHY\nROOT Hips\n{\n  OFFSET nope\n").unwrap();
    std::fs::write(
        &good,
        inbetween_io::to_bvh_string(&inbetween_core::procedural::gait(&inbetween_core::procedural::GaitParams {
            frames: 60,
            ..inbetween_core::procedural::GaitParams::walk()
        })),
    )
    .unwrap();
    // WebDriver adds files to a `multiple` input: empty it first, as a new pick would.
    b.eval("(document.getElementById('camera-characters').value = '', true)").unwrap();
    set_files_and_wait(&b, "camera-characters", &[good.as_path(), junk.as_path()]);
    let err = error_text(&b);
    assert!(err.contains("garbage.bvh:"), "the error should name the file and line: {err:?}");
    let st = click_and_wait(&b, "camera-generate");
    assert_eq!(st["lastJob"]["ok"], true, "{}", st["lastJob"]);
}
