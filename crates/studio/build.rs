//! Installs the front-end's npm dependencies (three.js, pinned by `web/package-lock.json`) into
//! the build folder with `npm ci` and copies the files the page imports into `$OUT_DIR/vendor`,
//! which the binary embeds. Without Node (or without the registry) the build still succeeds:
//! `$OUT_DIR/vendor/MISSING.txt` says what is missing, and the studio serves a page saying what
//! to install. `INBETWEEN_STUDIO_NO_NPM=1` skips npm on purpose.

use std::path::{Path, PathBuf};
use std::process::Command;

/// Files of the `three` package the page imports (the import map points `three` and
/// `three/addons/` at them).
const THREE_FILES: &[&str] = &[
    "LICENSE",
    "package.json",
    "build/three.module.js",
    "build/three.core.js",
    "examples/jsm/controls/OrbitControls.js",
    "examples/jsm/controls/TransformControls.js",
    "examples/jsm/loaders/GLTFLoader.js",
    "examples/jsm/utils/BufferGeometryUtils.js",
    "examples/jsm/utils/SkeletonUtils.js",
];

fn main() {
    let manifest = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR"));
    let out = PathBuf::from(std::env::var("OUT_DIR").expect("cargo sets OUT_DIR"));
    let web = manifest.join("web");
    for f in ["package.json", "package-lock.json"] {
        println!("cargo:rerun-if-changed={}", web.join(f).display());
    }
    println!("cargo:rerun-if-changed=build.rs");
    // The page's own files are embedded by include_dir!, which tells cargo nothing: a change
    // there re-runs this script, and so rebuilds the crate.
    println!("cargo:rerun-if-changed={}", web.join("app").display());
    println!("cargo:rerun-if-env-changed=INBETWEEN_STUDIO_NO_NPM");
    let vendor = out.join("vendor");
    let _ = std::fs::remove_dir_all(&vendor);
    std::fs::create_dir_all(&vendor).expect("create $OUT_DIR/vendor");
    if let Err(why) = install(&web, &out, &vendor) {
        println!(
            "cargo:warning=inbetween-studio: three.js not installed ({why}); the studio page will say what to install"
        );
        let text = format!(
            "{why}\n\nThe studio's 3D view needs three.js, which the build installs with npm.\n\
             Install Node.js and npm (Debian/Ubuntu: apt-get install nodejs npm), make sure the npm registry\n\
             can be reached, then rebuild: cargo build -p inbetween-cli\n"
        );
        std::fs::write(vendor.join("MISSING.txt"), text).expect("write MISSING.txt");
    }
}

/// `npm ci` in `$OUT_DIR/npm` (skipped when the lock is unchanged since the last install), then
/// the page's files copied into `vendor/three`.
fn install(web: &Path, out: &Path, vendor: &Path) -> Result<(), String> {
    if std::env::var_os("INBETWEEN_STUDIO_NO_NPM").is_some_and(|v| v != "0") {
        return Err("INBETWEEN_STUDIO_NO_NPM is set".into());
    }
    let npm_dir = out.join("npm");
    std::fs::create_dir_all(&npm_dir).map_err(|e| format!("create {}: {e}", npm_dir.display()))?;
    let lock = std::fs::read(web.join("package-lock.json")).map_err(|e| format!("read package-lock.json: {e}"))?;
    let stamp = npm_dir.join(".installed-lock");
    let three = npm_dir.join("node_modules/three");
    let fresh = std::fs::read(&stamp).is_ok_and(|s| s == lock) && three.join("package.json").is_file();
    if !fresh {
        for f in ["package.json", "package-lock.json"] {
            std::fs::copy(web.join(f), npm_dir.join(f)).map_err(|e| format!("copy {f}: {e}"))?;
        }
        let npm = if cfg!(windows) { "npm.cmd" } else { "npm" };
        let run = Command::new(npm)
            .args(["ci", "--no-audit", "--no-fund", "--ignore-scripts", "--loglevel=error"])
            .current_dir(&npm_dir)
            .output()
            .map_err(|e| format!("npm not found ({e}): Node.js and npm are needed to build the studio's page"))?;
        if !run.status.success() {
            let err = String::from_utf8_lossy(&run.stderr);
            let tail: Vec<&str> = err.lines().rev().take(6).collect();
            return Err(format!(
                "npm ci failed ({}): {}",
                run.status,
                tail.into_iter().rev().collect::<Vec<_>>().join(" | ")
            ));
        }
        std::fs::write(&stamp, &lock).map_err(|e| format!("write {}: {e}", stamp.display()))?;
    }
    for f in THREE_FILES {
        let from = three.join(f);
        let to = vendor.join("three").join(f);
        std::fs::create_dir_all(to.parent().expect("a file has a parent")).map_err(|e| format!("{e}"))?;
        std::fs::copy(&from, &to).map_err(|e| format!("copy {}: {e}", from.display()))?;
    }
    Ok(())
}
