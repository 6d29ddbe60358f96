//! The studio's safety rules and job API over plain HTTP against a server on port 0 (issue 23).

mod common;

use common::*;
use inbetween_studio::{Studio, StudioConfig};
use serde_json::json;

fn studio(max_upload: u64, root: Option<&std::path::Path>) -> Studio {
    Studio::start(StudioConfig {
        port: 0,
        max_upload,
        root: root.map(|p| p.to_path_buf()),
        test_routes: true,
        ..StudioConfig::default()
    })
    .expect("start the studio")
}

#[test]
fn binds_loopback_by_default_and_serves_the_page() {
    let s = studio(1_000_000, None);
    assert!(s.addr().ip().is_loopback(), "{}", s.addr());
    assert_ne!(s.addr().port(), 0);
    let r = get(s.addr(), "/");
    assert_eq!(r.status, 200);
    assert!(r.text().contains("inbetween studio"), "{}", r.text());
    let info = get(s.addr(), "/api/info").json();
    assert_eq!(info["max_upload"], 1_000_000);
}

#[test]
fn refuses_other_hosts() {
    let s = studio(1_000_000, None);
    let port = s.addr().port();
    let evil = format!("rebind.example:{port}");
    let r = request(s.addr(), "GET", "/api/info", &[("Host", &evil)], b"");
    assert_eq!(r.status, 403, "{}", r.text());
    assert!(r.text().contains("rebind.example"), "{}", r.text());
    let local = format!("localhost:{port}");
    assert_eq!(request(s.addr(), "GET", "/api/info", &[("Host", &local)], b"").status, 200);
    let wrong_port = format!("127.0.0.1:{}", port.wrapping_add(1));
    assert_eq!(request(s.addr(), "GET", "/api/info", &[("Host", &wrong_port)], b"").status, 403);
}

#[test]
fn refuses_cross_origin_writes() {
    let s = studio(1_000_000, None);
    let body = json!({"path": "builtin:walk"}).to_string();
    let ct = ("Content-Type", "application/json");
    let r = request(s.addr(), "POST", "/api/mocap/open", &[ct, ("Origin", "http://evil.example")], body.as_bytes());
    assert_eq!(r.status, 403, "{}", r.text());
    let r = request(s.addr(), "POST", "/api/mocap/open", &[ct, ("Sec-Fetch-Site", "cross-site")], body.as_bytes());
    assert_eq!(r.status, 403, "{}", r.text());
    // A cross-origin read is a plain GET: allowed (the browser's same-origin policy hides it).
    assert_eq!(request(s.addr(), "GET", "/api/info", &[("Origin", "http://evil.example")], b"").status, 200);
    let own = format!("http://{}", s.addr());
    let r = request(s.addr(), "POST", "/api/mocap/open", &[ct, ("Origin", &own)], body.as_bytes());
    assert_eq!(r.status, 200, "{}", r.text());
}

#[test]
fn caps_uploads() {
    let s = studio(1000, None);
    let big = vec![b'x'; 5000];
    let r = request(s.addr(), "POST", "/api/mocap/upload?name=big.bvh", &[], &big);
    assert_eq!(r.status, 413, "{}", r.text());
    // Still serving.
    assert_eq!(get(s.addr(), "/api/info").status, 200);
}

#[test]
fn reads_client_named_paths_only_under_root() {
    let dir = tempfile::tempdir().unwrap();
    let inside = dir.path().join("takes");
    std::fs::create_dir_all(&inside).unwrap();
    std::fs::write(dir.path().join("secret.bvh"), "HIERARCHY").unwrap();
    let s = studio(1_000_000, Some(&inside));
    for bad in ["../secret.bvh", "/etc/passwd", "a/../../secret.bvh"] {
        let r = post_json(s.addr(), "/api/mocap/open", &json!({"path": bad}));
        assert_eq!(r.status, 403, "{bad}: {}", r.text());
    }
    #[cfg(unix)]
    {
        std::os::unix::fs::symlink(dir.path().join("secret.bvh"), inside.join("link.bvh")).unwrap();
        let r = post_json(s.addr(), "/api/mocap/open", &json!({"path": "link.bvh"}));
        assert_eq!(r.status, 403, "a link out of the root: {}", r.text());
    }
    let none = studio(1_000_000, None);
    let r = post_json(none.addr(), "/api/mocap/open", &json!({"path": "secret.bvh"}));
    assert_eq!(r.status, 403, "{}", r.text());
    assert!(r.text().contains("--root"), "{}", r.text());
}

#[test]
fn a_panicking_handler_does_not_stop_the_server() {
    let s = studio(1_000_000, None);
    let r = request(s.addr(), "POST", "/api/test/panic", &[], b"");
    assert_eq!(r.status, 500);
    assert!(r.text().contains("keeps serving"), "{}", r.text());
    assert_eq!(get(s.addr(), "/api/info").status, 200);
}

#[test]
fn garbage_upload_names_file_and_line_and_server_keeps_serving() {
    let s = studio(1_000_000, None);
    let (event, data) =
        run_job(s.addr(), "/api/mocap/upload?name=garbage.bvh", &[], b"HIERARCHY\nROOT Hips\n{\n  OFFSET 1 2\n");
    assert_eq!(event, "failed", "{data}");
    let msg = data["error"].as_str().unwrap();
    assert!(msg.contains("garbage.bvh:"), "{msg}");
    let (event, data) = run_job(s.addr(), "/api/mocap/upload?name=noise.bvh", &[], &[0xff, 0xfe, 0x00, 0x12]);
    assert_eq!(event, "failed", "{data}");
    assert!(data["error"].as_str().unwrap().contains("noise.bvh:1"), "{data}");
    let (event, data) = run_job(s.addr(), "/api/mocap/upload?name=take.fbx", &[], b"x");
    assert_eq!(event, "failed", "{data}");
    assert!(data["error"].as_str().unwrap().contains("expected a .bvh file"), "{data}");
    assert_eq!(get(s.addr(), "/api/info").status, 200);
}

#[test]
fn mocap_jobs_on_the_builtin_walk() {
    let s = studio(1_000_000, None);
    let (event, take) =
        run_job(s.addr(), "/api/mocap/open", &[("Content-Type", "application/json")], br#"{"path":"builtin:walk"}"#);
    assert_eq!(event, "result", "{take}");
    assert_eq!(take["frames"], 240);
    let original = get(s.addr(), take["files"]["original"].as_str().unwrap());
    assert!(original.text().starts_with("HIERARCHY"), "{}", original.text());
    for method in ["uniform", "greedy", "optimal"] {
        let body = json!({"method": method, "k": 10}).to_string();
        let (event, r) = run_job(s.addr(), "/api/mocap/keys", &[("Content-Type", "application/json")], body.as_bytes());
        assert_eq!(event, "result", "{method}: {r}");
        let keys: Vec<u64> = r["keys"].as_array().unwrap().iter().map(|k| k.as_u64().unwrap()).collect();
        assert_eq!(keys.len(), 10, "{method}");
        assert_eq!((keys[0], keys[9]), (0, 239), "{method}: first and last frames are keys");
        assert_eq!(r["per_frame_cm"].as_array().unwrap().len(), 240);
        let max = r["max_cm"].as_f64().unwrap();
        assert!(max > 0.0 && max.is_finite(), "{method}: {r}");
        assert!(r["message"].as_str().unwrap().contains("cm"), "{r}");
    }
    // Greedy and optimal keep per-take state between K changes (greedy's insertion order, the
    // optimal search's memo): K up and down gives the engine's own keys for each K.
    let walk = inbetween_core::procedural::gait(&inbetween_core::procedural::GaitParams {
        frames: 240,
        ..inbetween_core::procedural::GaitParams::walk()
    });
    let rep = inbetween_mocap::SphericalMotion::from_motion(&walk).unwrap();
    for k in [12, 7, 15, 9] {
        let angle = inbetween_mocap::ErrorMeasure::Angle;
        for (method, want) in [
            ("greedy", inbetween_mocap::select::greedy(&rep, k, angle).unwrap()),
            ("optimal", inbetween_mocap::select::optimal_spherical(&rep, k, angle).unwrap()),
        ] {
            let body = json!({"method": method, "k": k}).to_string();
            let (event, r) =
                run_job(s.addr(), "/api/mocap/keys", &[("Content-Type", "application/json")], body.as_bytes());
            assert_eq!(event, "result", "{method}: {r}");
            let keys: Vec<usize> = r["keys"].as_array().unwrap().iter().map(|k| k.as_u64().unwrap() as usize).collect();
            assert_eq!(keys, want.frames(), "{method} K={k}");
        }
    }
    // SIDQL keys 64-frame windows: a 240-frame take is 4 windows, so K = 10 works and K = 4 is
    // refused with the engine's words (its 5 window ends are all keys).
    let body = json!({"method": "sidql", "k": 10}).to_string();
    let (event, r) = run_job(s.addr(), "/api/mocap/keys", &[("Content-Type", "application/json")], body.as_bytes());
    assert_eq!(event, "result", "{r}");
    assert_eq!(r["keys"].as_array().unwrap().len(), 10, "{r}");
    let body = json!({"method": "sidql", "k": 4}).to_string();
    let (event, r) = run_job(s.addr(), "/api/mocap/keys", &[("Content-Type", "application/json")], body.as_bytes());
    assert_eq!(event, "failed", "{r}");
    assert!(r["error"].as_str().unwrap().contains("K must be at least 5"), "{r}");
    // The error bound: every joint of every frame of the rebuilt clip under it.
    let body = json!({"method": "bound", "bound_cm": 2.0}).to_string();
    let (event, r) = run_job(s.addr(), "/api/mocap/keys", &[("Content-Type", "application/json")], body.as_bytes());
    assert_eq!(event, "result", "{r}");
    assert!(r["max_cm"].as_f64().unwrap() <= 2.0 + 1e-9, "{r}");
    let body = json!({"bound_cm": 1.0}).to_string();
    let (event, r) = run_job(s.addr(), "/api/mocap/compress", &[("Content-Type", "application/json")], body.as_bytes());
    assert_eq!(event, "result", "{r}");
    assert!(r["ratio"].as_f64().unwrap() > 1.0, "{r}");
    assert!(r["error_cm"].as_f64().unwrap() <= 1.0 + 1e-9, "{r}");
    let ibk = get(s.addr(), r["files"]["ibk"].as_str().unwrap());
    assert_eq!(ibk.body.len() as u64, r["bytes"].as_u64().unwrap());
}

/// The face, video and camera panels (issue 24) refuse what they cannot use with a message, and a
/// malformed or random body on any route gets a 4xx answer while the server keeps serving.
#[test]
fn new_panels_refuse_bad_requests_and_keep_serving() {
    let s = studio(1_000_000, None);
    let a = s.addr();
    let ct = [("Content-Type", "application/json")];
    let failed = |path: &str, body: &[u8]| {
        let (event, data) = run_job(a, path, &ct, body);
        assert_eq!(event, "failed", "{path}: {data}");
        data["error"].as_str().unwrap().to_string()
    };
    // Nothing open yet.
    assert!(failed("/api/face/edit", br#"{"start_s":1,"end_s":2}"#).contains("open a face take first"));
    assert!(failed("/api/video/generate", b"{}").contains("open a clip first"));
    assert!(failed("/api/camera/generate", br#"{"keys":{"keys":[]}}"#).contains("open a scene first"));
    assert_eq!(request(a, "POST", "/api/face/history", &ct, br#"{"step":"undo"}"#).status, 400);
    assert_eq!(request(a, "POST", "/api/camera/key_at", &ct, br#"{"frame":3}"#).status, 400);
    // Bad files name themselves.
    let e = failed("/api/face/upload?name=junk.csv", b"Timecode,BlendshapeCount,EyeBlinkLeft\n00:00:00:00.000,1,x\n");
    assert!(e.contains("junk.csv"), "{e}");
    assert!(failed("/api/face/upload?name=take.txt", b"hello").contains("take.txt: expected a Live Link Face CSV"));
    assert!(failed("/api/face/upload?name=bytes.csv", &[0xff, 0xfe, 0x00]).contains("bytes.csv:1"));
    assert!(failed("/api/video/upload?name=clip.avi", b"RIFF").contains("clip.avi: expected an .mp4"));
    assert!(failed("/api/video/upload?name=bad.mp4", b"\0\0\0\x18ftypisom junk").contains("bad.mp4"));
    assert!(failed("/api/camera/upload?name=b.bvh&slot=1", b"HIERARCHY").contains("b.bvh"));
    assert!(failed("/api/camera/reference?name=ref.json", b"{\"characters\": [").contains("ref.json:1:"));
    // A face take, then edits the engine refuses.
    let (event, take) = run_job(a, "/api/face/open", &ct, br#"{"path":"builtin:procedural"}"#);
    assert_eq!(event, "result", "{take}");
    assert!(failed("/api/face/edit", br#"{"start_s":1,"end_s":2,"constraint":"mime"}"#).contains("expected none, keys"));
    assert!(failed("/api/face/edit", br#"{"start_s":1,"end_s":2,"method":"magic"}"#).contains("expected auto"));
    assert!(failed("/api/face/edit", br#"{"start_s":1,"end_s":2,"groups":"ears"}"#).contains("ears"));
    assert!(failed("/api/face/edit", br#"{"start_s":11,"end_s":40}"#).contains("runs past the clip's end"));
    let e = failed(
        "/api/face/edit",
        br#"{"start_s":1,"end_s":2,"constraint":"keys","keys":[{"time_s":1.5,"shapes":{"Nose":1}}]}"#,
    );
    assert!(e.contains("'Nose' is not an ARKit blendshape name"), "{e}");
    assert!(failed("/api/face/edit", br#"{"start_s":1,"end_s":2,"constraint":"noisy"}"#).contains("needs its file"));
    let (event, r) = run_job(a, "/api/face/edit", &ct, br#"{"start_s":1,"end_s":2}"#);
    assert_eq!(event, "result", "{r}");
    assert!(r["variants"].is_null(), "one fill, no variants: {}", r["variants"]);
    for n in [0, 7] {
        let body = format!(r#"{{"start_s":1,"end_s":2,"variants":{n}}}"#);
        assert!(failed("/api/face/edit", body.as_bytes()).contains("expected 1 to 6"), "variants {n}");
    }
    let pick = |body: &[u8]| request(a, "POST", "/api/face/pick", &ct, body);
    let e = pick(br#"{"variant":1}"#);
    assert_eq!(e.status, 400);
    assert!(e.text().contains("no variants to pick from"), "{}", e.text());
    // A camera scene, then keys the engine refuses.
    let (event, scene) = run_job(a, "/api/camera/open", &ct, br#"{"path":"builtin:pair"}"#);
    assert_eq!(event, "result", "{scene}");
    let e = failed(
        "/api/camera/generate",
        br#"{"keys":{"keys":[{"frame":900,"camera":{"pa":[-0.3,0],"pb":[0.3,0],"theta":1,"phi":0.2}}]}}"#,
    );
    assert!(e.contains("frame 900"), "{e}");
    assert!(failed("/api/camera/generate", br#"{"keys":{"keys":[]},"styles":["noir"]}"#).contains("noir"));
    assert_eq!(
        request(a, "POST", "/api/camera/toric", &ct, br#"{"frame":5000,"position":[0,1,5],"rotation":[0,0,0,1]}"#)
            .status,
        400
    );
    // Malformed and random bodies on every POST route: a 4xx or a failed job, never a dead server.
    let routes = [
        "/api/face/open",
        "/api/face/edit",
        "/api/face/history",
        "/api/face/pick",
        "/api/video/open",
        "/api/video/generate",
        "/api/camera/open",
        "/api/camera/key_at",
        "/api/camera/toric",
        "/api/camera/generate",
    ];
    let mut seed = 12345u64;
    for route in routes {
        for body in [&b"{"[..], b"[1,2,3]", b"{\"start_s\": \"x\"}", b"null"] {
            let r = request(a, "POST", route, &ct, body);
            assert!((400..500).contains(&r.status) || r.status == 200, "{route}: {} {}", r.status, r.text());
        }
        let noise: Vec<u8> = (0..64)
            .map(|_| {
                seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                (seed >> 56) as u8
            })
            .collect();
        let r = request(a, "POST", route, &ct, &noise);
        assert!((400..500).contains(&r.status), "{route}: {} {}", r.status, r.text());
    }
    assert_eq!(get(a, "/api/info").status, 200);
}

/// An edit with variants: as many different fills as asked, the first applied; picking another makes
/// it the version shown (undo still goes back to before the edit); a bad number or a version the
/// variants do not belong to is refused.
#[test]
fn face_variants_are_different_fills_and_a_pick_swaps_the_version() {
    let s = studio(1_000_000, None);
    let a = s.addr();
    let ct = [("Content-Type", "application/json")];
    let (event, take) = run_job(a, "/api/face/open", &ct, br#"{"path":"builtin:procedural"}"#);
    assert_eq!(event, "result", "{take}");
    let (event, r) = run_job(a, "/api/face/edit", &ct, br#"{"start_s":3,"end_s":6,"seed":5,"variants":3}"#);
    assert_eq!(event, "result", "{r}");
    let vs = r["variants"].as_array().expect("variants in the answer");
    assert_eq!(vs.len(), 3);
    assert_eq!((r["version"].as_u64(), r["versions"].as_u64()), (Some(1), Some(2)), "one new version");
    assert!(r["message"].as_str().unwrap().contains("3 variants (seeds 5..7)"), "{}", r["message"]);
    assert_eq!(vs[0]["columns"], r["columns"], "the first variant is the one applied");
    for (k, v) in vs.iter().enumerate() {
        assert_eq!((v["variant"].as_u64(), v["seed"].as_u64()), (Some(k as u64 + 1), Some(5 + k as u64)));
        assert!(v["masked_mse"].as_f64().unwrap() > 0.0);
    }
    assert_ne!(vs[0]["columns"], vs[1]["columns"], "retrieval variants draw different segments");
    assert_ne!(vs[1]["columns"], vs[2]["columns"]);
    let pick = |body: &[u8]| request(a, "POST", "/api/face/pick", &ct, body);
    let p = pick(br#"{"variant":2}"#);
    assert_eq!(p.status, 200, "{}", p.text());
    let p = p.json();
    assert_eq!((p["version"].as_u64(), p["versions"].as_u64()), (Some(1), Some(2)), "picked in place");
    let (r0, r1) = (vs[1]["rows"][0].as_u64().unwrap() as usize, vs[1]["rows"][1].as_u64().unwrap() as usize);
    for (name, col) in vs[1]["columns"].as_object().unwrap() {
        assert_eq!(p["columns"][name].as_array().unwrap()[r0..r1], col.as_array().unwrap()[..], "{name}");
    }
    for bad in [&br#"{"variant":0}"#[..], br#"{"variant":4}"#] {
        let e = pick(bad);
        assert_eq!(e.status, 400);
        assert!(e.text().contains("expected 1 to 3"), "{}", e.text());
    }
    let u = request(a, "POST", "/api/face/history", &ct, br#"{"step":"undo"}"#).json();
    assert_eq!(u["version"].as_u64(), Some(0));
    assert_ne!(u["columns"], p["columns"], "undo goes back to before the edit");
    let e = pick(br#"{"variant":1}"#);
    assert_eq!(e.status, 400);
    assert!(e.text().contains("belong to version 1"), "{}", e.text());
    let r = request(a, "POST", "/api/face/history", &ct, br#"{"step":"redo"}"#).json();
    assert_eq!(r["columns"], p["columns"], "redo shows the picked variant");
}

#[test]
fn a_cancelled_optimal_search_stops_its_engine_early() {
    // The exact optimum on 1000 frames takes seconds the first time on a take; cancelled after
    // 0.3 s, the engine itself must stop soon after (its cancel token is checked per frame of each
    // pass), not only the job's events.
    let s = studio(1_000_000, None);
    let (event, _) = run_job(
        s.addr(),
        "/api/mocap/open",
        &[("Content-Type", "application/json")],
        br#"{"path":"builtin:walk-1000"}"#,
    );
    assert_eq!(event, "result");
    let r = post_json(s.addr(), "/api/mocap/keys", &json!({"method": "optimal", "k": 20}));
    assert_eq!(r.status, 200, "{}", r.text());
    let answer = r.json();
    assert!(answer.get("event").is_none(), "the search ended within the first answer: {answer}");
    let id = answer["job"].as_u64().unwrap();
    let status = |id: u64| get(s.addr(), &format!("/api/jobs/{id}")).json();
    assert_eq!(status(id)["working"], true);
    let cancelled = post_json(s.addr(), &format!("/api/jobs/{id}/cancel"), &json!({}));
    assert_eq!(cancelled.status, 200, "{}", cancelled.text());
    let t = std::time::Instant::now();
    while status(id)["working"] == true {
        assert!(t.elapsed().as_secs_f64() < 1.5, "the optimal search still runs 1.5 s after its cancel");
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    let st = status(id);
    eprintln!("stopped {:.0} ms after the cancel: {st}", t.elapsed().as_secs_f64() * 1000.0);
    assert_eq!((st["ended"].clone(), st["cancelled"].clone()), (json!(true), json!(true)));
    assert_eq!(follow(s.addr(), id).0, "cancelled");
    // The take still answers; an unknown job is a 404.
    let (event, r) = run_job(
        s.addr(),
        "/api/mocap/keys",
        &[("Content-Type", "application/json")],
        json!({"method": "uniform", "k": 20}).to_string().as_bytes(),
    );
    assert_eq!(event, "result", "{r}");
    assert_eq!(get(s.addr(), "/api/jobs/999999").status, 404);
}
