"""Type stubs of the extension module (the public API is re-exported by `inbetween`)."""

import os
from typing import Any, Callable, Dict, List, Optional, Tuple

import numpy as np
import numpy.typing as npt

_Progress = Optional[Callable[[int, int], object]]
_Path = str | os.PathLike[str]

__version__: str

class InbetweenError(Exception): ...
class ShapeError(InbetweenError): ...

class Clip:
    """A skeleton's motion (BVH or ASF/AMC), in the file's own form and unit."""

    @property
    def joints(self) -> List[str]: ...
    @property
    def parents(self) -> List[int]: ...
    @property
    def offsets_cm(self) -> npt.NDArray[np.float32]: ...
    @property
    def fps(self) -> float: ...
    @property
    def num_frames(self) -> int: ...
    @property
    def duration_s(self) -> float: ...
    @property
    def cm_per_unit(self) -> float: ...
    @property
    def unit(self) -> str: ...
    @property
    def source(self) -> str: ...
    @property
    def rotations(self) -> npt.NDArray[np.float32]: ...
    @property
    def translations(self) -> npt.NDArray[np.float32]: ...
    def positions_cm(self) -> npt.NDArray[np.float32]: ...
    @staticmethod
    def from_arrays(
        joints: List[str],
        parents: List[int],
        offsets_cm: npt.ArrayLike,
        fps: float,
        rotations: npt.ArrayLike,
        translations: npt.ArrayLike,
    ) -> Clip: ...
    def crop(self, start: int, end: Optional[int] = None) -> Clip: ...
    def write(self, path: _Path) -> None: ...
    def to_bvh(self) -> str: ...
    def preview(
        self,
        path: _Path,
        frame: Optional[int] = None,
        compare: Optional[Clip] = None,
        width: int = 480,
        height: int = 360,
        max_frames: int = 150,
        title: Optional[str] = None,
        progress: _Progress = None,
    ) -> str: ...
    def _repr_png_(self) -> bytes: ...
    def __len__(self) -> int: ...

class FaceClip:
    """ARKit blendshape weights over time (Live Link Face CSV, curve CSV/JSON)."""

    @property
    def names(self) -> List[str]: ...
    @property
    def fps(self) -> float: ...
    @property
    def times(self) -> npt.NDArray[np.float64]: ...
    @property
    def num_frames(self) -> int: ...
    @property
    def source(self) -> str: ...
    @property
    def weights(self) -> npt.NDArray[np.float32]: ...
    @staticmethod
    def from_arrays(weights: npt.ArrayLike, fps: float) -> FaceClip: ...
    @property
    def channel_names(self) -> List[str]: ...
    @property
    def values(self) -> npt.NDArray[np.float32]: ...
    @property
    def duration_s(self) -> float: ...
    def write(self, path: _Path, live_link: Optional[bool] = None) -> None: ...
    def preview(self, path: _Path, compare: Optional[FaceClip] = None, progress: _Progress = None) -> str: ...
    def _repr_png_(self) -> bytes: ...
    def __len__(self) -> int: ...

class Reader:
    """Runtime sampler of an .ibk version 4 file."""

    def __init__(self, data: bytes) -> None: ...
    @property
    def num_joints(self) -> int: ...
    @property
    def num_frames(self) -> int: ...
    @property
    def duration_s(self) -> float: ...
    @property
    def fps(self) -> float: ...
    @property
    def bound_cm(self) -> float: ...
    @property
    def joints(self) -> List[str]: ...
    @property
    def parents(self) -> List[int]: ...
    def sample(self, t: float, rotations: npt.NDArray[np.float32], translations: npt.NDArray[np.float32]) -> None: ...

def read_clip(path: _Path, unit: Optional[str] = None) -> Clip: ...
def read_face_clip(path: _Path) -> FaceClip: ...
def ibk_compress(
    clip: Clip,
    max_error_cm: Optional[float],
    k: Optional[int],
    version: Optional[str],
    segment_len: Optional[int],
    max_gap_s: float,
    progress: _Progress,
) -> Tuple[bytes, str]: ...
def ibk_decompress(data: bytes) -> Clip: ...
class JobReport:
    """An engine job's report: `json()` its JSON, `str()` its words."""

    def json(self) -> str: ...
    def __str__(self) -> str: ...

def mocap_select(
    clip: Clip,
    method: str,
    k: Optional[int] = None,
    bound_cm: Optional[float] = None,
    max_gap_s: Optional[float] = None,
    progress: _Progress = None,
    bound_deg: Optional[float] = None,
    curve: Optional[str] = None,
    euler_orders: Optional[List[Optional[str]]] = None,
    pre_rotations: Optional[List[float]] = None,
    euler_reference: Optional[List[float]] = None,
) -> Tuple[List[int], Dict[str, npt.NDArray[np.float32]], str, str, Clip, str]: ...
def mocap_reconstruct(
    clip: Clip,
    keys: List[int],
    progress: _Progress = None,
    curve: Optional[str] = None,
    euler_orders: Optional[List[Optional[str]]] = None,
    pre_rotations: Optional[List[float]] = None,
    euler_reference: Optional[List[float]] = None,
) -> Tuple[Clip, npt.NDArray[np.float64], float, float, JobReport]: ...
def mocap_bezier(
    clip: Clip,
    keys: List[int],
    curve: Optional[str] = None,
    euler_orders: Optional[List[Optional[str]]] = None,
    pre_rotations: Optional[List[float]] = None,
    euler_reference: Optional[List[float]] = None,
) -> Dict[str, Any]: ...
def camera_generate(
    keys_json: str,
    characters: Optional[Tuple[Clip, Clip]] = None,
    scene: Optional[str] = None,
    style: str = "relative",
    exact_keys: bool = True,
    causal: bool = False,
    json: Optional[str] = None,
    gltf: Optional[str] = None,
    gif: Optional[str] = None,
    progress: _Progress = None,
    fov_deg: Optional[float] = None,
    aspect: Optional[float] = None,
    names: Optional[Tuple[str, str]] = None,
    reference: Optional[Tuple[List[List[float]], List[List[float]]]] = None,
) -> Dict[str, Any]: ...
def face_edit(
    clip: FaceClip,
    spans: List[Tuple[float, float] | str],
    keys_json: Optional[str] = None,
    keys_path: Optional[_Path] = None,
    guide: Optional[FaceClip] = None,
    guide_path: Optional[_Path] = None,
    text: Optional[str] = None,
    text_span: Optional[Tuple[float, float] | str] = None,
    visemes_path: Optional[_Path] = None,
    phonemes: Optional[List[Tuple[float, float, str]]] = None,
    tier: Optional[str] = None,
    groups: Optional[str] = None,
    method: str = "auto",
    weights: Optional[_Path] = None,
    library: Optional[List[FaceClip]] = None,
    variants: int = 1,
    seed: int = 1,
    max_rows: Optional[int] = None,
    max_mask_s: Optional[float] = None,
    progress: _Progress = None,
) -> List[Tuple[FaceClip, Dict[str, Any]]]: ...
def face_synth(seconds: float = 10.0, seed: int = 1) -> Tuple[FaceClip, List[Tuple[float, float, str]]]: ...
def video_resequence(
    path: _Path,
    start: int = 0,
    length: Optional[int] = None,
    seed: Optional[int] = None,
    loop_close: bool = False,
    count: int = 1,
    out: Optional[_Path] = None,
    sheet: Optional[_Path] = None,
    blend: int = 0,
    explain: bool = False,
    stop_early: bool = False,
    transitions: bool = True,
    allow_reverse: bool = False,
    allow_cuts: bool = False,
    metric: str = "rsfnet",
    steps: Optional[int] = None,
    cache_dir: Optional[_Path] = None,
    max_frames: Optional[int] = None,
    progress: _Progress = None,
) -> Tuple[str, str, List[npt.NDArray[np.int64]]]: ...
def script_run(
    text: str,
    out_dir: Optional[str] = None,
    seed: Optional[int] = None,
    optimize: Optional[bool] = None,
    shared_motions: Optional[bool] = None,
    progress: _Progress = None,
) -> Dict[str, Any]: ...
def batch_run_input(job: str, path: _Path, root: _Path, out: _Path, options: str) -> str: ...
def batch_extensions(job: str) -> List[str]: ...
def _bench_rust(
    what: str,
    clip: Clip,
    repeats: int,
    method: Optional[str] = None,
    k: Optional[int] = None,
    bound_cm: Optional[float] = None,
    keys: Optional[List[int]] = None,
    max_error_cm: Optional[float] = None,
    pool: bool = True,
) -> List[float]: ...
def _bench_sample_rust(data: bytes, times: List[float]) -> float: ...
def _bench_face_rust(
    clip: FaceClip,
    spans: List[Tuple[float, float]],
    repeats: int,
    variants: int = 1,
    seed: int = 1,
    keys_json: Optional[str] = None,
    pool: bool = True,
) -> List[float]: ...
def _panic_in_job() -> None: ...
def _bench_video_rust(
    path: _Path,
    repeats: int,
    start: int = 0,
    length: Optional[int] = None,
    seed: int = 1,
    metric: str = "rsfnet",
    cache_dir: Optional[_Path] = None,
    pool: bool = True,
) -> List[float]: ...
def _rayon_threads() -> int: ...
def _build_profile() -> str: ...
def _empty_job() -> None: ...
