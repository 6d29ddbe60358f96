"""Video resequencing: new frame orders of one clip from a start frame (RSFNet metric + SDPF path
finding; the video engine's `ResequenceJob`, as `inbetween video resequence`)."""

from __future__ import annotations

import json
import numbers
import os
from dataclasses import dataclass, field
from typing import Any, Dict, List, Optional, Union

import numpy as np

from . import _native
from ._native import InbetweenError
from ._progress import Callback, progress_callback

__all__ = ["Step", "Sequence", "Resequenced", "resequence", "METRICS"]

#: `metric=`: RSFNet trained on the clip (the paper; cached per clip) or downscaled pixels (ablation).
METRICS = ("rsfnet", "pixels")

PathLike = Union[str, "os.PathLike[str]"]


@dataclass(frozen=True)
class Step:
    """A step of a new order that is not the source's next frame, in the engine's words."""

    position: int  #: position in the order of the frame the step enters
    from_frame: int  #: source frame before the step
    to_frame: int  #: source frame after it
    #: "back" / "jump" (drawn by Eq. 20), "cut", "loop", "replay", "transition" (matched), "repeat"
    kind: str
    text: str  #: the step's candidates, what each constraint removed and the choice


@dataclass(frozen=True)
class Sequence:
    """One new order, measured and explained."""

    order: np.ndarray  #: source frame of each position, int64 `[L]`, the start frame first
    seed: int
    stop: str  #: why the walk ended ("TargetLength", "LoopClosed", …)
    closes_loop: bool  #: the last frame steps back to the start (with `loop=True`)
    closing: Optional[Step]  #: that closing step
    cuts: List[int]  #: positions entered by a cut to another shot or a jump cut inside one
    loops: List[int]  #: positions entered by a loop back or a matched transition
    backward_steps: int  #: steps to one of the 3 previous source frames
    md: float  #: M_D (Eq. 21), mean RMS difference of the order's transitions (of the written frames with a blend)
    delta_o: float  #: Δo (Eq. 23)
    distinct: float  #: share of the source's frames shown
    steps: List[Step]  #: every step that is not the source's next frame, explained
    blended: List[int]  #: positions written as a cross-fade (with `blend`)
    explain: str = field(repr=False)  #: the whole walk in words
    file: Optional[str] = None  #: the clip written (with `out`)
    sheet: Optional[str] = None  #: its contact sheet

    def __len__(self) -> int:
        return len(self.order)


@dataclass(frozen=True)
class Resequenced:
    """What `resequence` made: the orders and the analysed clip."""

    sequences: List[Sequence]
    source: str
    frames: int
    width: int
    height: int
    fps: float
    shots: int
    shot: np.ndarray  #: shot of every source frame, int64 `[N]`
    source_md: float  #: M_D of the source order, the reference for `Sequence.md`
    metric: str  #: how the metric was made (trained on the clip, or read from its cache)
    start: int
    walk_s: float  #: seconds of the walks
    report: Dict[str, Any] = field(repr=False)  #: the job's report as a dict
    text: str = field(repr=False)  #: the report in words (what the CLI prints)

    def __len__(self) -> int:
        return len(self.sequences)

    def __getitem__(self, i: int) -> Sequence:
        return self.sequences[i]

    def __str__(self) -> str:
        return self.text


def _step(d: Optional[Dict[str, Any]]) -> Optional[Step]:
    if d is None:
        return None
    return Step(int(d["position"]), int(d["from"]), int(d["to"]), d["kind"], d["text"])


def _whole(name: str, value: Any, least: int) -> None:
    if isinstance(value, bool) or not isinstance(value, numbers.Integral) or value < least:
        raise InbetweenError(f"{name} {value!r}: expected a whole number, at least {least}")


def resequence(
    path: PathLike,
    *,
    start: int = 0,
    length: Optional[int] = None,
    seed: Optional[int] = None,
    loop: bool = False,
    count: int = 1,
    out: Optional[PathLike] = None,
    sheet: Optional[PathLike] = None,
    blend: int = 0,
    explain: bool = False,
    stop_early: bool = False,
    transitions: bool = True,
    allow_reverse: bool = False,
    allow_cuts: bool = False,
    metric: str = "rsfnet",
    steps: Optional[int] = None,
    cache_dir: Optional[PathLike] = None,
    max_frames: Optional[int] = None,
    progress: Optional[Callback] = None,
) -> Resequenced:
    """New frame orders of the clip at `path` (.mp4, .gif or a folder of PNG/JPEG frames) from
    frame `start`, by the video engine's `ResequenceJob` (as `inbetween video resequence`).

    `length` frames (default: the source's count), `seed` of the walk's draws, `loop=True` to end on
    a frame that can step back to the start, `count` distinct orders (seeds drawn from `seed`).
    `out` (.mp4 or .gif) writes each order (numbered with `count > 1`) and a contact sheet beside it
    (or at `sheet`), all together or none; `blend` cross-fades jumps over that many frames.
    `stop_early`, `transitions=False`, `allow_reverse`, `allow_cuts`, `metric="pixels"` are the
    CLI's ablations and options; `steps` RSFNet's training steps, `cache_dir` where the trained
    metric is kept per clip (default `~/.cache/inbetween/video`), `max_frames` reads only the first
    frames. `explain=True` adds each walk and how each shot's motion was judged to `text`; every
    sequence carries its explained `steps` and `explain` either way."""
    _whole("start", start, 0)
    _whole("count", count, 1)
    _whole("blend", blend, 0)
    if length is not None:
        _whole("length", length, 1)
    if seed is not None:
        _whole("seed", seed, 0)
    if max_frames is not None:
        _whole("max_frames", max_frames, 1)
    if steps is not None:
        _whole("steps", steps, 1)
    if metric not in METRICS:
        raise InbetweenError(f"metric {metric!r}: expected one of {', '.join(METRICS)}")
    fspath = lambda p: None if p is None else os.fspath(p)  # noqa: E731
    with progress_callback(progress, "video") as cb:
        report_json, text, orders = _native.video_resequence(
            os.fspath(path), start, length, seed, bool(loop), count, fspath(out), fspath(sheet), blend, bool(explain),
            bool(stop_early), bool(transitions), bool(allow_reverse), bool(allow_cuts), metric, steps,
            fspath(cache_dir), max_frames, cb,
        )
    report = json.loads(report_json)
    a = report["analysis"]
    sequences = []
    for order, s in zip(orders, report["sequences"]):
        sequences.append(
            Sequence(
                order=order,
                seed=int(s["seed"]),
                stop=s["stop"],
                closes_loop=bool(s["closes_loop"]),
                closing=_step(s["closing"]),
                cuts=[int(p) for p in s["cuts"]],
                loops=[int(p) for p in s["loops"]],
                backward_steps=int(s["backward_steps"]),
                md=float(s["md"]),
                delta_o=float(s["delta_o"]),
                distinct=float(s["distinct"]),
                steps=[_step(j) for j in s["jumps"]],
                blended=[int(p) for p in s["blended"]],
                explain=s["explain"],
                file=s["file"],
                sheet=s["sheet"],
            )
        )
    return Resequenced(
        sequences=sequences,
        source=a["source"],
        frames=int(a["frames"]),
        width=int(a["width"]),
        height=int(a["height"]),
        fps=float(a["fps"]),
        shots=int(a["shots"]),
        shot=np.asarray(a["shot"], dtype=np.int64),
        source_md=float(a["source_md"]),
        metric=a["metric"],
        start=int(report["start"]),
        walk_s=float(report["walk_s"]),
        report=report,
        text=text,
    )
