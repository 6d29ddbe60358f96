"""A scene for camera_from_armatures, shared by the headless tests (test_camera.py) and the window
session (ui_camera.py): a scene camera keyed beside two armatures, and the engine's framing
targets measured with plain mathutils after `frame_set` (independent of the add-on)."""

from __future__ import annotations

import builtins

import numpy as np

import bpy
from bpy_extras.object_utils import world_to_camera_view
from mathutils import Vector

KEY_FRAMES = (20, 90, 160)
#: The engine frames the point this far above the shoulder midpoint (metres).
ABOVE_SHOULDERS_M = 0.15
#: Scene rate: the camera engine's networks step every 5th frame and were trained at 30 fps; the
#: CMU takes (120 fps) are retimed to it by Blender's importer.
FPS = 30
#: The upper-arm joints of the CMU skeleton (the engine's notes name the ones it took; test_camera.py
#: checks that they are these).
SHOULDERS = ("LeftShoulder", "RightShoulder")


def import_take(path):
    """A BVH take by Blender's own importer at the CMU unit, retimed to the scene's 30 fps
    (`use_fps_scale`); Debian's Blender 3.4 opens the file with mode 'rU', which Python 3.11
    refuses: the importer's `open` drops the U (../shared/notes/blender.md)."""
    import io_anim_bvh.import_bvh as importer

    if getattr(importer, "open", builtins.open) is builtins.open:
        importer.open = lambda f, mode="r", *a, **k: builtins.open(f, mode.replace("U", ""), *a, **k)
    sc = bpy.context.scene
    sc.render.fps, sc.render.fps_base = FPS, 1.0
    r = bpy.ops.import_anim.bvh(
        filepath=str(path), global_scale=0.056444, update_scene_fps=False, use_fps_scale=True,
        update_scene_duration=False,
    )
    assert r == {"FINISHED"}, r
    return bpy.context.active_object


def target(ob):
    """World point the engine frames on an armature: 15 cm above the upper arms' heads' midpoint
    (plain mathutils after frame_set, independent of the add-on)."""
    mw = ob.matrix_world
    mid = (mw @ ob.pose.bones[SHOULDERS[0]].head + mw @ ob.pose.bones[SHOULDERS[1]].head) / 2
    return mid + Vector((0.0, 0.0, ABOVE_SHOULDERS_M / bpy.context.scene.unit_settings.scale_length))


def on_screen(cam, obs, frames):
    """(K, 2, 2) screen positions (0..1) of each armature's target through `cam` at `frames`."""
    sc = bpy.context.scene
    out = []
    for f in frames:
        sc.frame_set(f)
        ev = cam.evaluated_get(bpy.context.evaluated_depsgraph_get())
        out.append([tuple(world_to_camera_view(sc, ev, target(ob)))[:2] for ob in obs])
    return np.array(out)


def select(active, *others):
    for ob in bpy.context.view_layer.objects:
        ob.select_set(False)
    for ob in (active,) + others:
        ob.select_set(True)
    bpy.context.view_layer.objects.active = active


def keyed_camera(a, b, frames=KEY_FRAMES):
    """A scene camera keyed at `frames` (see `key_at`)."""
    sc = bpy.context.scene
    data = bpy.data.cameras.new("Cam")
    data.lens = 35.0
    cam = bpy.data.objects.new("Cam", data)
    sc.collection.objects.link(cam)
    sc.camera = cam
    for i, f in enumerate(frames):
        key_at(cam, a, b, f, i)
    return cam


def key_at(cam, a, b, f, i=0):
    """A key of `cam` at frame `f`: beside the pair, a little above, aimed near their midpoint; `i`
    moves it to another side."""
    bpy.context.scene.frame_set(f)
    ta, tb = target(a), target(b)
    mid = (ta + tb) / 2
    across = (tb - ta).cross(Vector((0.0, 0.0, 1.0))).normalized()
    along = (tb - ta).normalized()
    cam.location = mid + across * (5.0 + i) + along * (1.0 - i) + Vector((0.0, 0.0, 0.8 + 0.3 * i))
    aim = mid + Vector((0.2 * i, 0.0, -0.1))
    cam.rotation_euler = (aim - cam.location).to_track_quat("-Z", "Y").to_euler()
    cam.keyframe_insert("location", frame=f)
    cam.keyframe_insert("rotation_euler", frame=f)
