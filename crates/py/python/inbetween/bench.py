"""`python -m inbetween.bench`: each job called from Python and the same work called from Rust (the
functions the extension runs, timed inside it), on the same inputs in one process (a CMU take, a Live
Link capture, an MP4), and the `.ibk` runtime sampler's time per pose from Python and from Rust.

    python -m inbetween.bench [--data DIR] [--repeats N] [--budget-s S] [--threads N] [--out FILE.md]

Like with like: the Rust side runs on a thread of rayon's pool, where the Python functions run their
jobs (same thread kind, allocator arena and pool; the job's time measured there), so the difference is
what the Python call adds: argument and result conversion, the hop to the pool thread and back, the
GIL, the Python wrapper. The Rust call on the calling thread (as the CLI runs a job) is shown beside
it. The three calls are interleaved, in an order that alternates every round (A B C, C B A, …), with
a garbage collection before each round, so the machine's drift falls on all alike. The overhead is
the median of the rounds' ratios `python / rust − 1`, with a 90 % bootstrap interval, and the ratio of
the minima; the goal is under 5 % on every job over 10 ms.
"""

from __future__ import annotations

import argparse
import gc
import json
import os
import pathlib
import platform
import statistics
import sys
import tempfile
import time
from dataclasses import dataclass
from typing import Callable, List, Tuple

import numpy as np

import inbetween
from inbetween import _native, face, ibk, mocap, video


@dataclass
class Row:
    """One job's timings (ms per call), round by round."""

    name: str
    python: List[float]
    rust_pool: List[float]
    rust_calling: List[float]

    def overhead(self) -> Tuple[float, float, float, float]:
        """(median of the rounds' ratios − 1, its 90 % bootstrap interval low, high, ratio of the minima − 1)."""
        ratios = np.array(self.python) / np.array(self.rust_pool)
        rng = np.random.default_rng(44)  # seeded: the interval is the same for the same timings
        boot = np.median(rng.choice(ratios, size=(2000, len(ratios)), replace=True), axis=1)
        lo, hi = np.percentile(boot, [5, 95])
        return (
            float(np.median(ratios)) - 1,
            float(lo) - 1,
            float(hi) - 1,
            min(self.python) / min(self.rust_pool) - 1,
        )


def _ms(f: Callable[[], object]) -> float:
    t = time.perf_counter()
    f()
    return (time.perf_counter() - t) * 1e3


def _data_dir(given: str | None) -> pathlib.Path:
    if given:
        return pathlib.Path(given)
    if os.environ.get("INBETWEEN_DATA"):
        return pathlib.Path(os.environ["INBETWEEN_DATA"])
    for p in (pathlib.Path("../shared/data"), pathlib.Path(__file__).resolve().parents[4].parent / "shared" / "data"):
        if p.is_dir():
            return p
    return pathlib.Path("../shared/data")


def measure(
    name: str,
    python: Callable[[], object],
    rust: Callable[[bool], float],
    min_rounds: int,
    budget_s: float,
) -> Row:
    """Interleaved rounds of the three calls (see the module doc): at least `min_rounds`, more while
    the row has run under `budget_s` seconds (at most 200)."""
    python()  # warm: caches, the committed networks and library, page faults
    rust(True)
    rust(False)
    row = Row(name, [], [], [])
    calls = [
        lambda: row.python.append(_ms(python)),
        lambda: row.rust_pool.append(rust(True)),
        lambda: row.rust_calling.append(rust(False)),
    ]
    start = time.perf_counter()
    rounds = 0
    while rounds < min_rounds or (time.perf_counter() - start < budget_s and rounds < 200):
        gc.collect()
        for call in calls if rounds % 2 == 0 else calls[::-1]:
            call()
        rounds += 1
    return row


def run(data: pathlib.Path, min_rounds: int, budget_s: float) -> Tuple[List[Row], Tuple[float, float, int, float, float]]:
    path = data / "mocap" / "cmu" / "cgspeed" / "131_01.bvh"
    if not path.exists():
        raise SystemExit(f"no data at {path} (give --data or INBETWEEN_DATA)")
    clip = inbetween.read(path)
    keys = mocap.select_keys(clip, max_error_cm=1.0, progress=False)
    frames = [int(f) for f in keys.frames]
    quiet = dict(progress=False)
    jobs = [
        ("read BVH (994 frames)", lambda: inbetween.read(path), "read", dict()),
        ("select_keys max_error_cm=1", lambda: mocap.select_keys(clip, max_error_cm=1.0, **quiet), "select",
         dict(method="error_bounded", bound_cm=1.0)),
        ("select_keys k=40 optimal", lambda: mocap.select_keys(clip, k=40, **quiet), "select",
         dict(method="optimal", k=40)),
        ("reconstruct from the 1 cm keys", lambda: mocap.reconstruct(clip, frames, **quiet), "reconstruct",
         dict(keys=frames)),
        ("ibk.compress max_error_cm=1", lambda: ibk.compress(clip, 1.0, **quiet), "compress", dict(max_error_cm=1.0)),
    ]
    timed = [(name, py_call, lambda pool, kind=kind, kw=kw: _native._bench_rust(kind, clip, 1, pool=pool, **kw)[0])
             for name, py_call, kind, kw in jobs]
    capture = data / "face" / "neurosync" / "livelink" / "Happy" / "Happy.csv"
    if capture.exists():
        take = inbetween.read(capture)
        spans = [(4.0, 6.5)]
        face_keys = [{"time_s": 5.0, "shapes": {"JawOpen": 0.8}}]
        label = f"Happy.csv ({take.num_frames} frames at {take.fps:.0f} fps), 4-6.5 s"
        for variants in (1, 3):
            timed.append((
                f"face.edit unguided (retrieval), {variants} variant{'s' if variants > 1 else ''}; {label}",
                lambda v=variants: face.edit(take, spans, variants=v, **quiet),
                lambda pool, v=variants: _native._bench_face_rust(take, spans, 1, variants=v, pool=pool)[0],
            ))
        timed.append((
            f"face.edit one key (network); {label}",
            lambda: face.edit(take, spans, keys=face_keys, **quiet),
            lambda pool: _native._bench_face_rust(take, spans, 1, keys_json=json.dumps(face_keys), pool=pool)[0],
        ))
    mp4 = data / "video" / "carphone_pristine.mp4"
    if mp4.exists():
        cache = tempfile.mkdtemp(prefix="inbetween-bench-video-")  # the first (warming) call trains RSFNet here
        timed.append((
            "video.resequence carphone_pristine.mp4 (120 frames), 120 from frame 0, metric cached",
            lambda: video.resequence(mp4, length=120, cache_dir=cache, **quiet),
            lambda pool: _native._bench_video_rust(mp4, 1, length=120, cache_dir=cache, pool=pool)[0],
        ))
    rows = []
    for name, py_call, rust_call in timed:
        rows.append(measure(name, py_call, rust_call, min_rounds, budget_s))
        print(f"  {name}: {len(rows[-1].python)} rounds", file=sys.stderr, flush=True)
    # The runtime sampler: every frame time and the half-frame between, played forwards.
    data_v4 = ibk.compress(clip, 1.0, progress=False)
    reader = ibk.Reader(data_v4)
    times = [i / (2 * clip.fps) for i in range(2 * clip.num_frames - 1)]
    rot, tr = ibk.pose_buffers(reader)
    best_py, best_rust = float("inf"), float("inf")
    for _ in range(max(min_rounds, 7)):
        t = time.perf_counter()
        for s in times:
            reader.sample(s, rot, tr)
        best_py = min(best_py, (time.perf_counter() - t) * 1e9 / len(times))
        best_rust = min(best_rust, _native._bench_sample_rust(data_v4, times))
    # The hop every long call makes: an empty job to a thread of rayon's pool and back.
    hops = [_ms(_native._empty_job) * 1e3 for _ in range(2000)]
    return rows, (best_py, best_rust, len(data_v4), statistics.median(hops), min(hops))


def table(rows: List[Row], sample, load: Tuple[float, float]) -> str:
    out = [
        f"inbetween {inbetween.__version__} ({_native._build_profile()} build), Python {platform.python_version()}, "
        f"numpy {np.__version__}, {os.cpu_count()} CPUs, rayon pool of {_native._rayon_threads()} threads, load average "
        f"{load[0]:.1f} at the start and {load[1]:.1f} at the end; CMU 131_01 (994 frames at 120 fps), Live Link "
        "Happy.csv, carphone_pristine.mp4",
        "",
        "| job | rounds | from Python (ms, median / min) | from Rust, pool thread (ms, median / min) "
        "| Python overhead (median of rounds [90 % interval]) | overhead of the minima "
        "| from Rust, calling thread (ms, median) |",
        "| --- | ---: | ---: | ---: | ---: | ---: | ---: |",
    ]
    for r in rows:
        med, lo, hi, mins = r.overhead()
        out.append(
            f"| {r.name} | {len(r.python)} | {statistics.median(r.python):.2f} / {min(r.python):.2f} "
            f"| {statistics.median(r.rust_pool):.2f} / {min(r.rust_pool):.2f} "
            f"| {100 * med:+.1f} % [{100 * lo:+.1f}, {100 * hi:+.1f}] | {100 * mins:+.1f} % "
            f"| {statistics.median(r.rust_calling):.2f} |"
        )
    py_ns, rust_ns, size, hop_us, hop_min_us = sample
    out.append(
        f"| Reader.sample, one pose (.ibk v4 at 1 cm, {size} bytes; best of rounds) | | {py_ns:.0f} ns | {rust_ns:.0f} ns "
        f"| +{py_ns - rust_ns:.0f} ns per call | | |"
    )
    out.append(
        f"| an empty job: the hop to a pool thread and back every long call makes (µs; 2000 calls) | 2000 "
        f"| {hop_us:.0f} / {hop_min_us:.0f} µs | | | | |"
    )
    return "\n".join(out)


def main(argv: List[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m inbetween.bench", description=__doc__.splitlines()[0])
    ap.add_argument("--data", help="the shared data folder (default: INBETWEEN_DATA or ../shared/data)")
    ap.add_argument("--repeats", type=int, default=9, help="rounds per job at least (default 9)")
    ap.add_argument("--budget-s", type=float, default=20.0,
                    help="more rounds (up to 200) while a job's rows have taken under this many seconds (default 20)")
    ap.add_argument("--threads", type=int,
                    help="threads of rayon's pool (RAYON_NUM_THREADS; default: as set, else one per CPU)")
    ap.add_argument("--out", help="also write the table (Markdown) here")
    a = ap.parse_args(argv)
    if a.threads:
        os.environ["RAYON_NUM_THREADS"] = str(a.threads)  # read when the pool starts, at the first job
    load0 = os.getloadavg()[0]
    rows, sample = run(_data_dir(a.data), max(1, a.repeats), max(0.0, a.budget_s))
    text = table(rows, sample, (load0, os.getloadavg()[0]))
    print(text)
    if a.out:
        pathlib.Path(a.out).write_text(text + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
