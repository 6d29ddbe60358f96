"""Clips and face clips: reading, arrays, writing, previews, and bad input."""

from __future__ import annotations

import numpy as np
import pytest

import inbetween
from inbetween import Clip, FaceClip, InbetweenError, ShapeError


def test_read_bvh_gives_arrays_of_the_documented_shapes(cmu_bvh):
    clip = inbetween.read(cmu_bvh)
    assert isinstance(clip, Clip)
    t, j = clip.num_frames, len(clip.joints)
    assert t == 994 and j == len(clip.parents) and clip.parents[0] == -1
    assert clip.fps == pytest.approx(120.0, rel=1e-3)
    rot, tr, off = clip.rotations, clip.translations, clip.offsets_cm
    assert rot.shape == (t, j, 4) and rot.dtype == np.float32
    assert tr.shape == (t, 3) and tr.dtype == np.float32
    assert off.shape == (j, 3) and off.dtype == np.float32
    np.testing.assert_allclose(np.linalg.norm(rot, axis=-1), 1.0, atol=1e-5)
    # A CMU take is an adult: the rest pose's height in cm, whatever the file's unit.
    height = np.ptp(clip.positions_cm()[0, :, 1])
    assert 100.0 < height < 220.0, height
    assert "131_01.bvh" in repr(clip)


def test_outputs_are_new_arrays(cmu_bvh):
    clip = inbetween.read(cmu_bvh)
    a = clip.rotations
    a[:] = 0.0
    assert np.abs(np.linalg.norm(clip.rotations, axis=-1) - 1.0).max() < 1e-5


def test_asf_amc_reads_like_bvh(cmu_amc):
    clip = inbetween.read(cmu_amc)
    assert clip.num_frames > 100 and clip.rotations.shape[1] == len(clip.joints)


def test_from_arrays_rebuilds_the_same_positions(cmu_bvh):
    clip = inbetween.read(cmu_bvh).crop(0, 120)
    rot, tr = clip.rotations, clip.translations
    rot_before = rot.copy()
    again = Clip.from_arrays(clip.joints, clip.parents, clip.offsets_cm, clip.fps, rot, tr)
    np.testing.assert_array_equal(rot, rot_before)  # inputs are never modified
    assert again.num_frames == 120
    err = np.linalg.norm(again.positions_cm() - clip.positions_cm(), axis=-1).max()
    assert err < 0.01, f"{err} cm"


def test_write_then_read_is_the_same_clip(cmu_bvh, tmp_path):
    clip = inbetween.read(cmu_bvh).crop(10, 70)
    out = tmp_path / "crop.bvh"
    clip.write(out)
    back = inbetween.read(out)
    assert back.joints == clip.joints and back.num_frames == 60
    np.testing.assert_allclose(back.positions_cm(), clip.positions_cm(), atol=1e-3)


def test_preview_gif_png_and_notebook_picture(cmu_bvh, tmp_path):
    clip = inbetween.read(cmu_bvh).crop(0, 60)
    calls = []
    gif = clip.preview(tmp_path / "walk.gif", progress=lambda d, t: calls.append((d, t)))
    assert gif.read_bytes()[:6] == b"GIF89a"
    png = clip.preview(tmp_path / "walk.png", frame=30, compare=clip)
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert clip._repr_png_()[:8] == b"\x89PNG\r\n\x1a\n"
    assert calls and calls[-1][0] == calls[-1][1], calls[-3:]
    with pytest.raises(InbetweenError, match=r"\.gif \(animation\) or \.png"):
        clip.preview(tmp_path / "walk.mp3")


def test_face_clip_from_live_link(livelink_csv, tmp_path):
    face = inbetween.read(livelink_csv)
    assert isinstance(face, FaceClip)
    w = face.weights
    assert w.shape == (face.num_frames, 52) and w.dtype == np.float32 and len(face.names) == 52
    assert face.names[0] == "EyeBlinkLeft" and 0.0 <= w.min() and w.max() <= 1.0
    out = tmp_path / "face.csv"
    face.write(out)
    np.testing.assert_allclose(inbetween.read(out).weights, w, atol=1e-4)
    again = FaceClip.from_arrays(w[:50], 60.0)
    assert again.num_frames == 50
    assert face._repr_png_()[:4] == b"\x89PNG"
    short = FaceClip.from_arrays(w[:90], face.fps)
    gif = short.preview(tmp_path / "face.gif", compare=short)
    assert gif.read_bytes()[:6] == b"GIF89a"


def test_bad_files_name_the_file(tmp_path):
    bad = tmp_path / "garbage.bvh"
    bad.write_bytes(b"HIERARCHY\nROOT hips {\n OFFSET 0 zero 0\n")
    with pytest.raises(InbetweenError, match="garbage.bvh"):
        inbetween.read(bad)
    with pytest.raises(InbetweenError, match="missing.bvh"):
        inbetween.read(tmp_path / "missing.bvh")
    with pytest.raises(InbetweenError, match="unit"):
        inbetween.read(bad, unit="furlong")
    csv = tmp_path / "face.csv"
    csv.write_text("Timecode,BlendShapeCount,EyeBlinkLeft\n00:00:00:00.000,1,zero\n")
    with pytest.raises(InbetweenError, match="face.csv"):
        inbetween.read(csv)


def test_shapes_and_values_are_checked():
    joints, parents = ["hips", "spine"], [-1, 0]
    off = np.zeros((2, 3), np.float32)
    rot = np.tile(np.array([0, 0, 0, 1], np.float32), (5, 2, 1))
    tr = np.zeros((5, 3), np.float32)
    Clip.from_arrays(joints, parents, off, 30.0, rot, tr)
    with pytest.raises(ShapeError, match=r"expected \[T, J, 4\]"):
        Clip.from_arrays(joints, parents, off, 30.0, rot[:, :, :3].copy(), tr)
    with pytest.raises(ShapeError, match=r"expected \[T, 3\]"):
        Clip.from_arrays(joints, parents, off, 30.0, rot, tr[:4])
    # Any real dtype is taken (float64, nested lists); strings are not.
    Clip.from_arrays(joints, parents, off.tolist(), 30.0, rot.astype(np.float64), tr)
    with pytest.raises(ShapeError, match=r"dtype <U1; expected float32 \[T, 3\]"):
        Clip.from_arrays(joints, parents, off, 30.0, rot, np.full((5, 3), "x"))
    nan = rot.copy()
    nan[2, 1, 0] = np.nan
    with pytest.raises(InbetweenError, match="frame 2"):
        Clip.from_arrays(joints, parents, off, 30.0, nan, tr)
    with pytest.raises(InbetweenError, match="at least one"):
        Clip.from_arrays(joints, parents, off, 30.0, rot[:0], tr[:0])
    with pytest.raises(InbetweenError, match="earlier joint"):
        Clip.from_arrays(joints, [-1, 5], off, 30.0, rot, tr)
    with pytest.raises(ShapeError, match=r"\[T, 52\]"):
        FaceClip.from_arrays(np.zeros((4, 51), np.float32), 30.0)
