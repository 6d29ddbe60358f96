"""camera.generate with keys given as camera poses (world position, rotation, field of view): the
track sees both targets where each pose key does, at the key's frame; a pose that cannot frame them
is an error naming the key's frame."""

from __future__ import annotations

import numpy as np
import pytest

import inbetween
from inbetween import InbetweenError, camera

FOV, ASPECT = 40.0, 1.5


@pytest.fixture(scope="module")
def pair(data):
    cg = data / "mocap" / "cmu" / "cgspeed"
    if not (cg / "131_02.bvh").exists():
        pytest.skip(f"skipped: no data at {cg}")
    a = inbetween.read(cg / "131_01.bvh").crop(0, 640)
    b = inbetween.read(cg / "131_02.bvh").crop(0, 640)
    # B three metres along +X of where it was recorded (the takes share one spot).
    b = inbetween.Clip.from_arrays(
        b.joints, b.parents, b.offsets_cm, b.fps, b.rotations, b.translations + np.float32([300.0, 0.0, 0.0])
    )
    return a, b


def look_at(position, target):
    """(x, y, z, w) rotation of a camera at `position` looking at `target`, +Y up, no roll."""
    f = np.asarray(target, float) - np.asarray(position, float)
    f /= np.linalg.norm(f)
    right = np.cross(f, [0.0, 1.0, 0.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, f)
    m = np.stack([right, up, -f], axis=1)  # columns: camera axes in the world
    w = np.sqrt(max(1e-12, 1.0 + m[0, 0] + m[1, 1] + m[2, 2])) / 2.0
    return np.array([(m[2, 1] - m[1, 2]) / (4 * w), (m[0, 2] - m[2, 0]) / (4 * w), (m[1, 0] - m[0, 1]) / (4 * w), w])


def rotate(q, v):
    """v rotated by the unit quaternion q (x, y, z, w)."""
    u, w = np.asarray(q[:3], float), float(q[3])
    return v + 2.0 * np.cross(u, np.cross(u, v) + w * v)


def screen(position, rotation, point, fov_deg=FOV, aspect=ASPECT):
    """Normalised screen position ([-1, 1]², y up) of a world point through a pinhole lens."""
    q = rotate(np.asarray(rotation) * [-1, -1, -1, 1], np.asarray(point, float) - position)
    assert q[2] < 0, f"{point} is behind the camera"
    ty = np.tan(np.radians(fov_deg) / 2)
    return np.array([q[0] / (-q[2] * ty * aspect), q[1] / (-q[2] * ty)])


def poses_beside(targets, frames, side=4.5, up=1.2):
    """Hand-set poses: beside the pair at each frame, aimed a little off their midpoint."""
    out = []
    for i, f in enumerate(frames):
        a, b = targets[f]
        mid = (a + b) / 2
        across = np.cross(b - a, [0.0, 1.0, 0.0])
        across /= np.linalg.norm(across)
        pos = mid + across * (side + i) + np.array([0.0, up, 0.0])
        out.append((f, pos, look_at(pos, mid + np.array([0.15 * i, -0.1, 0.0]))))
    return out


def test_pose_keys_are_met_at_their_screen_positions(pair):
    # Where the targets are: a first track over the same scene, with Toric keys.
    toric = camera.generate([{"frame": 0, "camera": {"pa": [-0.3, 0], "pb": [0.3, 0], "theta": 1.6, "phi": 0.2}}],
                            characters=pair, progress=False)
    assert not toric.notes or not any("moved" in n for n in toric.notes), toric.notes
    targets = {int(f): t for f, t in zip(toric.frames, toric.targets_m)}
    frames = [10, 70, 150]
    poses = poses_beside(targets, frames)
    keys = [camera.pose_key(f, p, q, fov_deg=FOV) for f, p, q in poses]
    track = camera.generate(keys, characters=pair, style="orbit", aspect=ASPECT, progress=False)
    assert np.allclose(track.fov_y_rad, np.radians(FOV)) and track.aspect == ASPECT, "the keys' lens"
    worst = 0.0
    for f, p, q in poses:
        row = list(track.frames).index(f)
        np.testing.assert_allclose(track.targets_m[row], targets[f], atol=1e-9)
        for t in targets[f]:
            want = screen(p, q, t)
            got = screen(track.positions_m[row], track.rotations[row], t)
            worst = max(worst, float(np.abs(got - want).max()))
        np.testing.assert_allclose(track.positions_m[row], p, atol=1e-6)
    print(f"\npose keys at frames {frames}: targets on screen within {worst:.2e} of the poses'")
    assert worst < 1e-6
    # The same keys as plain dicts (position, rotation, fov_deg at the top level) make the same track.
    flat = [{"frame": f, "position": p, "rotation": q, "fov_deg": FOV} for f, p, q in poses]
    again = camera.generate(flat, characters=pair, style="orbit", aspect=ASPECT, progress=False)
    np.testing.assert_array_equal(again.positions_m, track.positions_m)


def test_bad_pose_keys_name_the_key_frame(pair):
    toric = camera.generate([{"frame": 0, "camera": {"pa": [-0.3, 0], "pb": [0.3, 0], "theta": 1.6, "phi": 0.2}}],
                            characters=pair, progress=False)
    targets = {int(f): t for f, t in zip(toric.frames, toric.targets_m)}
    (f0, p0, q0), (f1, p1, q1) = poses_beside(targets, [10, 90])
    a, b = targets[90]
    away = look_at(p1, p1 + (p1 - (a + b) / 2))  # turned round: both targets behind
    with pytest.raises(InbetweenError, match=r"key 1 \(frame 90\).*behind the camera"):
        camera.generate([camera.pose_key(f0, p0, q0), camera.pose_key(90, p1, away)], characters=pair, progress=False)
    with pytest.raises(InbetweenError, match=r"key 1 \(frame 90\).*field of view 60"):
        camera.generate(
            [camera.pose_key(f0, p0, q0, fov_deg=FOV), camera.pose_key(90, p1, q1, fov_deg=60.0)],
            characters=pair, progress=False,
        )
    with pytest.raises(InbetweenError, match="not both"):
        camera.generate([{"frame": 0, "position": p0, "rotation": q0, "camera": {"theta": 1}}], characters=pair)
    with pytest.raises(InbetweenError, match="needs `position`"):
        camera.generate([{"frame": 0, "camera": {"rotation": list(q0)}}], characters=pair, progress=False)
    # Two takes at one spot: the engine moves one aside, so a pose in the takes' world cannot hold.
    a = pair[0]
    near = inbetween.Clip.from_arrays(  # A's take 20 cm aside
        a.joints, a.parents, a.offsets_cm, a.fps, a.rotations, a.translations + np.float32([20.0, 0.0, 0.0])
    )
    with pytest.raises(InbetweenError, match="frame 10.*moved"):
        camera.generate([camera.pose_key(f0, p0, q0)], characters=(a, near), names=("A", "B"), progress=False)


def test_a_reference_camera_gives_the_style(pair):
    key = {"pa": [-0.3, 0.1], "pb": [0.3, 0.1], "theta": 1.6, "phi": 0.2}
    # 5 s at the takes' 120 fps (30 of the networks' steps; at least 10 are needed).
    keys = [{"frame": 0, "camera": key}, {"frame": 600, "camera": dict(key, theta=2.0)}]
    tracks = {s: camera.generate(keys, characters=pair, style=s, progress=False) for s in ("orbit", "relative")}
    ref = camera.generate(keys, characters=pair, reference=tracks["orbit"], progress=False)
    assert ref.style == "reference"
    row = list(ref.frames).index(600)
    np.testing.assert_allclose(ref.toric[row], [-0.3, 0.1, 0.3, 0.1, 2.0, 0.2], atol=1e-6)
    gap = {s: float(np.linalg.norm(ref.positions_m - t.positions_m, axis=1).mean()) for s, t in tracks.items()}
    print(f"\nreference = the orbit track: mean distance to the orbit camera {gap['orbit']:.3f} m, "
          f"to the relative camera {gap['relative']:.3f} m")
    # The reference's code is its own: it moves the camera unlike either named style's. (Which style
    # a 5 s keyed track reads as is the extractor's call: here nearer relative than orbit.)
    assert min(gap.values()) > 1e-3, gap
    with pytest.raises(InbetweenError, match="has 190 frames; at least 200"):
        camera.generate(keys, characters=pair, reference=(ref.positions_m[:190], ref.rotations[:190]), progress=False)
    turned = ref.rotations.copy()  # frame 30 looks away from both characters
    p, mid = ref.positions_m[30], ref.targets_m[30].mean(axis=0)
    turned[30] = look_at(p, 2 * p - mid)
    with pytest.raises(InbetweenError, match=r"reference: frame 30 \(0\.25 s\): the camera cannot frame both"):
        camera.generate(keys, characters=pair, reference=(ref.positions_m, turned), progress=False)
