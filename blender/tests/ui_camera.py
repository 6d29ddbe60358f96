"""camera_from_armatures with a window (driven by ui_session.py's timer after its reduce phases):
the modal run keeps the main loop going, its result hits the keys, undo restores the camera's
action, and Esc during a shot-list run leaves nothing changed."""

import builtins

import numpy as np

import bpy
from camera_scene import key_at, keyed_camera, on_screen, select


def actions():
    return sorted(a.name for a in bpy.data.actions)


def step(state, now, say, fail, override, take_b):
    """One tick of the camera phases; returns the next interval, or None when done."""
    phase = state["phase"]
    if phase == "camera":
        import io_anim_bvh.import_bvh as importer

        importer.open = lambda f, mode="r", *a, **k: builtins.open(f, mode.replace("U", ""), *a, **k)
        with override():
            bpy.ops.import_anim.bvh(filepath=str(take_b), global_scale=0.056444, update_scene_fps=True)
        a, b = bpy.data.objects["131_01"], bpy.data.objects[take_b.stem]
        b.location.x += 3.0
        sc = bpy.context.scene
        sc.frame_start, sc.frame_end = 1, 700
        keyed_camera(a, b, frames=(20, 160))
        select(a, b)
        state["want"] = on_screen(bpy.data.objects["Cam"], (a, b), (20, 160))
        with override():
            bpy.ops.ed.undo_push(message="camera keyed")
            r = bpy.ops.inbetween.camera_from_armatures("INVOKE_DEFAULT")
        if r != {"RUNNING_MODAL"}:
            fail(f"camera_from_armatures returned {r}, expected a modal run")
        state.update(phase="camera_running", t=now, start=now, before=actions())
        return 0.01
    if phase == "camera_running":
        act = bpy.data.objects["Cam"].animation_data.action
        if act.name.endswith(".inbetween.relative") and "inbetween_camera" in act:
            state.update(phase="camera_done", t=now)
            return 0.3
        if now - state["t"] > 120:
            fail("the modal camera run did not finish in 120 s")
        return 0.01
    if phase == "camera_done":
        from inbetween_blender.runner import STATS

        cam, a, b = (bpy.data.objects[n] for n in ("Cam", "131_01", "131_02"))
        err = float(np.abs(on_screen(cam, (a, b), (20, 160)) - state["want"]).max())
        say(
            f"modal camera: {cam.animation_data.action.name}, keys on screen within {err:.2e}, "
            f"{now - state['start']:.1f} s; {STATS['slices']} slices, the longest {STATS['max_slice_s']:.3f} s"
        )
        if err > 0.01 or STATS["max_slice_s"] > 0.5:
            fail(f"screen error {err} or a slice of {STATS['max_slice_s']:.2f} s")
        with override():
            bpy.ops.ed.undo()
        cam = bpy.data.objects["Cam"]
        if cam.animation_data.action.name != "CamAction" or any(".inbetween." in n for n in actions()):
            fail(f"undo left camera action {cam.animation_data.action.name!r}, actions {actions()}")
        say("undo restored the camera's action; actions", actions())
        select(bpy.data.objects["131_01"], bpy.data.objects["131_02"])
        # Keys far apart: sampling alone takes seconds, so Esc comes mid-run.
        key_at(cam, bpy.data.objects["131_01"], bpy.data.objects["131_02"], 600, 2)  # a valid key: only Esc stops it
        before = actions()
        with override():
            r = bpy.ops.inbetween.camera_from_armatures("INVOKE_DEFAULT", shot_list=True)
        if r != {"RUNNING_MODAL"}:
            fail(f"second camera_from_armatures returned {r}")
        state.update(phase="camera_cancelling", t=now, before=before)
        return 0.4
    if phase == "camera_cancelling":
        win = bpy.context.window_manager.windows[0]
        win.event_simulate(type="ESC", value="PRESS")
        win.event_simulate(type="ESC", value="RELEASE")
        state.update(phase="camera_cancelled", t=now)
        return 0.5
    if phase == "camera_cancelled":
        cam = bpy.data.objects["Cam"]
        if actions() != state["before"] or cam.animation_data.action.name != "CamAction":
            fail(f"Esc left actions {actions()} and {cam.animation_data.action.name!r} assigned")
        say("Esc cancelled the camera run; nothing changed")
        return None
    fail(f"unknown camera phase {phase}")
    return None

