//! Runs the Python package's pytest suite (`crates/py/tests/test_*.py`) under `cargo test`.
//!
//! No second build: `cargo test --workspace` has already compiled this crate's extension module
//! (`lib_native.so`, the cdylib) with the workspace's features and profile, so the test lays the
//! package out under the target folder (`python/inbetween` plus that library as
//! `_native.abi3.so`, the layout `maturin develop` installs) and runs pytest on it with the Python
//! of the venv `.ci/run` makes (`$CARGO_TARGET_DIR/py-venv`: numpy, pytest, maturin). Without that
//! venv it makes one when `python3` can; without `python3` it prints `skipped: no python3/maturin`.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The target folder's profile directory (`target/debug`) this test binary was built into.
fn profile_dir() -> PathBuf {
    let exe = std::env::current_exe().expect("test executable");
    exe.parent().and_then(Path::parent).expect("target/<profile>/deps/<test>").to_path_buf()
}

/// The venv under the target folder: `target/py-venv`, beside the profile directories.
fn venv_dir() -> PathBuf {
    profile_dir().parent().expect("target folder").join("py-venv")
}

/// A venv whose Python has numpy and pytest, made when missing. Err: why there is none.
fn python() -> Result<PathBuf, String> {
    if let Some(p) = std::env::var_os("INBETWEEN_PYTHON") {
        return Ok(PathBuf::from(p));
    }
    let venv = venv_dir();
    let py = venv.join("bin/python");
    let ready = |py: &Path| {
        Command::new(py).args(["-c", "import numpy, pytest"]).output().map(|o| o.status.success()).unwrap_or(false)
    };
    if ready(&py) {
        return Ok(py);
    }
    let made = Command::new("python3").args(["-m", "venv"]).arg(&venv).output();
    match made {
        Ok(o) if o.status.success() => {}
        Ok(o) => return Err(format!("python3 -m venv failed: {}", String::from_utf8_lossy(&o.stderr).trim())),
        Err(e) => return Err(format!("no python3 ({e})")),
    }
    let pip = Command::new(&py)
        .args(["-m", "pip", "install", "-q", "--disable-pip-version-check", "numpy", "pytest", "maturin"])
        .output()
        .map_err(|e| e.to_string())?;
    if !pip.status.success() || !ready(&py) {
        return Err(format!(
            "pip install numpy pytest maturin failed: {}",
            String::from_utf8_lossy(&pip.stderr).trim()
        ));
    }
    Ok(py)
}

/// Lays out the package (`python/inbetween` + the built extension) under `site`.
fn lay_out(site: &Path) -> std::io::Result<()> {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("python/inbetween");
    let pkg = site.join("inbetween");
    if pkg.exists() {
        std::fs::remove_dir_all(&pkg)?;
    }
    std::fs::create_dir_all(&pkg)?;
    for entry in std::fs::read_dir(&src)? {
        let path = entry?.path();
        if path.is_file() {
            std::fs::copy(&path, pkg.join(path.file_name().expect("file name")))?;
        }
    }
    let lib = profile_dir().join("lib_native.so");
    std::fs::copy(&lib, pkg.join("_native.abi3.so")).map(|_| ()).map_err(|e| {
        std::io::Error::new(e.kind(), format!("{}: {e} (built by `cargo test -p inbetween-py`)", lib.display()))
    })
}

#[test]
fn pytest_suite() {
    let py = match python() {
        Ok(p) => p,
        Err(why) => {
            println!("skipped: no python3/maturin ({why})");
            return;
        }
    };
    let site = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("py-site");
    lay_out(&site).expect("laying out the package");
    let tests = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests");
    let mut cmd = Command::new(&py);
    // The CLI of the same build, when `cargo test --workspace` made it: byte-for-byte comparisons.
    let cli = profile_dir().join("inbetween");
    if cli.is_file() {
        cmd.env("INBETWEEN_BIN", &cli);
    }
    let out = cmd
        .args(["-m", "pytest", "-q", "-p", "no:cacheprovider", "-rs", "--durations=5"])
        .arg(&tests)
        .env("PYTHONPATH", &site)
        .env("PYTHONDONTWRITEBYTECODE", "1")
        .env("INBETWEEN_NO_PROGRESS", "1")
        .output()
        .expect("running pytest");
    let text = format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    println!("{text}");
    assert!(out.status.success(), "pytest failed ({}):\n{text}", out.status);
}
