//! Runs the Blender add-on's tests (`blender/tests/test_*.py`) inside real Blender under `cargo test`.
//!
//! The add-on is packed by `scripts/build-blender-addon.sh OUT --native LIB` from the extension
//! module this crate's build has just made (`target/debug/lib_native.so`, as `tests/python.rs`
//! uses it: no second build), so the tests load the add-on folder exactly as a user installs it
//! (the package unpacked in its `_vendor/`). Blender runs headless with pytest inside:
//! `blender -b --factory-startup -noaudio --python-exit-code 1 --python-expr "…sys.exit(pytest.main(…))"`
//! (the `sys.exit` makes a failing suite fail the process). When `xvfb-run` is there, a second run
//! with a window checks what needs one: the modal operator, its progress and Esc, and undo.
//!
//! Needs Blender with numpy and pytest in its Python (Debian: `apt-get install blender
//! python3-numpy python3-pytest`, which `.ci/run` does); prints `skipped: no blender` without
//! Blender. `INBETWEEN_BLENDER` names another Blender binary.
//!
//! Blender 5.0's API: the same tests with plain pytest in the venv `.ci/run` makes beside the
//! target folder (`$CARGO_TARGET_DIR/bpy-venv`: PyPI's `bpy` 5.0.1, numpy < 2, pytest; Python 3.11),
//! or `INBETWEEN_BPY_PYTHON`; `skipped: no bpy 5.0.1 venv` without it (the test downloads nothing).

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn profile_dir() -> PathBuf {
    let exe = std::env::current_exe().expect("test executable");
    exe.parent().and_then(Path::parent).expect("target/<profile>/deps/<test>").to_path_buf()
}

fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").canonicalize().expect("repository root")
}

fn text(out: &Output) -> String {
    format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr))
}

/// The Blender binary, or why there is none usable.
fn blender() -> Result<PathBuf, String> {
    let bin = std::env::var_os("INBETWEEN_BLENDER").map(PathBuf::from).unwrap_or_else(|| PathBuf::from("blender"));
    let probe = Command::new(&bin)
        .args(["-b", "--factory-startup", "-noaudio", "--python-exit-code", "1", "--python-expr"])
        .arg("import numpy, pytest")
        .output();
    match probe {
        Err(e) => Err(format!("no blender ({}: {e})", bin.display())),
        Ok(o) if !o.status.success() => Err(format!(
            "no blender with numpy and pytest in its Python (apt-get install python3-numpy python3-pytest): {}",
            text(&o).lines().rev().take(3).collect::<Vec<_>>().join(" | ")
        )),
        Ok(_) => Ok(bin),
    }
}

#[test]
fn blender_suite() {
    let bin = match blender() {
        Ok(b) => b,
        Err(why) => {
            println!("skipped: {why}");
            return;
        }
    };
    let root = repo_root();
    let tmp = PathBuf::from(env!("CARGO_TARGET_TMPDIR"));
    let out = tmp.join("blender-addon");
    let lib = profile_dir().join("lib_native.so");
    let built = Command::new(root.join("scripts/build-blender-addon.sh"))
        .arg(&out)
        .arg("--native")
        .arg(&lib)
        .output()
        .expect("running scripts/build-blender-addon.sh");
    assert!(built.status.success(), "build-blender-addon.sh failed:\n{}", text(&built));
    // A user scripts folder with the add-on in addons/, as Blender's installer leaves it.
    let scripts = tmp.join("blender-scripts");
    let addons = scripts.join("addons");
    std::fs::create_dir_all(&addons).expect("scripts folder");
    let link = addons.join("inbetween_blender");
    if link.symlink_metadata().is_ok() {
        std::fs::remove_file(&link).or_else(|_| std::fs::remove_dir_all(&link)).expect("old add-on link");
    }
    std::os::unix::fs::symlink(out.join("inbetween_blender"), &link).expect("linking the add-on");
    let zip = std::fs::read_dir(&out)
        .expect("build output")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .find(|p| p.extension().is_some_and(|x| x == "zip"))
        .expect("the extension zip");
    let tests = root.join("blender/tests");
    let run = |cmd: &mut Command| {
        cmd.env("BLENDER_USER_SCRIPTS", &scripts)
            .env("INBETWEEN_ADDON_ZIP", &zip)
            .env("PYTHONDONTWRITEBYTECODE", "1")
            .env("INBETWEEN_NO_PROGRESS", "1")
            .current_dir(&tests)
            .output()
            .expect("running blender")
    };
    let expr = format!(
        "import sys, pytest; sys.exit(pytest.main(['-q', '-p', 'no:cacheprovider', '-rs', '-s', '--durations=5', {:?}]))",
        tests.display().to_string()
    );
    let suite = run(Command::new(&bin)
        .args(["-b", "--factory-startup", "-noaudio", "--python-exit-code", "1", "--python-expr"])
        .arg(&expr));
    let log = text(&suite);
    println!("{log}");
    assert!(suite.status.success(), "the Blender suite failed ({}):\n{log}", suite.status);

    // Blender 5.0's API (layered actions, pose bone selection) through PyPI's bpy module.
    let bpy_python = std::env::var_os("INBETWEEN_BPY_PYTHON")
        .map(PathBuf::from)
        .unwrap_or_else(|| profile_dir().parent().expect("target folder").join("bpy-venv/bin/python"));
    let has_bpy = Command::new(&bpy_python)
        .args(["-c", "import bpy, numpy, pytest"])
        .output()
        .map(|o| o.status.success())
        .unwrap_or(false);
    if has_bpy {
        let five =
            run(Command::new(&bpy_python).args(["-m", "pytest", "-q", "-p", "no:cacheprovider", "-rs"]).arg(&tests));
        let log = text(&five);
        println!("bpy 5.0.1:\n{log}");
        assert!(five.status.success(), "the suite under bpy 5.0.1 failed ({}):\n{log}", five.status);
    } else {
        println!("skipped: no bpy 5.0.1 venv at {} (.ci/run makes it)", bpy_python.display());
    }

    // With a window (modal progress, Esc, undo): only where a virtual display can be had.
    if Command::new("xvfb-run").arg("--help").output().is_err() {
        println!("skipped: no xvfb-run (the modal operator, Esc and undo need a window)");
        return;
    }
    let ui = run(Command::new("xvfb-run")
        .args(["-a", "-s", "-screen 0 1280x800x24"])
        .arg(&bin)
        .args(["--factory-startup", "-noaudio", "--enable-event-simulate", "--python-exit-code", "1", "--python"])
        .arg(tests.join("ui_session.py")));
    let log = text(&ui);
    println!("{log}");
    assert!(ui.status.success(), "the Blender UI session failed ({}):\n{log}", ui.status);
    assert!(log.contains("ui session: ok"), "the UI session did not finish:\n{log}");
}
