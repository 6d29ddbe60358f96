"""Keyframes of a motion clip: choose them (`select_keys`), rebuild the clip from them
(`reconstruct`), and hand them to a curve editor (`bezier_handles`)."""

from __future__ import annotations

import functools
import json
from dataclasses import dataclass, field
from typing import Any, Dict, Optional, Sequence

import numpy as np

from . import _native
from ._native import Clip, InbetweenError
from ._progress import Callback, progress_callback

__all__ = ["Keys", "Reconstruction", "BezierHandles", "select_keys", "reconstruct", "bezier_handles", "METHODS", "CURVES"]

METHODS = ("optimal", "error_bounded", "greedy", "sidql", "uniform")
#: How rotations are evaluated between keys: "hermite" (the engine's own, on the rotation
#: manifold) or "quaternion_bezier" (a cubic per quaternion component, normalised: what a DCC plays
#: back from Bezier F-curves with the handles of `bezier_handles`, e.g. Blender's quaternion mode)
#: or "euler_bezier" (a cubic per Euler angle, `pre ⊗ R(E)`: what a DCC plays from Euler F-curves,
#: e.g. Blender's Euler modes, BVH and Maya channels; see `select_keys` for the playback).
CURVES = ("hermite", "quaternion_bezier", "euler_bezier")


@dataclass(frozen=True)
class Reconstruction:
    """A clip rebuilt from keys and its joint position error against the source."""

    clip: Clip
    #: Mean joint position error of each frame, cm, float64 `[T]`.
    error_per_frame_cm: np.ndarray
    mean_error_cm: float
    max_error_cm: float
    #: The engine's report: a dict, or the native report (read into a dict on first use).
    _report: Any = field(repr=False, compare=False)
    _text: Optional[str] = field(default=None, repr=False, compare=False)

    @functools.cached_property
    def report(self) -> Dict[str, Any]:
        """The job's report (keys, curve, error) as a dict."""
        return self._report if isinstance(self._report, dict) else json.loads(self._report.json())

    @property
    def text(self) -> str:
        """The job's report in words."""
        return self._text if self._text is not None else str(self._report)


@dataclass(frozen=True)
class Keys:
    """Key frames chosen by `select_keys`, the key poses with their tangents, and the errors."""

    #: Frame index of each key, int64 `[K]` (first and last frame included).
    frames: np.ndarray
    #: Local rotations at the keys, unit quaternions (x, y, z, w), float32 `[K, J, 4]`.
    rotations: np.ndarray
    #: Body-frame angular velocities at the keys (the rotation tangents), rad/s, float32 `[K, J, 3]`.
    angular_velocities: np.ndarray
    #: Local translations at the keys (rest offsets plus channels), cm, float32 `[K, J, 3]`.
    translations_cm: np.ndarray
    #: Translation velocities at the keys (the translation tangents), cm/s, float32 `[K, J, 3]`.
    velocities_cm_s: np.ndarray
    method: str
    #: The rebuilt clip and its measured error.
    reconstruction: Reconstruction
    #: The job's report (planned spherical-model error, timings) as a dict, and in words.
    report: Dict[str, Any] = field(repr=False)
    text: str = field(repr=False)
    #: With curve "euler_bezier": the Euler angles at the keys (x, y, z by axis, radians, NaN for
    #: joints played from quaternions) and their rates (rad/s), float32 `[K, J, 3]`; else None.
    euler_angles: Optional[np.ndarray] = None
    euler_rates: Optional[np.ndarray] = None

    def __len__(self) -> int:
        return len(self.frames)


def _reconstruction(clip: Clip, report: Dict[str, Any], text: str) -> Reconstruction:
    err = report["error"]
    return Reconstruction(
        clip=clip,
        error_per_frame_cm=np.asarray(err["per_frame_cm"], dtype=np.float64),
        mean_error_cm=float(err["mean_cm"]),
        max_error_cm=float(err["max_cm"]),
        _report=report,
        _text=text,
    )


def _euler(
    clip: Clip,
    curve: str,
    euler_orders: Optional[Sequence[Optional[str]]],
    pre_rotations: Any,
    euler_reference: Any,
) -> Dict[str, Any]:
    """The Euler playback arguments of the native calls, checked and flattened."""
    given = euler_orders is not None or pre_rotations is not None or euler_reference is not None
    if given and curve != "euler_bezier":
        raise InbetweenError(f"euler_orders, pre_rotations and euler_reference need curve 'euler_bezier', not {curve!r}")
    out: Dict[str, Any] = {}
    if euler_orders is not None:
        out["euler_orders"] = [None if o is None else str(o) for o in euler_orders]
    for name, value, width in (("pre_rotations", pre_rotations, 4), ("euler_reference", euler_reference, 3)):
        if value is None:
            continue
        arr = np.asarray(value, dtype=np.float64)
        if arr.ndim < 2 or arr.shape[-1] != width:
            raise InbetweenError(f"{name}: expected float [..., {width}], got shape {list(arr.shape)}")
        out[name] = arr.ravel().tolist()
    return out


def select_keys(
    clip: Clip,
    max_error_cm: Optional[float] = None,
    *,
    max_error_deg: Optional[float] = None,
    k: Optional[int] = None,
    method: Optional[str] = None,
    curve: str = "hermite",
    max_gap_s: Optional[float] = None,
    progress: Optional[Callback] = None,
    euler_orders: Optional[Sequence[Optional[str]]] = None,
    pre_rotations: Any = None,
    euler_reference: Any = None,
) -> Keys:
    """Keyframes of `clip` by the mocap engine's `SelectJob`.

    Give `max_error_cm` and/or `max_error_deg` (the fewest keys keeping every joint of every frame
    within them, positions in cm and local rotations in degrees, measured on the clip rebuilt
    along `curve`; method "error_bounded") or `k` keys (method "optimal" unless `method` names
    "greedy", "sidql" or "uniform"). The clip is rebuilt from the keys (rotations along `curve`,
    cubic Hermite translations) and the error measured on it. For keys a DCC will play back with
    Bezier curves, pass `curve="quaternion_bezier"` (quaternion F-curves) or `curve="euler_bezier"`
    (Euler F-curves) and hand the keys to `bezier_handles` with the same arguments.

    Euler playback: a joint's local rotation is `pre ⊗ R(E)`. `euler_orders` gives each joint's
    order in the engine's convention (the BVH channel order, composed left to right: "ZYX" is
    Rz·Ry·Rx, which Blender calls "XYZ"; None: that joint plays quaternion curves), by default the
    clip's own channels; `pre_rotations` `[J, 4]` (x, y, z, w) a constant rotation on the left
    (Blender: the bone's rest rotation relative to its parent), by default none; `euler_reference`
    `[T, J, 3]` the DCC's own angles (x, y, z by axis, radians), so the keys carry the curves'
    own values (by default the angles are made continuous along each track)."""
    bounded = max_error_cm is not None or max_error_deg is not None
    if method is None:
        method = "error_bounded" if bounded else "optimal"
    if method not in METHODS and method not in ("bound", "error-bounded"):
        raise InbetweenError(f"method {method!r}: expected one of {', '.join(METHODS)}")
    if curve not in CURVES:
        raise InbetweenError(f"curve {curve!r}: expected one of {', '.join(CURVES)}")
    if method in ("error_bounded", "bound", "error-bounded"):
        if not bounded or k is not None:
            raise InbetweenError(f"method {method!r} takes max_error_cm and/or max_error_deg (bounds), not k")
    elif k is None or bounded:
        raise InbetweenError(f"method {method!r} takes k (the number of keys, ends included), not max_error_cm")
    euler = _euler(clip, curve, euler_orders, pre_rotations, euler_reference)
    with progress_callback(progress, "choosing keys") as cb:
        frames, poses, report_json, text, rebuilt, rec_text = _native.mocap_select(
            clip, method, k, max_error_cm, max_gap_s, cb, max_error_deg, curve, **euler
        )
    report = json.loads(report_json)
    rec = report["reconstruction"]
    return Keys(
        frames=np.asarray(frames, dtype=np.int64),
        rotations=poses["rotations"],
        angular_velocities=poses["angular_velocities"],
        translations_cm=poses["translations_cm"],
        velocities_cm_s=poses["velocities_cm_s"],
        method=report["method"],
        reconstruction=_reconstruction(rebuilt, rec, rec_text),
        report=report,
        text=text,
        euler_angles=poses.get("euler_angles"),
        euler_rates=poses.get("euler_rates"),
    )


def _frames(keys: "Keys | Sequence[int] | np.ndarray") -> list:
    frames = keys.frames if isinstance(keys, Keys) else keys
    arr = np.asarray(frames)
    if arr.ndim != 1 or arr.dtype.kind not in "iu":
        raise InbetweenError(f"keys: expected frame indices, int [K]; got dtype {arr.dtype} shape {list(arr.shape)}")
    return [int(f) for f in arr]


def reconstruct(
    clip: Clip,
    keys: "Keys | Sequence[int] | np.ndarray",
    *,
    curve: Optional[str] = None,
    progress: Optional[Callback] = None,
    euler_orders: Optional[Sequence[Optional[str]]] = None,
    pre_rotations: Any = None,
    euler_reference: Any = None,
) -> Reconstruction:
    """`clip` rebuilt from its poses at `keys` (a `Keys`, or frame indices; the first and last
    frames are added when missing) by the mocap engine's `ReconstructJob`, rotations along `curve`
    (by default the one `keys` were chosen with, else "hermite"; Euler playback as in
    `select_keys`)."""
    if curve is None:
        curve = keys.report["reconstruction"]["curve"] if isinstance(keys, Keys) else "hermite"
    if curve not in CURVES:
        raise InbetweenError(f"curve {curve!r}: expected one of {', '.join(CURVES)}")
    euler = _euler(clip, curve, euler_orders, pre_rotations, euler_reference)
    frames = _frames(keys)
    with progress_callback(progress, "reconstructing") as cb:
        rebuilt, per_frame_cm, mean_cm, max_cm, report = _native.mocap_reconstruct(clip, frames, cb, curve, **euler)
    return Reconstruction(rebuilt, per_frame_cm, mean_cm, max_cm, report)


@dataclass(frozen=True)
class BezierHandles:
    """Keys as a DCC's Bezier F-curves hold them: per key a value and a left and a right handle
    for each quaternion component (x, y, z, w) and each translation axis of every joint. A DCC
    evaluating these curves (handles "free" or "aligned", never "auto"; quaternions normalised)
    plays back exactly `reconstruct(clip, keys, curve="quaternion_bezier")`."""

    #: Key frames, int64 `[K]`.
    frames: np.ndarray
    #: Each key's left and right handle times, frames (fractional), float64 `[K]`.
    left_frames: np.ndarray
    right_frames: np.ndarray
    #: Local rotations (x, y, z, w), signs continuous along each joint, float64 `[K, J, 4]`, and
    #: their handles' values.
    rotations: np.ndarray
    rotations_left: np.ndarray
    rotations_right: np.ndarray
    #: Local translations (rest offsets plus channels), cm, float64 `[K, J, 3]`, and handles.
    translations_cm: np.ndarray
    translations_left_cm: np.ndarray
    translations_right_cm: np.ndarray
    #: With curve "euler_bezier": Euler angles (x, y, z by axis: the DCC's X, Y and Z rotation
    #: curves), radians, continuous along each joint (NaN for joints played from quaternions),
    #: float64 `[K, J, 3]`, and handles; else None.
    euler: Optional[np.ndarray] = None
    euler_left: Optional[np.ndarray] = None
    euler_right: Optional[np.ndarray] = None


def bezier_handles(
    clip: Clip,
    keys: "Keys | Sequence[int] | np.ndarray",
    *,
    curve: str = "quaternion_bezier",
    euler_orders: Optional[Sequence[Optional[str]]] = None,
    pre_rotations: Any = None,
    euler_reference: Any = None,
) -> BezierHandles:
    """The Bezier keys (values and handles) that make a DCC's own curve evaluation reproduce the
    engine's "quaternion_bezier" in-betweens of `clip` at `keys` (choose the keys with
    `select_keys(..., curve="quaternion_bezier")` for the bound to hold on the DCC's playback).
    With `curve="euler_bezier"` and the Euler playback `select_keys` was given, also the Euler
    curves that play its "euler_bezier" in-betweens."""
    if curve not in ("quaternion_bezier", "euler_bezier"):
        raise InbetweenError(f"curve {curve!r}: expected quaternion_bezier or euler_bezier")
    euler = _euler(clip, curve, euler_orders, pre_rotations, euler_reference)
    d = _native.mocap_bezier(clip, _frames(keys), curve, **euler)
    return BezierHandles(frames=np.asarray(d.pop("frames"), dtype=np.int64), **d)
