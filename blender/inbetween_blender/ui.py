"""Panels and menu entries: the 3D View's N-panel (tab "inbetween"), the Graph Editor's and the Dope
Sheet's Key menus. Settings live on the scene (`scene.inbetween`) so the panel keeps them."""


import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, PointerProperty

from .ops_reduce import METHOD_ITEMS, ROTATION_ITEMS, draw_props


class InbetweenSettings(bpy.types.PropertyGroup):
    max_error_cm: FloatProperty(name="Max Error (cm)", default=1.0, min=0.0, soft_min=0.01, soft_max=20.0)
    max_error_deg: FloatProperty(name="Max Angle (°)", default=0.0, min=0.0, soft_max=30.0)
    keys: IntProperty(name="Keys", description="A key count instead of the bound (0: use the bound)", min=0)
    method: EnumProperty(name="Method", items=METHOD_ITEMS, default="AUTO")
    use_preview_range: BoolProperty(
        name="Scene Range Only", description="Reduce only the scene's frame range (the preview range when set)"
    )
    selected_only: BoolProperty(name="Selected Bones")
    include_tails: BoolProperty(name="Bound Tails", default=True)
    rotation: EnumProperty(name="Rotation", items=ROTATION_ITEMS, default="KEEP")
    new_action: BoolProperty(name="New Action", default=True)


#: The panel's settings, in order.
SETTINGS = (
    "max_error_cm", "max_error_deg", "keys", "method", "use_preview_range", "selected_only", "include_tails",
    "rotation", "new_action",
)


def reduce_button(layout, context):
    s = context.scene.inbetween
    op = layout.operator("inbetween.reduce_keys", icon="IPO_BEZIER")
    for name in SETTINGS:
        if name != "use_preview_range":
            setattr(op, name, getattr(s, name))
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
        draw_props(layout.column(), s, SETTINGS)
        reduce_button(layout, context)


class INBETWEEN_PT_reduce_graph(INBETWEEN_PT_reduce):
    bl_space_type = "GRAPH_EDITOR"


class INBETWEEN_PT_scene(bpy.types.Panel):
    bl_label = "Scene and Face"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "inbetween"

    def draw(self, context):
        col = self.layout.column()
        col.operator("inbetween.text_to_scene", icon="TEXT")
        col.operator("inbetween.camera_from_armatures", icon="CAMERA_DATA")
        col.operator("inbetween.face_inpaint", icon="SHAPEKEY_DATA")
        row = col.row(align=True)
        row.operator("inbetween.import_live_link", text="Import Live Link", icon="IMPORT")
        row.operator("inbetween.export_live_link", text="Export Live Link", icon="EXPORT")


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
