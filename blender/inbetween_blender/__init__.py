"""inbetween for Blender: the inbetween engines on Blender's data. Reduce an armature's keys to a
bound in cm measured in Blender; inpaint a face's shape keys; a camera over two armatures; a text
into an animated scene.

One source for both: Blender 3.4+ loads this folder as an add-on (`bl_info`, the engines' package
unpacked in `_vendor/`), 4.2+ as an extension (`blender_manifest.toml`, the package as a wheel)."""

bl_info = {
    "name": "inbetween",
    "author": "inbetween contributors",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "View3D > Sidebar > inbetween; Graph Editor / Dope Sheet > Key",
    "description": "Keys reduced to a bound in cm, face inpainting, camera in-betweening, text to scene",
    "category": "Animation",
}

from . import engine  # noqa: E402

engine.add_vendor_path()

import bpy  # noqa: E402

from . import ops_camera, ops_face, ops_reduce, ops_scene, ui  # noqa: E402

_MODULES = [ops_reduce, ops_scene, ops_face, ops_camera]


def _classes():
    for m in _MODULES:
        yield from m.CLASSES
    yield from ui.CLASSES


def register():
    for cls in _classes():
        bpy.utils.register_class(cls)
    ui.register()


def unregister():
    ui.unregister()
    for cls in reversed(list(_classes())):
        bpy.utils.unregister_class(cls)
