"""Reduce keys: the mocap engine's key selection on an armature's action, written back as Bezier
F-curves whose handles come from the engine's tangents, and the bound checked on what Blender
evaluates.

The work is a generator (`ReduceJob.steps`) that yields `(fraction, words)` between slices of at
most a few tens of milliseconds, so a modal operator keeps the UI live; the engine itself runs on a
worker thread (the native call releases the GIL).

Rotation curves. A bone in QUATERNION mode gets four quaternion F-curves: the engine's key values
and handles (its `quaternion_bezier` curve: per-component cubic Hermite, normalised, exactly what
Blender evaluates for FREE handles a third of a segment out), mapped into the bone's rest frame by
`rest_rel⁻¹ ⊗ ·` (a fixed unit quaternion on the left is an orthogonal map of the four components,
so it commutes with component-wise Hermite and with normalising). A bone in an Euler mode keeps
Euler curves (so the original action still plays with the bone's mode unchanged, and keys outside
a frame range are untouched), chosen for them: the engine's `euler_bezier` curve plays each such
joint as `rest_rel ⊗ R(E)`, a cubic Hermite per angle of the bone's own Euler values (its mode's
order, the original curves' values as the reference so the keys carry them) with slopes the Euler
rates `Ė = J(E)⁻¹ ω`; the engine gives the values and handles, which are what Blender evaluates.
The bound is then measured in Blender on every frame; where it is exceeded (float32 storage, an
angle bound the engine bounds on local rotations only), the worst frame of each such segment
becomes a key, until it holds (`rounds` in the result; `engine_keys` the engine's own count).
"""

from __future__ import annotations

import math
import threading
from dataclasses import dataclass, field
from typing import Dict, Iterator, List, Optional, Tuple

import numpy as np

from . import anim, engine
from .jobs import Cancelled, JobError, call_engine, engine_fractions, fractions  # noqa: F401 (Cancelled: tests)
from .rig import Rig, RigError, mat3_to_quat, quat_conj, quat_mul, sample

ReduceError = JobError  #: the name tests and scripts know

METHODS = ("error_bounded", "optimal", "greedy", "sidql", "uniform")
#: Rounds of tightening before giving up on the bound.
MAX_ROUNDS = 6
#: Slack on the measured bound: float32 curve storage.
BOUND_SLACK_CM = 1e-3


@dataclass
class ReduceOptions:
    max_error_cm: float = 1.0
    max_error_deg: float = 0.0  #: 0: no bound on angles
    keys: int = 0  #: > 0: this many keys instead of a bound
    method: str = "auto"
    frame_start: Optional[int] = None
    frame_end: Optional[int] = None
    selected_only: bool = False
    new_action: bool = True
    include_tails: bool = True  #: bound the tails of end bones (finger and toe tips) too
    #: "keep": Euler bones keep Euler curves; "quaternion": they get quaternion curves (the engine's
    #: own curve, so fewer keys) and their rotation mode is switched
    rotation: str = "keep"

    def validate(self) -> None:
        if self.keys < 0:
            raise JobError(f"keys {self.keys}: expected 0 (use the bound) or a count of at least 2")
        if self.keys == 1:
            raise JobError("keys 1: expected at least 2 (the first and last frames are keys)")
        if self.keys == 0 and not (math.isfinite(self.max_error_cm) and self.max_error_cm > 0):
            raise JobError(f"max error {self.max_error_cm} cm: expected a positive number of centimetres")
        if not (math.isfinite(self.max_error_deg) and self.max_error_deg >= 0):
            raise JobError(f"max error {self.max_error_deg}°: expected 0 (none) or a positive number of degrees")
        method = self.engine_method()
        if method not in METHODS:
            raise JobError(f"method {self.method!r}: expected one of auto, {', '.join(METHODS)}")
        if self.keys == 0 and method != "error_bounded":
            raise JobError(f"method {method} takes a key count (keys ≥ 2); a bound in cm needs error_bounded")
        if self.keys > 0 and method == "error_bounded":
            raise JobError("method error_bounded takes the bound in cm (keys = 0)")
        if self.rotation not in ("keep", "quaternion"):
            raise JobError(f"rotation {self.rotation!r}: expected keep or quaternion")
        if self.rotation == "quaternion" and (self.frame_start is not None or self.frame_end is not None):
            raise JobError("quaternion curves for Euler bones need the whole action: use rotation keep for a frame range")
        if self.frame_start is not None and self.frame_end is not None and self.frame_end <= self.frame_start:
            raise JobError(f"frame range {self.frame_start}–{self.frame_end}: expected the end after the start")

    def engine_method(self) -> str:
        m = self.method.lower()
        if m == "auto":
            return "optimal" if self.keys > 0 else "error_bounded"
        return m


@dataclass
class ReduceResult:
    action: str
    original: str
    frames: Tuple[int, int]
    key_frames_before: int
    key_frames_after: int
    keys_before: int  #: keyframes on the reduced F-curves inside the range
    keys_after: int
    curves: int
    bones: int
    max_error_cm: float  #: measured in Blender, every frame, heads and tails of every bone
    mean_error_cm: float
    outside_max_cm: float  #: outside the frame range (0 when untouched)
    max_error_deg: float
    bound_cm: Optional[float]
    engine_keys: int  #: the engine's selection, before keys were added where Blender's curve left the bound
    rounds: int
    engine_max_error_cm: float  #: the engine's own figure on its curve
    switched: int = 0  #: Euler bones switched to quaternion rotation
    #: per round: key frames, the max measured in Blender (cm, degrees)
    history: List[Tuple[int, float, float]] = field(default_factory=list)
    notes: List[str] = field(default_factory=list)

    def properties(self) -> Dict[str, object]:
        """The result as ID properties (stored on the new action: what was done and measured)."""
        d = {k: v for k, v in self.__dict__.items() if v is not None}
        d["frames"] = list(self.frames)
        d["notes"] = "; ".join(self.notes)
        d["history"] = [list(h) for h in self.history]
        return d

    def message(self) -> str:
        s = (
            f"{self.key_frames_before} → {self.key_frames_after} keys, max {self.max_error_cm:.3f} cm "
            f"measured in Blender (mean {self.mean_error_cm:.3f} cm, {self.max_error_deg:.2f}°) on frames "
            f"{self.frames[0]}–{self.frames[1]}; {self.bones} bones, action {self.action!r}"
        )
        if self.key_frames_after > self.engine_keys:
            s += (
                f"; {self.key_frames_after - self.engine_keys} keys added to the engine's {self.engine_keys} "
                f"where Blender's curve left the bound ({self.rounds} rounds)"
            )
        if self.notes:
            s += "; " + "; ".join(self.notes)
        return s


EULER_MODES = ("XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX")


def engine_order(mode: str) -> str:
    """The engine's Euler order (channel order, composed left to right) of a Blender rotation mode:
    Blender's "XYZ" applies X first, R = Rz·Ry·Rx, which the engine calls "ZYX"."""
    return mode[::-1]


@dataclass
class _Channel:
    bone: str
    joint: int
    data_path: str
    index: int
    kind: str  # "quat", "euler", "loc"
    euler_order: str = ""  #: an Euler bone's mode when its curves become quaternion curves


class ReduceJob:
    """Reduce the keys of armature `ob`'s action (see the module's words)."""

    def __init__(self, context, ob, options: ReduceOptions):
        self.scene = context.scene
        self.ob = ob
        self.options = options
        self.cancel = threading.Event()
        self.result: Optional[ReduceResult] = None
        self.created = None  # the new action, removed again on cancel or error
        self.original_action = None
        self.modes: Dict[str, str] = {}  # rotation modes switched, restored on cancel or error

    # -- checks that need no engine ------------------------------------------------------------
    def check(self):
        ob, o = self.ob, self.options
        o.validate()
        if ob is None or ob.type != "ARMATURE":
            raise JobError("no armature selected: select an armature with an action")
        ad = ob.animation_data
        if ad is None or ad.action is None:
            raise JobError(f"{ob.name}: no action to reduce")
        action = ad.action
        lo, hi = (int(round(v)) for v in action.frame_range)
        a = lo if o.frame_start is None else int(o.frame_start)
        b = hi if o.frame_end is None else int(o.frame_end)
        if a < lo or b > hi or b - a < 2:
            raise JobError(
                f"frames {a}–{b}: expected at least 3 frames inside the action's range {lo}–{hi}"
            )
        return action, (lo, hi), (a, b)

    def steps(self) -> Iterator[Tuple[float, str]]:
        inbetween = engine.require()
        ob, scene, o = self.ob, self.scene, self.options
        action, (lo, hi), (a, b) = self.check()
        try:
            rig = Rig.of(ob, scene, tails=o.include_tails)
        except RigError as e:
            raise JobError(str(e)) from None
        chans = anim.channels(ob, action)
        selected = {pb.name for pb in ob.pose.bones if anim.bone_selected(pb)} if o.selected_only else None
        if selected is not None and not selected:
            raise JobError(f"{ob.name}: no bones selected (pose mode), or turn off 'Selected bones'")
        todo, notes = self._channels(rig, chans, selected)
        if not todo:
            raise JobError(f"{ob.name}: no rotation or root location curves to reduce in {action.name!r}")
        all_frames = np.arange(lo, hi + 1)
        inside = (all_frames >= a) & (all_frames <= b)
        frame_now = scene.frame_current
        self.original_action = action
        try:
            basis, before = yield from fractions(sample(ob, scene, rig, all_frames), 0.0, 0.2, "sampling the action")
            before_rot = None
            if o.max_error_deg > 0:
                before_rot = yield from fractions(self._world_rotations(ob, scene, all_frames), 0.2, 0.25, "sampling angles")
            offsets, rots, trans = rig.clip_arrays(basis[inside])
            fps = scene.render.fps / scene.render.fps_base
            clip = inbetween.Clip.from_arrays(rig.names, rig.parents, offsets, fps, rots, trans)
            times = [anim.key_times(chans[(c.data_path, c.index)]) for c in todo if (c.data_path, c.index) in chans]
            times = [t[(t >= a) & (t <= b)] for t in times]
            keys_before = int(sum(len(t) for t in times))
            key_frames_before = len(np.unique(np.round(np.concatenate(times))))
            yield 0.2, "sampling the action"
            # Always on a copy: a cancelled or failed run leaves the original as it was.
            new = action.copy()
            new.name = action.name + ".reduced"
            new.use_fake_user = False
            self.created = new
            ob.animation_data.action = new
            bound = o.max_error_cm if o.keys == 0 else None
            switched = self._switch_modes(ob, new, todo, rig)
            if switched:
                notes.append(
                    f"{len(switched)} bones switched from Euler to quaternion rotation (the new action keys "
                    "rotation_mode; set the mode back to play the original)"
                )
            euler = self._euler_playback(rig, action, np.arange(a, b + 1), basis[inside])
            keys = yield from engine_fractions(
                call_engine(
                    engine.select_keys,
                    self.cancel,
                    clip,
                    o.engine_method(),
                    bound,
                    o.keys or None,
                    bound_deg=o.max_error_deg,
                    euler=euler,
                ),
                0.25,
                0.55,
                "choosing keys",
            )
            frames = np.asarray(keys.frames, dtype=np.int64)  # clip frames (0 = frame a)
            rounds = 0
            history: List[Tuple[int, float, float]] = []
            while True:
                rounds += 1
                bz = engine.bezier_handles(clip, frames, euler)
                yield from fractions(
                    self._write(ob, new, rig, todo, bz, fps, (a, b), basis[inside]), 0.55, 0.6, "writing keys"
                )
                _, after = yield from fractions(sample(ob, scene, rig, all_frames), 0.6, 0.9, "measuring in Blender")
                err = np.linalg.norm(after - before, axis=-1)  # (T, P) cm
                max_in = float(err[inside].max())
                per_frame = err[inside].max(axis=1)
                deg, deg_frame = 0.0, np.zeros(b - a + 1)
                if before_rot is not None:
                    after_rot = yield from fractions(
                        self._world_rotations(ob, scene, all_frames), 0.9, 0.95, "measuring angles"
                    )
                    deg_all = _angle_deg(before_rot, after_rot)  # (T, B)
                    deg_frame = deg_all[inside].max(axis=1)
                    deg = float(deg_all.max())
                history.append((len(frames), max_in, deg))
                if bound is None or rounds >= MAX_ROUNDS:
                    break
                over = per_frame > bound + BOUND_SLACK_CM
                if o.max_error_deg > 0:
                    over |= deg_frame > o.max_error_deg
                if not over.any():
                    break
                # Keys where Blender's curve leaves the bound: the worst frame of each such segment.
                worst = np.where(over, np.maximum(per_frame / bound, deg_frame / max(o.max_error_deg, 1e-9)), 0.0)
                add = [s + 1 + int(np.argmax(worst[s + 1 : e])) for s, e in zip(frames[:-1], frames[1:]) if e - s > 1 and worst[s + 1 : e].max() > 0]
                if not add:
                    break
                frames = np.union1d(frames, add)
                yield 0.55, f"adding {len(add)} keys (round {rounds + 1})"
            frames = frames + a
            if bound is not None and max_in > bound + BOUND_SLACK_CM:
                notes.append(f"bound not met after {rounds} rounds")
            if o.max_error_deg > 0 and deg > o.max_error_deg:
                notes.append(f"angle bound {o.max_error_deg}° not met ({deg:.2f}°)")
            keys_after = len(frames) * len(todo)
            if o.new_action:
                action.use_fake_user = True  # kept beside the result
            else:
                name = action.name
                action.user_remap(new)
                import bpy

                bpy.data.actions.remove(action)
                new.name = name
            self.result = ReduceResult(
                action=new.name,
                original=new.name if not o.new_action else action.name,
                frames=(a, b),
                key_frames_before=key_frames_before,
                key_frames_after=len(frames),
                keys_before=keys_before,
                keys_after=keys_after,
                curves=len(todo),
                bones=len({c.bone for c in todo}),
                max_error_cm=max_in,
                mean_error_cm=float(err[inside].mean()),
                outside_max_cm=float(err[~inside].max()) if (~inside).any() else 0.0,
                max_error_deg=deg,
                bound_cm=bound,
                engine_keys=len(keys.frames),
                rounds=rounds,
                engine_max_error_cm=float(keys.reconstruction.max_error_cm),
                switched=len(switched),
                history=history,
                notes=notes,
            )
            new["inbetween_reduce"] = self.result.properties()
            self.created = None
            self.modes = {}
        finally:
            scene.frame_set(frame_now)
        yield 1.0, "done"

    def message(self) -> str:
        return self.result.message()

    def rollback(self) -> None:
        """Undoes what a cancelled or failed run changed (the new action and its assignment)."""
        for name, mode in self.modes.items():
            self.ob.pose.bones[name].rotation_mode = mode
        self.modes = {}
        if self.created is not None:
            if self.ob.animation_data is not None and self.original_action is not None:
                self.ob.animation_data.action = self.original_action
            import bpy

            bpy.data.actions.remove(self.created)
            self.created = None

    # -- pieces ------------------------------------------------------------------------------------
    def _channels(self, rig: Rig, chans: anim.Channels, selected) -> Tuple[List[_Channel], List[str]]:
        todo: List[_Channel] = []
        notes: List[str] = []
        pose = self.ob.pose.bones
        for j in range(rig.num_bones):
            pb = pose[rig.bone_index[j]]
            if selected is not None and pb.name not in selected:
                continue
            base = f'pose.bones["{_escape(pb.name)}"]'
            mode = pb.rotation_mode
            if mode == "QUATERNION":
                path, n, kind = base + ".rotation_quaternion", 4, "quat"
            elif mode == "AXIS_ANGLE":
                path, n, kind = base + ".rotation_axis_angle", 4, None
            else:
                path, n, kind = base + ".rotation_euler", 3, "euler"
            animated = any((path, i) in chans for i in range(n))
            if animated and kind is None:
                notes.append(f"{pb.name}: axis-angle curves kept as they are")
            elif animated and kind == "euler" and self.options.rotation == "quaternion":
                path = base + ".rotation_quaternion"
                todo += [_Channel(pb.name, j, path, i, "quat", euler_order=mode) for i in range(4)]
            elif animated:
                todo += [_Channel(pb.name, j, path, i, kind) for i in range(n)]
            loc = base + ".location"
            if any((loc, i) in chans for i in range(3)):
                if rig.parents[j] < 0:
                    todo += [_Channel(pb.name, j, loc, i, "loc") for i in range(3)]
                else:
                    notes.append(f"{pb.name}: location curves kept as they are (the engines move the root only)")
        return todo, notes

    def _switch_modes(self, ob, action, todo: List[_Channel], rig: Rig) -> List[str]:
        """Bones whose Euler curves become quaternion curves (option rotation="quaternion"): their
        mode switched (a constant rotation_mode curve in the new action records it), their Euler
        curves dropped from the new action. Returns their names."""
        names = sorted({c.bone for c in todo if c.euler_order})
        if not names:
            return []
        chans = anim.channels(ob, action)
        value = {i.identifier: i.value for i in ob.pose.bones[0].bl_rna.properties["rotation_mode"].enum_items}
        for name in names:
            pb = ob.pose.bones[name]
            self.modes[name] = pb.rotation_mode
            base = f'pose.bones["{_escape(name)}"]'
            for i in range(3):
                fc = chans.get((base + ".rotation_euler", i))
                if fc is not None:
                    anim.remove_fcurve(ob, action, fc)
            pb.rotation_mode = "QUATERNION"
            fc = chans.get((base + ".rotation_mode", 0)) or anim.new_fcurve(ob, action, base + ".rotation_mode", 0, name)
            lo, hi = action.frame_range
            fc.keyframe_points.clear()
            for f in (lo, hi):
                k = fc.keyframe_points.insert(f, value["QUATERNION"])
                k.interpolation = "CONSTANT"
        return names

    def _write(self, ob, action, rig: Rig, todo: List[_Channel], bz, fps, rng, basis):
        """Writes the engine's Bezier keys `bz` (clip frames from 0 = frame a) into the reduced
        channels. Yields progress per bone."""
        a, b = rng
        chans = anim.channels(ob, action)
        orig = anim.channels(ob, self.original_action)
        frames = np.asarray(bz["frames"], dtype=np.float64) + a
        lf = np.asarray(bz["left_frames"], dtype=np.float64) + a
        rf = np.asarray(bz["right_frames"], dtype=np.float64) + a
        rest_q = mat3_to_quat(rig.rest_rel[:, :3, :3])  # (B, 4) wxyz
        wxyz = [3, 0, 1, 2]
        q_val = np.asarray(bz["rotations"], dtype=np.float64)[..., wxyz]  # (K, J, 4)
        q_left = np.asarray(bz["rotations_left"], dtype=np.float64)[..., wxyz]
        q_right = np.asarray(bz["rotations_right"], dtype=np.float64)[..., wxyz]
        t_val = np.asarray(bz["translations_cm"], dtype=np.float64)
        t_right = np.asarray(bz["translations_right_cm"], dtype=np.float64)
        e_val, e_left, e_right = (
            None if bz.get(name) is None else np.asarray(bz[name], dtype=np.float64)
            for name in ("euler", "euler_left", "euler_right")
        )
        by_bone: Dict[int, List[_Channel]] = {}
        for c in todo:
            by_bone.setdefault(c.joint, []).append(c)
        # Rates per frame from the right handles (each key's one slope; the first and last keys'
        # handles mirror their one segment).
        gap_r = (rf - frames)[:, None]
        for n, (j, cs) in enumerate(by_bone.items()):
            yield n / len(by_bone)
            for kind in ("quat", "euler", "loc"):
                group = [c for c in cs if c.kind == kind]
                if not group:
                    continue
                if kind == "loc":
                    inv = np.linalg.inv(rig.rest_rel[j][:3, :3])
                    values = np.array([_orig_values(orig, group, f, basis[int(f) - a, j], "loc") for f in frames])
                    rate = (t_right[:, j] - t_val[:, j]) / gap_r / rig.cm_per_unit @ inv.T  # per frame
                    left, right = values - rate * (frames - lf)[:, None], values + rate * gap_r
                elif kind == "quat":
                    # The rest frame's inverse on the left: an orthogonal map of the components.
                    r_inv = quat_conj(rest_q[j])[None]
                    q, ql, qr = (quat_mul(r_inv, x[:, j]) for x in (q_val, q_left, q_right))
                    start = _orig_values(orig, group, a, basis[0, j], "quat")
                    if np.dot(start, q[0]) < 0:  # the original's sign at the first key
                        q, ql, qr = -q, -ql, -qr
                    values, left, right = q, ql, qr
                else:
                    # The engine's Euler curves of this bone: x, y, z as rotation_euler holds them.
                    values, left, right = e_val[:, j].copy(), e_left[:, j].copy(), e_right[:, j].copy()
                    # The values are the original curves' own (the engine's reference) to
                    # rounding: take them exactly, so a range's end keys join the curve outside.
                    for i in range(3):
                        fc = orig.get((group[0].data_path, i))
                        if fc is not None:
                            own = np.array([fc.evaluate(f) for f in frames])
                            d = np.where(np.abs(own - values[:, i]) < 1e-4, own - values[:, i], 0.0)
                            values[:, i] += d
                            left[:, i] += d
                            right[:, i] += d
                for c in group:
                    i = c.index
                    fc = chans.get((c.data_path, i))
                    if fc is None:
                        fc = anim.new_fcurve(ob, action, c.data_path, i, c.bone)
                        chans[(c.data_path, i)] = fc
                    anim.replace_range(
                        fc,
                        frames,
                        values[:, i],
                        np.stack([lf, left[:, i]], axis=1),
                        np.stack([rf, right[:, i]], axis=1),
                    )

    def _euler_playback(self, rig: Rig, action, frames: np.ndarray, basis: np.ndarray):
        """The engine's Euler playback of the rig (None when no bone plays Euler curves): each bone
        in an Euler mode its order, its rest rotation relative to its parent as the pre-rotation,
        and the original action's own angles at `frames` as the reference (the evaluated basis
        where a curve is missing); quaternion and axis-angle bones and tail joints play quaternion
        curves."""
        from mathutils import Matrix

        pose = self.ob.pose.bones
        orig = anim.channels(self.ob, action)
        nj = len(rig.names)
        orders: List[Optional[str]] = [None] * nj
        pre = np.zeros((nj, 4))
        pre[:, 3] = 1.0
        ref = np.zeros((len(frames), nj, 3))
        rest_q = mat3_to_quat(rig.rest_rel[:, :3, :3])  # (B, 4) wxyz
        for j in range(rig.num_bones):
            pb = pose[rig.bone_index[j]]
            mode = pb.rotation_mode
            if mode not in EULER_MODES:
                continue
            orders[j] = engine_order(mode)
            pre[j] = rest_q[j][[1, 2, 3, 0]]
            path = f'pose.bones["{_escape(pb.name)}"].rotation_euler'
            for i in range(3):
                fc = orig.get((path, i))
                if fc is not None:
                    ref[:, j, i] = [fc.evaluate(float(f)) for f in frames]
                else:
                    ref[:, j, i] = [Matrix(m[:3, :3].tolist()).to_euler(mode)[i] for m in basis[:, j]]
        if not any(orders):
            return None
        return {"euler_orders": orders, "pre_rotations": pre, "euler_reference": ref}

    def _world_rotations(self, ob, scene, frames):
        """Yields progress; returns each bone's armature-space orientation per frame (T, B, 4)."""
        out = []
        for i, f in enumerate(frames):
            scene.frame_set(int(f))
            out.append(_pose_matrices(ob)[:, :3, :3])
            yield (i + 1) / len(frames)
        return mat3_to_quat(np.array(out))


def _pose_matrices(ob) -> np.ndarray:
    from .rig import matrices

    return matrices(ob.pose.bones, "matrix")


def _angle_deg(qa: np.ndarray, qb: np.ndarray) -> np.ndarray:
    """Angles between orientations, degrees, elementwise over (…, 4)."""
    d = np.abs(np.sum(qa * qb, axis=-1)).clip(0.0, 1.0)
    return np.degrees(2 * np.arccos(d))


def _orig_values(orig: anim.Channels, group, frame, basis: np.ndarray, kind: str) -> np.ndarray:
    """The original action's own values of a bone's channel set at `frame` (its curves where it
    has them, the evaluated basis elsewhere)."""
    if kind == "quat":
        v = mat3_to_quat(basis[:3, :3])
    else:
        v = basis[:3, 3].copy()
    path = group[0].data_path
    for i in range(len(v)):
        fc = orig.get((path, i))
        if fc is not None:
            v[i] = fc.evaluate(frame)
    return v


def _escape(name: str) -> str:
    return name.replace("\\", "\\\\").replace('"', '\\"')
