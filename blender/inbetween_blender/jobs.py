"""What the operators share: a job's error type, the engine run on a worker thread with progress
and cancelling, and the step helpers the modal runner advances."""

from __future__ import annotations

import threading
import time
from typing import Dict, Iterator, Optional, Tuple


class JobError(Exception):
    """Bad input or a failed job, in words for Blender's report."""


class Cancelled(Exception):
    """Esc pressed."""


def call_engine(fn, cancel: threading.Event, *args, **kwargs):
    """Runs `fn(*args, progress=cb, **kwargs)` on a worker thread; yields `(done, total)` while it
    runs; returns its result or raises its error. Setting `cancel` stops the job (the callback
    raises, which the native job treats as a cancel)."""
    state = {"done": 0, "total": 0}

    def cb(done: int, total: int) -> None:
        if cancel.is_set():
            raise Cancelled()
        state["done"], state["total"] = done, total

    out: Dict[str, object] = {}

    def work() -> None:
        try:
            out["value"] = fn(*args, progress=cb, **kwargs)
        except BaseException as e:  # handed to the main thread
            out["error"] = e

    th = threading.Thread(target=work, name="inbetween job", daemon=True)
    th.start()
    while th.is_alive():
        th.join(0.02)
        yield state["done"], state["total"]
    if cancel.is_set():
        raise Cancelled()
    if "error" in out:
        raise out["error"]  # type: ignore[misc]
    return out["value"]


def fractions(gen, lo: float, hi: float, words: str):
    """Maps a generator's fractions 0..1 onto lo..hi and passes its result on."""
    try:
        while True:
            f = next(gen)
            yield lo + (hi - lo) * f, words
    except StopIteration as stop:
        return stop.value


def engine_fractions(gen, lo: float, hi: float, words: str):
    """Maps an engine call's `(done, total)` onto lo..hi and passes its result on."""
    try:
        while True:
            done, total = next(gen)
            f = done / total if total else 0.0
            yield lo + (hi - lo) * f, words
    except StopIteration as stop:
        return stop.value


def time_slice(steps: Iterator[Tuple[float, str]], budget_s: float = 0.1) -> Optional[Tuple[float, str]]:
    """Advances `steps` for about `budget_s`; returns the last `(fraction, words)` or None when done."""
    end = time.perf_counter() + budget_s
    last = None
    for last in steps:
        if time.perf_counter() >= end:
            return last
    return None
