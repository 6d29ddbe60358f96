"""`.ibk` files: compress a clip, decompress bytes, and sample a version 4 file at run time."""

from __future__ import annotations

from typing import Optional, Tuple, Union, overload

import numpy as np

from . import _native
from ._native import Clip, Reader
from ._progress import Callback, progress_callback

__all__ = ["compress", "decompress", "Reader", "pose_buffers"]


def compress(
    clip: Clip,
    max_error_cm: Optional[float] = None,
    *,
    k: Optional[int] = None,
    version: Optional[str] = None,
    segment_len: Optional[int] = None,
    max_gap_s: float = 0.5,
    report: bool = False,
    progress: Optional[Callback] = None,
) -> Union[bytes, Tuple[bytes, str]]:
    """The `.ibk` bytes of `clip`, exactly as `inbetween mocap compress` writes them: with
    `max_error_cm` a version 4 file (every frame; `version="v3"` for the entropy-coded one), with
    `k` a version 2 file of k keyframes. `report=True` also returns the job's report text."""
    with progress_callback(progress, "compressing") as cb:
        data, text = _native.ibk_compress(clip, max_error_cm, k, version, segment_len, max_gap_s, cb)
    return (data, text) if report else data


def decompress(data: bytes) -> Clip:
    """The clip an `.ibk` file (any version) holds."""
    return _native.ibk_decompress(bytes(data))


def pose_buffers(reader: Reader) -> Tuple[np.ndarray, np.ndarray]:
    """Two zeroed float32 buffers for `reader.sample`: rotations `[J, 4]`, translations `[J, 3]`."""
    j = reader.num_joints
    return np.zeros((j, 4), np.float32), np.zeros((j, 3), np.float32)
