"""face.edit and face.synth from Python, on a real Live Link capture and a procedural one; Live Link
files read and written back."""

from __future__ import annotations

import numpy as np
import pytest

import inbetween
from inbetween import FaceClip, InbetweenError, ShapeError, face


@pytest.fixture(scope="module")
def happy(livelink_csv) -> FaceClip:
    return inbetween.read(livelink_csv)


@pytest.fixture(scope="module")
def synthetic():
    return face.synth(seconds=8.0, seed=3)


def _inside(clip: FaceClip, spans) -> np.ndarray:
    """Rows whose time lies inside a span (seconds from the first frame, ends included)."""
    t = clip.times - clip.times[0]
    return np.any([(t >= a) & (t <= b) for a, b in spans], axis=0)


def test_variants_differ_the_seed_repeats_and_only_the_spans_change(happy):
    spans = [(4.0, 6.5)]
    made = face.edit(happy, spans, variants=3, seed=7, progress=False)
    assert len(made) == 3 and [r.seed for r in made.reports] == [7, 8, 9]
    assert all(r.guidance == "unguided" and r.method == "retrieval" for r in made.reports)
    inside = _inside(happy, spans)
    source = happy.values
    for clip, report in made:
        assert clip.num_frames == happy.num_frames and clip.channel_names == happy.channel_names
        np.testing.assert_array_equal(clip.times, happy.times)
        # Rows outside the span keep the capture bit for bit; inside, the face moves.
        np.testing.assert_array_equal(clip.values[~inside], source[~inside])
        assert np.abs(clip.weights[inside] - happy.weights[inside]).max() > 0.05
        a, b = report.changed_rows
        assert inside[a] and inside[b - 1], report.changed_rows
        assert report.before.shape == report.after.shape == report.mask.shape == (report.before.shape[0], 52)
        assert report.mask.any() and 0.0 < report.masked_mse < 1.0
    w = [c.weights[inside] for c in made.clips]
    for i in range(3):
        for j in range(i + 1, 3):
            assert np.abs(w[i] - w[j]).mean() > 1e-3, f"variants {i + 1} and {j + 1} are the same fill"
    d = [r.difference_from_first for r in made.reports]
    assert d[0] is None and all(x > 1e-3 for x in d[1:]), d
    again = face.edit(happy, spans, variants=2, seed=7, progress=False)
    for k in range(2):
        np.testing.assert_array_equal(again.clips[k].values, made.clips[k].values)
    # Variant k has seed S + k - 1: seed 8 alone is the second variant of seed 7 (the same number of variants).
    shifted = face.edit(happy, spans, variants=3, seed=8, progress=False)
    np.testing.assert_array_equal(shifted.clips[0].values, made.clips[1].values)
    assert "variant 2 (seed 8): retrieval, unguided" in made.reports[1].text


def test_keys_are_hit_on_a_real_capture_and_the_file_round_trips(happy, tmp_path):
    keys = [{"time_s": 5.0, "shapes": {"JawOpen": 0.8, "MouthSmileLeft": 0.1}}]
    (clip, report), = face.edit(happy, "4s..6.5s", keys=keys, progress=False)
    assert report.guidance == "keyframes" and report.method.startswith("network")
    assert report.key_frames == [125]
    jaw, smile = happy.names.index("JawOpen"), happy.names.index("MouthSmileLeft")
    # Hit exactly at the model rate; the capture's nearest row (its own timecode, within 1/120 s of
    # 5 s) lies on the curve through the key.
    assert report.after[125, jaw] == np.float32(0.8) and report.after[125, smile] == np.float32(0.1)
    row = int(np.argmin(np.abs(happy.times - happy.times[0] - 5.0)))
    assert abs(happy.times[row] - happy.times[0] - 5.0) < 1 / 120
    assert abs(clip.weights[row, jaw] - 0.8) < 0.01 and abs(clip.weights[row, smile] - 0.1) < 0.01
    # The edit keeps the capture's layout: written back as Live Link Face CSV, read again the same.
    out = tmp_path / "edited.csv"
    clip.write(out)
    assert out.read_text().startswith("Timecode,BlendshapeCount,")
    back = inbetween.read(out)
    np.testing.assert_allclose(back.values, clip.values, atol=1e-4)
    np.testing.assert_allclose(back.times, clip.times, atol=1e-4)


def test_live_link_round_trip_keeps_every_column(happy, tmp_path):
    assert len(happy.channel_names) >= 61 and happy.channel_names[52] == "HeadYaw"
    first = tmp_path / "first.csv"
    happy.write(first)
    back = inbetween.read(first)
    assert back.channel_names == happy.channel_names and back.num_frames == happy.num_frames
    np.testing.assert_allclose(back.times, happy.times, atol=1e-4)  # timecodes at 1/60000 s
    np.testing.assert_allclose(back.values, happy.values, atol=1e-4)
    # Written again, the file is the same bytes: the writer's rounding is a fixed point.
    second = tmp_path / "second.csv"
    back.write(second)
    assert second.read_bytes() == first.read_bytes()
    # A .json path gets the curve format; live_link=False a curve CSV; both read back the same values.
    for name, flag in (("curves.json", None), ("curves.csv", False)):
        p = tmp_path / name
        happy.write(p, live_link=flag)
        assert not p.read_text().startswith("Timecode")
        np.testing.assert_allclose(inbetween.read(p).values, happy.values, atol=1e-4)


def test_procedural_capture_text_and_visemes_drive_the_mouth(synthetic):
    clip, phonemes = synthetic
    assert clip.fps == 25.0 and clip.num_frames == 200 and phonemes and len(phonemes[0]) == 3
    again, _ = face.synth(seconds=8.0, seed=3)
    np.testing.assert_array_equal(again.values, clip.values)
    spans = [(2.0, 4.0)]
    (said, report), = face.edit(clip, spans, text="our little brother", progress=False)
    assert report.guidance == "visemes" and any("eyes and brows are filled unguided" in n for n in report.notes)
    inside = _inside(clip, spans)
    np.testing.assert_array_equal(said.values[~inside], clip.values[~inside])
    jaw = clip.names.index("JawOpen")
    assert np.ptp(said.weights[inside, jaw]) > 0.05, "the jaw should move while the text is spoken"
    # The procedural clip's own phonemes as the viseme guide, only the mouth and jaw regenerated.
    timed = [p for p in phonemes if p[0] < 4.0 and p[1] > 2.0]
    (mouth, report), = face.edit(clip, spans, visemes=timed, groups=["mouth", "jaw"], progress=False)
    blink = clip.names.index("EyeBlinkLeft")
    np.testing.assert_array_equal(mouth.weights[:, blink], clip.weights[:, blink])
    assert set(report.changed_shapes) <= {n for n in clip.names if n.startswith(("Mouth", "Jaw"))}
    # The baselines repeat whatever the seed; a noisy guide gives a fill near the guide.
    lin = face.edit(clip, spans, method="linear", variants=2, progress=False)
    np.testing.assert_array_equal(lin.clips[0].values, lin.clips[1].values)
    noisy = FaceClip.from_arrays(np.clip(clip.weights + 0.02, 0.0, 1.0), clip.fps)
    (cleaned, report), = face.edit(clip, spans, guide=noisy, progress=False)
    assert report.guidance == "noisy"
    assert np.abs(cleaned.weights[inside] - clip.weights[inside]).mean() < 0.1


def test_bad_spans_and_arguments_raise_clear_errors(synthetic):
    clip, _ = synthetic
    cases = [
        (dict(spans=[(7.5, 9.0)]), InbetweenError, "runs past the clip's end"),
        (dict(spans=[(9.0, 9.5)]), InbetweenError, "starts after the clip ends"),
        (dict(spans=[(3.0, 2.0)]), InbetweenError, "expected 0 ≤ start < end"),
        (dict(spans=[(float("nan"), 2.0)]), InbetweenError, "expected 0 ≤ start < end"),
        (dict(spans=[]), InbetweenError, "no span to edit"),
        (dict(spans=[(1.0,)]), ShapeError, r"spans\[0\]: \(1.0,\); expected \(start_s, end_s\)"),
        (dict(spans=np.zeros((2, 3))), ShapeError, r"shape \[2, 3\]; expected \[S, 2\]"),
        (dict(spans="4s..x"), InbetweenError, "4s..x"),
        (dict(spans=[(1.0, 2.0)], keys=[{"time_s": 5.0, "shapes": {"JawOpen": 0.5}}]), InbetweenError,
         "key 0 at 5.000 s lies outside every edited span"),
        (dict(spans=[(1.0, 2.0)], keys=[{"time_s": 1.5, "shapes": {"Jaw": 0.5}}]), InbetweenError, "Jaw"),
        (dict(spans=[(1.0, 2.0)], keys=[{"time_s": 1.5, "shapes": {"JawOpen": 1.5}}]), InbetweenError,
         r"outside \[0, 1\]"),
        (dict(spans=[(1.0, 2.0)], keys=[{"time_s": 1.5, "shapes": {}}], text="hello"), InbetweenError,
         "keys and text given together"),
        (dict(spans=[(1.0, 2.0)], method="bezier"), InbetweenError, "auto, network, retrieval, linear, cubic"),
        (dict(spans=[(1.0, 2.0)], groups="nose"), InbetweenError, "unknown blendshape group 'nose'"),
        (dict(spans=[(1.0, 2.0)], variants=0), InbetweenError, "at least 1"),
        (dict(spans=[(1.0, 2.0)], visemes=[(1.0, 1.5, "QQ")]), InbetweenError, "QQ"),
        (dict(spans=[(1.0, 2.0)], library=[clip], keys=[{"time_s": 1.5, "shapes": {"JawOpen": 0.5}}]),
         InbetweenError, "library is read only by method retrieval"),
        (dict(spans=[(1.0, 2.0)], max_rows=10), InbetweenError, r"200 rows, more than the limit of 10 rows \(max_rows\)"),
    ]
    for kwargs, kind, pattern in cases:
        with pytest.raises(kind, match=pattern):
            face.edit(clip, progress=False, **kwargs)
    with pytest.raises(InbetweenError, match="expected a FaceClip"):
        face.edit(inbetween.Clip.from_arrays(["hips"], [-1], np.zeros((1, 3)), 30.0, np.tile([0, 0, 0, 1.0], (3, 1, 1)),
                                             np.zeros((3, 3))), [(0.0, 0.05)])
    with pytest.raises(InbetweenError, match="expected a positive duration"):
        face.synth(seconds=0.0)
