"""A fixed-base robot's exported position servos carry its weight through MuJoCo's gravcomp.

A position servo alone holds a loaded joint off its target by load/kp: a Panda-like arm held
horizontal sagged 62.8 mrad on a wrist joint in the exported scene. MuJoCo computes that load
itself: `gravcomp="1"` on a body applies the force that cancels its weight, and
`actuatorgravcomp="true"` on a joint sends the joint's share through the joint's actuator,
where `actuatorfrcrange` (the effort limit) bounds servo and compensation together, so a joint
asked for more than its effort gives exactly its effort. A twin World does the same at run time
for the bodies its position commands hold (`twin_cli.world.gravity_comp`).

In the file a body is compensated when every joint between it and the world is a position
servo: a body below a passive, effort or velocity joint falls as it does in Gazebo, and one
below a joint whose tags give its servo a PID (which Gazebo runs alone) sags by load/kp. A body the
robot's own tags already compensate (Gazebo's gravity off) keeps its value. A floating robot
(a free joint) gets none: compensating its bodies would make the whole robot weightless. The
control record keeps what each change replaced, so a World spawning the file hands the
compensation to `twin_cli.world.gravity_comp`, which switches it with the commands.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from collections.abc import Container

    import mujoco

GRAVCOMP = "exported_gravcomp"  # key of a replaced motor's record: what `compensate` changed
FULL = 1.0  # gravcomp of a body whose whole weight the servos hold


def compensate(spec: mujoco.MjSpec, held: dict[str, tuple[float, float]]) -> dict[str, dict]:
    """Writes gravcomp into a fixed-base `spec` for the joints in `held` (see module doc).

    Args:
        spec: the robot, its servos already written.
        held: each position-servoed joint and its force range [N m or N] (infinite: none).

    Returns:
        For each joint changed, what it replaced (for `restore_gravcomp`); empty for a floating
        robot.
    """
    import mujoco

    if any(joint.type == mujoco.mjtJoint.mjJNT_FREE for joint in spec.joints):
        return {}
    changed = {}
    for name, (low, high) in held.items():
        joint = spec.joint(name)
        changed[name] = {
            "actgravcomp": bool(joint.actgravcomp),
            "actfrclimited": int(joint.actfrclimited),
            "actfrcrange": [float(v) for v in joint.actfrcrange],
        }
        joint.actgravcomp = True
        if np.isfinite(low) and np.isfinite(high):  # compensation within the servo's own range
            joint.actfrclimited = mujoco.mjtLimited.mjLIMITED_TRUE
            joint.actfrcrange = np.array([low, high])
    for body in spec.bodies:
        if body is spec.worldbody or body.gravcomp != 0.0 or not _chain_held(spec, body, held):
            continue
        body.gravcomp = FULL
        owner = _nearest_joint(body)  # the change is restored with this joint's
        changed[owner].setdefault("bodies", []).append(body.name)
    return changed


def _chain_held(spec: mujoco.MjSpec, body: mujoco.MjsBody, held: Container[str]) -> bool:
    """Whether `body` moves and every joint from it down to the world is in `held`."""
    moves = False
    while body is not spec.worldbody:
        for joint in body.joints:
            if joint.name not in held:
                return False
            moves = True
        body = body.parent
    return moves


def _nearest_joint(body: mujoco.MjsBody) -> str:
    """The first joint on the way from `body` to the world (`body` is in a held chain)."""
    while not body.joints:
        body = body.parent
    return body.joints[0].name


def restore_gravcomp(spec: mujoco.MjSpec, joint_name: str, changed: dict | None) -> None:
    """Undoes `compensate` for one joint: its actuator-gravcomp attributes and the bodies
    recorded with it, as `changed` (its entry of what `compensate` returned) says they were."""
    import mujoco

    if not changed:
        return
    joint = spec.joint(joint_name)
    joint.actgravcomp = bool(changed["actgravcomp"])
    joint.actfrclimited = mujoco.mjtLimited(changed["actfrclimited"])
    joint.actfrcrange = np.array(changed["actfrcrange"], dtype=float)
    for name in changed.get("bodies", []):
        spec.body(name).gravcomp = 0.0
