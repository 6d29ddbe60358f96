"""`python -m inbetween.bench`'s machinery on a small edit (no shared data needed): the three calls
interleaved, the Rust side on a pool thread and on the calling thread, and the table."""

from __future__ import annotations

import math

from inbetween import _native, bench, face


def test_rounds_are_interleaved_and_the_table_has_the_overhead():
    clip, _ = face.synth(4.0, seed=2)
    spans = [(1.0, 2.0)]
    row = bench.measure(
        "face.edit linear",
        lambda: face.edit(clip, spans, method="linear", progress=False),
        lambda pool: _native._bench_face_rust(clip, spans, 1, pool=pool)[0],
        min_rounds=3,
        budget_s=0.0,
    )
    assert len(row.python) == len(row.rust_pool) == len(row.rust_calling) == 3
    assert all(t > 0 for t in row.python + row.rust_pool + row.rust_calling)
    med, lo, hi, mins = row.overhead()
    assert all(math.isfinite(x) for x in (med, lo, hi, mins)) and lo <= med <= hi
    text = bench.table([row], (900.0, 400.0, 1000, 80.0, 40.0), (1.0, 1.2))
    assert "| face.edit linear | 3 |" in text and "+500 ns per call" in text and "| 80 / 40 µs |" in text
    _native._empty_job()
    assert _native._rayon_threads() >= 1 and _native._build_profile() in ("dev", "release")
