//! `inbetween batch …` as a cluster runs it: shards as separate processes (flags and the Slurm and
//! Kubernetes variables), a shard killed mid-way and rerun, a garbage file, the summary; and the
//! CMU corpus in 3 shards against one run (real data, skipped without it).

use std::collections::BTreeMap;
use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

fn inbetween() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_inbetween"));
    c.env("RUST_BACKTRACE", "0").env("INBETWEEN_NO_PROGRESS", "1");
    for v in ["SLURM_ARRAY_TASK_ID", "SLURM_ARRAY_TASK_COUNT", "SLURM_ARRAY_TASK_MIN", "JOB_COMPLETION_INDEX"] {
        c.env_remove(v);
    }
    c
}

fn run(args: &[&str], env: &[(&str, &str)]) -> Output {
    let mut c = inbetween();
    c.args(args);
    for (k, v) in env {
        c.env(k, v);
    }
    c.output().expect("runs the binary")
}

fn text(o: &Output) -> String {
    format!("{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr))
}

fn s(p: &Path) -> String {
    p.to_string_lossy().into_owned()
}

/// `count` procedural takes of `frames` frames below `dir` (two folders) and a garbage .bvh.
fn corpus(dir: &Path, count: usize, frames: usize) {
    for (i, m) in inbetween_core::procedural::gait_library(11, count, frames, 30.0).iter().enumerate() {
        let path = dir.join(if i % 2 == 0 { "walks" } else { "more/walks" }).join(format!("t{i:02}.bvh"));
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        inbetween_io::write_bvh(&path, m).unwrap();
    }
    std::fs::write(dir.join("walks/garbage.bvh"), [0xffu8, 0xfe, 0x00, 0x42]).unwrap();
}

/// The visible files below `dir` (not result lines) with their bytes.
fn outputs(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    fn walk(root: &Path, dir: &Path, out: &mut BTreeMap<String, Vec<u8>>) {
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            let name = p.file_name().unwrap().to_string_lossy().into_owned();
            if p.is_dir() {
                walk(root, &p, out);
            } else if !name.starts_with("results-") && !name.starts_with('.') {
                out.insert(s(p.strip_prefix(root).unwrap()), std::fs::read(&p).unwrap());
            }
        }
    }
    let mut out = BTreeMap::new();
    walk(dir, dir, &mut out);
    out
}

/// Every result line below `dir`, by input, timing dropped; panics on a duplicate input.
fn lines(dir: &Path) -> BTreeMap<String, serde_json::Value> {
    let mut all = BTreeMap::new();
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        let name = p.file_name().unwrap().to_string_lossy().into_owned();
        if name.starts_with("results-") && name.ends_with(".jsonl") {
            let text = std::fs::read_to_string(&p).unwrap();
            assert!(text.is_empty() || text.ends_with('\n'), "{name}: a partial last line");
            for l in text.lines() {
                let mut v: serde_json::Value = serde_json::from_str(l).unwrap();
                v["seconds"] = 0.into();
                let input = v["input"].as_str().unwrap().to_string();
                assert!(all.insert(input.clone(), v).is_none(), "{input}: two lines");
            }
        }
    }
    all
}

#[test]
fn shards_as_processes_equal_one_run_and_a_killed_shard_resumes() {
    let tmp = tempfile::tempdir().unwrap();
    let (input, one, three) = (tmp.path().join("in"), tmp.path().join("one"), tmp.path().join("three"));
    corpus(&input, 9, 120);
    let o = run(&["batch", "mocap-compress", &s(&input), "-o", &s(&one), "--max-error", "1cm"], &[]);
    assert!(o.status.success(), "{}", text(&o));
    assert!(text(&o).contains("9 ok, 1 failed, 0 skipped"), "{}", text(&o));
    assert!(text(&o).contains("garbage.bvh"), "the failure is printed: {}", text(&o));

    // Three processes at once: by flag, by Slurm's variables (an array 1-3), by an Indexed Job's.
    let out3 = s(&three);
    let base = ["batch", "mocap-compress", &s(&input), "-o", &out3, "--max-error", "1cm"];
    let mut children = Vec::new();
    let mut flagged = inbetween();
    flagged.args(base).args(["--shard", "0/3"]);
    children.push(flagged);
    let mut slurm = inbetween();
    slurm
        .args(base)
        .env("SLURM_ARRAY_TASK_ID", "2")
        .env("SLURM_ARRAY_TASK_COUNT", "3")
        .env("SLURM_ARRAY_TASK_MIN", "1");
    children.push(slurm);
    let mut k8s = inbetween();
    k8s.args(base).args(["--shards", "3"]).env("JOB_COMPLETION_INDEX", "2");
    children.push(k8s);
    let running: Vec<_> =
        children.iter_mut().map(|c| c.stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().unwrap()).collect();
    for child in running {
        let o = child.wait_with_output().unwrap();
        assert!(o.status.success(), "{}", text(&o));
    }
    for i in 0..3 {
        assert!(three.join(format!("results-{i}.jsonl")).is_file(), "shard {i} wrote its lines");
    }
    assert_eq!(outputs(&one), outputs(&three), "the shards' outputs are one run's, byte for byte");
    assert_eq!(lines(&one), lines(&three), "and so are the lines");
    assert_eq!(outputs(&one).len(), 9);
    assert!(outputs(&one).contains_key("more/walks/t01.ibk"));
    let bad = &lines(&one)["walks/garbage.bvh"];
    assert_eq!(bad["ok"], false);
    assert!(bad["error"].as_str().unwrap().contains("garbage.bvh"), "{bad}");

    // The summary merges the three shards.
    let o = run(&["batch", "summary", &out3], &[]);
    assert!(o.status.success(), "{}", text(&o));
    assert!(text(&o).contains("10 inputs from 10 lines in 3 result files: 9 ok, 1 failed"), "{}", text(&o));
    let o = run(&["batch", "summary", &out3, "--json"], &[]);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["failures"].as_array().unwrap().len(), 1);

    // Killed mid-way (after its first lines), then run again: every input once, nothing partial.
    let killed = tmp.path().join("killed");
    let mut child = inbetween()
        .args(["batch", "mocap-compress", &s(&input), "-o", &s(&killed), "--max-error", "1cm"])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let t = Instant::now();
    let first_lines = killed.join("results-0.jsonl");
    while std::fs::read_to_string(&first_lines).map_or(0, |t| t.lines().count()) < 2
        && t.elapsed() < Duration::from_secs(60)
    {
        std::thread::sleep(Duration::from_millis(5));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    let done_before = std::fs::read_to_string(&first_lines).unwrap().lines().count();
    let o = run(&["batch", "mocap-compress", &s(&input), "-o", &s(&killed), "--max-error", "1cm"], &[]);
    assert!(o.status.success(), "{}", text(&o));
    assert_eq!(lines(&killed), lines(&one), "no input lost or doubled after the kill ({done_before} lines before it)");
    assert_eq!(outputs(&killed), outputs(&one), "no output half-written");

    // Run again: everything done is skipped.
    let o = run(&["batch", "mocap-compress", &s(&input), "-o", &s(&one), "--max-error", "1cm", "--strict"], &[]);
    assert!(text(&o).contains("0 ok, 1 failed, 9 skipped"), "{}", text(&o));
    assert!(!o.status.success(), "--strict fails on the garbage file");
}

/// Arguments, environment, what the error says.
type Case<'a> = (&'a [&'a str], &'a [(&'a str, &'a str)], &'a str);

#[test]
fn bad_batch_requests_name_the_flag() {
    let tmp = tempfile::tempdir().unwrap();
    let input = tmp.path().join("in");
    corpus(&input, 1, 30);
    let out = s(&tmp.path().join("out"));
    let cases: &[Case] = &[
        (&["batch", "mocap-compress", &s(&input), "-o", &out], &[], "--max-error"),
        (
            &["batch", "mocap-compress", &s(&input), "-o", &out, "--max-error", "1cm", "--shard", "3/3"],
            &[],
            "shard 3 of 3",
        ),
        (
            &["batch", "mocap-compress", &s(&input), "-o", &out, "--max-error", "1cm", "--mask", "1s..2s"],
            &[],
            "--mask does not apply",
        ),
        (
            &["batch", "mocap-compress", &s(&input), "-o", &out, "--max-error", "1cm"],
            &[("JOB_COMPLETION_INDEX", "1")],
            "--shards",
        ),
        (
            &["batch", "mocap-compress", &s(&input), "-o", &out, "--max-error", "1cm", "--shards", "2"],
            &[],
            "--shard i/n",
        ),
        (&["batch", "summary", &s(&tmp.path().join("nothing"))], &[], "expected a batch's output folder"),
    ];
    for (args, env, expected) in cases {
        let o = run(args, env);
        assert!(!o.status.success(), "{args:?}");
        assert!(text(&o).contains(expected), "{args:?}: {}", text(&o));
        assert!(!text(&o).contains("panicked"), "{}", text(&o));
    }
}

#[test]
fn cmu_corpus_in_three_shards_equals_one_run() {
    inbetween_io::data::with_shared_data("batch on the CMU corpus", |data| {
        let cmu = data.join("mocap/cmu");
        let tmp = tempfile::tempdir().unwrap();
        let (one, three) = (tmp.path().join("one"), tmp.path().join("three"));
        let o = run(&["batch", "mocap-compress", &s(&cmu), "-o", &s(&one), "--max-error", "1cm"], &[]);
        assert!(o.status.success(), "{}", text(&o));
        let running: Vec<_> = (0..3)
            .map(|i| {
                inbetween()
                    .args(["batch", "mocap-compress", &s(&cmu), "-o", &s(&three), "--max-error", "1cm"])
                    .args(["--shard", &format!("{i}/3")])
                    .stdout(Stdio::piped())
                    .stderr(Stdio::piped())
                    .spawn()
                    .unwrap()
            })
            .collect();
        for c in running {
            let o = c.wait_with_output().unwrap();
            assert!(o.status.success(), "{}", text(&o));
        }
        let (a, b) = (outputs(&one), outputs(&three));
        assert_eq!(a.keys().collect::<Vec<_>>(), b.keys().collect::<Vec<_>>());
        assert!(a == b, "byte-identical outputs");
        assert_eq!(lines(&one), lines(&three));
        let all = lines(&one);
        assert!(all.len() >= 30, "{} takes", all.len());
        assert!(all.values().all(|l| l["ok"] == true), "every CMU take compresses");
        // The same bytes as `inbetween mocap compress` on one take.
        let take = cmu.join("cgspeed/01_01.bvh");
        let single = tmp.path().join("single.ibk");
        let o = run(&["mocap", "compress", &s(&take), "-o", &s(&single), "--max-error", "1cm"], &[]);
        assert!(o.status.success(), "{}", text(&o));
        assert_eq!(std::fs::read(&single).unwrap(), a["cgspeed/01_01.ibk"]);
    });
}
