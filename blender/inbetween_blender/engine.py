"""The `inbetween` package: bundled in the add-on folder (`_vendor/`, Blender 3.x) or installed
from the extension's wheel (4.2+)."""

from __future__ import annotations

import inspect
import os
import sys

import numpy as np

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


def select_keys(clip, method: str, bound_cm, k, progress=None):
    """Key frames of `clip` chosen for Blender's curve: `inbetween.mocap.select_keys` with
    `curve="quaternion_bezier"`, so the engine's bound holds on what Blender plays."""
    inbetween = require()
    from .jobs import JobError

    mocap = inbetween.mocap
    if _has(mocap.select_keys, "curve"):
        kwargs = {"method": method, "progress": progress, "curve": CURVE}
        if bound_cm is not None:
            kwargs["max_error_cm"] = bound_cm
        else:
            kwargs["k"] = k
        return mocap.select_keys(clip, **kwargs)
    native = inbetween._native
    if not hasattr(native, "mocap_bezier"):
        raise JobError(f"the inbetween package {inbetween.__version__} has no Blender curve; update it")
    # A package whose Python layer predates the curve option: the same job through its module.
    import json

    frames, poses, report_json, text, rebuilt = native.mocap_select(
        clip, method, k, bound_cm, None, progress or None, None, CURVE
    )
    report = json.loads(report_json)
    return mocap.Keys(
        frames=np.asarray(frames, dtype=np.int64),
        rotations=poses["rotations"],
        angular_velocities=poses["angular_velocities"],
        translations_cm=poses["translations_cm"],
        velocities_cm_s=poses["velocities_cm_s"],
        method=report["method"],
        reconstruction=mocap._reconstruction(rebuilt, report["reconstruction"], str(rebuilt)),
        report=report,
        text=text,
    )


def bezier_handles(clip, frames) -> dict:
    """Per key and joint the value and both handles of every channel (`inbetween.mocap.
    bezier_handles`): `frames`, `left_frames`, `right_frames` `[K]`; `rotations`,
    `rotations_left`, `rotations_right` `[K, J, 4]` (x, y, z, w); `translations_cm`,
    `translations_left_cm`, `translations_right_cm` `[K, J, 3]`."""
    inbetween = require()
    keys = [int(f) for f in frames]
    fn = getattr(inbetween.mocap, "bezier_handles", None)
    out = fn(clip, keys) if fn is not None else inbetween._native.mocap_bezier(clip, keys)
    if isinstance(out, dict):
        return out
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
