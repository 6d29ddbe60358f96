"""A story through text_to_scene, rendered headlessly (Workbench, the shot camera) at three frames:

    blender -b --factory-startup -noaudio --python blender/bench/render_story.py -- OUT_DIR

Writes OUT_DIR/story_<frame>.png (480x320) and prints the operator's report."""

import os
import pathlib
import sys

import addon_utils
import bpy

STORY = "Anna walks to the sofa and sits down. Ben stands by the window and waves at her."

out = pathlib.Path(sys.argv[sys.argv.index("--") + 1] if "--" in sys.argv else "blender/docs")
out.mkdir(parents=True, exist_ok=True)
assert addon_utils.enable("inbetween_blender", default_set=True) is not None
for ob in list(bpy.data.objects):
    bpy.data.objects.remove(ob)
text = bpy.data.texts.new("story")
text.write(STORY)
assert bpy.ops.inbetween.text_to_scene(text="story") == {"FINISHED"}
sc = bpy.context.scene
sc.render.engine = "BLENDER_WORKBENCH"
sc.display.shading.light = "STUDIO"
sc.display.shading.color_type = "MATERIAL"
sc.render.resolution_x, sc.render.resolution_y, sc.render.resolution_percentage = 480, 320, 100
for f in (sc.frame_start, (sc.frame_start + sc.frame_end) // 2, sc.frame_end):
    sc.frame_set(f)
    sc.render.filepath = str(out / f"story_{f:03d}.png")
    bpy.ops.render.render(write_still=True)
    print("render:", sc.render.filepath)
sys.stdout.flush()
os._exit(0)
