"""Camera in-betweening: a camera track through keyframes over two characters, in a style."""

from __future__ import annotations

import json
import os
from dataclasses import dataclass, field
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple

import numpy as np

from . import _native
from ._native import Clip, InbetweenError
from ._progress import Callback, progress_callback

__all__ = ["Track", "generate", "pose_key", "STYLES"]

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
    #: world positions of the two framed targets (15 cm above each one's shoulder midpoint), metres `[T, 2, 3]`
    targets_m: np.ndarray
    aspect: float  #: the lens's width / height
    characters: List[str]
    fps: float
    style: str
    #: (key frame, the network's miss there before correction, Toric units)
    key_residuals: List[Tuple[int, float]]
    worst_key_miss: float
    max_corrected_residual: float
    text: str = field(repr=False)
    #: what building the scene from two takes did beyond the obvious (roles found, a take moved aside)
    notes: List[str] = field(default_factory=list)


def pose_key(
    frame: int,
    position: Sequence[float],
    rotation: Sequence[float],
    fov_deg: Optional[float] = None,
    targets: Optional[Tuple[str, str]] = None,
) -> Dict[str, Any]:
    """A keyframe given as a camera pose: world `position` in metres (Y up), `rotation` a unit
    quaternion (x, y, z, w) from camera to world (the camera looks down its local -Z, +Y up),
    `fov_deg` its vertical field of view (then the lens's). The engine turns it into Toric
    coordinates at `frame` against the key's two targets."""
    cam: Dict[str, Any] = {"position": [float(v) for v in position], "rotation": [float(v) for v in rotation]}
    if fov_deg is not None:
        cam["fov_deg"] = float(fov_deg)
    key: Dict[str, Any] = {"frame": int(frame), "camera": cam}
    if targets is not None:
        key["targets"] = list(targets)
    return key


_POSE_FIELDS = ("position", "rotation", "fov_deg")


def _key(k: Mapping[str, Any]) -> Dict[str, Any]:
    """A key as the keys file holds it; `position`/`rotation`/`fov_deg` at the top level move into
    its `camera`."""
    d = dict(k)
    if any(f in d for f in _POSE_FIELDS):
        if "camera" in d:
            raise InbetweenError(
                f"key at frame {d.get('frame')}: give either `camera` or a pose (position, rotation), not both"
            )
        d["camera"] = {f: d.pop(f) for f in _POSE_FIELDS if f in d}
    cam = d.get("camera")
    if isinstance(cam, Mapping):
        d["camera"] = {n: np.asarray(v, dtype=np.float64).tolist() for n, v in cam.items()}
    return d


def _reference(ref: Any) -> Optional[Tuple[List[List[float]], List[List[float]]]]:
    if ref is None:
        return None
    pos, rot = (ref.positions_m, ref.rotations) if isinstance(ref, Track) else ref
    pos, rot = np.asarray(pos, dtype=np.float64), np.asarray(rot, dtype=np.float64)
    if pos.ndim != 2 or pos.shape[1] != 3 or rot.shape != (len(pos), 4):
        raise InbetweenError(f"reference: positions {pos.shape} and rotations {rot.shape}; expected [T, 3] and [T, 4]")
    return pos.tolist(), rot.tolist()


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
    fov_deg: Optional[float] = None,
    aspect: Optional[float] = None,
    names: Optional[Tuple[str, str]] = None,
    reference: "Optional[Track | Tuple[Any, Any]]" = None,
) -> Track:
    """A camera track by the camera engine's `GenerateJob` (as `inbetween camera generate`).

    `keys`: keyframes as the keys file holds them, e.g. `{"frame": 0, "camera": {"pa": [-0.33, 0],
    "pb": [0.33, 0], "theta": 0.9, "phi": 0.2}}` (optional `targets`, `velocity`), or as a camera
    pose (`pose_key(frame, position, rotation, fov_deg)`, or a dict with `position`, `rotation`
    (x, y, z, w) and `fov_deg`), which the engine turns into Toric coordinates at the key's frame;
    a pose that cannot frame both targets there raises `InbetweenError` naming the key's frame.
    The lens: `fov_deg` (vertical) and `aspect` (width / height), by default the first pose key's
    field of view (else 45 degrees) and 16:9. The scene is
    two mocap clips (`characters=(a, b)`: roots from the hips, shoulders from the upper arms;
    `names=(name_a, name_b)` names them for keys' `targets` and `main`, default their files) or a
    scene JSON. `json_path`, `gltf`, `gif` also write the track, a glTF camera animation and a
    top-down preview. `reference`: a camera to take the style from instead of `style`, as world
    `(positions [T, 3] metres, rotations [T, 4] (x, y, z, w))` over the same scene, one per frame
    from frame 0 (at least 10 of the networks' 1/6 s steps: 50 frames at 30 fps, 200 at 120 fps),
    or a `Track` over it; the extractor's code (§4.1) from its Toric track against the two
    characters."""
    doc: Dict[str, Any] = {"keys": [_key(k) for k in keys]}
    if main is not None:
        doc["main"] = main
    fspath = lambda p: None if p is None else os.fspath(p)  # noqa: E731
    with progress_callback(progress, "camera") as cb:
        d = _native.camera_generate(
            json.dumps(doc), characters, fspath(scene), style, exact_keys, causal, fspath(json_path), fspath(gltf),
            fspath(gif), cb, fov_deg, aspect, None if names is None else (str(names[0]), str(names[1])),
            _reference(reference),
        )
    return Track(
        frames=np.asarray(d["frames"], dtype=np.int64),
        positions_m=d["positions_m"],
        rotations=d["rotations"],
        fov_y_rad=d["fov_y_rad"],
        toric=d["toric"],
        targets=np.asarray(d["targets"], dtype=np.int64).reshape(-1, 2),
        targets_m=d["targets_m"],
        aspect=float(d["aspect"]),
        characters=list(d["characters"]),
        fps=float(d["fps"]),
        style=d["style"],
        key_residuals=[(int(f), float(r)) for f, r in d["key_residuals"]],
        worst_key_miss=float(d["worst_key_miss"]),
        max_corrected_residual=float(d["max_corrected_residual"]),
        text=d["text"],
        notes=list(d["notes"]),
    )
