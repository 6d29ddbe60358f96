//! Batch runs on procedural takes: shards together equal the unsharded run byte for byte, reruns skip
//! what is done, a partial line from a kill is cut off, and a bad file fails only its own line.

use inbetween_batch::{results, BatchJob, Kind, Options, ResultLine, Shard, SummaryJob};
use inbetween_core::cancel::Cancel;
use inbetween_core::procedural::gait_library;
use inbetween_io::Progress;
use std::collections::BTreeMap;
use std::path::Path;

/// Six procedural takes in two folders, and one file that is not BVH.
fn corpus(dir: &Path) {
    for (i, m) in gait_library(3, 6, 48, 30.0).iter().enumerate() {
        let sub = if i % 2 == 0 { "a" } else { "b/c" };
        let path = dir.join(sub).join(format!("take_{i}.bvh"));
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        inbetween_io::write_bvh(&path, m).unwrap();
    }
    std::fs::write(dir.join("a/broken.bvh"), "HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0\n").unwrap();
    std::fs::write(dir.join("a/notes.txt"), "not an input of mocap jobs").unwrap();
}

fn job(input: &Path, out: &Path, shard: Shard) -> BatchJob {
    BatchJob {
        kind: Kind::MocapCompress,
        input_dir: input.to_path_buf(),
        out_dir: out.to_path_buf(),
        shard,
        options: Options { max_error_cm: Some(1.0), ..Options::default() },
    }
}

fn run(job: &BatchJob) -> inbetween_batch::BatchReport {
    job.run(&Cancel::new(), &Progress::hidden()).unwrap()
}

/// Every line of every result file, by input, without the timing.
fn lines(out: &Path) -> BTreeMap<String, ResultLine> {
    let mut all = BTreeMap::new();
    for file in results::files_in(out).unwrap() {
        for mut l in results::read(&file).unwrap() {
            l.seconds = 0.0;
            assert!(all.insert(l.input.clone(), l).is_none(), "one line per input");
        }
    }
    all
}

/// Every file below `dir` except result lines, with its bytes.
fn files(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    walk(dir, dir)
}

fn walk(root: &Path, dir: &Path) -> BTreeMap<String, Vec<u8>> {
    let mut out = BTreeMap::new();
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            out.extend(walk(root, &p));
        } else if !p.file_name().unwrap().to_string_lossy().starts_with("results-") {
            out.insert(p.strip_prefix(root).unwrap().to_string_lossy().into_owned(), std::fs::read(&p).unwrap());
        }
    }
    out
}

#[test]
fn three_shards_equal_one_run_and_reruns_skip() {
    let tmp = tempfile::tempdir().unwrap();
    let (input, one, three) = (tmp.path().join("in"), tmp.path().join("one"), tmp.path().join("three"));
    corpus(&input);

    let whole = run(&job(&input, &one, Shard::ALL));
    assert_eq!((whole.manifest, whole.inputs, whole.ok, whole.failed, whole.skipped), (7, 7, 6, 1, 0));
    let mut count = 0;
    for i in 0..3 {
        let r = run(&job(&input, &three, Shard::new(i, 3).unwrap()));
        count += r.inputs;
    }
    assert_eq!(count, 7, "every input in exactly one shard");
    assert_eq!(files(&one), files(&three), "the shards' outputs are the unsharded run's, byte for byte");
    assert_eq!(lines(&one), lines(&three), "and so are their lines");
    assert_eq!(files(&one).keys().cloned().collect::<Vec<_>>().len(), 6);
    assert!(one.join("b/c/take_1.ibk").is_file(), "outputs mirror the inputs' paths");

    // The bad file failed its own line, naming the file and where it broke.
    let l = &lines(&one)["a/broken.bvh"];
    assert!(!l.ok && l.outputs.is_empty());
    let e = l.error.as_deref().unwrap();
    assert!(e.contains("broken.bvh:4") && e.contains("expected"), "{e}");

    // A rerun skips every input done, and runs the failed one again (it fails again).
    let again = run(&job(&input, &one, Shard::ALL));
    assert_eq!((again.ok, again.failed, again.skipped), (0, 1, 6));
    let n_lines: usize = results::files_in(&one).unwrap().iter().map(|f| results::read(f).unwrap().len()).sum();
    assert_eq!(n_lines, 8, "7 lines, and one more for the failed input's retry");

    // A changed option hashes differently: the input runs again.
    let looser = BatchJob {
        options: Options { max_error_cm: Some(2.0), ..Options::default() },
        ..job(&input, &one, Shard::ALL)
    };
    assert_eq!(run(&looser).ok, 6);

    let s = SummaryJob { out_dir: three.clone(), slowest: 3 }.run().unwrap();
    assert_eq!((s.inputs, s.ok, s.failures.len(), s.files.len(), s.slowest.len()), (7, 6, 1, 3, 3));
    assert!(s.to_string().contains("a/broken.bvh"), "{s}");
}

#[test]
fn a_kill_mid_line_and_a_lost_output_are_redone_once() {
    let tmp = tempfile::tempdir().unwrap();
    let (input, out) = (tmp.path().join("in"), tmp.path().join("out"));
    corpus(&input);
    run(&job(&input, &out, Shard::ALL));
    let file = out.join(results::file_name(0));
    // As if killed while writing the last line, after an output was lost.
    let text = std::fs::read_to_string(&file).unwrap();
    let mut kept: Vec<&str> = text.lines().collect();
    let last = kept.pop().unwrap();
    let last_input = serde_json::from_str::<ResultLine>(last).unwrap().input;
    std::fs::write(&file, format!("{}\n{}", kept.join("\n"), &last[..last.len() / 2])).unwrap();
    std::fs::remove_file(out.join("a/take_0.ibk")).unwrap();
    let before = files(&out);
    let r = run(&job(&input, &out, Shard::ALL));
    // take_0 (its output gone), the input whose line was cut, and the bad file run again.
    assert_eq!(r.skipped, 7 - 3, "{r}");
    let lines = results::read(&file).unwrap();
    let last_lines = lines.iter().filter(|l| l.input == last_input).count();
    assert_eq!(last_lines, 1, "the cut line is replaced, not duplicated");
    assert!(out.join("a/take_0.ibk").is_file());
    assert_eq!(files(&out).len(), before.len() + 1);
    // No staging leftovers or temp files.
    assert!(files(&out).keys().all(|k| !k.contains(".tmp") && !k.starts_with('.')), "{:?}", files(&out).keys());
}

#[test]
fn bad_options_and_folders_are_refused_before_any_work() {
    let tmp = tempfile::tempdir().unwrap();
    let input = tmp.path().join("in");
    corpus(&input);
    let err = |j: BatchJob| j.validate().unwrap_err().to_string();
    let base = job(&input, &tmp.path().join("out"), Shard::ALL);
    assert!(err(BatchJob { out_dir: input.join("inside"), ..base.clone() }).contains("inside the input folder"));
    assert!(err(BatchJob { options: Options::default(), ..base.clone() }).contains("either an error bound"));
    let nan = Options { max_error_cm: Some(f64::NAN), ..Options::default() };
    assert!(err(BatchJob { options: nan, ..base.clone() }).contains("expected a positive length"));
    let mask = Options { mask: Some("1s..2s".into()), max_error_cm: Some(1.0), ..Options::default() };
    assert!(err(BatchJob { options: mask, ..base.clone() }).contains("option `mask` does not apply to mocap-compress"));
    assert!(err(BatchJob { input_dir: tmp.path().join("missing"), ..base.clone() }).contains("expected a folder"));
    assert!(inbetween_batch::Kind::parse("mocap-zip").unwrap_err().to_string().contains("mocap-compress"));
}

#[test]
fn keys_json_holds_the_select_jobs_report() {
    let tmp = tempfile::tempdir().unwrap();
    let (input, out) = (tmp.path().join("in"), tmp.path().join("out"));
    corpus(&input);
    let j = BatchJob {
        kind: Kind::MocapKeys,
        options: Options { max_error_cm: Some(1.0), ..Options::default() },
        ..job(&input, &out, Shard::ALL)
    };
    let r = run(&j);
    assert_eq!((r.ok, r.failed), (6, 1), "{r}");
    let keys: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("a/take_0.keys.json")).unwrap()).unwrap();
    assert_eq!(keys["method"], "error_bounded");
    let line = lines(&out).remove("a/take_0.bvh").unwrap();
    assert_eq!(line.report["keys"], keys["reconstruction"]["keys"]["frames"]);
    // The bound holds on the rebuilt clip (the search measures segments on it).
    let max_cm = line.report["max_cm"].as_f64().unwrap();
    assert!(max_cm > 0.0 && max_cm <= 1.0 + 1e-9, "{}", line.report);
}

#[test]
fn face_edit_changes_only_the_masked_span_of_each_take() {
    use inbetween_face::data::{read_clip, write_clip};
    use inbetween_face::procedural::{generate, ProceduralConfig};
    let tmp = tempfile::tempdir().unwrap();
    let (input, out) = (tmp.path().join("takes"), tmp.path().join("out"));
    for seed in 0..2u64 {
        let p = generate(&ProceduralConfig { duration_s: 6.0, ..Default::default() }, seed);
        std::fs::create_dir_all(&input).unwrap();
        write_clip(&input.join(format!("take{seed}.csv")), &p.clip, true).unwrap();
    }
    let j = BatchJob {
        kind: Kind::FaceEdit,
        input_dir: input.clone(),
        out_dir: out.clone(),
        shard: Shard::ALL,
        options: Options { mask: Some("2s..3.5s".into()), ..Options::default() },
    };
    let r = run(&j);
    assert_eq!((r.ok, r.failed), (2, 0), "{r}");
    for seed in 0..2 {
        let (a, b) = (
            read_clip(&input.join(format!("take{seed}.csv"))).unwrap(),
            read_clip(&out.join(format!("take{seed}.csv"))).unwrap(),
        );
        assert_eq!(a.num_frames(), b.num_frames());
        let fps = a.measured_fps();
        let (mut inside, mut outside) = (0.0f32, 0.0f32);
        for f in 0..a.num_frames() {
            let t = f as f64 / fps;
            let d: f32 = a.frame(f).iter().zip(b.frame(f)).map(|(x, y)| (x - y).abs()).sum();
            if (2.0..3.5).contains(&t) {
                inside += d
            } else if !(1.9..3.6).contains(&t) {
                outside += d
            }
        }
        assert!(inside > 0.0, "the span was regenerated");
        assert_eq!(outside, 0.0, "frames away from the span are the take's");
    }
    let line = lines(&out).remove("take0.csv").unwrap();
    assert_eq!(line.report["live_link"], true);
    let bad = BatchJob { options: Options { mask: Some("9s..12s".into()), ..Options::default() }, ..j };
    let r = bad.run(&Cancel::new(), &Progress::hidden()).unwrap();
    // Other options hash differently, so the takes run again, and a span past the end fails each line.
    assert_eq!((r.skipped, r.failed), (0, 2), "{r}");
    assert!(r.failures[0].1.contains("9s..12s"), "{:?}", r.failures);
}
