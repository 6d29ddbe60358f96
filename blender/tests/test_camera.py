"""camera_from_armatures on two CMU takes imported with Blender's BVH importer: the scene camera's
keys are hit (at 30 fps, the takes retimed by the importer; both characters' targets on screen where the key camera puts them, measured in
Blender), one action per style for the shot list, the original camera action kept, bad inputs
reported with nothing changed. (Undo, the modal run and Esc need a window: ui_camera.py, run by
ui_session.py under xvfb.)"""

from __future__ import annotations

import numpy as np
import pytest

import bpy
from camera_scene import KEY_FRAMES, import_take, keyed_camera, on_screen, select, target
from conftest import data_dir, keyframes, need
from mathutils import Vector


@pytest.fixture
def two():
    cg = data_dir() / "mocap" / "cmu" / "cgspeed"
    a = import_take(need(cg / "131_01.bvh"))
    b = import_take(need(cg / "131_02.bvh"))
    b.location.x += 3.0  # the takes were recorded at one spot
    sc = bpy.context.scene
    sc.frame_start, sc.frame_end = 1, 200
    sc.render.resolution_x, sc.render.resolution_y = 960, 540
    return a, b


def test_camera_hits_every_key_on_screen(two):
    a, b = two
    cam = keyed_camera(a, b)
    original = cam.animation_data.action
    keys_before = keyframes(original)
    want = on_screen(cam, (a, b), KEY_FRAMES)
    assert ((want > 0.05) & (want < 0.95)).all(), f"the key cameras frame both: {want}"
    select(a, b)
    assert bpy.ops.inbetween.camera_from_armatures(style="ORBIT") == {"FINISHED"}
    new = cam.animation_data.action
    assert new is not original and new.name == original.name + ".inbetween.orbit"
    assert original.use_fake_user, "the original camera action is kept"
    after = keyframes(original)
    assert all(np.array_equal(after[c], keys_before[c]) for c in keys_before), "the original is untouched"
    got = on_screen(cam, (a, b), KEY_FRAMES)
    err = np.abs(got - want).max()
    report = new["inbetween_camera"]
    print(
        f"\ncamera through {len(KEY_FRAMES)} keys (orbit): targets on screen within {err:.2e} of the key camera "
        f"(add-on's measure {report['max_key_screen_error']:.2e}), network key miss "
        f"{report['network_key_miss']:.4f} (Toric units, before the engine's correction)"
    )
    assert err < 0.01, f"screen positions off by {err:.4f} at the keys"
    assert "shoulders LeftShoulder / RightShoulder" in report["notes"], report["notes"]
    # The engine's framed points are the bones' (the armatures' world transforms, axes and units
    # carried over): at each key, against the upper arms measured here.
    sc = bpy.context.scene
    gap = 0.0
    for f, (pa, pb) in zip(KEY_FRAMES, report["key_targets"]):
        sc.frame_set(f)
        gap = max(gap, (Vector(pa) - target(a)).length, (Vector(pb) - target(b)).length)
    print(f"engine's framed points vs the bones: {gap * 1000:.3f} mm")
    assert gap < 1e-3
    # In between, the camera moves through the shot (not a cut, not a hold).
    path = []
    for f in range(KEY_FRAMES[0], KEY_FRAMES[-1] + 1):
        sc.frame_set(f)
        path.append(tuple(cam.matrix_world.translation))
    steps = np.linalg.norm(np.diff(np.array(path), axis=0), axis=1)
    assert steps.max() < 0.5 and steps.sum() > 1.0, f"steps up to {steps.max():.3f}, path {steps.sum():.2f}"


def test_shot_list_makes_one_action_per_style(two):
    a, b = two
    cam = keyed_camera(a, b, frames=(20, 120))
    want = on_screen(cam, (a, b), (20, 120))
    select(b, a)  # B active: it is character A now
    assert bpy.ops.inbetween.camera_from_armatures(style="SIDE", shot_list=True) == {"FINISHED"}
    # Blender names the camera's first action after the object: CamAction.
    actions = {s: bpy.data.actions.get(f"CamAction.inbetween.{s}") for s in ("direct", "relative", "side", "orbit")}
    assert all(actions.values()), sorted(a.name for a in bpy.data.actions)
    assert cam.animation_data.action == actions["side"]
    paths = {}
    for style, action in actions.items():
        cam.animation_data.action = action
        got = on_screen(cam, (a, b), (20, 120))
        assert np.abs(got - want).max() < 0.01, f"{style}: {np.abs(got - want).max():.4f}"
        sc = bpy.context.scene
        sc.frame_set(70)
        paths[style] = np.array(cam.matrix_world.translation)
        assert action["inbetween_camera"]["characters"] == [b.name, a.name]
    # The relative style keeps the pair framed: both points inside the picture on every frame.
    cam.animation_data.action = actions["relative"]
    seen = on_screen(cam, (b, a), range(20, 121))
    inside = ((seen >= 0) & (seen <= 1)).all(axis=(1, 2))
    print(f"\nrelative: both framed points inside the picture on {inside.sum()}/{len(inside)} frames")
    assert inside.all()
    spread = max(np.linalg.norm(paths[s] - paths[t]) for s in paths for t in paths)
    print(f"\nshot list: four actions, camera positions at frame 70 up to {spread:.2f} m apart")
    assert spread > 0.05, "the styles move the camera differently"


def test_a_reference_camera_gives_the_style(two):
    a, b = two
    cam = keyed_camera(a, b, frames=(20, 120))
    original = cam.animation_data.action
    want = on_screen(cam, (a, b), (20, 120))
    select(a, b)
    assert bpy.ops.inbetween.camera_from_armatures(style="ORBIT") == {"FINISHED"}
    # The orbit result, played by a copy of the camera, is the reference.
    ref = cam.copy()
    bpy.context.scene.collection.objects.link(ref)
    cam.animation_data.action = original
    r = bpy.ops.inbetween.camera_from_armatures(style="REFERENCE", reference_camera=ref.name)
    assert r == {"FINISHED"}
    new = cam.animation_data.action
    assert new.name == "CamAction.inbetween.reference" and new["inbetween_camera"]["style"] == "reference"
    err = np.abs(on_screen(cam, (a, b), (20, 120)) - want).max()
    print(f"\nreference camera: keys on screen within {err:.2e}")
    assert err < 0.01
    with pytest.raises(RuntimeError, match="name the reference camera"):
        bpy.ops.inbetween.camera_from_armatures(style="REFERENCE")
    with pytest.raises(RuntimeError, match="is the camera being made"):
        bpy.ops.inbetween.camera_from_armatures(style="REFERENCE", reference_camera=cam.name)


def test_bad_inputs_report_and_change_nothing(two):
    a, b = two
    cam = keyed_camera(a, b)

    def state():
        return sorted(x.name for x in bpy.data.actions), cam.animation_data.action.name

    before = state()

    def refused(match, **kw):
        with pytest.raises(RuntimeError, match=match):
            bpy.ops.inbetween.camera_from_armatures(**kw)
        assert state() == before

    select(cam)
    refused("0 armatures selected")
    select(a)
    refused("1 armature selected")
    select(a, b)
    bpy.context.scene.camera = None
    refused("no scene camera")
    bpy.context.scene.camera = cam
    refused("character B: 'Nobody' is not an armature", armature_a=a.name, armature_b="Nobody")
    bare = bpy.data.objects.new("Bare", bpy.data.cameras.new("Bare"))
    bpy.context.scene.collection.objects.link(bare)
    refused("Bare has no keyframes", camera="Bare")
    bpy.context.scene.camera = bare
    refused("Bare has no keyframes")
    bpy.context.scene.camera = cam
    # A key where the camera looks away from both characters: the engine names the key's frame.
    sc = bpy.context.scene
    sc.frame_set(90)
    cam.rotation_euler.z += 3.14159
    cam.keyframe_insert("rotation_euler", frame=90)
    before = state()
    refused(r"key 1 \(frame 90\): the camera pose cannot frame A = `131_01` and B = `131_02` there: target A is behind")


def test_registered():
    assert bpy.ops.inbetween.camera_from_armatures.get_rna_type().bl_rna.identifier == (
        "INBETWEEN_OT_camera_from_armatures"
    )
