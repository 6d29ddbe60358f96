"""text_to_scene: a story in a text block becomes objects and animated characters in a new
collection, the shot camera the scene camera; an empty text changes nothing."""

from __future__ import annotations

import pytest

import bpy


def test_a_story_becomes_a_scene_with_animated_characters():
    text = bpy.data.texts.new("story")
    text.write("Anna walks to the sofa and sits down. Ben stands by the window and waves at her.")
    assert bpy.ops.inbetween.text_to_scene(text="story") == {"FINISHED"}
    coll = bpy.data.collections["inbetween story"]
    objects = list(coll.all_objects)
    meshes = [o for o in objects if o.type == "MESH"]
    sc = bpy.context.scene
    print(f"\nstory: {len(objects)} objects, {len(meshes)} meshes, camera {sc.camera.name if sc.camera else None}")
    assert len(meshes) >= 3, "furniture and bodies"
    # Each character is a node with animated parts that move between the first and last frames.
    for name in ("Anna", "Ben"):
        root = bpy.data.objects[name]
        assert root.name in coll.all_objects
        parts = [o for o in root.children_recursive if o.animation_data and o.animation_data.action]
        assert parts, f"{name} has no animated parts"
        sc.frame_set(sc.frame_start)
        a = [o.matrix_world.translation.copy() for o in parts]
        sc.frame_set(sc.frame_end)
        b = [o.matrix_world.translation.copy() for o in parts]
        moved = max((x - y).length for x, y in zip(a, b))
        print(f"{name}: {len(parts)} animated parts, moved up to {moved:.2f} m")
        assert moved > 0.05
    assert sc.camera is not None and sc.camera.name in coll.all_objects
    assert sc.frame_end > sc.frame_start


def test_an_empty_text_reports_an_error_and_changes_nothing():
    bpy.data.texts.new("empty")
    before = (len(bpy.data.objects), len(bpy.data.collections), bpy.context.scene.camera)
    with pytest.raises(RuntimeError) as e:
        bpy.ops.inbetween.text_to_scene(text="empty")
    assert "is empty" in str(e.value) and "Traceback" not in str(e.value)
    with pytest.raises(RuntimeError) as e:
        bpy.ops.inbetween.text_to_scene(text="no such text")
    assert "no such text block" in str(e.value)
    assert (len(bpy.data.objects), len(bpy.data.collections), bpy.context.scene.camera) == before
