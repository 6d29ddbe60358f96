"""Text to animation: a story in plain English becomes a furnished, animated scene."""

from __future__ import annotations

import json
import os
from dataclasses import dataclass, field
from typing import Any, Dict, List, Optional

from . import _native
from ._native import Clip
from ._progress import Callback, progress_callback

__all__ = ["Story", "run"]


@dataclass(frozen=True)
class Story:
    """What `run` made."""

    gltf: bytes  #: the animated scene, glTF 2.0 (JSON, buffers embedded)
    characters: Dict[str, Clip]  #: one clip per character (the common rig, metres)
    scene: Dict[str, Any]  #: the scene graph: room, placed objects, relations
    frames: int
    fps: float
    notes: List[str]  #: what could not be done as asked
    files: List[str] = field(repr=False)  #: files written (only when `out_dir` was given)


def run(
    text: str,
    *,
    out_dir: "Optional[str | os.PathLike[str]]" = None,
    seed: Optional[int] = None,
    optimize: Optional[bool] = None,
    shared_motions: Optional[bool] = None,
    progress: Optional[Callback] = None,
) -> Story:
    """Animates `text` by the script engine's `RunJob` (as `inbetween script run`); the job's
    defaults apply where an argument is None. With `out_dir` the glTF, a BVH per character, the
    preview GIF and the charts are also written there."""
    with progress_callback(progress, "script") as cb:
        d = _native.script_run(text, None if out_dir is None else os.fspath(out_dir), seed, optimize, shared_motions, cb)
    return Story(
        gltf=bytes(d["gltf"]),
        characters=dict(d["characters"]),
        scene=json.loads(d["scene_json"]),
        frames=int(d["frames"]),
        fps=float(d["fps"]),
        notes=list(d["notes"]),
        files=[str(p) for p in d["files"]],
    )
