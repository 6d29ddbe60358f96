"""Shared fixtures of the add-on's tests, run inside Blender (`blender -b … --python-expr "import
pytest; sys.exit(pytest.main([...]))"`, see crates/py/tests/blender.rs): the add-on enabled, an
empty scene per test, the real data (`../shared/data` or INBETWEEN_DATA), Blender's BVH importer
with Debian's Blender 3.4 bug worked around, and an independent measure of joint positions."""

from __future__ import annotations

import builtins
import os
import pathlib

import numpy as np
import pytest

import bpy  # first: in the bpy module, addon_utils is importable only after it
import addon_utils  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[2]
ADDON = "inbetween_blender"


def data_dir() -> pathlib.Path:
    env = os.environ.get("INBETWEEN_DATA")
    return pathlib.Path(env) if env else ROOT.parent / "shared" / "data"


def need(path: pathlib.Path) -> pathlib.Path:
    if not path.exists():
        pytest.skip(f"skipped: no data at {path}")
    return path


@pytest.fixture(scope="session", autouse=True)
def addon():
    mod = addon_utils.enable(ADDON, default_set=True, handle_error=None)
    assert mod is not None, f"{ADDON} did not enable (BLENDER_USER_SCRIPTS={os.environ.get('BLENDER_USER_SCRIPTS')})"
    return mod


def clear_scene() -> None:
    for coll in (bpy.data.objects, bpy.data.armatures, bpy.data.meshes, bpy.data.cameras, bpy.data.actions,
                 bpy.data.texts, bpy.data.shape_keys, bpy.data.materials):
        for item in list(coll):
            try:
                coll.remove(item)
            except (TypeError, RuntimeError):  # shape keys go with their mesh
                pass
    for c in list(bpy.data.collections):
        bpy.data.collections.remove(c)
    sc = bpy.context.scene
    sc.unit_settings.scale_length = 1.0
    sc.frame_set(1)


@pytest.fixture(autouse=True)
def empty_scene():
    clear_scene()
    yield
    clear_scene()


def import_bvh(path: pathlib.Path, scale: float = 0.056444, rotate_mode: str = "NATIVE"):
    """Blender's own BVH importer (CMU cgspeed units to metres by default). Debian's Blender 3.4
    opens the file with mode 'rU', which Python 3.11 refuses: the importer module's `open` drops
    the U (../shared/notes/blender.md)."""
    import io_anim_bvh.import_bvh as importer

    if getattr(importer, "open", builtins.open) is builtins.open:
        importer.open = lambda f, mode="r", *a, **k: builtins.open(f, mode.replace("U", ""), *a, **k)
    r = bpy.ops.import_anim.bvh(
        filepath=str(path), global_scale=scale, rotate_mode=rotate_mode, update_scene_fps=True,
        update_scene_duration=True,
    )
    assert r == {"FINISHED"}
    return bpy.context.active_object


def world_points(ob, frames, tails: bool = True) -> np.ndarray:
    """World head (and tail) positions of every bone on every frame, cm: (T, P, 3). Plain mathutils
    after `frame_set`, independent of the add-on's own sampling."""
    sc = bpy.context.scene
    cm = 100.0 * sc.unit_settings.scale_length
    out = []
    for f in frames:
        sc.frame_set(int(f))
        mw = ob.matrix_world
        pts = [mw @ pb.head for pb in ob.pose.bones]
        if tails:
            pts += [mw @ pb.tail for pb in ob.pose.bones]
        out.append([tuple(p) for p in pts])
    return np.array(out) * cm


def curves(action) -> list:
    """Every F-curve of an action: `Action.fcurves` on 3.x/4.x, every channelbag's on 5.x."""
    if hasattr(action, "fcurves"):
        return list(action.fcurves)
    return [fc for layer in action.layers for strip in layer.strips for bag in strip.channelbags for fc in bag.fcurves]


def keyframes(action) -> dict:
    """(data path, index) -> (N, 6) co, left and right handles of every key."""
    out = {}
    for fc in curves(action):
        n = len(fc.keyframe_points)
        arrs = []
        for f in ("co", "handle_left", "handle_right"):
            a = np.zeros(2 * n, dtype=np.float32)
            fc.keyframe_points.foreach_get(f, a)
            arrs.append(a.reshape(n, 2))
        out[(fc.data_path, fc.array_index)] = np.concatenate(arrs, axis=1)
    return out
