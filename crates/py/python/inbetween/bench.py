"""`python -m inbetween.bench`: each job called from Python and the same work called from Rust (the
functions the extension runs, timed inside it), on the same inputs in one run (a CMU take, a Live
Link capture), and the `.ibk` runtime sampler's time per pose from Python and from Rust.

    python -m inbetween.bench [--data DIR] [--repeats N] [--out FILE.md]

The Python overhead is `python / rust - 1`; the goal is under 5 % on every job over 10 ms.
"""

from __future__ import annotations

import argparse
import json
import os
import pathlib
import platform
import statistics
import sys
import tempfile
import time
from typing import Callable, List, Tuple

import numpy as np

import inbetween
from inbetween import _native, face, ibk, mocap, video


def _median_ms(f: Callable[[], object], repeats: int) -> float:
    times = []
    for _ in range(repeats):
        t = time.perf_counter()
        f()
        times.append((time.perf_counter() - t) * 1e3)
    return statistics.median(times)


def _data_dir(given: str | None) -> pathlib.Path:
    if given:
        return pathlib.Path(given)
    if os.environ.get("INBETWEEN_DATA"):
        return pathlib.Path(os.environ["INBETWEEN_DATA"])
    for p in (pathlib.Path("../shared/data"), pathlib.Path(__file__).resolve().parents[4].parent / "shared" / "data"):
        if p.is_dir():
            return p
    return pathlib.Path("../shared/data")


def run(data: pathlib.Path, repeats: int) -> Tuple[List[Tuple[str, float, float]], Tuple[float, float, int]]:
    path = data / "mocap" / "cmu" / "cgspeed" / "131_01.bvh"
    if not path.exists():
        raise SystemExit(f"no data at {path} (give --data or INBETWEEN_DATA)")
    clip = inbetween.read(path)
    keys = mocap.select_keys(clip, max_error_cm=1.0, progress=False)
    frames = [int(f) for f in keys.frames]
    quiet = dict(progress=False)
    jobs = [
        ("read BVH (994 frames)", lambda: inbetween.read(path), dict()),
        ("select_keys max_error_cm=1", lambda: mocap.select_keys(clip, max_error_cm=1.0, **quiet),
         dict(method="error_bounded", bound_cm=1.0)),
        ("select_keys k=40 optimal", lambda: mocap.select_keys(clip, k=40, **quiet), dict(method="optimal", k=40)),
        ("reconstruct from the 1 cm keys", lambda: mocap.reconstruct(clip, frames, **quiet), dict(keys=frames)),
        ("ibk.compress max_error_cm=1", lambda: ibk.compress(clip, 1.0, **quiet), dict(max_error_cm=1.0)),
    ]
    kinds = ["read", "select", "select", "reconstruct", "compress"]
    timed = [(name, py_call, lambda kw=kw, kind=kind: _native._bench_rust(kind, clip, 1, **kw)[0])
             for (name, py_call, kw), kind in zip(jobs, kinds)]
    capture = data / "face" / "neurosync" / "livelink" / "Happy" / "Happy.csv"
    if capture.exists():
        take = inbetween.read(capture)
        spans = [(4.0, 6.5)]
        keys = [{"time_s": 5.0, "shapes": {"JawOpen": 0.8}}]
        label = f"Happy.csv ({take.num_frames} frames at {take.fps:.0f} fps), 4-6.5 s"
        timed += [
            (f"face.edit unguided, 3 variants; {label}", lambda: face.edit(take, spans, variants=3, **quiet),
             lambda: _native._bench_face_rust(take, spans, 1, variants=3)[0]),
            (f"face.edit one key (network); {label}", lambda: face.edit(take, spans, keys=keys, **quiet),
             lambda: _native._bench_face_rust(take, spans, 1, keys_json=json.dumps(keys))[0]),
        ]
    mp4 = data / "video" / "carphone_pristine.mp4"
    if mp4.exists():
        cache = tempfile.mkdtemp(prefix="inbetween-bench-video-")  # the first (warming) call trains RSFNet here
        timed.append(
            ("video.resequence carphone_pristine.mp4 (120 frames), 120 from frame 0, metric cached",
             lambda: video.resequence(mp4, length=120, cache_dir=cache, **quiet),
             lambda: _native._bench_video_rust(mp4, 1, length=120, cache_dir=cache)[0]),
        )
    rows = []
    for name, py_call, rust_call in timed:
        py_call()  # warm: caches, the committed policy, page faults
        # Interleaved, so that the machine's drift falls on both sides alike.
        py_ms, rust_ms = [], []
        for _ in range(repeats):
            py_ms.append(_median_ms(py_call, 1))
            rust_ms.append(rust_call())
        rows.append((name, statistics.median(py_ms), statistics.median(rust_ms)))
    # The runtime sampler: every frame time and the half-frame between, played forwards.
    data_v4 = ibk.compress(clip, 1.0, progress=False)
    reader = ibk.Reader(data_v4)
    times = [i / (2 * clip.fps) for i in range(2 * clip.num_frames - 1)]
    rot, tr = ibk.pose_buffers(reader)
    best_py, best_rust = float("inf"), float("inf")
    for _ in range(repeats):
        t = time.perf_counter()
        for s in times:
            reader.sample(s, rot, tr)
        best_py = min(best_py, (time.perf_counter() - t) * 1e9 / len(times))
        best_rust = min(best_rust, _native._bench_sample_rust(data_v4, times))
    return rows, (best_py, best_rust, len(data_v4))


def table(rows, sample) -> str:
    out = [
        f"inbetween {inbetween.__version__}, Python {platform.python_version()}, numpy {np.__version__}, "
        f"{os.cpu_count()} CPUs; CMU 131_01 (994 frames at 120 fps), Live Link Happy.csv, carphone_pristine.mp4; "
        "medians",
        "",
        "| job | from Python (ms) | from Rust (ms) | Python overhead |",
        "| --- | ---: | ---: | ---: |",
    ]
    for name, p, r in rows:
        out.append(f"| {name} | {p:.2f} | {r:.2f} | {100 * (p / r - 1):+.1f} % |")
    py_ns, rust_ns, size = sample
    out.append(
        f"| Reader.sample, one pose (ns; .ibk v4 at 1 cm, {size} bytes) | {py_ns:.0f} ns | {rust_ns:.0f} ns | "
        f"+{py_ns - rust_ns:.0f} ns per call |"
    )
    return "\n".join(out)


def main(argv: List[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m inbetween.bench", description=__doc__.splitlines()[0])
    ap.add_argument("--data", help="the shared data folder (default: INBETWEEN_DATA or ../shared/data)")
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--out", help="also write the table (Markdown) here")
    a = ap.parse_args(argv)
    rows, sample = run(_data_dir(a.data), max(1, a.repeats))
    text = table(rows, sample)
    print(text)
    if a.out:
        pathlib.Path(a.out).write_text(text + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
