"""Facial animation editing: regenerate spans of a blendshape capture, unguided or guided by keys,
a noisy take, text or phoneme timings (the face engine's `EditJob`, as `inbetween face edit`)."""

from __future__ import annotations

import json
import numbers
import os
from dataclasses import dataclass, field
from typing import Any, Dict, Iterator, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from . import _native
from ._native import FaceClip, InbetweenError, ShapeError
from ._progress import Callback, progress_callback

__all__ = ["Edit", "EditReport", "edit", "synth", "METHODS", "GROUPS"]

#: `method=` names: "auto" picks retrieval when unguided or guided by a noisy take, the network for
#: keys and visemes (and whenever `weights` is given), from the face bench's tables.
METHODS = ("auto", "network", "retrieval", "linear", "cubic")
#: `groups=` names (comma-separated or a list); "lower" is jaw, mouth, cheeks, tongue; "upper" eyes, brows.
GROUPS = ("eyes", "brows", "jaw", "mouth", "cheeks", "tongue", "lower", "upper", "all")

PathLike = Union[str, "os.PathLike[str]"]
Span = Union[Tuple[float, float], str]

_SPAN_FORM = "(start_s, end_s) in seconds from the first frame, or text like '4.0s..6.5s' or '240f..390f'"


@dataclass(frozen=True)
class EditReport:
    """What one variant of an edit did."""

    variant: int  #: 1-based
    seed: int
    method: str  #: the method that ran: "retrieval", "network (keyframes)", "linear", …
    guidance: str  #: "unguided", "keyframes", "noisy" or "visemes"
    spans_s: List[Tuple[float, float]]  #: the edited spans, seconds from the first frame
    model_fps: float  #: the rate the engine edits at (25 fps); `before`, `after`, `mask` are at it
    segments: List[Tuple[int, int]]  #: the spans as model-rate frames (start, end exclusive)
    key_frames: List[int]  #: model-rate frames of the keys
    #: Mean squared difference from what was there, over the regenerated entries (weight², 0..1).
    masked_mse: float
    #: Mean |difference| from variant 1 inside the spans (blendshape weight, 0..1); None for variant 1.
    difference_from_first: Optional[float]
    #: Input rows the edit changed, `(first, last + 1)` (the capture's own frames); (0, 0) when none.
    changed_rows: Tuple[int, int]
    changed_shapes: List[str]  #: ARKit shapes with a changed value
    ms: float  #: time of this variant's edit, ms
    notes: List[str]
    before: np.ndarray = field(repr=False)  #: the input at the model rate, float32 `[N, 52]`
    after: np.ndarray = field(repr=False)  #: the edit at the model rate, float32 `[N, 52]`
    mask: np.ndarray = field(repr=False)  #: regenerated entries at the model rate, bool `[N, 52]`
    #: The report in words (the face engine's `VariantReport`), notes on their own lines.
    text: str = field(repr=False)

    def __str__(self) -> str:
        return self.text


@dataclass(frozen=True)
class Edit:
    """The `N` edited clips of `edit` and their reports; `edit[i]` is `(clips[i], reports[i])`."""

    clips: List[FaceClip]
    reports: List[EditReport]

    def __len__(self) -> int:
        return len(self.clips)

    def __iter__(self) -> Iterator[Tuple[FaceClip, EditReport]]:
        return iter(zip(self.clips, self.reports))

    def __getitem__(self, i: int) -> Tuple[FaceClip, EditReport]:
        return self.clips[i], self.reports[i]


def _span(value: Any, name: str) -> Span:
    if isinstance(value, str):
        return value
    try:
        items = list(value)
    except TypeError:
        raise ShapeError(f"{name}: {value!r}; expected {_SPAN_FORM}") from None
    if len(items) != 2 or not all(isinstance(v, numbers.Real) for v in items):
        raise ShapeError(f"{name}: {value!r}; expected {_SPAN_FORM}")
    return (float(items[0]), float(items[1]))


def _spans(spans: Any) -> List[Span]:
    if isinstance(spans, str):
        return [spans]
    if isinstance(spans, tuple) and len(spans) == 2 and all(isinstance(v, numbers.Real) for v in spans):
        return [(float(spans[0]), float(spans[1]))]
    if isinstance(spans, np.ndarray):
        if spans.ndim != 2 or spans.shape[1] != 2:
            raise ShapeError(f"spans: shape {list(spans.shape)}; expected [S, 2] (start_s, end_s)")
        spans = spans.tolist()
    try:
        items = list(spans)
    except TypeError:
        raise ShapeError(f"spans: {spans!r}; expected a list of {_SPAN_FORM}") from None
    return [_span(s, f"spans[{i}]") for i, s in enumerate(items)]


def _is_path(value: Any) -> bool:
    return isinstance(value, (str, os.PathLike))


def _keys(keys: Any) -> Tuple[Optional[str], Optional[str]]:
    """(keys JSON, keys file) from a path, a list of keys or a `{"keys": [...]}` mapping."""
    if keys is None:
        return None, None
    if _is_path(keys):
        return None, os.fspath(keys)
    if isinstance(keys, Mapping):
        keys = dict(keys)
    elif isinstance(keys, Sequence):
        keys = [dict(k) if isinstance(k, Mapping) else k for k in keys]
    else:
        raise InbetweenError(
            f"keys: {type(keys).__name__}; expected a keys file or a list like "
            '[{"time_s": 5.0, "shapes": {"JawOpen": 0.8}}]'
        )
    try:
        return json.dumps(keys, allow_nan=True), None
    except TypeError as e:
        raise InbetweenError(f"keys: {e}; expected numbers and ARKit names") from None


def edit(
    clip: FaceClip,
    spans: Union[Span, Sequence[Span]],
    *,
    keys: Optional[Union[PathLike, Sequence[Mapping[str, Any]], Mapping[str, Any]]] = None,
    guide: Optional[Union[FaceClip, PathLike]] = None,
    text: Optional[str] = None,
    text_span: Optional[Span] = None,
    visemes: Optional[Union[PathLike, Sequence[Tuple[float, float, str]]]] = None,
    tier: Optional[str] = None,
    groups: Optional[Union[str, Sequence[str]]] = None,
    method: str = "auto",
    weights: Optional[PathLike] = None,
    library: Optional[Sequence[Union[FaceClip, PathLike]]] = None,
    variants: int = 1,
    seed: int = 1,
    max_rows: Optional[int] = None,
    max_mask_s: Optional[float] = None,
    progress: Optional[Callback] = None,
) -> Edit:
    """Regenerates `spans` of `clip` by the face engine's `EditJob` (as `inbetween face edit`),
    `variants` times with seeds `seed, seed + 1, …`. Frames outside the spans keep the input's
    values bit for bit.

    - `spans`: `[(4.0, 6.5)]` seconds from the first frame, or the CLI's text (`"4s..6.5s"`,
      `"240f..390f"` in the clip's own frames); one span alone is accepted too.
    - One guidance at most: `keys` (a keys file, or `[{"time_s": 5.0, "shapes": {"JawOpen": 0.8}}]`:
      shapes hit exactly there, the others follow the capture), `guide` (a noisy take of the same
      performance: a `FaceClip` or a file), `text` (English spoken over `text_span`, default the first
      span), `visemes` (a TextGrid / phoneme CSV or JSON file with `tier`, or
      `[(start_s, end_s, "AA"), …]` ARPAbet phonemes).
    - `groups`: the shapes to regenerate (`"mouth,jaw"` or `["mouth", "jaw"]`, see `GROUPS`); by
      default every shape, visemes guiding the speech groups and the rest filled unguided.
    - `method`: see `METHODS`; `weights` a network's weights file; `library` clips retrieval draws
      from (default 120 s of procedural faces; the clip itself outside the spans is always searched).
    - `max_rows`, `max_mask_s`: the job's limits (default one hour at 60 fps, 600 s).

    Returns an `Edit`: `clips` (N `FaceClip`s at the input's frame times) and `reports`.
    """
    if not isinstance(clip, FaceClip):
        raise InbetweenError(
            f"clip: {type(clip).__name__}; expected a FaceClip (inbetween.read of a Live Link Face CSV or a curve "
            "CSV/JSON, FaceClip.from_arrays or face.synth)"
        )
    if method not in METHODS:
        raise InbetweenError(f"method {method!r}: expected one of {', '.join(METHODS)}")
    if isinstance(variants, bool) or not isinstance(variants, numbers.Integral) or variants < 1:
        raise InbetweenError(f"variants {variants!r}: expected a whole number, at least 1")
    if isinstance(seed, bool) or not isinstance(seed, numbers.Integral) or seed < 0:
        raise InbetweenError(f"seed {seed!r}: expected a whole number, at least 0")
    keys_json, keys_path = _keys(keys)
    guide_clip = guide if isinstance(guide, FaceClip) else None
    guide_path = os.fspath(guide) if guide is not None and guide_clip is None and _is_path(guide) else None
    if guide is not None and guide_clip is None and guide_path is None:
        raise InbetweenError(f"guide: {type(guide).__name__}; expected a FaceClip or a clip file")
    visemes_path, phonemes = None, None
    if visemes is not None:
        if _is_path(visemes):
            visemes_path = os.fspath(visemes)
        else:
            try:
                phonemes = [(float(a), float(b), str(p)) for a, b, p in visemes]
            except (TypeError, ValueError):
                raise ShapeError(
                    "visemes: expected a TextGrid / phoneme CSV or JSON file, or [(start_s, end_s, phoneme), …]"
                ) from None
    if groups is not None and not isinstance(groups, str):
        groups = ",".join(str(g) for g in groups)
    lib: Optional[List[FaceClip]] = None
    if library is not None:
        lib = []
        for i, item in enumerate(library):
            c = item if isinstance(item, FaceClip) else _native.read_face_clip(os.fspath(item))
            lib.append(c)
    with progress_callback(progress, "face edit") as cb:
        made = _native.face_edit(
            clip,
            _spans(spans),
            keys_json,
            keys_path,
            guide_clip,
            guide_path,
            text,
            None if text_span is None else _span(text_span, "text_span"),
            visemes_path,
            phonemes,
            tier,
            groups,
            method,
            None if weights is None else os.fspath(weights),
            lib,
            int(variants),
            int(seed),
            max_rows,
            max_mask_s,
            cb,
        )
    clips, reports = [], []
    for edited, d in made:
        clips.append(edited)
        reports.append(
            EditReport(
                variant=int(d["variant"]),
                seed=int(d["seed"]),
                method=d["method"],
                guidance=d["guidance"],
                spans_s=[(float(a), float(b)) for a, b in d["spans_s"]],
                model_fps=float(d["model_fps"]),
                segments=[(int(a), int(b)) for a, b in d["segments"]],
                key_frames=[int(f) for f in d["key_frames"]],
                masked_mse=float(d["masked_mse"]),
                difference_from_first=None if d["difference_from_first"] is None else float(d["difference_from_first"]),
                changed_rows=(int(d["changed_rows"][0]), int(d["changed_rows"][1])),
                changed_shapes=list(d["changed_shapes"]),
                ms=float(d["ms"]),
                notes=list(d["notes"]),
                before=d["before"],
                after=d["after"],
                mask=d["mask"],
                text=d["text"],
            )
        )
    return Edit(clips=clips, reports=reports)


def synth(seconds: float = 10.0, seed: int = 1) -> Tuple[FaceClip, List[Tuple[float, float, str]]]:
    """A procedural face capture (as `inbetween face synth`): speech, blinks, expressions, head and
    gaze at 25 fps, and the phonemes it speaks as `(start_s, end_s, ARPAbet phoneme)`; the same seed
    gives the same clip."""
    return _native.face_synth(float(seconds), int(seed))
