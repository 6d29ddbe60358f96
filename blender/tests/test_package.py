"""The built add-on and extension (scripts/build-blender-addon.sh): the add-on folder Blender loaded
brings the engines in _vendor/, and the extension zip holds a manifest naming its wheel."""

from __future__ import annotations

import os
import pathlib
import tomllib
import zipfile

import pytest

import bpy  # noqa: F401  (first: in the bpy module addon_utils comes with it)
import addon_utils  # noqa: E402


def test_the_loaded_add_on_brings_the_engines():
    import inbetween

    mod = next(m for m in addon_utils.modules() if m.__name__ == "inbetween_blender")
    folder = pathlib.Path(mod.__file__).parent
    if not (folder / "_vendor").is_dir():
        pytest.skip(f"skipped: {folder} is a source folder, not a build (no _vendor/)")
    assert pathlib.Path(inbetween.__file__).resolve().is_relative_to((folder / "_vendor").resolve())
    assert inbetween.__version__ == ".".join(map(str, mod.bl_info["version"]))


def test_extension_zip_names_its_wheel():
    path = os.environ.get("INBETWEEN_ADDON_ZIP")
    if not path:
        pytest.skip("skipped: no INBETWEEN_ADDON_ZIP (set by crates/py/tests/blender.rs)")
    with zipfile.ZipFile(path) as z:
        names = set(z.namelist())
        manifest = tomllib.loads(z.read("blender_manifest.toml").decode())
        assert manifest["schema_version"] == "1.0.0" and manifest["type"] == "add-on"
        assert manifest["id"] == "inbetween_blender" and manifest["blender_version_min"] == "4.2.0"
        assert len(manifest["tagline"]) <= 64 and not manifest["tagline"].endswith(".")
        assert pathlib.Path(path).name == f"inbetween_blender-{manifest['version']}.zip"
        assert "__init__.py" in names and not any(n.startswith("_vendor/") for n in names)
        (wheel,) = manifest["wheels"]
        assert wheel.startswith("./wheels/") and wheel[2:] in names
        assert manifest["platforms"] == ["linux-x64"]
        import io

        with zipfile.ZipFile(io.BytesIO(z.read(wheel[2:]))) as w:
            inner = set(w.namelist())
    assert {"inbetween/__init__.py", "inbetween/mocap.py", "inbetween/_native.abi3.so"} <= inner
    assert any(n.endswith(".dist-info/RECORD") for n in inner)


def test_operators_panels_and_menus_are_registered():
    for op in ("reduce_keys", "text_to_scene", "face_inpaint", "import_live_link", "export_live_link"):
        assert hasattr(bpy.ops.inbetween, op), op
        assert getattr(bpy.ops.inbetween, op).get_rna_type().bl_rna.identifier == f"INBETWEEN_OT_{op}"
    for panel in ("INBETWEEN_PT_reduce", "INBETWEEN_PT_reduce_graph", "INBETWEEN_PT_scene"):
        assert hasattr(bpy.types, panel), panel
    from inbetween_blender import ui

    for menu in ui.MENUS:
        assert ui.menu_entry in getattr(bpy.types, menu)._dyn_ui_initialize()
    assert bpy.context.scene.inbetween.max_error_cm == 1.0


INSTALL = """
import bpy, sys
r = bpy.ops.extensions.package_install_files(filepath=sys.argv[1], repo="user_default", enable_on_install=True)
assert r == {"FINISHED"}, r
assert "bl_ext.user_default.inbetween_blender" in bpy.context.preferences.addons.keys()
import inbetween
assert "/extensions/" in inbetween.__file__, inbetween.__file__
bpy.ops.object.armature_add()
try:
    bpy.ops.inbetween.reduce_keys()
except RuntimeError as e:
    assert "no action to reduce" in str(e), e
    print("installed and enabled; reduce_keys reports:", e)
else:
    raise AssertionError("reduce_keys on an armature without an action did not report an error")
"""


def test_the_extension_zip_installs_and_enables_in_blender_4_2_and_later(tmp_path):
    import subprocess
    import sys

    path = os.environ.get("INBETWEEN_ADDON_ZIP")
    if not path:
        pytest.skip("skipped: no INBETWEEN_ADDON_ZIP (set by crates/py/tests/blender.rs)")
    if bpy.app.version < (4, 2, 0):
        pytest.skip(f"skipped: Blender {bpy.app.version_string} has no extensions (4.2+; the bpy module run covers it)")
    if "site-packages" not in pathlib.Path(bpy.__file__).parts:
        pytest.skip("skipped: installs in a second process of the bpy module (PyPI's bpy), not a Blender binary")
    # A fresh process with its own home: the install writes into the user's extensions folder.
    env = dict(os.environ, HOME=str(tmp_path))
    env.pop("BLENDER_USER_SCRIPTS", None)
    out = subprocess.run([sys.executable, "-c", INSTALL, path], env=env, capture_output=True, text=True, timeout=300)
    print(out.stdout[-2000:], out.stderr[-2000:])
    assert out.returncode == 0, out.stderr[-2000:]
