"""face_inpaint on a mesh with the 52 ARKit shape keys animated by a procedural capture: only the
range changes, variants become actions, keyframe and text guidance, Live Link CSV both ways, bad
inputs."""

from __future__ import annotations

import numpy as np
import pytest

import bpy
from conftest import curves, keyframes


@pytest.fixture(autouse=True)
def face_engine():
    import inbetween

    if not hasattr(getattr(inbetween, "face", None), "edit"):
        pytest.skip("skipped: this inbetween package has no face.edit")


def face_mesh(seconds: float = 8.0, seed: int = 3, with_keys: bool = True):
    """A plane with the 52 ARKit shape keys (ARKit's own lower-case names) keyed every frame from
    the face engine's procedural capture at 25 fps."""
    import inbetween
    from inbetween_blender import anim

    clip, _ = inbetween.face.synth(seconds, seed=seed)
    sc = bpy.context.scene
    sc.render.fps, sc.render.fps_base = 25, 1.0
    bpy.ops.mesh.primitive_plane_add()
    ob = bpy.context.active_object
    if not with_keys:
        return ob, clip
    ob.shape_key_add(name="Basis")
    names = [n[0].lower() + n[1:] for n in clip.names]
    for n in names:
        ob.shape_key_add(name=n)
    keys = ob.data.shape_keys
    keys.animation_data_create()
    act = bpy.data.actions.new("capture")
    keys.animation_data.action = act
    w = clip.weights
    frames = np.arange(1, len(w) + 1, dtype=np.float32)
    for i, n in enumerate(names):
        fc = anim.new_fcurve(keys, act, f'key_blocks["{n}"].value', 0, None)
        fc.keyframe_points.add(len(frames))
        fc.keyframe_points.foreach_set("co", np.stack([frames, w[:, i]], 1).ravel())
        fc.keyframe_points.foreach_set("interpolation", np.ones(len(frames), dtype=np.int32))  # LINEAR
        fc.update()
    return ob, clip


def values(action, frames):
    return {fc.data_path: np.array([fc.evaluate(f) for f in frames]) for fc in curves(action)}


def test_unguided_inpaint_changes_only_the_range_and_makes_variants():
    ob, clip = face_mesh()
    keys = ob.data.shape_keys
    original = keys.animation_data.action
    before = keyframes(original)
    assert bpy.ops.inbetween.face_inpaint(frame_start=60, frame_end=110, variants=2, seed=5) == {"FINISHED"}
    v1 = keys.animation_data.action
    v2 = bpy.data.actions["capture.inpaint2"]
    assert v1.name == "capture.inpaint1" and v1 is not original
    assert all(np.array_equal(keyframes(original)[c], before[c]) for c in before), "the original is kept as it was"
    frames = np.arange(1, 201)
    inside = (frames >= 60) & (frames <= 110)
    orig_v, new_v, new_v2 = values(original, frames), values(v1, frames), values(v2, frames)
    changed = [p for p in orig_v if np.any(orig_v[p][inside] != new_v[p][inside])]
    outside_same = all(np.array_equal(orig_v[p][~inside], new_v[p][~inside]) for p in orig_v)
    diff2 = max(np.abs(new_v[p][inside] - new_v2[p][inside]).max() for p in new_v)
    print(f"\nface: {len(changed)} shapes changed inside 60-110, variants differ by up to {diff2:.3f}")
    assert outside_same, "frames outside the range keep their values"
    assert len(changed) >= 10
    assert diff2 > 1e-3, "two variants are two different fills"
    assert list(v1["inbetween_face"]["frames"]) == [60, 110]


def test_keyframes_inside_the_range_guide_the_fill():
    ob, clip = face_mesh()
    act = ob.data.shape_keys.animation_data.action
    jaw = next(fc for fc in curves(act) if fc.data_path == 'key_blocks["jawOpen"].value')
    # Keep only two keys inside 60-110 on the jaw; the target at 85 is wide open.
    for kp in reversed(list(jaw.keyframe_points)):
        if 60 < kp.co[0] < 110 and kp.co[0] not in (70, 85):
            jaw.keyframe_points.remove(kp)
    jaw.keyframe_points[[round(k.co[0]) for k in jaw.keyframe_points].index(85)].co[1] = 0.9
    jaw.update()
    assert bpy.ops.inbetween.face_inpaint(frame_start=60, frame_end=110, guide="KEYS") == {"FINISHED"}
    new = ob.data.shape_keys.animation_data.action
    fc = next(fc for fc in curves(new) if fc.data_path == 'key_blocks["jawOpen"].value')
    print(f"\njawOpen at the key (85): {fc.evaluate(85):.3f} (key 0.9)")
    assert abs(fc.evaluate(85) - 0.9) < 0.05
    assert new["inbetween_face"]["guidance"] == "keyframes"


def test_text_guides_the_mouth():
    ob, _ = face_mesh()
    r = bpy.ops.inbetween.face_inpaint(frame_start=30, frame_end=120, guide="TEXT", text="hello there, how are you")
    assert r == {"FINISHED"}
    assert ob.data.shape_keys.animation_data.action["inbetween_face"]["guidance"] == "visemes"


def test_live_link_csv_round_trip(tmp_path):
    ob, clip = face_mesh(seconds=4.0)
    path = tmp_path / "face.csv"
    assert bpy.ops.inbetween.export_live_link(filepath=str(path)) == {"FINISHED"}
    first = ob.data.shape_keys.animation_data.action
    assert bpy.ops.inbetween.import_live_link(filepath=str(path)) == {"FINISHED"}
    second = ob.data.shape_keys.animation_data.action
    assert second is not first
    frames = np.arange(1, 101)
    a, b = values(first, frames), values(second, frames)
    err = max(np.abs(a[p] - b[p]).max() for p in a)
    print(f"\nLive Link round trip: max |difference| {err:.2e}")
    assert err < 1e-3


@pytest.mark.parametrize(
    "setup, kwargs, words",
    [
        ("plain", {"frame_start": 10, "frame_end": 50}, "no shape keys"),
        ("face", {"frame_start": 50, "frame_end": 10}, "expected a range inside"),
        ("face", {"frame_start": 10, "frame_end": 5000}, "expected a range inside"),
        ("face", {"frame_start": 10, "frame_end": 50, "guide": "TAKE", "take": "nope"}, "no such action"),
        ("face", {"frame_start": 10, "frame_end": 50, "guide": "TEXT", "text": "  "}, "text to speak is empty"),
    ],
)
def test_bad_inputs_report_an_error_and_change_nothing(setup, kwargs, words):
    ob, _ = face_mesh(with_keys=setup == "face")
    acts = sorted(a.name for a in bpy.data.actions)
    with pytest.raises(RuntimeError) as e:
        bpy.ops.inbetween.face_inpaint(**kwargs)
    assert words in str(e.value) and "Traceback" not in str(e.value), str(e.value)
    assert sorted(a.name for a in bpy.data.actions) == acts


def test_a_noisy_take_in_another_action_guides_the_fill():
    ob, clip = face_mesh()
    keys = ob.data.shape_keys
    take = keys.animation_data.action.copy()
    take.name = "noisy take"
    rng = np.random.default_rng(7)
    for fc in curves(take):
        n = len(fc.keyframe_points)
        co = np.zeros(2 * n, dtype=np.float32)
        fc.keyframe_points.foreach_get("co", co)
        co[1::2] = np.clip(co[1::2] + rng.normal(0, 0.08, n), 0, 1)
        fc.keyframe_points.foreach_set("co", co)
        fc.update()
    r = bpy.ops.inbetween.face_inpaint(frame_start=60, frame_end=110, guide="TAKE", take="noisy take")
    assert r == {"FINISHED"}
    assert keys.animation_data.action["inbetween_face"]["guidance"] == "noisy"


TEXTGRID = """File type = "ooTextFile"
Object class = "TextGrid"

xmin = 0
xmax = 8
tiers? <exists>
size = 1
item []:
    item [1]:
        class = "IntervalTier"
        name = "phones"
        xmin = 0
        xmax = 8
        intervals: size = 6
        intervals [1]:
            xmin = 0
            xmax = 2.4
            text = ""
        intervals [2]:
            xmin = 2.4
            xmax = 2.6
            text = "HH"
        intervals [3]:
            xmin = 2.6
            xmax = 2.9
            text = "AH"
        intervals [4]:
            xmin = 2.9
            xmax = 3.1
            text = "L"
        intervals [5]:
            xmin = 3.1
            xmax = 3.5
            text = "OW"
        intervals [6]:
            xmin = 3.5
            xmax = 8
            text = ""
"""


def test_a_textgrid_guides_the_mouth(tmp_path):
    ob, _ = face_mesh()
    path = tmp_path / "hello.TextGrid"
    path.write_text(TEXTGRID)
    r = bpy.ops.inbetween.face_inpaint(frame_start=55, frame_end=95, guide="VISEMES", visemes=str(path))
    assert r == {"FINISHED"}
    assert ob.data.shape_keys.animation_data.action["inbetween_face"]["guidance"] == "visemes"
