"""The exported `home` keyframe stands a floating robot on the floor, as `--on-ground` does.

A converted floating robot's free joint starts where its root link is in the description, most
often the origin, so legs and feet reach below z = 0. A MuJoCo user who resets a scene to `home`
then starts the robot inside the ground: measured on the bundled humanoid, 0.95 m deep, and
with ctrl 0 the ground's contact threw it 179 m up within 10 s. A twin World spawned
`--on-ground` lowers or raises the robot until its lowest collision point rests on z = 0 and
keeps the key's joint values and orientation; `place_on_ground` gives the keyframe the same
shift, on every free joint (the root and an SDF model's other unjoined links), with the same
geometry (`converters.mjcf.lowest_point`), so the key is that spawn's state to the bit. The
key's ctrl is not changed here (`export_servos` writes the posture its position servos hold).
A fixed-base robot keeps its pose: its base is where its description welds it.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from converters.mjcf.lowest_point import collision_geoms, lowest_point

if TYPE_CHECKING:
    import mujoco

HOME_KEY = "home"  # the converter's keyframe of the robot's initial posture (mjcf.builder)


def place_on_ground(spec: mujoco.MjSpec) -> float | None:
    """Shifts every free joint of `spec`'s `home` keyframe so the robot's lowest collision
    point is at z = 0 (changes `spec`; its model's qpos0 stays as it was).

    Returns:
        The height the key was raised by [m], or None when nothing moved: no `home` key, no free
        joint, or no bounded collision geometry.
    """
    import mujoco

    key = next((k for k in spec.keys if k.name == HOME_KEY), None)
    if key is None:
        return None
    model = spec.copy().compile()
    free = np.flatnonzero(model.jnt_type == mujoco.mjtJoint.mjJNT_FREE)
    if len(free) == 0:
        return None
    data = mujoco.MjData(model)
    data.qpos[:] = model.key(HOME_KEY).qpos
    mujoco.mj_kinematics(model, data)
    on_bodies = np.flatnonzero(model.geom_bodyid != 0)  # the world body's geoms stay put
    low = lowest_point(model, data, collision_geoms(model, on_bodies))
    if low is None:
        return None
    qpos = data.qpos.copy()
    qpos[model.jnt_qposadr[free] + 2] -= low
    key.qpos = qpos
    return -float(low)
