"""camera and script from Python, on real takes and a story."""

from __future__ import annotations

import json

import numpy as np
import pytest

import inbetween
from inbetween import InbetweenError, camera, script

KEY = {"pa": [-0.3, 0.1], "pb": [0.3, 0.1], "theta": 1.6, "phi": 0.2}


@pytest.fixture(scope="module")
def pair(data):
    cg = data / "mocap" / "cmu" / "cgspeed"
    if not (cg / "131_02.bvh").exists():
        pytest.skip(f"skipped: no data at {cg}")
    return inbetween.read(cg / "131_01.bvh").crop(0, 300), inbetween.read(cg / "131_02.bvh").crop(0, 300)


def test_camera_track_through_keys(pair, tmp_path):
    # 2 s apart at the takes' 120 fps (12 of the networks' 1/6 s steps).
    keys = [{"frame": 0, "camera": KEY}, {"frame": 240, "camera": dict(KEY, theta=2.2, phi=0.35)}]
    track = camera.generate(keys, characters=pair, style="orbit", gltf=tmp_path / "cam.gltf", progress=False)
    t = len(track.frames)
    assert t > 240 and track.positions_m.shape == (t, 3) and track.rotations.shape == (t, 4)
    assert track.toric.shape == (t, 6) and track.fov_y_rad.shape == (t,) and track.targets.shape == (t, 2)
    np.testing.assert_allclose(np.linalg.norm(track.rotations, axis=1), 1.0, atol=1e-9)
    # Exact keys: the track passes through each key (the correction's residual is rounding).
    row = list(track.frames).index(240)
    np.testing.assert_allclose(track.toric[row], [-0.3, 0.1, 0.3, 0.1, 2.2, 0.35], atol=1e-6)
    assert track.max_corrected_residual < 1e-6 and track.style == "orbit"
    assert json.loads((tmp_path / "cam.gltf").read_text())["asset"]["version"] == "2.0"
    other = camera.generate(keys, characters=pair, style="direct", progress=False)
    assert np.abs(other.positions_m - track.positions_m).max() > 0.05, "styles should move the camera differently"


def test_camera_bad_requests(pair):
    with pytest.raises(InbetweenError, match="unknown style `dolly`"):
        camera.generate([{"frame": 0, "camera": KEY}], characters=pair, style="dolly")
    with pytest.raises(InbetweenError, match="key 1.*frame 5000"):
        camera.generate([{"frame": 0, "camera": KEY}, {"frame": 5000, "camera": KEY}], characters=pair)
    with pytest.raises(InbetweenError, match="characters=.*scene="):
        camera.generate([{"frame": 0, "camera": KEY}])
    with pytest.raises(InbetweenError, match="keys"):
        camera.generate([{"frame": 0}], characters=pair)


def test_script_story_to_clips_and_gltf(tmp_path):
    story = script.run("A man walks to the chair and sits on it.", out_dir=tmp_path, progress=False)
    doc = json.loads(story.gltf)
    assert doc["asset"]["version"] == "2.0" and doc.get("animations")
    assert story.characters, story
    (name, clip), = story.characters.items()
    assert clip.num_frames == story.frames and clip.rotations.shape[1] == len(clip.joints)
    # The character moves: its root travels more than half a metre.
    root = clip.positions_cm()[:, 0, :]
    assert np.linalg.norm(root[-1] - root[0]) > 50.0 or np.ptp(root, axis=0).max() > 50.0
    assert any(o for o in json.dumps(story.scene).lower().split('"') if "chair" in o)
    assert story.files and all(str(tmp_path) in f for f in story.files)
    with pytest.raises(InbetweenError, match="empty"):
        script.run("   ")
