"""`bpy.ops.inbetween.reduce_keys`: the armature's action reduced to the fewest keys that keep every
bone within a bound in cm (measured in Blender), or to a key count."""


import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty

from .reduce import ReduceJob, ReduceOptions
from .runner import JobOperator

METHOD_ITEMS = [
    ("AUTO", "Auto", "Error-bounded with a bound in cm, optimal with a key count"),
    ("ERROR_BOUNDED", "Error-bounded", "The fewest keys keeping every joint within the bound"),
    ("OPTIMAL", "Optimal", "The key count's best keys (dynamic programming)"),
    ("GREEDY", "Greedy", "Keys added where the error is largest"),
    ("SIDQL", "SIDQL", "The paper's reinforcement-learned selector"),
    ("UNIFORM", "Uniform", "Evenly spaced keys"),
]

ROTATION_ITEMS = [
    ("KEEP", "Keep Mode", "Euler bones keep Euler curves, keys chosen for them (and added where Blender's curve still leaves the bound)"),
    (
        "QUATERNION",
        "Quaternion",
        "Euler bones get quaternion curves, the engine's own curve (fewest keys); their rotation mode is switched "
        "to quaternion, and keyed so in the new action",
    ),
]


class INBETWEEN_OT_reduce_keys(JobOperator, bpy.types.Operator):
    """Reduce the active armature's keys to a bound in cm on the bones (or a key count); the result
    goes to a new action, the original is kept"""

    bl_idname = "inbetween.reduce_keys"
    bl_label = "Reduce Keys (inbetween)"
    bl_options = {"REGISTER", "UNDO"}

    max_error_cm: FloatProperty(
        name="Max Error (cm)",
        description="Largest distance any bone's head or tail may move from the original, centimetres "
        "in the scene's units",
        default=1.0,
        min=0.0,
        soft_min=0.01,
        soft_max=20.0,
    )
    max_error_deg: FloatProperty(
        name="Max Angle (°)",
        description="Also bound each bone's orientation error, degrees (0: no angle bound)",
        default=0.0,
        min=0.0,
        soft_max=30.0,
    )
    keys: IntProperty(
        name="Keys",
        description="A key count instead of the bound (0: use the bound)",
        default=0,
        min=0,
    )
    method: EnumProperty(name="Method", items=METHOD_ITEMS, default="AUTO")
    frame_start: IntProperty(name="Start", description="First frame to reduce (default: the action's first)")
    frame_end: IntProperty(name="End", description="Last frame to reduce (default: the action's last)")
    use_frame_range: BoolProperty(
        name="Frame Range", description="Reduce only frames Start to End (also on when either is given)"
    )
    selected_only: BoolProperty(name="Selected Bones", description="Reduce only the selected pose bones")
    include_tails: BoolProperty(
        name="Bound Tails",
        description="Also keep the tails of end bones (finger, toe and head tips) within the bound",
        default=True,
    )
    rotation: EnumProperty(name="Rotation", items=ROTATION_ITEMS, default="KEEP")
    new_action: BoolProperty(
        name="New Action",
        description="Write the result to a new action and keep the original (off: replace it)",
        default=True,
    )

    def make_job(self, context):
        from . import engine

        engine.require()
        given = self.properties.is_property_set
        start = self.frame_start if self.use_frame_range or given("frame_start") else None
        end = self.frame_end if self.use_frame_range or given("frame_end") else None
        options = ReduceOptions(
            max_error_cm=self.max_error_cm,
            max_error_deg=self.max_error_deg,
            keys=self.keys,
            method=self.method.lower(),
            frame_start=start,
            frame_end=end,
            selected_only=self.selected_only,
            new_action=self.new_action,
            include_tails=self.include_tails,
            rotation=self.rotation.lower(),
        )
        ob = context.active_object
        job = ReduceJob(context, ob, options)
        job.check()
        return job

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        col = layout.column()
        draw_props(col, self, ("max_error_cm", "max_error_deg", "keys", "method", "use_frame_range"))
        sub = col.column(align=True)
        sub.active = self.use_frame_range
        draw_props(sub, self, ("frame_start", "frame_end"))
        draw_props(col, self, ("selected_only", "include_tails", "rotation", "new_action"))


def draw_props(layout, data, names) -> None:
    for name in names:
        layout.prop(data, name)


CLASSES = (INBETWEEN_OT_reduce_keys,)
