"""An armature as the engines see it: joints, parents, rest offsets and local rotations in cm,
sampled from what Blender evaluates; and world head/tail positions for measuring.

Blender poses a bone relative to its rest frame: the armature-space pose of bone j is
`P_j = P_parent @ R_j @ B_j` with `R_j = parent.matrix_local⁻¹ @ bone.matrix_local` (the rest
transform relative to the parent) and `B_j` the pose basis (location, rotation, scale curves).
The engines' clip has a joint's local rotation relative to its parent's frame, so the joint
rotation given to them is `q_j = rot(R_j) ⊗ rot(B_j)`, and its offset `R_j.t + R_j.rot · B_j.t`.
Every bone's tail whose position no child's head gives is an extra leaf joint, so the engines
bound the whole bone.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import List, Sequence

import numpy as np


def quat_mul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton product of (…, 4) quaternions in Blender's (w, x, y, z) order."""
    aw, ax, ay, az = np.moveaxis(a, -1, 0)
    bw, bx, by, bz = np.moveaxis(b, -1, 0)
    return np.stack(
        [
            aw * bw - ax * bx - ay * by - az * bz,
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
        ],
        axis=-1,
    )


def quat_conj(q: np.ndarray) -> np.ndarray:
    return q * np.array([1.0, -1.0, -1.0, -1.0])


def mat3_to_quat(m: np.ndarray) -> np.ndarray:
    """(…, 3, 3) rotation matrices to unit quaternions (w, x, y, z) (Shepperd's method: each from
    its largest diagonal combination, so no division by a small number)."""
    m = np.asarray(m, dtype=np.float64)
    shape = m.shape[:-2]
    r = m.reshape(-1, 3, 3)
    d0, d1, d2 = r[:, 0, 0], r[:, 1, 1], r[:, 2, 2]
    cand = np.stack([1 + d0 + d1 + d2, 1 + d0 - d1 - d2, 1 - d0 + d1 - d2, 1 - d0 - d1 + d2], axis=1)
    pick = cand.argmax(axis=1)
    s = 2.0 * np.sqrt(np.maximum(cand[np.arange(len(r)), pick], 1e-300))
    a21, a12 = r[:, 2, 1], r[:, 1, 2]
    a02, a20 = r[:, 0, 2], r[:, 2, 0]
    a10, a01 = r[:, 1, 0], r[:, 0, 1]
    q = np.where(
        (pick == 0)[:, None],
        np.stack([0.25 * s, (a21 - a12) / s, (a02 - a20) / s, (a10 - a01) / s], axis=1),
        np.where(
            (pick == 1)[:, None],
            np.stack([(a21 - a12) / s, 0.25 * s, (a01 + a10) / s, (a02 + a20) / s], axis=1),
            np.where(
                (pick == 2)[:, None],
                np.stack([(a02 - a20) / s, (a01 + a10) / s, 0.25 * s, (a12 + a21) / s], axis=1),
                np.stack([(a10 - a01) / s, (a02 + a20) / s, (a12 + a21) / s, 0.25 * s], axis=1),
            ),
        ),
    )
    q /= np.linalg.norm(q, axis=-1, keepdims=True)
    return q.reshape(shape + (4,))


def make_continuous(q: np.ndarray) -> np.ndarray:
    """Flips signs along axis 0 so consecutive quaternions lie in the same hemisphere."""
    q = np.array(q, dtype=np.float64)
    for t in range(1, len(q)):
        flip = np.sum(q[t] * q[t - 1], axis=-1) < 0
        q[t][flip] *= -1
    return q


def matrices(collection, attr: str) -> np.ndarray:
    """A collection's 4×4 matrix property as (n, 4, 4) row-major float64 (foreach_get is column-major)."""
    flat = np.zeros(len(collection) * 16, dtype=np.float32)
    collection.foreach_get(attr, flat)
    return flat.reshape(-1, 4, 4).transpose(0, 2, 1).astype(np.float64)


@dataclass
class Rig:
    """The joints of an armature object: its bones in parent-first order, plus tail joints."""

    names: List[str]  #: bone names (the joints that are bones come first)
    bone_index: List[int]  #: index into `ob.pose.bones` of each bone joint
    parents: List[int]  #: parent joint, -1 for a root
    rest_rel: np.ndarray  #: (B, 4, 4) rest transform of each bone relative to its parent (armature units)
    tails: List[int]  #: bone joint of each tail joint
    tail_lengths: np.ndarray  #: bone length of each tail joint (armature units)
    cm_per_unit: float  #: centimetres per armature-space unit (scene unit scale × object scale)
    with_tails: bool = True  #: tails are bounded and measured

    @property
    def num_bones(self) -> int:
        return len(self.bone_index)

    @classmethod
    def of(cls, ob, scene, tails: bool = True) -> "Rig":
        bones = ob.data.bones
        pose_names = [pb.name for pb in ob.pose.bones]
        index = {n: i for i, n in enumerate(pose_names)}
        order: List[int] = []
        seen = set()

        def visit(bone) -> None:
            order.append(index[bone.name])
            seen.add(bone.name)
            for child in bone.children:
                visit(child)

        for bone in bones:
            if bone.parent is None:
                visit(bone)
        joint = {pose_names[b]: j for j, b in enumerate(order)}
        parents = []
        rest = matrices(bones, "matrix_local")  # armature space, in data.bones order
        data_index = {b.name: i for i, b in enumerate(bones)}
        rest_rel = np.zeros((len(order), 4, 4))
        for j, b in enumerate(order):
            bone = bones[pose_names[b]]
            m = rest[data_index[bone.name]]
            if bone.parent is None:
                parents.append(-1)
                rest_rel[j] = m
            else:
                parents.append(joint[bone.parent.name])
                rest_rel[j] = np.linalg.inv(rest[data_index[bone.parent.name]]) @ m
        tail_joints, lengths = [], []
        for j, b in enumerate(order):
            bone = bones[pose_names[b]]
            tail = np.array(bone.tail_local)
            if tails and not any(np.linalg.norm(np.array(c.head_local) - tail) < 1e-6 for c in bone.children):
                tail_joints.append(j)
                lengths.append(bone.length)
        scale = np.array(ob.matrix_world.to_scale())
        if np.ptp(scale) > 1e-6 * max(abs(scale).max(), 1e-12):
            raise RigError(f"{ob.name}: scaled unevenly ({scale[0]:g}, {scale[1]:g}, {scale[2]:g}); apply the scale first")
        cm = 100.0 * scene.unit_settings.scale_length * float(abs(scale[0]))
        return cls(
            names=[pose_names[b] for b in order] + [pose_names[order[j]] + ".tail" for j in tail_joints],
            bone_index=order,
            parents=parents + tail_joints,
            rest_rel=rest_rel,
            tails=tail_joints,
            tail_lengths=np.array(lengths, dtype=np.float64),
            cm_per_unit=cm,
            with_tails=tails,
        )

    def clip_arrays(self, basis: np.ndarray):
        """The engines' arrays from pose bases `(T, B, 4, 4)` (bone joints' order): offsets `[J, 3]`
        cm, rotations `[T, J, 4]` (x, y, z, w), root translations `[T, 3]` cm. A bone whose basis
        moves it (location keys below the root) gets its first frame's offset."""
        t, nb = basis.shape[:2]
        rr = self.rest_rel[None].repeat(t, 0)
        local = rr @ basis  # (T, B, 4, 4): joint frame relative to the parent's frame
        rot = np.zeros((t, len(self.names), 4))
        rot[..., 0] = 1.0
        rot[:, :nb] = make_continuous(mat3_to_quat(local[..., :3, :3]))
        offsets = np.zeros((len(self.names), 3))
        offsets[:nb] = local[0, :, :3, 3] * self.cm_per_unit
        offsets[nb:, 1] = self.tail_lengths * self.cm_per_unit
        roots = [j for j, p in enumerate(self.parents[:nb]) if p < 0]
        if len(roots) != 1:
            raise RigError(f"{len(roots)} root bones: the engines take one root (parent the others to it)")
        trans = local[:, roots[0], :3, 3] * self.cm_per_unit
        offsets[roots[0]] = trans[0]
        return offsets.astype(np.float32), rot[..., [1, 2, 3, 0]].astype(np.float32), trans.astype(np.float32)


class RigError(Exception):
    """An armature the engines cannot take, in words."""


def sample(ob, scene, rig: Rig, frames: Sequence[int]):
    """Yields progress while setting each frame; returns `(basis (T, B, 4, 4), points (T, P, 3))`:
    the pose bases Blender evaluated and the world positions of every bone's head (and tail, when
    the rig bounds tails), in cm."""
    pose_bones = ob.pose.bones
    n = len(pose_bones)
    basis = np.zeros((len(frames), rig.num_bones, 4, 4))
    points = np.zeros((len(frames), 2 * n if rig.with_tails else n, 3))
    heads = np.zeros(n * 3, dtype=np.float32)
    tails = np.zeros(n * 3, dtype=np.float32)
    world = np.array(ob.matrix_world, dtype=np.float64)
    order = rig.bone_index
    for i, f in enumerate(frames):
        scene.frame_set(int(f))
        basis[i] = matrices(pose_bones, "matrix_basis")[order]
        pose_bones.foreach_get("head", heads)
        p = heads.reshape(-1, 3)
        if rig.with_tails:
            pose_bones.foreach_get("tail", tails)
            p = np.concatenate([p, tails.reshape(-1, 3)])
        points[i] = p.astype(np.float64) @ world[:3, :3].T + world[:3, 3]
        yield (i + 1) / len(frames)
    points *= 100.0 * scene.unit_settings.scale_length
    return basis, points
