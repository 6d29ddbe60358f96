"""inbetween: AI-assisted keyframe animation from Python, numpy arrays in and out.

    import inbetween
    clip = inbetween.read("walk.bvh")
    keys = inbetween.mocap.select_keys(clip, max_error_cm=1.0)
    print(len(keys), "keys, max error", keys.reconstruction.max_error_cm, "cm")
    keys.reconstruction.clip.write("walk_1cm.bvh")
    keys.reconstruction.clip.preview("walk_1cm.gif", compare=clip)

Every function runs one of the engines' public jobs (the same code as the `inbetween` CLI); errors
are `InbetweenError` with the CLI's message. Long jobs release the GIL, take
`progress=callable(done, total)` (a tqdm bar when tqdm is installed and no callback is given) and
stop on Ctrl-C.
"""

from __future__ import annotations

import os
from typing import Optional, Union

from . import _native
from ._native import Clip, FaceClip, InbetweenError, ShapeError, __version__

PathLike = Union[str, "os.PathLike[str]"]

FACE_EXTENSIONS = (".csv", ".json")


def read(path: PathLike, unit: Optional[str] = None) -> Union[Clip, FaceClip]:
    """Reads a motion or face file: BVH or ASF/AMC (the .asf beside the .amc) gives a `Clip`;
    Live Link Face CSV, curve CSV or curve JSON gives a `FaceClip`. `unit` (cm, m, mm, in, cmu or
    cm per unit) overrides the length unit inferred from a skeleton's rest pose."""
    path = os.fspath(path)
    if path.lower().endswith(FACE_EXTENSIONS):
        if unit is not None:
            raise InbetweenError(f"{path}: `unit` applies to skeletons (BVH, ASF/AMC), not to face clips")
        return _native.read_face_clip(path)
    return _native.read_clip(path, unit)


from . import camera, face, ibk, mocap, script, video  # noqa: E402  (they import the names above)

__all__ = [
    "Clip",
    "FaceClip",
    "InbetweenError",
    "ShapeError",
    "read",
    "mocap",
    "ibk",
    "camera",
    "face",
    "script",
    "video",
    "__version__",
]
