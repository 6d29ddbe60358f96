"""camera_from_armatures on two CMU takes (the scene of blender/tests/test_camera.py: 131_01 and
131_02 imported with Blender's BVH importer at 30 fps, B 3 m aside, a camera keyed at frames 20,
90, 160),
shot list on, rendered headlessly by Workbench through the camera at five frames (the keys and
half-way between), one row per camera: the user's keys played by Blender's own interpolation, then
the four styles. Bones are drawn as boxes parented to them (armatures do not render), A red, B
blue; the framed points (15 cm above each shoulder midpoint) as yellow spheres.

    blender -b --factory-startup -noaudio --python blender/bench/render_camera.py -- OUT_DIR

Writes OUT_DIR/camera_sheet.png (rows: keys, direct, relative, side, orbit; columns: frames) and
prints the operator's report and per row the screen error at the keys and on how many frames both
framed points are inside the picture."""

import os
import pathlib
import sys

import numpy as np

import addon_utils
import bpy

HERE = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "tests"))
from camera_scene import KEY_FRAMES, import_take, keyed_camera, on_screen, select, target  # noqa: E402
from conftest import clear_scene, data_dir  # noqa: E402

FRAMES = (20, 55, 90, 125, 160)
W, H = 320, 180

out = pathlib.Path(sys.argv[sys.argv.index("--") + 1] if "--" in sys.argv else "blender/docs")
out.mkdir(parents=True, exist_ok=True)
assert addon_utils.enable("inbetween_blender", default_set=True) is not None
clear_scene()
cg = data_dir() / "mocap" / "cmu" / "cgspeed"
a = import_take(cg / "131_01.bvh")
b = import_take(cg / "131_02.bvh")
b.location.x += 3.0
sc = bpy.context.scene
sc.frame_start, sc.frame_end = 1, 200


def material(name, rgb):
    m = bpy.data.materials.new(name)
    m.diffuse_color = (*rgb, 1.0)
    return m


def dress(ob, mat):
    """A box along every bone, parented to it."""
    for bone in ob.data.bones:
        if bone.length < 1e-3:
            continue
        mesh = bpy.data.meshes.new(bone.name)
        s = 0.035
        verts = [(x, y, z) for x in (-s, s) for y in (0.0, 1.0) for z in (-s, s)]
        faces = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
        mesh.from_pydata(verts, [], faces)
        mesh.materials.append(mat)
        box = bpy.data.objects.new(f"{ob.name}.{bone.name}", mesh)
        sc.collection.objects.link(box)
        box.parent, box.parent_type, box.parent_bone = ob, "BONE", bone.name
        box.location = (0.0, -bone.length, 0.0)  # bone parenting puts the child at the tail
        box.scale = (1.0, bone.length, 1.0)


def marker(name, mat):
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.12)
    m = bpy.context.active_object
    m.name = name
    m.data.materials.append(mat)
    return m


red, blue = material("A", (0.85, 0.2, 0.15)), material("B", (0.15, 0.35, 0.85))
dress(a, red)
dress(b, blue)
bpy.ops.mesh.primitive_plane_add(size=40.0)
floor = bpy.context.active_object
floor.data.materials.append(material("floor", (0.55, 0.55, 0.5)))
cam = keyed_camera(a, b)
want = on_screen(cam, (a, b), KEY_FRAMES)
select(a, b)
r = bpy.ops.inbetween.camera_from_armatures(style="ORBIT", shot_list=True)
assert r == {"FINISHED"}, r
yellow = material("target", (1.0, 0.85, 0.1))
markers = (marker("target A", yellow), marker("target B", yellow))

sc.render.engine = "BLENDER_WORKBENCH"
sc.display.shading.light = "STUDIO"
sc.display.shading.color_type = "MATERIAL"
sc.render.resolution_x, sc.render.resolution_y, sc.render.resolution_percentage = W, H, 100
rows = [("keys", "CamAction")] + [(s, f"CamAction.inbetween.{s}") for s in ("direct", "relative", "side", "orbit")]
sheet = np.zeros((len(rows) * H, len(FRAMES) * W, 4), dtype=np.float32)
tmp = out / "_frame.png"
for i, (label, action) in enumerate(rows):
    cam.animation_data.action = bpy.data.actions[action]
    err = np.abs(on_screen(cam, (a, b), KEY_FRAMES) - want).max()
    span = list(range(KEY_FRAMES[0], KEY_FRAMES[-1] + 1))
    seen = on_screen(cam, (a, b), span)
    inside = ((seen >= 0.0) & (seen <= 1.0)).all(axis=(1, 2))
    print(
        f"render: {label}: {action}, screen error at the keys {err:.2e}; both framed points inside the frame on "
        f"{inside.sum()}/{len(span)} frames {KEY_FRAMES[0]}-{KEY_FRAMES[-1]}"
        + (f" (outside: {[f for f, i in zip(span, inside) if not i][:1]}…{[f for f, i in zip(span, inside) if not i][-1:]})" if not inside.all() else "")
    )
    for j, f in enumerate(FRAMES):
        sc.frame_set(f)
        for m, ob in zip(markers, (a, b)):
            m.location = target(ob)
        sc.render.filepath = str(tmp)
        bpy.ops.render.render(write_still=True)
        img = bpy.data.images.load(str(tmp))
        px = np.array(img.pixels[:], dtype=np.float32).reshape(H, W, 4)
        bpy.data.images.remove(img)
        # Image rows run bottom-up; the sheet's first row is at the top.
        y = (len(rows) - 1 - i) * H
        sheet[y : y + H, j * W : (j + 1) * W] = px
        # A white rule under each row and right of each frame.
        sheet[y, j * W : (j + 1) * W] = 1.0
        sheet[y : y + H, j * W] = 1.0
os.unlink(tmp)
img = bpy.data.images.new("camera_sheet", len(FRAMES) * W, len(rows) * H, alpha=True)
img.pixels[:] = sheet.ravel()
settings = sc.render.image_settings
settings.file_format, settings.color_mode, settings.color_depth, settings.compression = "PNG", "RGB", "8", 100
img.save_render(str(out / "camera_sheet.png"), scene=sc)
print("render:", out / "camera_sheet.png", "rows", [r[0] for r in rows], "frames", FRAMES)
sys.stdout.flush()
os._exit(0)
