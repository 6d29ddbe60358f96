"""What needs a window (run by crates/py/tests/blender.rs under xvfb-run, Blender started with
`--enable-event-simulate`): reduce_keys as a modal operator (progress, the main loop kept running),
undo of its result, and Esc cancelling a run with nothing changed; then the same for
camera_from_armatures (ui_camera.py). Driven by a timer, since the
main loop has to run for a modal operator; prints `ui session: ok` at the end, exits 1 on failure."""

import builtins
import os
import pathlib
import sys
import time
import traceback

import addon_utils
import bpy

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))  # camera_scene, ui_camera

DATA = pathlib.Path(os.environ.get("INBETWEEN_DATA") or pathlib.Path(__file__).resolve().parents[3] / "shared" / "data")
TAKE = DATA / "mocap" / "cmu" / "cgspeed" / "131_01.bvh"

state = {"phase": "start", "t": 0.0, "gaps": [], "last": None}


def say(*a):
    print("ui session:", *a)
    sys.stdout.flush()


def fail(msg):
    say("FAILED:", msg)
    os._exit(1)


def override():
    win = bpy.context.window_manager.windows[0]
    area = next(a for a in win.screen.areas if a.type == "VIEW_3D")
    region = next(r for r in area.regions if r.type == "WINDOW")
    return bpy.context.temp_override(window=win, area=area, region=region)


def armature():
    return bpy.data.objects.get("131_01")


def actions():
    return sorted(a.name for a in bpy.data.actions)


def step():
    now = time.perf_counter()
    if state["last"] is not None and state["phase"] in ("reducing", "cancelling"):
        state["gaps"].append(now - state["last"])
    state["last"] = now
    phase = state["phase"]
    if phase == "start":
        if not TAKE.exists():
            say(f"skipped: no data at {TAKE}")
            say("ok")
            bpy.ops.wm.quit_blender()
            return None
        assert addon_utils.enable("inbetween_blender", default_set=True) is not None
        import io_anim_bvh.import_bvh as importer

        importer.open = lambda f, mode="r", *a, **k: builtins.open(f, mode.replace("U", ""), *a, **k)
        with override():
            bpy.ops.import_anim.bvh(filepath=str(TAKE), global_scale=0.056444, update_scene_fps=True)
            bpy.ops.ed.undo_push(message="imported")
            r = bpy.ops.inbetween.reduce_keys("INVOKE_DEFAULT", max_error_cm=1.0)
        if r != {"RUNNING_MODAL"}:
            fail(f"reduce_keys returned {r}, expected a modal run")
        state.update(phase="reducing", t=now, start=now)
        return 0.01
    if phase == "reducing":
        act = armature().animation_data.action
        if act.name.endswith(".reduced") and "inbetween_reduce" in act:
            state.update(phase="reduced", t=now)
            return 0.3  # the operator returns FINISHED and pushes its undo step
        if now - state["t"] > 120:
            fail("the modal reduction did not finish in 120 s")
        return 0.01
    if phase == "reduced":
        from inbetween_blender.runner import STATS

        gaps = state["gaps"]
        act = armature().animation_data.action
        say(
            f"modal reduce: {act['inbetween_reduce']['key_frames_after']} keys, "
            f"max {act['inbetween_reduce']['max_error_cm']:.3f} cm, {now - state['start']:.1f} s; "
            f"{STATS['slices']} slices, the longest {STATS['max_slice_s']:.3f} s (the add-on's hold on the main "
            f"loop); main-loop ticks {len(gaps)}, longest gap {max(gaps):.3f} s (slice plus the window's redraw)"
        )
        say("rounds (key frames, max cm, max degrees):", [tuple(h) for h in act["inbetween_reduce"]["history"]])
        if STATS["slices"] < 5 or STATS["max_slice_s"] > 0.5:
            fail(f"the modal run held the main loop {STATS['max_slice_s']:.2f} s at once")
        with override():
            bpy.ops.ed.undo()
        ob = armature()
        if ob.animation_data.action.name != "131_01" or "131_01.reduced" in actions():
            fail(f"undo left action {ob.animation_data.action.name!r}, actions {actions()}")
        say("undo restored the original action; actions", actions())
        before = actions()
        with override():
            r = bpy.ops.inbetween.reduce_keys("INVOKE_DEFAULT", max_error_cm=0.3)
        if r != {"RUNNING_MODAL"}:
            fail(f"second reduce_keys returned {r}")
        state.update(phase="cancelling", t=now, gaps=[], before=before)
        return 0.4
    if phase == "cancelling":
        win = bpy.context.window_manager.windows[0]
        win.event_simulate(type="ESC", value="PRESS")
        win.event_simulate(type="ESC", value="RELEASE")
        state.update(phase="cancelled", t=now)
        return 0.5
    if phase == "cancelled":
        ob = armature()
        if actions() != state["before"] or ob.animation_data.action.name != "131_01":
            fail(f"Esc left actions {actions()} and {ob.animation_data.action.name!r} assigned")
        say("Esc cancelled the run; nothing changed")
        state["phase"] = "camera"
        return 0.1
    if phase.startswith("camera"):
        import ui_camera

        interval = ui_camera.step(state, now, say, fail, override, TAKE.with_name("131_02.bvh"))
        if interval is None:
            say("ok")
            bpy.ops.wm.quit_blender()
        return interval
    fail(f"unknown phase {phase}")


def tick():
    try:
        return step()
    except Exception:
        traceback.print_exc()
        fail("exception")


bpy.app.timers.register(tick, first_interval=0.5)
