"""Panels and menu entries: the 3D View's N-panel (tab "inbetween"), the Graph Editor's and the Dope
Sheet's Key menus. Settings live on the scene (`scene.inbetween`) so the panel keeps them."""


import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, PointerProperty

from .ops_reduce import METHOD_ITEMS


class InbetweenSettings(bpy.types.PropertyGroup):
    max_error_cm: FloatProperty(name="Max Error (cm)", default=1.0, min=0.0, soft_min=0.01, soft_max=20.0)
    max_error_deg: FloatProperty(name="Max Angle (°)", default=0.0, min=0.0, soft_max=30.0)
    keys: IntProperty(name="Keys", description="A key count instead of the bound (0: use the bound)", min=0)
    method: EnumProperty(name="Method", items=METHOD_ITEMS, default="AUTO")
    use_preview_range: BoolProperty(
        name="Scene Range Only", description="Reduce only the scene's frame range (the preview range when set)"
    )
    selected_only: BoolProperty(name="Selected Bones")
    new_action: BoolProperty(name="New Action", default=True)


def reduce_button(layout, context):
    s = context.scene.inbetween
    op = layout.operator("inbetween.reduce_keys", icon="IPO_BEZIER")
    op.max_error_cm = s.max_error_cm
    op.max_error_deg = s.max_error_deg
    op.keys = s.keys
    op.method = s.method
    op.selected_only = s.selected_only
    op.new_action = s.new_action
    if s.use_preview_range:
        sc = context.scene
        op.use_frame_range = True
        op.frame_start = sc.frame_preview_start if sc.use_preview_range else sc.frame_start
        op.frame_end = sc.frame_preview_end if sc.use_preview_range else sc.frame_end


class INBETWEEN_PT_reduce(bpy.types.Panel):
    bl_label = "Reduce Keys"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "inbetween"

    @classmethod
    def poll(cls, context):
        ob = context.active_object
        return ob is not None and ob.type == "ARMATURE"

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        s = context.scene.inbetween
        col = layout.column()
        col.prop(s, "max_error_cm")
        col.prop(s, "max_error_deg")
        col.prop(s, "keys")
        col.prop(s, "method")
        col.prop(s, "use_preview_range")
        col.prop(s, "selected_only")
        col.prop(s, "new_action")
        reduce_button(layout, context)


class INBETWEEN_PT_reduce_graph(INBETWEEN_PT_reduce):
    bl_space_type = "GRAPH_EDITOR"


class INBETWEEN_PT_scene(bpy.types.Panel):
    bl_label = "Scene, Camera, Face"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "inbetween"

    def draw(self, context):
        col = self.layout.column()
        for idname, icon in (
            ("inbetween.text_to_scene", "TEXT"),
            ("inbetween.camera_from_armatures", "CAMERA_DATA"),
            ("inbetween.face_inpaint", "SHAPEKEY_DATA"),
        ):
            if hasattr(bpy.types, "INBETWEEN_OT_" + idname.split(".")[1]):
                col.operator(idname, icon=icon)


def menu_entry(self, context):
    self.layout.separator()
    self.layout.operator("inbetween.reduce_keys", icon="IPO_BEZIER")


CLASSES = (InbetweenSettings, INBETWEEN_PT_reduce, INBETWEEN_PT_reduce_graph, INBETWEEN_PT_scene)
MENUS = ("GRAPH_MT_key", "DOPESHEET_MT_key")


def register():
    bpy.types.Scene.inbetween = PointerProperty(type=InbetweenSettings)
    for m in MENUS:
        getattr(bpy.types, m).append(menu_entry)


def unregister():
    for m in MENUS:
        getattr(bpy.types, m).remove(menu_entry)
    del bpy.types.Scene.inbetween
