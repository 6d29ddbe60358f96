"""The `inbetween` package: bundled in the add-on folder (`_vendor/`, Blender 3.x) or installed
from the extension's wheel (4.2+)."""

from __future__ import annotations

import inspect
import os
import sys


VENDOR = os.path.join(os.path.dirname(__file__), "_vendor")


def add_vendor_path() -> None:
    if os.path.isdir(VENDOR) and VENDOR not in sys.path:
        sys.path.insert(0, VENDOR)


def require():
    """The `inbetween` module, or an error that says how to get it."""
    from .jobs import JobError

    add_vendor_path()
    try:
        import inbetween
    except ImportError as e:
        raise JobError(
            f"the inbetween engines are not installed ({e}); build the add-on with "
            "scripts/build-blender-addon.sh, or pip install the inbetween package into Blender's Python"
        ) from None
    return inbetween


#: The curve Blender evaluates for a pose bone in quaternion mode with FREE handles a third of a
#: segment out: per-component cubic Hermite, normalised (mocap's `RotationCurve::QuaternionBezier`).
CURVE = "quaternion_bezier"
#: The curve Blender evaluates for pose bones in Euler modes (three Bezier F-curves, composed after
#: the bone's rest rotation), the others as CURVE (mocap's `RotationCurve::EulerBezier`).
EULER_CURVE = "euler_bezier"


def _has(fn, name: str) -> bool:
    try:
        return name in inspect.signature(fn).parameters
    except (TypeError, ValueError):
        return False


def select_keys(clip, method: str, bound_cm, k, progress=None, bound_deg=None, euler=None):
    """Key frames of `clip` chosen for Blender's curves: `inbetween.mocap.select_keys` with
    `curve="quaternion_bezier"`, or with `euler` (a dict of `euler_orders`, `pre_rotations`,
    `euler_reference`) `curve="euler_bezier"`, so the engine's bounds (cm, and degrees when given)
    hold on what Blender plays for quaternion and Euler bones."""
    from .jobs import JobError

    mocap = require().mocap
    if not _has(mocap.select_keys, "curve"):
        raise JobError("this inbetween package has no Blender curve (select_keys(curve=...)); update it")
    if euler and not _has(mocap.select_keys, "euler_orders"):
        raise JobError("this inbetween package has no Euler curve (select_keys(euler_orders=...)); update it")
    kwargs = {"method": method, "progress": progress, "curve": EULER_CURVE if euler else CURVE, **(euler or {})}
    if bound_cm is not None:
        kwargs["max_error_cm"] = bound_cm
        if bound_deg:
            kwargs["max_error_deg"] = bound_deg
    else:
        kwargs["k"] = k
    return mocap.select_keys(clip, **kwargs)


def bezier_handles(clip, frames, euler=None) -> dict:
    """Per key and joint the value and both handles of every channel (`inbetween.mocap.
    bezier_handles`): `frames`, `left_frames`, `right_frames` `[K]`; `rotations`,
    `rotations_left`, `rotations_right` `[K, J, 4]` (x, y, z, w); `translations_cm`,
    `translations_left_cm`, `translations_right_cm` `[K, J, 3]`; with `euler` (as for
    `select_keys`) `euler`, `euler_left`, `euler_right` `[K, J, 3]` (x, y, z, radians)."""
    mocap = require().mocap
    if euler:
        out = mocap.bezier_handles(clip, [int(f) for f in frames], curve=EULER_CURVE, **euler)
    else:
        out = mocap.bezier_handles(clip, [int(f) for f in frames])
    return {name: getattr(out, name, None) for name in _BEZIER_FIELDS}


_BEZIER_FIELDS = (
    "frames",
    "left_frames",
    "right_frames",
    "rotations",
    "rotations_left",
    "rotations_right",
    "translations_cm",
    "translations_left_cm",
    "translations_right_cm",
    "euler",
    "euler_left",
    "euler_right",
)
