"""reduce_keys against Blender's own Graph Editor > Decimate on the CMU takes, measured in Blender.

    xvfb-run -a blender --factory-startup -noaudio EMPTY.blend --python blender/bench/compare_decimate.py -- OUT_DIR [TAKE.bvh ...]

(Decimate is a Graph Editor operator, so Blender runs with a window; xvfb gives it one.) For each
take (default: the four cgspeed BVH of ../shared/data), imported with Blender's BVH importer at the
CMU unit (0.056444 m): reduce_keys at 1 cm keeping Euler curves (the engine's keys chosen for
them, and the key frames the add-on's refinement added where Blender's curve still left the bound),
reduce_keys at 1 cm with
quaternion curves, and Decimate in ERROR mode at the margin whose total keyframe count matches
the Euler run's (bisection on the margin), and Decimate at the largest margin that stays within
the bound. (EMPTY.blend, any saved file, keeps the splash screen out of the screenshots.) Every figure is measured the same way: world head and
tail of every bone after `frame_set`, every frame, against the original action; cm. Writes
OUT_DIR/decimate.md (the table) and OUT_DIR/decimate.json (rows of other takes already there are
kept, so one process per take works: Blender 3.4 once crashed on the third take of a long run), and
Graph Editor screenshots of one bone before and after (OUT_DIR/graph_*.png)."""

import builtins
import json
import math
import os
import pathlib
import sys
import time
import traceback

import numpy as np

import addon_utils
import bpy

ROOT = pathlib.Path(__file__).resolve().parents[2]
DATA = pathlib.Path(os.environ.get("INBETWEEN_DATA") or ROOT.parent / "shared" / "data")
CMU_M = 0.056444
BOUND_CM = 1.0

args = sys.argv[sys.argv.index("--") + 1 :] if "--" in sys.argv else []
OUT = pathlib.Path(args[0] if args else "blender/docs")
TAKES = [pathlib.Path(a) for a in args[1:]] or sorted((DATA / "mocap" / "cmu" / "cgspeed").glob("*.bvh"))


def clear():
    for coll in (bpy.data.objects, bpy.data.armatures, bpy.data.actions):
        for item in list(coll):
            coll.remove(item)


def import_take(path):
    import io_anim_bvh.import_bvh as importer

    importer.open = lambda f, mode="r", *a, **k: builtins.open(f, mode.replace("U", ""), *a, **k)
    bpy.ops.import_anim.bvh(filepath=str(path), global_scale=CMU_M, update_scene_fps=True, update_scene_duration=True)
    return bpy.context.active_object


def points(ob, frames):
    sc = bpy.context.scene
    out = []
    for f in frames:
        sc.frame_set(int(f))
        mw = ob.matrix_world
        out.append([tuple(mw @ pb.head) for pb in ob.pose.bones] + [tuple(mw @ pb.tail) for pb in ob.pose.bones])
    return np.array(out) * 100.0


def keyframe_counts(action):
    curves = [
        fc for fc in action.fcurves if fc.data_path.endswith(("rotation_euler", "rotation_quaternion", "location"))
    ]
    frames = {round(k.co[0]) for fc in curves for k in fc.keyframe_points}
    return sum(len(fc.keyframe_points) for fc in curves), len(frames), len(curves)


def graph_area():
    win = bpy.context.window_manager.windows[0]
    area = max(win.screen.areas, key=lambda a: a.width * a.height)
    area.type = "GRAPH_EDITOR"
    region = next(r for r in area.regions if r.type == "WINDOW")
    return win, area, region


def decimate(ob, action, margin):
    """A copy of `action` decimated by the Graph Editor at `margin`; returns it."""
    work = action.copy()
    ob.animation_data.action = work
    win, area, region = graph_area()
    area.spaces.active.dopesheet.show_only_selected = False
    with bpy.context.temp_override(window=win, area=area, region=region):
        bpy.ops.graph.reveal()
        bpy.ops.graph.select_all(action="SELECT")
        bpy.ops.graph.decimate(mode="ERROR", remove_error_margin=margin)
    # No Graph Editor left open on actions the bench then removes (Blender 3.4 crashed once here).
    area.type = "VIEW_3D"
    return work


def measure(ob, action, frames, reference):
    ob.animation_data.action = action
    err = np.linalg.norm(points(ob, frames) - reference, axis=-1)
    return float(err.max()), float(err.mean())


def screenshot(ob, action, bone, path):
    """The Graph Editor showing `bone`'s rotation curves of `action`: a window screenshot cropped to
    the editor (`screen.screenshot_area` gives a 1x1 image under xvfb)."""
    ob.animation_data.action = action
    win, area, region = graph_area()
    space = area.spaces.active
    space.dopesheet.show_only_selected = True
    bpy.context.view_layer.objects.active = ob
    ob.select_set(True)
    with bpy.context.temp_override(window=win, area=area, region=region):
        bpy.ops.object.mode_set(mode="POSE")
        for pb in ob.pose.bones:
            pb.bone.select = pb.name == bone  # Blender 3.x/4.x (the bench runs on Debian's 3.4)
        for fc in action.fcurves:
            fc.hide = f'"{bone}"' not in fc.data_path or "rotation" not in fc.data_path
            fc.select = not fc.hide
        bpy.ops.graph.view_all()
        bpy.ops.wm.redraw_timer(type="DRAW_WIN_SWAP", iterations=2)
    full = path.with_suffix(".window.png")
    with bpy.context.temp_override(window=win):
        bpy.ops.screen.screenshot(filepath=str(full))
    img = bpy.data.images.load(str(full))
    w, h = img.size
    px = np.array(img.pixels[:], dtype=np.float32).reshape(h, w, 4)
    crop = px[area.y : area.y + area.height, area.x : area.x + area.width]
    out = bpy.data.images.new(path.stem, crop.shape[1], crop.shape[0])
    out.pixels.foreach_set(crop.ravel())
    out.filepath_raw = str(path)
    out.file_format = "PNG"
    out.save()
    bpy.data.images.remove(out)
    bpy.data.images.remove(img)
    full.unlink()
    with bpy.context.temp_override(window=win, area=area, region=region):
        bpy.ops.object.mode_set(mode="OBJECT")
    for fc in action.fcurves:
        fc.hide = False
    area.type = "VIEW_3D"


def run():
    assert addon_utils.enable("inbetween_blender", default_set=True) is not None
    OUT.mkdir(parents=True, exist_ok=True)
    rows = []
    for take in TAKES:
        t0 = time.perf_counter()
        clear()
        ob = import_take(take)
        original = ob.animation_data.action
        lo, hi = (int(round(v)) for v in original.frame_range)
        frames = np.arange(lo, hi + 1)
        ref = points(ob, frames)
        before_total, before_frames, curves = keyframe_counts(original)
        modes = {pb.name: pb.rotation_mode for pb in ob.pose.bones}
        row = {"take": take.stem, "frames": len(frames), "curves": curves, "keyframes_before": before_total}
        for rotation in ("KEEP", "QUATERNION"):
            ob.animation_data.action = original
            t = time.perf_counter()
            bpy.ops.inbetween.reduce_keys(max_error_cm=BOUND_CM, rotation=rotation)
            took = time.perf_counter() - t
            reduced = ob.animation_data.action
            total, kframes, _ = keyframe_counts(reduced)
            mx, mean = measure(ob, reduced, frames, ref)
            row[rotation.lower()] = {
                "keyframes": total, "key_frames": kframes, "max_cm": mx, "mean_cm": mean, "seconds": took,
                "engine_keys": reduced["inbetween_reduce"]["engine_keys"],
            }
            if rotation == "KEEP" and take.stem == "131_01":
                screenshot(ob, original, "LeftKnee", OUT / "graph_before.png")
                screenshot(ob, reduced, "LeftKnee", OUT / "graph_reduced.png")
            for pb in ob.pose.bones:
                pb.rotation_mode = modes[pb.name]  # the importer's (ZYX and ZXY on these takes)
            ob.animation_data.action = original
            bpy.data.actions.remove(reduced)
        target = row["keep"]["keyframes"]
        # Bisection on log(margin): Decimate's total keyframes fall as the margin grows.
        lo_m, hi_m, best = 1e-5, 1.0, None
        for _ in range(18):
            m = math.sqrt(lo_m * hi_m)
            work = decimate(ob, original, m)
            total, kframes, _ = keyframe_counts(work)
            cand = (abs(total - target), m, total, kframes, work)
            if best is None or cand[0] < best[0]:
                if best is not None:
                    bpy.data.actions.remove(best[4])
                best = cand
            else:
                ob.animation_data.action = original
                bpy.data.actions.remove(work)
            if total > target:
                lo_m = m
            else:
                hi_m = m
            if abs(total - target) <= 0.01 * target:
                break
        _, m, total, kframes, work = best
        mx, mean = measure(ob, work, frames, ref)
        row["decimate"] = {"margin": m, "keyframes": total, "key_frames": kframes, "max_cm": mx, "mean_cm": mean}
        if take.stem == "131_01":
            screenshot(ob, work, "LeftKnee", OUT / "graph_decimate.png")
        ob.animation_data.action = original
        bpy.data.actions.remove(work)
        # The largest margin whose result stays within the bound, measured the same way.
        lo_m, hi_m, ok = 1e-5, 1.0, None
        for _ in range(12):
            m = math.sqrt(lo_m * hi_m)
            work = decimate(ob, original, m)
            mx, mean = measure(ob, work, frames, ref)
            total, kframes, _ = keyframe_counts(work)
            ob.animation_data.action = original
            bpy.data.actions.remove(work)
            if mx <= BOUND_CM:
                ok = {"margin": m, "keyframes": total, "key_frames": kframes, "max_cm": mx, "mean_cm": mean}
                lo_m = m
            else:
                hi_m = m
        row["decimate_at_bound"] = ok
        rows.append(row)
        print(f"compare: {take.stem} done in {time.perf_counter() - t0:.1f} s: {json.dumps(row)}")
        sys.stdout.flush()
    # Rows of earlier runs (one take per process is the robust way on Blender 3.4) are kept.
    path = OUT / "decimate.json"
    done = {r["take"] for r in rows}
    old = json.loads(path.read_text()) if path.exists() else []
    rows = sorted([r for r in old if r["take"] not in done] + rows, key=lambda r: r["take"])
    path.write_text(json.dumps(rows, indent=1))
    lines = [
        f"Bound {BOUND_CM:g} cm; errors measured in Blender {bpy.app.version_string} on every frame (world head and tail "
        "of every bone against the original action, cm). Keyframes: on the rotation and root location curves; "
        "key frames: frames holding a key.",
        "",
        "| take | frames | original keyframes | reduce_keys, Euler curves: keyframes (key frames; added in Blender) "
        "| max / mean cm "
        "| reduce_keys, quaternion curves: keyframes (key frames) | max / mean cm "
        "| Decimate (ERROR, margin), same keyframes: keyframes (key frames) | max / mean cm "
        f"| Decimate, largest margin within {BOUND_CM:g} cm: keyframes (key frames) | max / mean cm |",
        "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |",
    ]
    for r in rows:
        k, q, d, e = r["keep"], r["quaternion"], r["decimate"], r["decimate_at_bound"]
        lines.append(
            f"| {r['take']} | {r['frames']} | {r['keyframes_before']} | {k['keyframes']} ({k['key_frames']}; "
            f"{k['key_frames'] - k['engine_keys']}) "
            f"| {k['max_cm']:.3f} / {k['mean_cm']:.3f} | {q['keyframes']} ({q['key_frames']}) "
            f"| {q['max_cm']:.3f} / {q['mean_cm']:.3f} | {d['keyframes']} ({d['key_frames']}) at {d['margin']:.2g} "
            f"| {d['max_cm']:.3f} / {d['mean_cm']:.3f} | {e['keyframes']} ({e['key_frames']}) at {e['margin']:.2g} "
            f"| {e['max_cm']:.3f} / {e['mean_cm']:.3f} |"
        )
    (OUT / "decimate.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))
    print("compare: ok")
    sys.stdout.flush()


def main():
    try:
        run()
    except Exception:
        traceback.print_exc()
        sys.stdout.flush()
        os._exit(1)
    os._exit(0)


bpy.app.timers.register(main, first_interval=0.5)
