"""A fixed base for MJCF sources: each top-level body's free joint removed, keyframes kept whole.

A description that twin converts is welded by the converter (`ConvertOptions.fixed_base`); an
MJCF file or an MjSpec is welded here, so that `--fixed-base` means the same for every source
and a saved world (whose entities may be stored as MJCF) loads as it was spawned. A welded body
stays where the file puts it in its model frame, which the world attaches at the spawn pose.
"""

from __future__ import annotations

from dataclasses import replace
from typing import TYPE_CHECKING

import mujoco

if TYPE_CHECKING:
    from twin_cli.world.spawn import LoadedSource

# Sizes in qpos and qvel of each mjtJoint (free, ball, slide, hinge): MuJoCo's mjNQ/mjNV.
QPOS_WIDTH = {0: 7, 1: 4, 2: 1, 3: 1}
DOF_WIDTH = {0: 6, 1: 3, 2: 1, 3: 1}
FREE = int(mujoco.mjtJoint.mjJNT_FREE)
OPTION = "--fixed-base"


def weld_loaded(loaded: LoadedSource) -> LoadedSource:
    """`loaded` with its spec's floating roots welded and a note saying which (or that none
    floated, so nothing changed)."""
    welded = weld_roots(loaded.spec)
    if welded:
        notes = tuple(f"root '{body}' welded to the world ({OPTION})" for body in welded)
    else:
        notes = (f"{loaded.source} is already fixed to the world; {OPTION} changed nothing",)
    return replace(loaded, notes=loaded.notes + notes)


def weld_roots(spec: mujoco.MjSpec) -> list[str]:
    """Deletes the free joint of every top-level body of `spec`; returns those bodies' names.

    Keyframes written for the free layout lose the deleted joints' qpos and qvel entries, so
    the robot's own joints keep their values; a keyframe that gives no qpos (or qvel) is left
    as it is.
    """
    free = [i for i, joint in enumerate(spec.joints) if _floats_root(spec, joint)]
    if not free:
        return []
    joints = list(spec.joints)
    keep_q, keep_v = _kept_entries(joints, set(free))
    for key in spec.keys:
        if len(key.qpos) == len(keep_q) + QPOS_WIDTH[FREE] * len(free):
            key.qpos = [key.qpos[i] for i in keep_q]
        if len(key.qvel) == len(keep_v) + DOF_WIDTH[FREE] * len(free):
            key.qvel = [key.qvel[i] for i in keep_v]
    names = [joints[i].parent.name or "(unnamed)" for i in free]
    for i in free:
        spec.delete(joints[i])
    return names


def _floats_root(spec: mujoco.MjSpec, joint: mujoco.MjsJoint) -> bool:
    """Whether `joint` is the free joint of a body placed in the worldbody."""
    return int(joint.type) == FREE and joint.parent.parent == spec.worldbody


def _kept_entries(joints: list[mujoco.MjsJoint], removed: set[int]) -> tuple[list[int], list[int]]:
    """The qpos and qvel indices of every joint whose index is not in `removed`, in the spec's
    order, which is MuJoCo's qpos order."""
    keep_q: list[int] = []
    keep_v: list[int] = []
    q = v = 0
    for i, joint in enumerate(joints):
        nq, nv = QPOS_WIDTH[int(joint.type)], DOF_WIDTH[int(joint.type)]
        if i not in removed:
            keep_q += range(q, q + nq)
            keep_v += range(v, v + nv)
        q, v = q + nq, v + nv
    return keep_q, keep_v
