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


def _has(fn, name: str) -> bool:
    try:
        return name in inspect.signature(fn).parameters
    except (TypeError, ValueError):
        return False


def select_keys(clip, method: str, bound_cm, k, progress=None, bound_deg=None):
    """Key frames of `clip` chosen for Blender's curve: `inbetween.mocap.select_keys` with
    `curve="quaternion_bezier"`, so the engine's bounds (cm, and degrees when given) hold on what
    Blender plays for quaternion bones."""
    from .jobs import JobError

    mocap = require().mocap
    if not _has(mocap.select_keys, "curve"):
        raise JobError("this inbetween package has no Blender curve (select_keys(curve=...)); update it")
    kwargs = {"method": method, "progress": progress, "curve": CURVE}
    if bound_cm is not None:
        kwargs["max_error_cm"] = bound_cm
        if bound_deg:
            kwargs["max_error_deg"] = bound_deg
    else:
        kwargs["k"] = k
    return mocap.select_keys(clip, **kwargs)


def bezier_handles(clip, frames) -> dict:
    """Per key and joint the value and both handles of every channel (`inbetween.mocap.
    bezier_handles`): `frames`, `left_frames`, `right_frames` `[K]`; `rotations`,
    `rotations_left`, `rotations_right` `[K, J, 4]` (x, y, z, w); `translations_cm`,
    `translations_left_cm`, `translations_right_cm` `[K, J, 3]`."""
    out = require().mocap.bezier_handles(clip, [int(f) for f in frames])
    return {name: getattr(out, name) for name in _BEZIER_FIELDS}


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
)
