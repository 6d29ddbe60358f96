"""Running a job from an operator: synchronously from scripts and in background mode (`execute`),
as a modal operator with a progress bar and Esc to cancel from the UI (`invoke`). The job is a
generator of `(fraction, words)` advanced in slices of about 0.1 s on a timer, so the UI never
waits long on it; the engines run on a worker thread meanwhile.

A job object has `steps()` (the generator), `cancel` (a `threading.Event`), `rollback()` (undo
what a cancelled or failed run changed) and, when done, `message()`."""

from __future__ import annotations

import os
import time
import traceback

import bpy

SLICE_S = 0.1
#: The longest slice of the last modal run (what the add-on itself held the main loop for), seconds.
STATS = {"max_slice_s": 0.0, "slices": 0}
#: INBETWEEN_DEBUG=1: slices over 0.1 s and errors printed to the console.
DEBUG = bool(os.environ.get("INBETWEEN_DEBUG"))


def _error_text(e: BaseException) -> str:
    """An error in words: the engines' and ours as they are; anything else with its type."""
    if isinstance(e, _expected()):
        return str(e)
    return f"{type(e).__name__}: {e}"


class JobOperator:
    """Mixin for operators whose work is a job (see the module's words)."""

    def make_job(self, context):  # pragma: no cover - each operator defines it
        raise NotImplementedError

    def _fail(self, job, e: BaseException):
        if job is not None:
            try:
                job.rollback()
            except Exception:  # the error the user needs is `e`
                traceback.print_exc()
        if not isinstance(e, _expected()):
            traceback.print_exc()  # to the console, for a bug report; the UI gets one line
        self.report({"ERROR"}, _error_text(e))
        return {"CANCELLED"}

    def execute(self, context):
        job = None
        try:
            job = self.make_job(context)
            for _ in job.steps():
                pass
        except Exception as e:
            return self._fail(job, e)
        self.report({"INFO"}, job.message())
        return {"FINISHED"}

    def invoke(self, context, event):
        if bpy.app.background or context.window is None:
            return self.execute(context)
        try:
            self._job = self.make_job(context)
            self._steps = self._job.steps()
        except Exception as e:
            return self._fail(None, e)
        wm = context.window_manager
        self._timer = wm.event_timer_add(0.02, window=context.window)
        wm.progress_begin(0, 100)
        wm.modal_handler_add(self)
        STATS.update(max_slice_s=0.0, slices=0)
        return {"RUNNING_MODAL"}

    def _end(self, context):
        wm = context.window_manager
        wm.event_timer_remove(self._timer)
        wm.progress_end()
        if context.workspace is not None:
            context.workspace.status_text_set(None)

    def modal(self, context, event):
        from .jobs import time_slice

        if event.type == "ESC":
            self._job.cancel.set()
            self._steps.close()
            self._end(context)
            self._job.rollback()
            self.report({"WARNING"}, "cancelled; nothing changed")
            return {"CANCELLED"}
        if event.type != "TIMER":
            return {"RUNNING_MODAL"}
        t0 = time.perf_counter()
        try:
            state = time_slice(self._steps, SLICE_S)
        except Exception as e:
            self._end(context)
            if DEBUG:
                print(f"inbetween: {type(e).__name__}: {e}")
            return self._fail(self._job, e)
        took = time.perf_counter() - t0
        STATS.update(max_slice_s=max(STATS["max_slice_s"], took), slices=STATS["slices"] + 1)
        if DEBUG and took > 0.15:
            print(f"inbetween: slice of {took:.3f} s ending at {state}")
        if state is None:
            self._end(context)
            self.report({"INFO"}, self._job.message())
            return {"FINISHED"}
        fraction, words = state
        context.window_manager.progress_update(int(100 * fraction))
        if context.workspace is not None:
            context.workspace.status_text_set(f"inbetween: {words} ({100 * fraction:.0f} %), Esc to cancel")
        return {"RUNNING_MODAL"}


def _expected():
    from .jobs import JobError

    try:
        import inbetween

        return (JobError, inbetween.InbetweenError)
    except ImportError:
        return (JobError,)
