//! How the binary fails: `error: …` with causes, exit code 1, no backtrace even with
//! RUST_BACKTRACE set, unless `--debug` asks for one.

use std::process::Command;

fn run(args: &[&str], envs: &[(&str, &str)]) -> (Option<i32>, String) {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_inbetween"));
    cmd.args(args).env_remove("INBETWEEN_DEBUG").env_remove("RUST_LIB_BACKTRACE");
    for (k, v) in envs {
        cmd.env(k, v);
    }
    let out = cmd.output().unwrap();
    (out.status.code(), String::from_utf8_lossy(&out.stderr).into_owned())
}

#[test]
fn errors_print_one_message_and_exit_1_without_a_backtrace() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("missing.bvh");
    for backtrace in ["1", "full", "0"] {
        let (code, err) = run(&["info", missing.to_str().unwrap()], &[("RUST_BACKTRACE", backtrace)]);
        assert_eq!(code, Some(1), "{err}");
        assert!(err.starts_with("error: ") && err.contains("missing.bvh"), "{err}");
        assert!(!err.to_lowercase().contains("backtrace"), "RUST_BACKTRACE={backtrace} leaked a backtrace:\n{err}");
    }
}

#[test]
fn debug_flag_adds_the_backtrace() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("missing.bvh");
    let (code, err) = run(&["--debug", "info", missing.to_str().unwrap()], &[("RUST_BACKTRACE", "1")]);
    assert_eq!(code, Some(1), "{err}");
    assert!(err.starts_with("error: ") && err.contains("backtrace:"), "{err}");
}
