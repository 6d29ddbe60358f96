"""Batch jobs on a Dask cluster: one task per input, the same outputs and result lines as
`inbetween batch` (the same Rust code runs each input).

    from dask.distributed import Client
    import inbetween.batch
    reports = inbetween.batch.map("mocap-compress", paths, client=Client(...), out="ibk", max_error_cm=1.0)

Works with any `dask.distributed` client: a `LocalCluster` (made when `client` is None), a
`dask_jobqueue.SLURMCluster`, a Kubernetes cluster (dask-kubernetes), as long as the workers can
import `inbetween` and see the paths. A task whose worker dies is run again on another worker
(Dask's `allowed-failures`); a task that raised is retried `retries` times. A bad input is not an
exception: its line has `ok: false` and the error, as with the CLI.
"""

from __future__ import annotations

import json
import os
from typing import Any, Dict, Iterable, List, Optional

from . import _native
from ._native import InbetweenError

__all__ = ["map", "run_input", "JOBS"]

#: The jobs a batch can run, as the CLI names them.
JOBS = ("mocap-compress", "mocap-keys", "video-analyse", "script-run", "face-edit")

#: The options the jobs read (the fields of the Rust `Options`).
_OPTION_FIELDS = ("max_error_cm", "keys", "method", "mask", "seed")

#: The file the client appends the lines to (`inbetween batch summary OUT` reads it with the shards').
RESULTS_FILE = "results-dask.jsonl"


def _options_json(job: str, options: Dict[str, Any]) -> str:
    if job not in JOBS:
        raise InbetweenError(f"unknown batch job '{job}': expected one of {', '.join(JOBS)}")
    unknown = sorted(set(options) - set(_OPTION_FIELDS))
    if unknown:
        raise InbetweenError(f"unknown option(s) {', '.join(unknown)}: the batch jobs read {', '.join(_OPTION_FIELDS)}")
    return json.dumps({k: v for k, v in options.items() if v is not None})


def run_input(job: str, path: "os.PathLike[str] | str", root: "os.PathLike[str] | str", out: "os.PathLike[str] | str", **options: Any) -> Dict[str, Any]:
    """Runs `job` on one file (what each Dask task does): outputs below `out` at the file's path
    relative to `root`; returns its result line (`input`, `hash`, `ok`, `error`, `outputs`,
    `report`, `seconds`)."""
    line = _native.batch_run_input(job, os.fspath(path), os.fspath(root), os.fspath(out), _options_json(job, options))
    return json.loads(line)


def _task(path: str, job: str, root: str, out: str, options: str) -> str:
    # Runs on a worker: the GIL is released inside, so a threaded worker runs several at once.
    return _native.batch_run_input(job, path, root, out, options)


def _append(results: str, line: str) -> None:
    """Appends one line and syncs it, first cutting a partial last line left by a killed client."""
    with open(results, "a+b") as f:
        f.seek(0, os.SEEK_END)
        size = f.tell()
        if size:
            f.seek(0)
            data = f.read()
            keep = data.rfind(b"\n") + 1
            if keep != size:
                f.truncate(keep)
        f.write(line.encode("utf-8") + b"\n")
        f.flush()
        os.fsync(f.fileno())


def map(  # noqa: A001 - the name the issue and Dask users expect
    job: str,
    paths: Iterable["os.PathLike[str] | str"],
    client: Optional[Any] = None,
    out: "os.PathLike[str] | str" = "out/batch",
    root: Optional["os.PathLike[str] | str"] = None,
    retries: int = 2,
    progress: Any = None,
    **options: Any,
) -> List[Dict[str, Any]]:
    """Submits one task per path to a `dask.distributed` client and returns the result lines in the
    order of `paths`. Outputs mirror the paths below `root` (default: their deepest common folder)
    inside `out`; the lines are also appended to `out/results-dask.jsonl`. `options` are the job's
    (`max_error_cm`, `keys`, `method`, `mask`, `seed`). `client=None` starts a `LocalCluster` of
    worker processes for the call. `progress=callable(done, total)`, or a tqdm bar when tqdm is
    installed (`progress=False`: none)."""
    try:
        from dask.distributed import Client, LocalCluster, as_completed
    except ImportError as e:  # pragma: no cover - depends on the environment
        raise InbetweenError("inbetween.batch.map needs dask.distributed: pip install 'dask[distributed]'") from e
    opts = _options_json(job, options)
    paths = [os.path.abspath(os.fspath(p)) for p in paths]
    if not paths:
        return []
    if len(set(paths)) != len(paths):
        raise InbetweenError("the same path is given twice: each input is one task")
    exts = set(_native.batch_extensions(job))
    for p in paths:
        if p.lower().rsplit(".", 1)[-1] not in exts:
            raise InbetweenError(f"{p}: {job} reads {', '.join('.' + e for e in sorted(exts))} files")
    root = os.path.abspath(os.fspath(root)) if root is not None else os.path.commonpath([os.path.dirname(p) for p in paths])
    out = os.path.abspath(os.fspath(out))
    os.makedirs(out, exist_ok=True)
    results = os.path.join(out, RESULTS_FILE)

    own = None
    if client is None:
        own = LocalCluster(processes=True, threads_per_worker=1, dashboard_address=None)
        client = Client(own)
    try:
        futures = client.map(
            _task, paths, job=job, root=root, out=out, options=opts, retries=retries, pure=False,
            key=[f"inbetween-{job}-{i}" for i in range(len(paths))],
        )
        index = {f.key: i for i, f in enumerate(futures)}
        lines: List[Optional[Dict[str, Any]]] = [None] * len(paths)
        from ._progress import progress_callback

        with progress_callback(progress, job) as update:
            for done, fut in enumerate(as_completed(futures), start=1):
                text = fut.result()
                _append(results, text)
                lines[index[fut.key]] = json.loads(text)
                if update is not None:
                    update(done, len(paths))
        return [line for line in lines if line is not None]
    finally:
        if own is not None:
            client.close()
            own.close()
