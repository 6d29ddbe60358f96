"""`bpy.ops.inbetween.camera_from_armatures`: the camera engine over two armatures. The scene
camera's keyframes (its pose and field of view at each keyed frame) are the keys; the engine
generates a camera in one of its four styles that passes through every key, written to a new
action on the camera (the original action kept); `shot_list` writes one action per style to
switch between.

Frames and units. The engine's world is Y up, in metres; Blender's is Z up, in scene units
(`unit_settings.scale_length` metres each). A point maps by `C = (x, z, −y)`, a rotation by
`C · R`; a camera looks down its local −Z with +Y up in both, so a camera's rotation maps the same
way. Each armature becomes an engine clip (`rig.Rig`: bones as joints, local rotations, cm) whose
root carries the object's world transform and `C`, so the engine's forward kinematics lands on
the bones' world positions; the engine finds each one's hips and upper arms by name and frames the
point 15 cm above the shoulder midpoint. Key poses go to the engine as world poses with their
vertical field of view (`camera.pose_key`); it turns them into Toric coordinates at the key's
frame against the two characters (A: the active armature). The result is measured in Blender: at
every key the two targets are projected (`world_to_camera_view`) through the original and the new
camera, and the report gives the largest difference.
"""

import math
import re
import threading

import numpy as np

import bpy
from bpy.props import BoolProperty, EnumProperty, StringProperty

from . import anim, engine
from .jobs import JobError, call_engine, engine_fractions, fractions
from .rig import Rig, RigError, mat3_to_quat, quat_mul, sample
from .runner import JobOperator

#: The camera engine's styles (the CLI's `--style`).
STYLES = ("direct", "relative", "side", "orbit")
STYLE_ITEMS = [
    ("DIRECT", "Direct", "In front of the main character (A), swinging round as its torso turns"),
    ("RELATIVE", "Relative", "Rigid in the frame of the pair: dollies as they approach or part, the framing kept"),
    ("SIDE", "Side", "A profile two-shot on the pair's bisector at a constant distance, no zoom"),
    ("ORBIT", "Orbit", "Swings from one character's shoulder to the other's, whatever they do"),
    ("REFERENCE", "Reference Camera", "The style of another camera's motion over these two characters (Reference)"),
]
#: Blender (Z up) to the engine (Y up): (x, y, z) → (x, z, −y).
C = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])
#: Transform curves the new action holds; the camera's other curves are copied over.
TRANSFORM_PATHS = ("location", "rotation_euler", "rotation_quaternion", "rotation_axis_angle")
#: Largest change of the field of view between keys, radians: the engine frames through one lens.
FOV_TOLERANCE = 1e-4


def _matrix(m) -> np.ndarray:
    return np.array([list(r) for r in m], dtype=np.float64)


def lens_of(cam, scene, depsgraph):
    """(vertical field of view in radians, aspect) of `cam` as the render sees it."""
    r = scene.render
    p = _matrix(
        cam.calc_matrix_camera(
            depsgraph,
            x=r.resolution_x,
            y=r.resolution_y,
            scale_x=r.pixel_aspect_x,
            scale_y=r.pixel_aspect_y,
        )
    )
    if abs(p[0, 2]) > 1e-9 or abs(p[1, 2]) > 1e-9:
        raise JobError(
            f"{cam.name}: lens shift {cam.data.shift_x:g}, {cam.data.shift_y:g}: the engine frames with a centred "
            "lens; set Shift to 0"
        )
    return 2.0 * math.atan(1.0 / p[1, 1]), p[1, 1] / p[0, 0]


def camera_key_frames(cam):
    """Whole frames holding a key on the camera's location or rotation curves."""
    ad = cam.animation_data
    if ad is None or ad.action is None:
        return []
    frames = set()
    for fc in anim.fcurves(cam, ad.action):
        if fc.data_path in TRANSFORM_PATHS:
            for t in anim.key_times(fc):
                if abs(t - round(t)) > 1e-3:
                    raise JobError(f"{cam.name}: a key at frame {t:g}: keys must be on whole frames")
                frames.add(int(round(t)))
    return sorted(frames)


class CameraJob:
    """Generates the camera (see the module's words)."""

    def __init__(self, context, a, b, cam, styles, active_style, reference=None):
        self.scene = context.scene
        self.a, self.b, self.cam = a, b, cam
        self.reference = reference  #: the camera whose motion gives the "reference" style
        self.styles = list(styles)
        self.active_style = active_style
        self.cancel = threading.Event()
        self.created = []
        self.original_action = None
        self.summary = ""

    def check(self):
        a, b, cam, sc = self.a, self.b, self.cam, self.scene
        if cam is None:
            raise JobError("no scene camera: set one (Scene properties › Camera) and key it where it frames the two")
        if cam.type != "CAMERA":
            raise JobError(f"{cam.name} is not a camera")
        if cam.data.type != "PERSP":
            raise JobError(f"{cam.name}: a {cam.data.type.lower()} camera; the engine frames with a perspective lens")
        if cam.parent is not None:
            raise JobError(f"{cam.name} is parented to {cam.parent.name}: clear its parent (keep transform) first")
        if cam.rotation_mode == "AXIS_ANGLE":
            raise JobError(f"{cam.name}: rotation mode axis-angle; set an Euler or quaternion mode")
        delta = (
            cam.delta_location.length
            + abs(cam.delta_rotation_quaternion.angle)
            + sum(abs(v) for v in cam.delta_rotation_euler)
        )
        if delta > 1e-9:
            raise JobError(f"{cam.name}: delta transforms are set; apply or clear them first")
        ref = self.reference
        if "reference" in self.styles:
            if ref is None:
                raise JobError("style Reference Camera: name the reference camera (a camera object with an action)")
            if ref == cam:
                raise JobError(f"the reference camera {ref.name} is the camera being made: name another one")
            if ref.type != "CAMERA" or ref.animation_data is None or ref.animation_data.action is None:
                raise JobError(f"reference camera {ref.name}: expected a camera object with an action")
        frames = camera_key_frames(cam)
        if not frames:
            raise JobError(
                f"{cam.name} has no keyframes: key its location and rotation where it frames the two characters"
            )
        for ob, role in ((a, "A"), (b, "B")):
            ad = ob.animation_data
            if ad is None or ad.action is None:
                raise JobError(f"{ob.name} (character {role}): no action; the engine needs the armature's motion")
            paths = {fc.data_path for fc in anim.fcurves(ob, ad.action)}
            moving = sorted(paths & set(TRANSFORM_PATHS + ("scale",)))
            if moving:
                raise JobError(
                    f"{ob.name} (character {role}) moves as an object ({', '.join(moving)} keyed): the engine follows "
                    "its bones only; move the root bone instead"
                )
        if frames[0] < sc.frame_start or (len(frames) == 1 and frames[0] >= sc.frame_end):
            raise JobError(
                f"{cam.name}: key at frame {frames[0]} outside the scene's frames {sc.frame_start}–{sc.frame_end}"
                if frames[0] < sc.frame_start
                else f"{cam.name}: one key at frame {frames[0]}, the scene's last frame: nothing to generate"
            )
        last = frames[-1] if len(frames) > 1 else sc.frame_end
        return frames, last

    def steps(self):
        inbetween = engine.require()
        a, b, cam, sc = self.a, self.b, self.cam, self.scene
        frames, last = self.check()
        first = frames[0]
        span = np.arange(first, last + 1)
        m_per_unit = sc.unit_settings.scale_length
        fps = sc.render.fps / sc.render.fps_base
        frame_now = sc.frame_current
        try:
            clips = []
            for i, ob in enumerate((a, b)):
                try:
                    rig = Rig.of(ob, sc, tails=False)
                except RigError as e:
                    raise JobError(f"{ob.name}: {e}") from None
                basis, _ = yield from fractions(
                    sample(ob, sc, rig, span), 0.25 * i, 0.25 * (i + 1), f"sampling {ob.name}"
                )
                offsets, rots, trans = rig.clip_arrays(basis)
                rots, trans = self._to_engine_world(ob, rig, rots, trans)
                clips.append(inbetween.Clip.from_arrays(rig.names, rig.parents, offsets, fps, rots, trans))
            keys, fov, aspect = self._keys(frames, first)
            yield 0.5, "generating"
            tracks = {}
            reference = self._reference_poses(span) if "reference" in self.styles else None
            for i, style in enumerate(self.styles):
                lo = 0.5 + 0.4 * i / len(self.styles)
                how = {"reference": reference} if style == "reference" else {"style": style}
                track = yield from _blender_frames(first, inbetween.InbetweenError, engine_fractions(
                    call_engine(
                        inbetween.camera.generate,
                        self.cancel,
                        keys,
                        characters=tuple(clips),
                        names=(a.name, b.name),
                        fov_deg=math.degrees(fov),
                        aspect=aspect,
                        **how,
                    ),
                    lo,
                    lo + 0.4 / len(self.styles),
                    f"generating the {style} camera",
                ))
                tracks[style] = track
            yield 0.9, "writing the camera"
            # Measured in Blender at every key: both targets through the original and each new camera.
            points = self._targets(tracks[self.styles[0]], frames, first, m_per_unit)
            before = self._project(frames, points)
            ad = cam.animation_data
            self.original_action = ad.action
            results, errors = {}, {}
            for style, track in tracks.items():
                action = self._write(track, first, m_per_unit, style)
                results[style] = (action, track)
                errors[style] = float(np.abs(self._project(frames, points) - before).max())
            ad.action = results[self.active_style][0]
            self.original_action.use_fake_user = True  # kept beside the result
            chosen, track = results[self.active_style]
            err = errors[self.active_style]
            for style, (action, trk) in results.items():
                action["inbetween_camera"] = {
                    "style": style,
                    "characters": [a.name, b.name],
                    "key_frames": frames,
                    "frames": [int(first), int(last)],
                    "max_key_screen_error": errors[style],
                    "network_key_miss": trk.worst_key_miss,
                    "fov_deg": math.degrees(fov),
                    # Where the engine put the framed points at each key (Blender world units).
                    "key_targets": [[list(map(float, p)) for p in k] for k in points],
                    "notes": "; ".join(trk.notes),
                }
            others = [results[s][0].name for s in self.styles if s != self.active_style]
            self.summary = (
                f"camera {cam.name}: {chosen.name!r} through {len(frames)} keys ({self.active_style}, frames "
                f"{first}–{last}); at the keys both characters within {err:.2e} of the key camera on screen "
                f"(measured in Blender)"
            )
            if others:
                self.summary += f"; shot list: {', '.join(repr(n) for n in others)} beside it"
            self.created = []
        finally:
            sc.frame_set(frame_now)
        yield 1.0, "done"

    # -- pieces ------------------------------------------------------------------------------------
    def _to_engine_world(self, ob, rig, rots, trans):
        """The clip's root carries the object's world transform and the axis change: root rotation
        `C · R_object ⊗ q`, root translation `C · (M_object · t)` in cm."""
        w = _matrix(ob.matrix_world)
        s = float(np.cbrt(abs(np.linalg.det(w[:3, :3]))))
        r = C @ (w[:3, :3] / s)
        qr = mat3_to_quat(r)  # (w, x, y, z)
        roots = [j for j, p in enumerate(rig.parents[: rig.num_bones]) if p < 0]
        root = roots[0]
        q = rots[:, root][:, [3, 0, 1, 2]].astype(np.float64)  # (T, 4) w, x, y, z
        q = quat_mul(np.broadcast_to(qr, q.shape), q)
        rots = rots.copy()
        rots[:, root] = q[:, [1, 2, 3, 0]].astype(np.float32)
        t_units = trans.astype(np.float64) / rig.cm_per_unit
        world = t_units @ w[:3, :3].T + w[:3, 3]
        cm = 100.0 * self.scene.unit_settings.scale_length
        trans = (world @ C.T * cm).astype(np.float32)
        return rots, trans

    def _keys(self, frames, first):
        """The camera's pose and lens at each key frame, as engine pose keys (frames counted from
        the first key), the vertical field of view (radians) and the aspect."""
        sc, cam = self.scene, self.cam
        depsgraph = bpy.context.evaluated_depsgraph_get()
        keys, fovs = [], []
        aspect = None
        for f in frames:
            sc.frame_set(f)
            m = _matrix(cam.matrix_world)
            rot = m[:3, :3] / np.linalg.norm(m[:3, :3], axis=0)
            fov, aspect = lens_of(cam.evaluated_get(depsgraph), sc, depsgraph)
            fovs.append((f, fov))
            q = mat3_to_quat(C @ rot)  # (w, x, y, z)
            pos = C @ m[:3, 3] * sc.unit_settings.scale_length
            keys.append(inbetween_pose_key(f - first, pos, q[[1, 2, 3, 0]], math.degrees(fov)))
        f0, fov0 = fovs[0]
        for f, fov in fovs[1:]:
            if abs(fov - fov0) > FOV_TOLERANCE:
                raise JobError(
                    f"{cam.name}: the field of view changes between keys ({math.degrees(fov0):.2f}° at frame {f0}, "
                    f"{math.degrees(fov):.2f}° at frame {f}): the engine frames the track through one lens"
                )
        return keys, fov0, aspect

    def _reference_poses(self, span):
        """The reference camera's world pose at each frame of `span`, in the engine's frame."""
        sc, ref = self.scene, self.reference
        pos, rot = [], []
        for f in span:
            sc.frame_set(int(f))
            m = _matrix(ref.matrix_world)
            r = C @ (m[:3, :3] / np.linalg.norm(m[:3, :3], axis=0))
            pos.append(C @ m[:3, 3] * sc.unit_settings.scale_length)
            rot.append(mat3_to_quat(r)[[1, 2, 3, 0]])
        return np.array(pos), np.array(rot)

    def _write(self, track, first, m_per_unit, style):
        """A new action on the camera: location and rotation keyed on every frame of the track
        (linear in between), the original's other curves copied."""
        cam = self.cam
        ad = cam.animation_data
        name = f"{self.original_action.name if self.original_action else cam.name}.inbetween.{style}"
        action = bpy.data.actions.new(name)
        self.created.append(action)
        ad.action = action
        frames = np.asarray(track.frames, dtype=np.float64) + first
        pos = track.positions_m @ C / m_per_unit  # Cᵀ · p for each row
        rot_eng = track.rotations  # (T, 4) x, y, z, w
        mats = _quat_xyzw_to_mat(rot_eng)
        mats = np.einsum("ji,tjk->tik", C, mats)  # Cᵀ · R
        mode = cam.rotation_mode
        curves = {}
        for i in range(3):
            curves[("location", i)] = pos[:, i]
        if mode == "QUATERNION":
            q = mat3_to_quat(mats)
            for t in range(1, len(q)):
                if np.dot(q[t], q[t - 1]) < 0:
                    q[t] = -q[t]
            for i in range(4):
                curves[("rotation_quaternion", i)] = q[:, i]
        else:
            from mathutils import Matrix

            eul = np.zeros((len(mats), 3))
            prev = None
            for t, m in enumerate(mats):
                mm = Matrix([list(r) for r in m])
                e = mm.to_euler(mode, prev) if prev is not None else mm.to_euler(mode)
                eul[t] = tuple(e)
                prev = e
            for i in range(3):
                curves[("rotation_euler", i)] = eul[:, i]
        for (path, index), values in curves.items():
            fc = anim.new_fcurve(cam, action, path, index, "Object Transforms")
            pts = fc.keyframe_points
            pts.add(len(frames))
            co = np.stack([frames, values], axis=1).astype(np.float32).ravel()
            pts.foreach_set("co", co)
            pts.foreach_set("handle_left", co)
            pts.foreach_set("handle_right", co)
            linear = bpy.types.Keyframe.bl_rna.properties["interpolation"].enum_items["LINEAR"].value
            pts.foreach_set("interpolation", np.full(len(frames), linear, dtype=np.int32))
            fc.update()
        if self.original_action is not None:
            for fc in anim.fcurves(cam, self.original_action):
                if fc.data_path not in TRANSFORM_PATHS:
                    _copy_curve(cam, action, fc)
        return action

    def _targets(self, track, frames, first, m_per_unit):
        """World positions (Blender units) of the two framed targets at each key frame, as the
        engine placed them."""
        rows = {int(f): i for i, f in enumerate(track.frames)}
        return np.array([track.targets_m[rows[f - first]] @ C / m_per_unit for f in frames])  # (K, 2, 3)

    def _project(self, frames, points):
        """(K, 2, 2) screen positions (0..1, Blender's camera view) of the targets at each key."""
        from bpy_extras.object_utils import world_to_camera_view
        from mathutils import Vector

        sc = self.scene
        out = np.zeros((len(frames), 2, 2))
        for k, f in enumerate(frames):
            sc.frame_set(f)
            cam = self.cam.evaluated_get(bpy.context.evaluated_depsgraph_get())
            for j in range(2):
                v = world_to_camera_view(sc, cam, Vector(points[k, j]))
                out[k, j] = (v.x, v.y)
        return out

    def message(self) -> str:
        return self.summary

    def rollback(self) -> None:
        cam = self.cam
        if cam is not None and cam.animation_data is not None and self.created:
            cam.animation_data.action = self.original_action
        for action in self.created:
            bpy.data.actions.remove(action)
        self.created = []


def _blender_frames(first, error_type, gen):
    """Passes `gen` on; an engine error's key frames (counted from the first key) become Blender's."""
    try:
        return (yield from gen)
    except error_type as e:
        text = re.sub(r"\bframe (\d+)", lambda m: f"frame {int(m.group(1)) + first}", str(e))
        raise JobError(text) from None


def inbetween_pose_key(frame, position, rotation_xyzw, fov_deg):
    return {
        "frame": int(frame),
        "camera": {
            "position": [float(v) for v in position],
            "rotation": [float(v) for v in rotation_xyzw],
            "fov_deg": float(fov_deg),
        },
    }


def _quat_xyzw_to_mat(q):
    x, y, z, w = (q[:, i] for i in range(4))
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], axis=-1),
            np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], axis=-1),
            np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], axis=-1),
        ],
        axis=1,
    )


def _copy_curve(owner, action, src):
    fc = anim.new_fcurve(owner, action, src.data_path, src.array_index, src.group.name if src.group else None)
    n = len(src.keyframe_points)
    fc.keyframe_points.add(n)
    fields = (("co", np.float32, 2), ("handle_left", np.float32, 2), ("handle_right", np.float32, 2))
    for name, dtype, width in fields + (("interpolation", np.int32, 1),):
        buf = np.zeros(n * width, dtype=dtype)
        src.keyframe_points.foreach_get(name, buf)
        fc.keyframe_points.foreach_set(name, buf)
    for p, q in zip(fc.keyframe_points, src.keyframe_points):
        p.handle_left_type, p.handle_right_type = q.handle_left_type, q.handle_right_type
    fc.extrapolation = src.extrapolation
    fc.update()


def pick_characters(context, name_a: str, name_b: str):
    """Characters A and B: the named armatures, else the two selected ones (the active one is A)."""
    objects = bpy.data.objects
    if name_a or name_b:
        picked = []
        for role, name in (("A", name_a), ("B", name_b)):
            ob = objects.get(name) if name else None
            if ob is None or ob.type != "ARMATURE":
                raise JobError(f"character {role}: {name!r} is not an armature in this file")
            picked.append(ob)
        if picked[0] == picked[1]:
            raise JobError(f"characters A and B are both {picked[0].name!r}: name two armatures")
        return picked
    selected = [ob for ob in context.selected_objects if ob.type == "ARMATURE"]
    if len(selected) != 2:
        raise JobError(
            f"{len(selected)} armature{'s' if len(selected) != 1 else ''} selected: select the two characters' "
            "armatures (the active one is A)"
        )
    active = context.active_object
    if active in selected:
        selected.remove(active)
        return [active, selected[0]]
    return sorted(selected, key=lambda o: o.name)


class INBETWEEN_OT_camera_from_armatures(JobOperator, bpy.types.Operator):
    """Generate the scene camera's motion through its keyframes over two armatures, in one of the
    camera engine's styles (a new action on the camera; the original is kept)"""

    bl_idname = "inbetween.camera_from_armatures"
    bl_label = "Camera from Armatures (inbetween)"
    bl_options = {"REGISTER", "UNDO"}

    style: EnumProperty(name="Style", items=STYLE_ITEMS, default="RELATIVE")
    shot_list: BoolProperty(
        name="Shot List",
        description="Make one action per style (all four) to switch between in the Action editor; the "
        "chosen style's is assigned",
    )
    armature_a: StringProperty(name="Character A", description="Armature of character A (default: the active one)")
    armature_b: StringProperty(
        name="Character B", description="Armature of character B (default: the other selected one)"
    )
    camera: StringProperty(name="Camera", description="The camera (default: the scene camera)")
    reference_camera: StringProperty(
        name="Reference",
        description="Style Reference Camera: the camera whose motion over these characters gives the style",
    )

    def make_job(self, context):
        a, b = pick_characters(context, self.armature_a, self.armature_b)
        if self.camera:
            cam = bpy.data.objects.get(self.camera)
            if cam is None:
                raise JobError(f"camera {self.camera!r}: no such object")
        else:
            cam = context.scene.camera
        style = self.style.lower()
        styles = [style] + [s for s in STYLES if s != style] if self.shot_list else [style]
        reference = bpy.data.objects.get(self.reference_camera) if self.reference_camera else None
        if self.reference_camera and reference is None:
            raise JobError(f"reference camera {self.reference_camera!r}: no such object")
        job = CameraJob(context, a, b, cam, styles, style, reference)
        job.check()
        return job

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        for name in ("style", "reference_camera", "shot_list", "armature_a", "armature_b", "camera"):
            layout.prop(self, name)


CLASSES = (INBETWEEN_OT_camera_from_armatures,)
