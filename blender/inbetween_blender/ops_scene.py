"""`bpy.ops.inbetween.text_to_scene`: a text block becomes a furnished, animated scene (the script
engine's `RunJob`), imported with Blender's own glTF importer into a new collection, its shot
camera made the scene camera."""


import os
import tempfile
import threading

import bpy
from bpy.props import IntProperty, StringProperty

from . import engine
from .jobs import JobError, call_engine, engine_fractions
from .runner import JobOperator


def gltf_import_workaround() -> None:
    """Debian's Blender 3.4 glTF importer uses `numpy.bool`, gone from numpy 1.24: give it back
    (the alias numpy itself had)."""
    import numpy

    if "bool" not in numpy.__dict__:
        numpy.bool = numpy.bool_


class SceneJob:
    def __init__(self, context, text_name: str, seed: int, collection: str):
        self.scene = context.scene
        self.view_layer = context.view_layer
        self.text_name = text_name
        self.seed = seed
        self.collection_name = collection or "inbetween story"
        self.cancel = threading.Event()
        self.collection = None
        self.summary = ""
        self._scene_state = None

    def check(self) -> str:
        text = bpy.data.texts.get(self.text_name) if self.text_name else None
        if text is None:
            names = ", ".join(t.name for t in bpy.data.texts) or "none"
            raise JobError(f"text {self.text_name!r}: no such text block (texts: {names})")
        story = text.as_string().strip()
        if not story:
            raise JobError(f"text {text.name!r} is empty: write a story, e.g. 'Anna walks to the sofa and sits down.'")
        if self.seed < 0:
            raise JobError(f"seed {self.seed}: expected a whole number, at least 0")
        return story

    def steps(self):
        inbetween = engine.require()
        story = self.check()
        made = yield from engine_fractions(
            call_engine(inbetween.script.run, self.cancel, story, seed=self.seed), 0.0, 0.8, "animating the story"
        )
        yield 0.8, "importing the glTF"
        sc = self.scene
        self._scene_state = (sc.render.fps, sc.render.fps_base, sc.frame_start, sc.frame_end, sc.camera)
        fps = made.fps
        if abs(fps - round(fps)) < 1e-6:
            sc.render.fps, sc.render.fps_base = int(round(fps)), 1.0
        coll = bpy.data.collections.new(self.collection_name)
        sc.collection.children.link(coll)
        self.collection = coll
        gltf_import_workaround()
        before = set(bpy.data.objects)
        fd, path = tempfile.mkstemp(suffix=".gltf", prefix="inbetween-story-")
        try:
            with os.fdopen(fd, "wb") as f:
                f.write(made.gltf)
            r = bpy.ops.import_scene.gltf(filepath=path)
        finally:
            os.unlink(path)
            # What the importer made goes into the new collection (it links to the active one).
            for ob in set(bpy.data.objects) - before:
                for c in list(ob.users_collection):
                    c.objects.unlink(ob)
                coll.objects.link(ob)
        if r != {"FINISHED"}:
            raise JobError(f"Blender's glTF importer returned {r}")
        objects = list(coll.all_objects)
        cameras = [o for o in objects if o.type == "CAMERA"]
        animated = [o for o in objects if o.animation_data and o.animation_data.action]
        # A character is the node named after it, its body the animated nodes under it.
        by_name = {o.name: o for o in objects}
        characters = {
            name: sum(1 for o in by_name[name].children_recursive if o.animation_data and o.animation_data.action)
            for name in sorted(made.characters)
            if name in by_name
        }
        if cameras:
            sc.camera = cameras[0]
        sc.frame_start, sc.frame_end = 0, max(0, made.frames - 1)
        self.summary = (
            f"story: {len(objects)} objects in {coll.name!r}, {sum(n > 0 for n in characters.values())} animated "
            f"characters ({', '.join(f'{k}: {n} animated parts' for k, n in characters.items())}), "
            f"{len(animated)} animated objects, "
            f"camera {cameras[0].name if cameras else 'none'}, frames 0–{made.frames - 1} at {fps:g} fps"
        )
        if made.notes:
            self.summary += "; " + "; ".join(made.notes)
        coll["inbetween_story"] = {"characters": len(characters), "frames": made.frames, "notes": "; ".join(made.notes)}
        self.collection = None  # done: kept
        yield 1.0, "done"

    def message(self) -> str:
        return self.summary

    def rollback(self) -> None:
        coll = self.collection
        if coll is not None:
            for ob in list(coll.all_objects):
                bpy.data.objects.remove(ob)
            for child in list(coll.children_recursive):
                bpy.data.collections.remove(child)
            bpy.data.collections.remove(coll)
            self.collection = None
        if self._scene_state is not None:
            sc = self.scene
            sc.render.fps, sc.render.fps_base, sc.frame_start, sc.frame_end, sc.camera = self._scene_state
            self._scene_state = None


class INBETWEEN_OT_text_to_scene(JobOperator, bpy.types.Operator):
    """Turn a text block's story into a furnished, animated scene with a shot camera (imported into a
    new collection)"""

    bl_idname = "inbetween.text_to_scene"
    bl_label = "Text to Scene (inbetween)"
    bl_options = {"REGISTER", "UNDO"}

    text: StringProperty(name="Text", description="The text block holding the story")
    seed: IntProperty(name="Seed", description="Seed of every random choice", default=1, min=0)
    collection: StringProperty(name="Collection", description="Name of the new collection", default="inbetween story")

    def invoke(self, context, event):
        if not self.text:
            space = context.space_data
            if space is not None and space.type == "TEXT_EDITOR" and space.text is not None:
                self.text = space.text.name
        return super().invoke(context, event)

    def make_job(self, context):
        job = SceneJob(context, self.text, self.seed, self.collection)
        job.check()
        return job

    def draw(self, context):
        layout = self.layout
        layout.prop_search(self, "text", bpy.data, "texts")
        layout.prop(self, "seed")
        layout.prop(self, "collection")


CLASSES = (INBETWEEN_OT_text_to_scene,)
