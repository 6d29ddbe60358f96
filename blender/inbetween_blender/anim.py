"""F-curves on every Blender we support: `Action.fcurves` on 3.x/4.x, the slot's channelbag on
5.x (layered actions removed `Action.fcurves`); and replacing one frame range of a curve by
Bezier keys with handles we set (never Blender's auto handles, which would move them)."""

from __future__ import annotations

from typing import Dict, Optional, Tuple

import numpy as np

import bpy

#: (data path, array index) → F-curve
Channels = Dict[Tuple[str, int], "bpy.types.FCurve"]


def _slot(owner, action, create: bool):
    """5.x: the slot of `action` that animates `owner` (the assigned slot's identifier, else one
    named for `owner`, else the only one); made and assigned when `create` and none exists."""
    ad = owner.animation_data
    assigned = ad.action_slot if ad is not None and ad.action == action else None
    if assigned is not None:
        return assigned
    ident = ad.action_slot.identifier if ad is not None and ad.action_slot is not None else None
    for slot in action.slots:
        if slot.identifier == ident or slot.name_display == owner.name:
            return slot
    if len(action.slots) == 1:
        return action.slots[0]
    if not create:
        return None
    slot = action.slots.new(owner.id_type, owner.name)
    if ad is not None and ad.action == action:
        ad.action_slot = slot
    return slot


def _channelbag(owner, action, create: bool):
    """5.x: the channelbag of `owner`'s slot in `action` (layered actions; None when it has none)."""
    from bpy_extras import anim_utils

    slot = _slot(owner, action, create)
    if slot is None:
        return None
    if create:
        return anim_utils.action_ensure_channelbag_for_slot(action, slot)
    return anim_utils.action_get_channelbag_for_slot(action, slot)


def fcurves(owner, action):
    """The F-curves of `action` that animate `owner` (an object, or a mesh's shape key block);
    `Action.fcurves` on 3.x/4.x, the slot's channelbag on 5.x (empty when none)."""
    if hasattr(action, "fcurves"):
        return action.fcurves
    bag = _channelbag(owner, action, create=False)
    return bag.fcurves if bag is not None else []


def channels(owner, action) -> Channels:
    return {(fc.data_path, fc.array_index): fc for fc in fcurves(owner, action)}


def new_fcurve(owner, action, data_path: str, index: int, group: Optional[str]):
    """A new F-curve in `action` for `owner`, in the named group (a bone's name by convention)."""
    if hasattr(action, "fcurves"):
        return action.fcurves.new(data_path, index=index, action_group=group or "")
    bag = _channelbag(owner, action, create=True)
    fc = bag.fcurves.new(data_path, index=index)
    if group:
        grp = bag.groups.get(group) or bag.groups.new(group)
        fc.group = grp
    return fc


def remove_fcurve(owner, action, fc) -> None:
    if hasattr(action, "fcurves"):
        action.fcurves.remove(fc)
    else:
        _channelbag(owner, action, create=False).fcurves.remove(fc)


def bone_selected(pose_bone) -> bool:
    """A pose bone's selection: `PoseBone.select` on 5.x, `Bone.select` before."""
    return bool(pose_bone.select if hasattr(pose_bone, "select") else pose_bone.bone.select)


def select_bone(pose_bone, state: bool) -> None:
    if hasattr(pose_bone, "select"):
        pose_bone.select = state
    else:
        pose_bone.bone.select = state


def _enum_values(prop: str) -> Dict[str, int]:
    return {item.identifier: item.value for item in bpy.types.Keyframe.bl_rna.properties[prop].enum_items}


_FIELDS_2 = ("co", "handle_left", "handle_right")
_FIELDS_I = ("interpolation", "easing", "type")
_FIELDS_F = ("amplitude", "back", "period")


def key_times(fc) -> np.ndarray:
    """The frames of `fc`'s keys."""
    co = np.zeros(2 * len(fc.keyframe_points), dtype=np.float32)
    fc.keyframe_points.foreach_get("co", co)
    return co[0::2].astype(np.float64)


def _read(points) -> Dict[str, np.ndarray]:
    n = len(points)
    out = {}
    for f in _FIELDS_2:
        a = np.zeros(2 * n, dtype=np.float32)
        points.foreach_get(f, a)
        out[f] = a.reshape(n, 2).astype(np.float64)
    for f in _FIELDS_I:
        a = np.zeros(n, dtype=np.int32)
        points.foreach_get(f, a)
        out[f] = a
    for f in _FIELDS_F:
        a = np.zeros(n, dtype=np.float32)
        points.foreach_get(f, a)
        out[f] = a.astype(np.float64)
    return out


def replace_range(
    fc, frames: np.ndarray, values: np.ndarray, left: np.ndarray, right: np.ndarray, interpolation: str = "BEZIER"
) -> int:
    """Replaces the keys of `fc` on `frames[0] … frames[-1]` by Bezier keys at `frames` with
    `values` and FREE handles at `left`/`right` ((K, 2): frame, value). Keys outside are kept as
    they are; the first new key keeps the old key's left handle there and the last the old key's
    right handle and interpolation (frozen as FREE handles where they were automatic, since their
    neighbours change), so the curve outside the range does not change. Returns the number of keys
    removed.

    (Handle types cannot go through `foreach_set` (it ignores them silently), so the kept keys
    keep theirs by staying in place and only the new keys' types are set one by one.)"""
    a, b = float(frames[0]), float(frames[-1])
    points = fc.keyframe_points
    old = _read(points)
    x = old["co"][:, 0]
    eps = 1e-4
    keep = (x < a - eps) | (x > b + eps)
    at_a = np.nonzero(np.abs(x - a) <= eps)[0]
    at_b = np.nonzero(np.abs(x - b) <= eps)[0]
    k = len(frames)
    interp = _enum_values("interpolation")
    new = {
        "co": np.stack([frames, values], axis=1).astype(np.float64),
        "handle_left": np.array(left, dtype=np.float64),
        "handle_right": np.array(right, dtype=np.float64),
        "interpolation": np.full(k, interp[interpolation], dtype=np.int32),
        "easing": np.full(k, _enum_values("easing")["AUTO"], dtype=np.int32),
        "type": np.full(k, _enum_values("type")["KEYFRAME"], dtype=np.int32),
        "amplitude": np.full(k, 0.8),
        "back": np.full(k, 1.70158),
        "period": np.full(k, 4.1),
    }
    types = [["FREE", "FREE"] for _ in range(k)]
    if len(at_a) and np.any(x < a - eps):
        i = int(at_a[0])
        new["handle_left"][0] = old["handle_left"][i]
    if len(at_b) and np.any(x > b + eps):
        i = int(at_b[-1])
        new["handle_right"][-1] = old["handle_right"][i]
        for f in ("interpolation", "easing") + _FIELDS_F:
            new[f][-1] = old[f][i]
    removed = np.nonzero(~keep)[0]
    for i in removed[::-1]:
        points.remove(points[int(i)], fast=True)
    n_keep = len(points)
    points.add(k)
    for j, (lt, rt) in enumerate(types):
        p = points[n_keep + j]
        p.handle_left_type = lt
        p.handle_right_type = rt
    for f in old:
        arr = np.concatenate([old[f][keep], new[f]])
        points.foreach_set(f, arr.ravel().astype(np.int32 if arr.dtype.kind == "i" else np.float32))
    fc.update()
    return int(len(removed))
