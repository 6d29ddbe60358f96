"""Camera in-betweening: a camera track through keyframes over two characters, in a style."""

from __future__ import annotations

import json
import os
from dataclasses import dataclass, field
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple

import numpy as np

from . import _native
from ._native import Clip
from ._progress import Callback, progress_callback

__all__ = ["Track", "generate", "STYLES"]

#: The behaviours whose style codes the committed weights carry (the CLI's `--style`).
STYLES = ("direct", "relative", "side", "orbit")


@dataclass(frozen=True)
class Track:
    """A generated camera track, one row per frame."""

    frames: np.ndarray  #: scene frame of each row, int64 `[T]`
    positions_m: np.ndarray  #: camera position, metres, float64 `[T, 3]` (Y up)
    rotations: np.ndarray  #: camera orientation, unit quaternions (x, y, z, w), float64 `[T, 4]`
    fov_y_rad: np.ndarray  #: vertical field of view, radians, float64 `[T]`
    toric: np.ndarray  #: Toric coordinates (pA.x, pA.y, pB.x, pB.y, theta, phi), float64 `[T, 6]`
    targets: np.ndarray  #: the two characters framed, int64 `[T, 2]`
    characters: List[str]
    fps: float
    style: str
    #: (key frame, the network's miss there before correction, Toric units)
    key_residuals: List[Tuple[int, float]]
    worst_key_miss: float
    max_corrected_residual: float
    text: str = field(repr=False)


def generate(
    keys: Sequence[Mapping[str, Any]],
    *,
    characters: Optional[Tuple[Clip, Clip]] = None,
    scene: "Optional[str | os.PathLike[str]]" = None,
    style: str = "relative",
    main: Optional[str] = None,
    exact_keys: bool = True,
    causal: bool = False,
    json_path: "Optional[str | os.PathLike[str]]" = None,
    gltf: "Optional[str | os.PathLike[str]]" = None,
    gif: "Optional[str | os.PathLike[str]]" = None,
    progress: Optional[Callback] = None,
) -> Track:
    """A camera track by the camera engine's `GenerateJob` (as `inbetween camera generate`).

    `keys`: keyframes as the keys file holds them, e.g. `{"frame": 0, "camera": {"pa": [-0.33, 0],
    "pb": [0.33, 0], "theta": 0.9, "phi": 0.2}}` (optional `targets`, `velocity`). The scene is
    two mocap clips (`characters=(a, b)`: roots from the hips, shoulders from the upper arms) or a
    scene JSON. `json_path`, `gltf`, `gif` also write the track, a glTF camera animation and a
    top-down preview."""
    doc: Dict[str, Any] = {"keys": [dict(k) for k in keys]}
    if main is not None:
        doc["main"] = main
    fspath = lambda p: None if p is None else os.fspath(p)  # noqa: E731
    with progress_callback(progress, "camera") as cb:
        d = _native.camera_generate(
            json.dumps(doc), characters, fspath(scene), style, exact_keys, causal, fspath(json_path), fspath(gltf),
            fspath(gif), cb,
        )
    return Track(
        frames=np.asarray(d["frames"], dtype=np.int64),
        positions_m=d["positions_m"],
        rotations=d["rotations"],
        fov_y_rad=d["fov_y_rad"],
        toric=d["toric"],
        targets=np.asarray(d["targets"], dtype=np.int64).reshape(-1, 2),
        characters=list(d["characters"]),
        fps=float(d["fps"]),
        style=d["style"],
        key_residuals=[(int(f), float(r)) for f, r in d["key_residuals"]],
        worst_key_miss=float(d["worst_key_miss"]),
        max_corrected_residual=float(d["max_corrected_residual"]),
        text=d["text"],
    )
