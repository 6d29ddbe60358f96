"""video.resequence from Python on a real MP4: orders, cuts, loops, the explanation per step, the
files written, and bad requests."""

from __future__ import annotations

import numpy as np
import pytest

from inbetween import InbetweenError, video


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    """The clip's first 40 frames, a short RSFNet training (30 steps) and one metric cache for the
    module (the first call trains on the clip, later ones read it): a quick suite."""
    return dict(max_frames=40, steps=30, cache_dir=tmp_path_factory.mktemp("video-cache"))


def test_resequence_a_real_mp4_explained_and_written(mp4, quick, tmp_path):
    out = tmp_path / "new.gif"
    made = video.resequence(mp4, start=5, length=60, seed=3, count=2, out=out, **quick, progress=False)
    assert made.frames == 40 and made.width == 176 and made.height == 144 and made.fps > 0
    assert made.shot.shape == (40,) and made.source_md > 0
    assert 1 <= len(made) <= 2
    for i, s in enumerate(made.sequences):
        order = s.order
        assert order.dtype == np.int64 and len(order) == 60 and order[0] == 5
        assert order.min() >= 0 and order.max() < 40
        # Every step that is not the source's next frame is explained, and no other.
        off = [p for p in range(1, len(order)) if order[p] != order[p - 1] + 1]
        assert [st.position for st in s.steps] == off
        for st in s.steps:
            assert (st.from_frame, st.to_frame) == (order[st.position - 1], order[st.position])
            assert st.kind in ("back", "jump", "cut", "loop", "replay", "transition", "repeat") and st.text
        assert set(s.cuts) <= set(off) and set(s.loops) <= set(off)
        assert np.isfinite(s.md) and 0 < s.distinct <= 1 and s.explain
        # Written: numbered GIFs with their contact sheets.
        assert s.file.endswith(f"new-{i + 1}.gif") and open(s.file, "rb").read(6) == b"GIF89a"
        assert open(s.sheet, "rb").read(8) == b"\x89PNG\r\n\x1a\n"
    if len(made) == 2:
        assert not np.array_equal(made[0].order, made[1].order), "count=2 asks for distinct orders"
    # The same request again (the metric now read from the cache) gives the same orders.
    again = video.resequence(mp4, start=5, length=60, seed=3, count=2, **quick, progress=False)
    for a, b in zip(again.sequences, made.sequences):
        np.testing.assert_array_equal(a.order, b.order)
    assert all(s.file is None for s in again.sequences)
    assert "M_D" in again.text and str(mp4.name) in again.text


def test_loop_closes_on_the_start_or_says_it_did_not_written_as_mp4(mp4, quick, tmp_path):
    out = tmp_path / "loop.mp4"
    made = video.resequence(mp4, start=10, length=30, seed=1, loop=True, explain=True, out=out, **quick,
                            progress=False)
    s = made[0]
    # The MP4 holds the order's frames: read back, it has as many frames as the order.
    assert s.file == str(out) and out.read_bytes()[4:8] == b"ftyp"
    back = video.resequence(out, length=1, metric="pixels", progress=False)
    assert (back.frames, back.width, back.height) == (len(s.order), 176, 144)
    assert made.report["loop_close"] is True
    if s.closes_loop:
        assert s.closing is not None and s.closing.from_frame == s.order[-1] and s.closing.to_frame == 10
        assert "loop closes" in made.text
    else:
        assert s.closing is None and "no loop found" in made.text


def test_bad_requests_are_refused_with_their_reason(mp4, tmp_path):
    cases = [
        (dict(start=500, max_frames=30, metric="pixels"), "outside the clip"),
        (dict(out=tmp_path / "new.avi"), r"must end in \.mp4 or \.gif"),
        (dict(length=0), "length 0: expected a whole number, at least 1"),
        (dict(count=0), "count 0"),
        (dict(metric="sift"), "metric 'sift'"),
        (dict(count=99), "max_count"),
    ]
    for kwargs, pattern in cases:
        with pytest.raises(InbetweenError, match=pattern):
            video.resequence(mp4, progress=False, **kwargs)
    garbage = tmp_path / "garbage.mp4"
    garbage.write_bytes(b"\x00\x00\x00\x18ftypmp42" + b"\x01" * 200)
    with pytest.raises(InbetweenError, match="garbage.mp4"):
        video.resequence(garbage, metric="pixels", progress=False)
    with pytest.raises(InbetweenError, match="missing.mp4"):
        video.resequence(tmp_path / "missing.mp4", metric="pixels", progress=False)


def test_ctrl_c_stops_the_analysis_within_a_second(mp4, tmp_path):
    import _thread
    import threading
    import time

    sent = {}

    def interrupt():
        time.sleep(1.0)
        sent["at"] = time.perf_counter()
        _thread.interrupt_main()

    threading.Thread(target=interrupt, daemon=True).start()
    returned = False
    with pytest.raises(KeyboardInterrupt):
        # RSFNet trained for 5000 steps in a fresh cache: minutes, unless cancelled.
        video.resequence(mp4, max_frames=40, steps=5000, cache_dir=tmp_path, progress=False)
        returned = True
        time.sleep(3.0)
    stopped = time.perf_counter()
    assert not returned, "the analysis ended before Ctrl-C: nothing was cancelled (make it longer)"
    assert stopped - sent["at"] < 1.0, f"stopped {stopped - sent['at']:.2f} s after Ctrl-C"
