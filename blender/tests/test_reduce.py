"""reduce_keys on CMU takes imported with Blender's BVH importer: the bound measured in Blender on
every frame, frame ranges, selected bones, quaternion and Euler bones, key counts, bad inputs,
cancelling."""

from __future__ import annotations

import math

import numpy as np
import pytest

import bpy
from conftest import curves, data_dir, import_bvh, keyframes, need, world_points

BOUND_SLACK = 1e-3  # cm: float32 curve storage


@pytest.fixture
def take():
    return need(data_dir() / "mocap" / "cmu" / "cgspeed" / "131_01.bvh")


def frames_of(action):
    lo, hi = (int(round(v)) for v in action.frame_range)
    return np.arange(lo, hi + 1)


def measure(ob, original, reduced, frames, tails=True):
    ob.animation_data.action = original
    before = world_points(ob, frames, tails)
    ob.animation_data.action = reduced
    after = world_points(ob, frames, tails)
    return np.linalg.norm(after - before, axis=-1)  # (T, P) cm


def test_cmu_take_at_1cm_is_within_the_bound_on_every_frame(take):
    ob = import_bvh(take)
    original = ob.animation_data.action
    keys_before = keyframes(original)
    assert bpy.ops.inbetween.reduce_keys(max_error_cm=1.0) == {"FINISHED"}
    reduced = ob.animation_data.action
    assert reduced is not original and reduced.name == original.name + ".reduced"
    assert original.use_fake_user, "the original action is kept"
    # The original is untouched, key for key.
    after = keyframes(original)
    assert after.keys() == keys_before.keys()
    assert all(np.array_equal(after[c], keys_before[c]) for c in after)
    frames = frames_of(original)
    err = measure(ob, original, reduced, frames)
    r = reduced["inbetween_reduce"]
    print(
        f"\n131_01 at 1 cm: {r['key_frames_before']} -> {r['key_frames_after']} key frames, "
        f"measured here max {err.max():.4f} cm mean {err.mean():.4f} cm (add-on: {r['max_error_cm']:.4f}), "
        f"engine's keys {r['engine_keys']}, rounds {r['rounds']}"
    )
    assert err.max() <= 1.0 + BOUND_SLACK, f"max {err.max():.4f} cm at frame {frames[err.max(axis=1).argmax()]}"
    assert abs(err.max() - r["max_error_cm"]) < 1e-3, "the report states what Blender evaluates"
    assert r["key_frames_after"] < r["key_frames_before"] / 4
    # Every reduced curve is Bezier with FREE handles, keys on the same frames across bones.
    key_sets = set()
    for fc in curves(reduced):
        if "rotation" in fc.data_path or fc.data_path.endswith("location"):
            kp = fc.keyframe_points
            key_sets.add(tuple(round(k.co[0]) for k in kp))
            assert all(k.interpolation == "BEZIER" and k.handle_left_type == "FREE" for k in list(kp)[:-1])
    assert len(key_sets) == 1, "keys on the same frames across bones"


@pytest.mark.parametrize("rotation", ["quaternion", "keep"])
def test_key_count_is_near_the_librarys_for_the_same_bound(take, rotation):
    import inbetween

    ob = import_bvh(take)
    # The library bounds joints (bone heads); so does this run.
    r = bpy.ops.inbetween.reduce_keys(max_error_cm=1.0, include_tails=False, rotation=rotation.upper())
    assert r == {"FINISHED"}
    r = ob.animation_data.action["inbetween_reduce"]
    # The library's own on the same file and bound: for quaternion curves its quaternion_bezier
    # keys; for Euler curves its euler_bezier keys on the BVH's own Euler channels (Blender's
    # curves hold the Euler angles of the pose relative to each bone's rest frame: other angles of
    # the same rotations, so the counts need not agree exactly). Both printed.
    clip = inbetween.read(str(take))
    lib = {c: inbetween.mocap.select_keys(clip, 1.0, curve=c) for c in ("quaternion_bezier", "euler_bezier")}
    own = lib["euler_bezier" if rotation == "keep" else "quaternion_bezier"]
    ratio = r["key_frames_after"] / len(own)
    print(
        f"\nkeys at 1 cm ({rotation}): add-on {r['key_frames_after']} (engine {r['engine_keys']}, "
        f"{r['key_frames_after'] - r['engine_keys']} added in {r['rounds']} rounds; max {r['max_error_cm']:.3f} cm in "
        f"Blender); library euler_bezier {len(lib['euler_bezier'])} (max "
        f"{lib['euler_bezier'].reconstruction.max_error_cm:.3f} cm), quaternion_bezier "
        f"{len(lib['quaternion_bezier'])} (max {lib['quaternion_bezier'].reconstruction.max_error_cm:.3f} cm): "
        f"ratio to the library's own {ratio:.3f}"
    )
    assert r["max_error_cm"] <= 1.0 + BOUND_SLACK
    assert abs(ratio - 1.0) <= 0.10, f"add-on {r['key_frames_after']} keys vs library {len(own)}"
    if rotation == "quaternion":
        assert r["switched"] == 31
        assert all(pb.rotation_mode == "QUATERNION" for pb in ob.pose.bones)
    else:
        # Euler curves chosen for Blender's Euler curves: the engine's keys hold the bound there
        # (the refinement is a safety net for float32 storage).
        assert r["key_frames_after"] - r["engine_keys"] <= 0.02 * r["engine_keys"], r["history"]
        assert r["switched"] == 0 and not any(pb.rotation_mode == "QUATERNION" for pb in ob.pose.bones)


def test_frame_range_leaves_the_rest_untouched(take):
    ob = import_bvh(take)
    original = ob.animation_data.action
    keys_before = keyframes(original)
    assert bpy.ops.inbetween.reduce_keys(max_error_cm=1.0, frame_start=300, frame_end=600) == {"FINISHED"}
    reduced = ob.animation_data.action
    frames = frames_of(original)
    err = measure(ob, original, reduced, frames)
    inside = (frames >= 300) & (frames <= 600)
    assert err[~inside].max() == 0.0, "frames outside the range are exactly the original"
    assert err[inside].max() <= 1.0 + BOUND_SLACK
    # Keys outside keep their frames and values, and each curve evaluates as before there (the
    # importer's stale auto handles on its LINEAR keys may be recomputed; they shape nothing).
    orig_curves = {(fc.data_path, fc.array_index): fc for fc in curves(original)}
    outside = np.concatenate([np.arange(1, 300, 0.25), np.arange(600.25, 994.01, 0.25)])
    for fc in curves(reduced):
        c = (fc.data_path, fc.array_index)
        new_keys, ref = keyframes(reduced)[c], keys_before[c]
        out_new = new_keys[(new_keys[:, 0] < 300) | (new_keys[:, 0] > 600), :2]
        out_old = ref[(ref[:, 0] < 300) | (ref[:, 0] > 600), :2]
        assert np.array_equal(out_new, out_old), f"{c}: keys outside 300-600 changed"
        a = np.array([fc.evaluate(f) for f in outside])
        b = np.array([orig_curves[c].evaluate(f) for f in outside])
        assert np.array_equal(a, b), f"{c}: the curve changed outside 300-600"
    r = reduced["inbetween_reduce"]
    assert tuple(r["frames"]) == (300, 600)
    assert r["key_frames_after"] < 301 / 4


def test_selected_bones_only(take):
    ob = import_bvh(take)
    original = ob.animation_data.action
    keys_before = keyframes(original)
    picked = {"LeftHip", "LeftKnee", "LeftAnkle"}
    from inbetween_blender import anim

    for pb in ob.pose.bones:
        anim.select_bone(pb, pb.name in picked)
    assert bpy.ops.inbetween.reduce_keys(max_error_cm=1.0, selected_only=True) == {"FINISHED"}
    reduced = ob.animation_data.action
    changed = {c for c, k in keyframes(reduced).items() if not np.array_equal(k, keys_before[c])}
    bones = {c[0].split('"')[1] for c in changed}
    assert bones == picked
    err = measure(ob, original, reduced, frames_of(original))
    assert err.max() <= 1.0 + BOUND_SLACK


def test_quaternion_bones_get_quaternion_curves(take):
    ob = import_bvh(take, rotate_mode="QUATERNION")
    original = ob.animation_data.action
    assert bpy.ops.inbetween.reduce_keys(max_error_cm=1.0) == {"FINISHED"}
    reduced = ob.animation_data.action
    assert all(pb.rotation_mode == "QUATERNION" for pb in ob.pose.bones)
    assert any(fc.data_path.endswith("rotation_quaternion") for fc in curves(reduced))
    err = measure(ob, original, reduced, frames_of(original))
    r = reduced["inbetween_reduce"]
    print(f"\nquaternion bones: {r['key_frames_after']} keys, max {err.max():.4f} cm, rounds {r['rounds']}")
    assert err.max() <= 1.0 + BOUND_SLACK


def test_a_key_count_instead_of_a_bound(take):
    ob = import_bvh(take)
    assert bpy.ops.inbetween.reduce_keys(keys=25, method="UNIFORM") == {"FINISHED"}
    r = ob.animation_data.action["inbetween_reduce"]
    assert r["key_frames_after"] == 25 and r["rounds"] == 1
    assert math.isfinite(r["max_error_cm"]) and r["max_error_cm"] > 0


def test_bound_in_degrees_too(take):
    ob = import_bvh(take)
    assert bpy.ops.inbetween.reduce_keys(max_error_cm=2.0, max_error_deg=2.0) == {"FINISHED"}
    r = ob.animation_data.action["inbetween_reduce"]
    assert r["max_error_deg"] <= 2.0 and r["max_error_cm"] <= 2.0 + BOUND_SLACK


def test_in_place_replaces_the_action(take):
    ob = import_bvh(take)
    name = ob.animation_data.action.name
    assert bpy.ops.inbetween.reduce_keys(max_error_cm=1.0, new_action=False) == {"FINISHED"}
    assert [a.name for a in bpy.data.actions] == [name]
    assert ob.animation_data.action["inbetween_reduce"]["key_frames_after"] < 200


def _state():
    acts = {a.name: keyframes(a) for a in bpy.data.actions}
    assigned = {o.name: o.animation_data.action.name for o in bpy.data.objects if o.animation_data and o.animation_data.action}
    return acts, assigned


def _same(a, b):
    return a[1] == b[1] and a[0].keys() == b[0].keys() and all(
        x.keys() == b[0][n].keys() and all(np.array_equal(x[c], b[0][n][c]) for c in x) for n, x in a[0].items()
    )


@pytest.mark.parametrize(
    "setup, kwargs, words",
    [
        ("none", {}, "no armature selected"),
        ("mesh", {}, "no armature selected"),
        ("bare", {}, "no action"),
        ("take", {"max_error_cm": 0.0}, "max error 0.0 cm"),
        ("take", {"max_error_cm": float("nan")}, "max error nan cm"),
        ("take", {"keys": 1}, "keys 1"),
        ("take", {"frame_start": 500, "frame_end": 400}, "frame range 500–400"),
        ("take", {"frame_start": 900, "frame_end": 5000}, "inside the action's range"),
        ("take", {"method": "GREEDY"}, "takes a key count"),
        ("take", {"keys": 10, "method": "ERROR_BOUNDED"}, "takes the bound in cm"),
        ("take", {"selected_only": True}, "no bones selected"),
    ],
)
def test_bad_inputs_report_an_error_and_change_nothing(take, setup, kwargs, words):
    if setup == "take":
        ob = import_bvh(take)
        from inbetween_blender import anim

        for pb in ob.pose.bones:
            anim.select_bone(pb, False)
    elif setup == "mesh":
        bpy.ops.mesh.primitive_cube_add()
    elif setup == "bare":
        bpy.ops.object.armature_add()
    else:
        bpy.context.view_layer.objects.active = None
    before = _state()
    with pytest.raises(RuntimeError) as e:
        bpy.ops.inbetween.reduce_keys(**kwargs)
    msg = str(e.value)
    assert words in msg, msg
    assert "Traceback" not in msg, msg
    assert _same(_state(), before)


def test_cancel_mid_selection_changes_nothing(take):
    from inbetween_blender.reduce import Cancelled, ReduceJob, ReduceOptions

    ob = import_bvh(take)
    before = _state()
    job = ReduceJob(bpy.context, ob, ReduceOptions(max_error_cm=0.2))
    steps = job.steps()
    for fraction, words in steps:
        if words.startswith("choosing keys"):
            job.cancel.set()
            break
    with pytest.raises(Cancelled):
        for _ in steps:
            pass
    job.rollback()
    assert _same(_state(), before)
