"""The add-on's sidebar panels beside a CMU take, as a window screenshot (runs under xvfb):

    xvfb-run -a -s "-screen 0 1600x1000x24" blender --factory-startup -noaudio EMPTY.blend \\
        --python blender/bench/screenshot_panel.py -- OUT.png

(Blender 3.4 cannot switch a sidebar tab from Python, so the panels are shown in the Item tab.)"""

import builtins
import os
import pathlib
import sys
import traceback

import addon_utils
import bpy

ROOT = pathlib.Path(__file__).resolve().parents[2]
DATA = pathlib.Path(os.environ.get("INBETWEEN_DATA") or ROOT.parent / "shared" / "data")
OUT = pathlib.Path(sys.argv[sys.argv.index("--") + 1] if "--" in sys.argv else "blender/docs/panel.png")


def go():
    try:
        assert addon_utils.enable("inbetween_blender", default_set=True) is not None
        import io_anim_bvh.import_bvh as importer

        importer.open = lambda f, mode="r", *a, **k: builtins.open(f, mode.replace("U", ""), *a, **k)
        win = bpy.context.window_manager.windows[0]
        area = next(a for a in win.screen.areas if a.type == "VIEW_3D")
        region = next(r for r in area.regions if r.type == "WINDOW")
        with bpy.context.temp_override(window=win, area=area, region=region):
            bpy.ops.import_anim.bvh(
                filepath=str(DATA / "mocap/cmu/cgspeed/131_01.bvh"), global_scale=0.056444, update_scene_fps=True
            )
            bpy.ops.view3d.view_selected()
        area.spaces.active.show_region_ui = True
        from inbetween_blender import ui

        for cls in (ui.INBETWEEN_PT_reduce, ui.INBETWEEN_PT_scene):
            bpy.utils.unregister_class(cls)
            cls.bl_category = "Item"
            bpy.utils.register_class(cls)
        bpy.context.scene.frame_set(300)
        OUT.parent.mkdir(parents=True, exist_ok=True)
        with bpy.context.temp_override(window=win):
            bpy.ops.wm.redraw_timer(type="DRAW_WIN_SWAP", iterations=3)
            bpy.ops.screen.screenshot(filepath=str(OUT))
        print("screenshot:", OUT)
    except Exception:
        traceback.print_exc()
        sys.stdout.flush()
        os._exit(1)
    sys.stdout.flush()
    os._exit(0)


bpy.app.timers.register(go, first_interval=1.0)
