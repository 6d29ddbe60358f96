//! Helpers shared by the CLI's end-to-end tests.

use std::path::Path;

/// `stderr` of a run that must fail; checks it is one clear error, not a panic.
pub fn fails(out: &std::process::Output) -> String {
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!out.status.success(), "expected a failure; stdout {}", String::from_utf8_lossy(&out.stdout));
    assert!(err.starts_with("error: ") && !err.contains("panicked") && !err.contains("internal error"), "{err}");
    err
}

/// The names in a folder (staging folders included), sorted.
pub fn listing(d: &Path) -> Vec<String> {
    let mut v: Vec<String> =
        std::fs::read_dir(d).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    v.sort();
    v
}
