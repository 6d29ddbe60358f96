"""mocap keyframes and the .ibk codec, on a CMU take; cancellation and progress of long jobs."""

from __future__ import annotations

import _thread
import subprocess
import threading
import time

import numpy as np
import pytest

import inbetween
from inbetween import InbetweenError, ShapeError, ibk, mocap


@pytest.fixture(scope="module")
def take(cmu_bvh):
    return inbetween.read(cmu_bvh).crop(0, 480)


def test_keys_to_one_cm_measured_in_python(take):
    keys = mocap.select_keys(take, max_error_cm=1.0)
    n, j = len(keys), len(take.joints)
    assert 2 < n < take.num_frames // 4, n
    assert keys.frames[0] == 0 and keys.frames[-1] == take.num_frames - 1
    assert keys.rotations.shape == (n, j, 4) and keys.angular_velocities.shape == (n, j, 3)
    assert keys.translations_cm.shape == (n, j, 3) and keys.velocities_cm_s.shape == (n, j, 3)
    rec = mocap.reconstruct(take, keys)
    # Joint positions of both clips, by their own forward kinematics, measured here.
    err = np.linalg.norm(rec.clip.positions_cm() - take.positions_cm(), axis=-1)
    print(f"{n} keys: planned max {keys.report['planned']['max_cm']:.3f} cm, rebuilt max {err.max():.3f} cm")
    # The bound holds on the rebuilt clip, measured here on every joint of every frame (the
    # float32 arrays' rounding aside), and is what the engine reports.
    assert err.max() <= 1.0 + 1e-3, err.max()
    assert err.max() == pytest.approx(rec.max_error_cm, abs=1e-3)
    assert err.mean() == pytest.approx(rec.mean_error_cm, abs=1e-3)
    assert err.mean() < 0.2, err.mean()
    assert rec.max_error_cm == pytest.approx(keys.reconstruction.max_error_cm, rel=1e-9)
    assert rec.error_per_frame_cm.shape == (take.num_frames,)
    # The report: the same numbers as the arrays (read into a dict on first use), and in words.
    assert rec.report["error"]["max_cm"] == rec.max_error_cm and rec.report["keys"]["frames"] == keys.frames.tolist()
    np.testing.assert_array_equal(rec.report["error"]["per_frame_cm"], rec.error_per_frame_cm)
    assert rec.text.startswith(f"{take.num_frames} frames from {n} keys"), rec.text
    assert keys.reconstruction.text == rec.text
    # Fewer keys by K: a worse fit, never a crash.
    few = mocap.select_keys(take, k=4)
    assert len(few) == 4 and few.method == "optimal"
    assert few.reconstruction.mean_error_cm > keys.reconstruction.mean_error_cm


def _bezier(x, y, frame):
    """A cubic Bezier's value at `frame`, found as a DCC finds it: solve x(s) = frame, then y(s)."""
    lo, hi = 0.0, 1.0
    b = lambda c, s: (1 - s) ** 3 * c[0] + 3 * (1 - s) ** 2 * s * c[1] + 3 * (1 - s) * s * s * c[2] + s**3 * c[3]
    for _ in range(50):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if b(x, mid) < frame else (lo, mid)
    return b(np.asarray(y), 0.5 * (lo + hi))


def test_quaternion_bezier_keys_and_handles_play_back_within_the_bound(take):
    clip = take.crop(0, 240)
    keys = mocap.select_keys(clip, max_error_cm=1.0, max_error_deg=5.0, curve="quaternion_bezier")
    rec = mocap.reconstruct(clip, keys)  # the keys' own curve
    assert rec.report["curve"] == "quaternion_bezier"
    err = np.linalg.norm(rec.clip.positions_cm() - clip.positions_cm(), axis=-1)
    assert err.max() <= 1.0 + 1e-3, err.max()
    h = mocap.bezier_handles(clip, keys)
    n, j = len(keys), len(clip.joints)
    assert list(h.frames) == list(keys.frames)
    assert h.rotations.shape == h.rotations_left.shape == (n, j, 4) and h.translations_cm.shape == (n, j, 3)
    assert np.all(h.left_frames < h.frames) and np.all(h.right_frames > h.frames)
    # Evaluate every joint's four component curves as a DCC would, normalise, compare to the
    # engine's rebuilt rotations (a quaternion and its negative are one rotation).
    want = rec.clip.rotations
    worst = 0.0
    for s in range(n - 1):
        a, b = h.frames[s], h.frames[s + 1]
        x = [a, h.right_frames[s], h.left_frames[s + 1], b]
        for f in range(a, b + 1, 3):
            q = np.stack(
                [_bezier(x, [h.rotations[s, :, c], h.rotations_right[s, :, c], h.rotations_left[s + 1, :, c], h.rotations[s + 1, :, c]], f) for c in range(4)],
                axis=-1,
            )
            q /= np.linalg.norm(q, axis=-1, keepdims=True)
            worst = max(worst, float(np.max(1.0 - np.abs(np.sum(q * want[f], axis=-1)))))
    assert worst < 1e-5, worst
    with pytest.raises(InbetweenError, match="curve 'slerp'"):
        mocap.select_keys(clip, max_error_cm=1.0, curve="slerp")
    with pytest.raises(InbetweenError, match="degrees"):
        mocap.select_keys(clip, max_error_deg=float("nan"))


def _axis(axis, angle):
    """Rotation matrices about one axis, (…, 3, 3)."""
    c, s = np.cos(angle), np.sin(angle)
    m = np.zeros(np.shape(angle) + (3, 3))
    i, j = [(1, 2), (2, 0), (0, 1)]["XYZ".index(axis)]
    k = "XYZ".index(axis)
    m[..., k, k] = 1.0
    m[..., i, i] = m[..., j, j] = c
    m[..., i, j], m[..., j, i] = -s, s
    return m


def _quat_matrix(q):
    """(…, 4) (x, y, z, w) unit quaternions to (…, 3, 3)."""
    x, y, z, w = np.moveaxis(q, -1, 0)
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], -1),
            np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], -1),
            np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], -1),
        ],
        -2,
    )


def test_euler_bezier_keys_and_handles_play_back_within_the_bound(take):
    clip = take.crop(0, 240)
    j = len(clip.joints)
    rng = np.random.default_rng(45)
    orders = [("XYZ", "ZXY", "YZX", None)[i % 4] for i in range(j)]
    pre = rng.normal(size=(j, 4))
    pre /= np.linalg.norm(pre, axis=1, keepdims=True)
    euler = dict(euler_orders=orders, pre_rotations=pre)
    keys = mocap.select_keys(clip, max_error_cm=1.0, curve="euler_bezier", **euler)
    n = len(keys)
    assert keys.euler_angles.shape == keys.euler_rates.shape == (n, j, 3)
    assert np.isnan(keys.euler_angles[:, 3]).all() and not np.isnan(keys.euler_angles[:, 0]).any()
    rec = mocap.reconstruct(clip, keys, **euler)
    assert rec.report["curve"] == "euler_bezier"
    err = np.linalg.norm(rec.clip.positions_cm() - clip.positions_cm(), axis=-1)
    assert err.max() <= 1.0 + 1e-3, err.max()
    h = mocap.bezier_handles(clip, keys, curve="euler_bezier", **euler)
    assert h.euler.shape == h.euler_left.shape == h.euler_right.shape == (n, j, 3)
    assert np.allclose(h.euler[:, 0], keys.euler_angles[:, 0], atol=1e-5)
    # Every Euler joint's three curves evaluated as a DCC does, composed axis by axis after its
    # pre-rotation, against the engine's rebuilt rotations.
    want = _quat_matrix(rec.clip.rotations)
    worst = 0.0
    for s in range(n - 1):
        a, b = h.frames[s], h.frames[s + 1]
        x = [a, h.right_frames[s], h.left_frames[s + 1], b]
        for f in range(a, b + 1, 3):
            e = np.stack(
                [_bezier(x, [h.euler[s, :, c], h.euler_right[s, :, c], h.euler_left[s + 1, :, c], h.euler[s + 1, :, c]], f) for c in range(3)],
                axis=-1,
            )
            for jj, order in enumerate(orders):
                if order is None:
                    continue
                m = _quat_matrix(pre[jj])
                for axis in order:
                    m = m @ _axis(axis, e[jj, "XYZ".index(axis)])
                worst = max(worst, float(np.abs(m - want[f, jj]).max()))
    assert worst < 1e-4, worst
    # The DCC's own angles (here two turns up) are the keys' values.
    ref = np.zeros((clip.num_frames, j, 3))
    ref[keys.frames] = keys.euler_angles + 4 * np.pi
    ref[np.isnan(ref)] = 0.0
    h2 = mocap.bezier_handles(clip, keys, curve="euler_bezier", euler_reference=ref, **euler)
    assert np.allclose(h2.euler[:, :3], h.euler[:, :3] + 4 * np.pi, atol=1e-4)
    with pytest.raises(InbetweenError, match="need curve 'euler_bezier'"):
        mocap.select_keys(clip, max_error_cm=1.0, curve="quaternion_bezier", euler_orders=orders)
    with pytest.raises(InbetweenError, match="expected one per joint"):
        mocap.select_keys(clip, max_error_cm=1.0, curve="euler_bezier", euler_orders=["XYZ"])
    with pytest.raises(InbetweenError, match="Euler order 'ABC'"):
        mocap.select_keys(clip, max_error_cm=1.0, curve="euler_bezier", euler_orders=["ABC"] * j)


@pytest.mark.parametrize("method", ["greedy", "uniform", "sidql"])
def test_every_selector(take, method):
    keys = mocap.select_keys(take.crop(0, 120), k=8, method=method)
    assert len(keys) == 8 and keys.method == method, keys.text


def test_bad_selection_requests(take):
    with pytest.raises(InbetweenError, match="takes k"):
        mocap.select_keys(take, max_error_cm=1.0, method="greedy")
    with pytest.raises(InbetweenError, match="expected one of"):
        mocap.select_keys(take, k=5, method="best")
    with pytest.raises(InbetweenError, match="1000 keyframes do not fit a clip of 480 frames"):
        mocap.select_keys(take, k=1000)
    with pytest.raises(InbetweenError, match="positive"):
        mocap.select_keys(take, max_error_cm=-1.0)
    with pytest.raises(InbetweenError, match="999"):
        mocap.reconstruct(take, [0, 999])
    with pytest.raises(InbetweenError, match="frame indices"):
        mocap.reconstruct(take, np.array([0.5, 3.0]))


def test_compress_matches_the_cli_byte_for_byte(cmu_bvh, cli, tmp_path):
    clip = inbetween.read(cmu_bvh)
    data = ibk.compress(clip, 1.0)
    out = tmp_path / "cli.ibk"
    subprocess.run([str(cli), "mocap", "compress", str(cmu_bvh), "-o", str(out), "--max-error", "1cm"], check=True,
                   capture_output=True)
    assert data == out.read_bytes()


def test_compress_decompress_and_sample_into_a_buffer(take):
    data, text = ibk.compress(take, 0.5, report=True)
    assert data[:4] == b"IBK\0" and "virtual-vertex error" in text
    back = ibk.decompress(data)
    assert back.num_frames == take.num_frames and back.joints == take.joints
    err = np.linalg.norm(back.positions_cm() - take.positions_cm(), axis=-1).max()
    assert err < 1.0, err
    reader = ibk.Reader(data)
    assert reader.num_frames == take.num_frames and reader.joints == take.joints
    rot, tr = ibk.pose_buffers(reader)
    where = (rot.ctypes.data, tr.ctypes.data)
    want = back.rotations
    for f in (0, 17, take.num_frames - 1):
        reader.sample(f / take.fps, rot, tr)
        assert (rot.ctypes.data, tr.ctypes.data) == where  # written in place
        dots = np.abs((rot * want[f]).sum(-1))
        assert dots.min() > 1 - 1e-4, dots.min()
    np.testing.assert_allclose(tr[0], back.translations[-1], atol=0.05)
    with pytest.raises(ShapeError, match=r"expected float32 \[J, 4\] and \[J, 3\]"):
        reader.sample(0.0, rot[:3], tr)
    with pytest.raises(TypeError):
        reader.sample(0.0, rot.astype(np.float64), tr)


def test_garbage_ibk_bytes():
    with pytest.raises(InbetweenError, match="IBK|magic|truncated"):
        ibk.decompress(b"not an ibk file at all")
    with pytest.raises(InbetweenError, match="IBK|magic|truncated"):
        ibk.Reader(b"IBK\0\x04\x00")


def test_progress_reaches_the_end(take):
    seen = []
    mocap.select_keys(take, k=20, progress=lambda done, total: seen.append((done, total)))
    assert seen, "no progress reported"
    assert all(0 <= d <= t for d, t in seen) and seen[-1][0] == seen[-1][1]


def test_progress_callback_exception_stops_the_job(take):
    def boom(done, total):
        raise RuntimeError("stop here")

    with pytest.raises(RuntimeError, match="stop here"):
        mocap.select_keys(take, k=20, progress=boom)


def test_ctrl_c_cancels_an_optimal_search_within_a_second(long_bvh):
    clip = inbetween.read(long_bvh).crop(0, 2000)
    sent = {}

    def interrupt():
        time.sleep(0.5)
        sent["at"] = time.perf_counter()
        _thread.interrupt_main()

    threading.Thread(target=interrupt, daemon=True).start()
    start = time.perf_counter()
    returned = False
    with pytest.raises(KeyboardInterrupt):
        mocap.select_keys(clip, k=400, progress=False)
        returned = True
        time.sleep(2.0)
    stopped = time.perf_counter()
    assert not returned, "the search ended before Ctrl-C: nothing was cancelled (make it longer)"
    assert stopped - sent["at"] < 1.0, f"stopped {stopped - sent['at']:.2f} s after Ctrl-C"
    print(f"cancelled after {sent['at'] - start:.2f} s of search, {stopped - sent['at']:.3f} s after Ctrl-C")


def test_a_panic_is_an_exception_not_an_abort():
    with pytest.raises(InbetweenError, match="internal error.*deliberate panic"):
        inbetween._native._panic_in_job()
    assert inbetween.read  # the interpreter is still here
