"""The progress argument of long jobs: a callable(done, total), or a tqdm bar when tqdm is installed."""

from __future__ import annotations

import contextlib
from typing import Callable, Iterator, Optional

Callback = Callable[[int, int], object]


@contextlib.contextmanager
def progress_callback(progress: Optional[Callback], desc: str) -> Iterator[Optional[Callback]]:
    """Yields what to hand the native job: `progress` itself, else a tqdm bar's updater (shown
    only once the job reports a length), else None. `progress=False` shows nothing."""
    if progress is False:
        yield None
        return
    if progress is not None:
        yield progress
        return
    try:
        from tqdm.auto import tqdm
    except ImportError:
        yield None
        return
    bar = None

    def update(done: int, total: int) -> None:
        nonlocal bar
        if bar is None:
            bar = tqdm(total=total, desc=desc, leave=False)
        if bar.total != total:
            bar.total = total
        bar.n = done
        bar.refresh()

    try:
        yield update
    finally:
        if bar is not None:
            bar.close()
