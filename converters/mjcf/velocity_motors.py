"""Gazebo's joint motor for velocity commands, built from MuJoCo's own elements.

Gazebo drives a joint's velocity command (gazebo_ros2_control's velocity interface, DiffDrive)
with ODE's joint motor: a velocity constraint bounded by the joint's effort limit (FMax) that
stores nothing. A stalled joint slips at its effort and, released, comes back at its command
without paying the slip back; a servo with an integral (MuJoCo's `intvelocity`) stores it (a
0.1 N m wheel at 3 rad/s, overloaded 1.5× for 0.5 s, peaked at 43 rad/s after the release).

MuJoCo has that constraint as a tendon's dry friction, which bounds a velocity-level constraint
by `frictionloss` and keeps nothing between steps. Each joint J (hinge or slide) of effort E
(a large finite bound where J has no effort limit: gz-sim's velocity command is then unbounded)
whose tags offer velocity commands gets:
  - a rotor: a hinge or slide on J's axis at J's anchor, in a massless body that is a child of
    J's parent body (it turns relative to the same parent), with armature ARMATURE_RATIO × J's
    inertia about the axis, so that nothing J does changes its speed;
  - a `velocity` actuator on the rotor (ctrl = the commanded speed [rad/s or m/s]), kv =
    armature/h, which the implicit integrators integrate implicitly: it halves the rotor's
    speed error at every step;
  - a fixed tendon J − rotor with `frictionloss` = E, `solref_friction` = (2h, 1) and
    `solimp_friction` SOLIMP: J's speed is held to the rotor's within ±E, as ODE's motor.
Measured against the integral servo: a free 1 N m wheel reaches 95 % of 2 rad/s in 4 ms (the
effort allows 4 ms) without overshoot; after a 1 s stall at 2 rad/s it peaks at 2.00 rad/s
(servo 35.3); a held wheel pushed past its effort and released stays where it slipped.
The constraint is on (frictionloss E) when velocity is the joint's first mode; a World switches
it with the command's mode (`twin_cli.world.velocity_motors`) and leaves J's own motor for
the others.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    import mujoco

SUFFIX = "|velocity_motor"
"""The rotor body, joint, actuator and tendon of joint J are named J + SUFFIX: a mark no robot
file writes (SDF's nested names join with "::", so ":motor" named a nested model's `motor`)."""
ARMATURE_RATIO = 1e6  # rotor armature / J's inertia: the reference keeps its speed under J's pull
SOLIMP = 0.9999  # MuJoCo's largest impedance: the friction row as rigid as the solver allows
ROTOR_MASS = 1e-9  # [kg] the rotor body's mass: MuJoCo needs one on a body with a joint
UNBOUNDED_EFFORT = 1e9  # [N m or N] the tendon's bound for a joint without an effort limit


@dataclass(frozen=True)
class Motor:
    """One velocity motor to build.

    Attributes:
        joint: J's name. effort: its effort limit E [N m or N] (inf: none). inertia: its inertia
        about the axis [kg m² or kg]. speed: its velocity limit [rad/s or m/s] (inf: none), the
        rotor's ctrlrange. engaged: whether the constraint starts on (velocity is J's first mode).
    """

    joint: str
    effort: float
    inertia: float
    speed: float
    engaged: bool


def rotor_name(joint: str) -> str:
    """The name of joint `joint`'s rotor body, joint, actuator and tendon."""
    return joint + SUFFIX


def is_rotor(name: str) -> bool:
    """Whether an element's name is a velocity motor's (a rotor or its tendon)."""
    return name.endswith(SUFFIX)


def add_velocity_motors(
    spec: mujoco.MjSpec, motors: list[Motor], model: mujoco.MjModel, timestep: float
) -> None:
    """Adds each motor of `motors` to `spec` (module doc); `model` is `spec` compiled before.

    The spec's keyframes get the new joints (at 0) and actuators (ctrl 0), by name.
    """
    for motor in motors:
        _add_one(spec, motor, model, timestep)
    if motors and len(spec.keys):
        _rekey(spec, model)


def _add_one(spec: mujoco.MjSpec, motor: Motor, model: mujoco.MjModel, timestep: float) -> None:
    import mujoco

    j = model.joint(motor.joint).id
    child = int(model.jnt_bodyid[j])
    rotation = np.zeros(9)
    mujoco.mju_quat2Mat(rotation, model.body_quat[child])
    rotation = rotation.reshape(3, 3)
    anchor = model.body_pos[child] + rotation @ model.jnt_pos[j]
    axis = rotation @ model.jnt_axis[j]
    joint = spec.joint(motor.joint)
    parent = spec.body(model.body(int(model.body_parentid[child])).name)
    name = rotor_name(motor.joint)
    body = parent.add_body(name=name, pos=anchor)
    body.explicitinertial = True
    body.mass = ROTOR_MASS
    body.inertia = np.full(3, ROTOR_MASS)
    body.ipos = np.zeros(3)  # an inertial with a position is written to the file
    armature = ARMATURE_RATIO * motor.inertia
    rotor = body.add_joint(name=name, type=joint.type, axis=axis, armature=armature)
    # nothing from a default class: the rotor's only force is its actuator and the tendon's
    rotor.damping, rotor.stiffness = np.zeros(len(rotor.damping)), np.zeros(len(rotor.stiffness))
    rotor.frictionloss, rotor.springref = 0.0, 0.0
    rotor.limited = mujoco.mjtLimited.mjLIMITED_FALSE
    actuator = spec.add_actuator(name=name, target=name)
    actuator.trntype = mujoco.mjtTrn.mjTRN_JOINT
    actuator.gear = np.array([1.0, 0.0, 0.0, 0.0, 0.0, 0.0])
    actuator.set_to_velocity(kv=armature / timestep)
    if np.isfinite(motor.speed):
        actuator.ctrllimited = mujoco.mjtLimited.mjLIMITED_TRUE
        actuator.ctrlrange = np.array([-motor.speed, motor.speed])
    tendon = spec.add_tendon(name=name)
    tendon.wrap_joint(motor.joint, 1.0)
    tendon.wrap_joint(name, -1.0)
    tendon.frictionloss = min(motor.effort, UNBOUNDED_EFFORT) if motor.engaged else 0.0
    tendon.damping, tendon.stiffness = (
        np.zeros(len(tendon.damping)),
        np.zeros(len(tendon.stiffness)),
    )
    tendon.limited = mujoco.mjtLimited.mjLIMITED_FALSE
    tendon.solref_friction = np.array([2.0 * timestep, 1.0])
    tendon.solimp_friction = np.array([SOLIMP, SOLIMP, 0.001, 0.5, 2.0])


def _rekey(spec: mujoco.MjSpec, before: mujoco.MjModel) -> None:
    """Each keyframe of `spec` rewritten for its new joints and actuators, by name: qpos and
    qvel of the rotors 0 (a rotor's angle means nothing), their ctrl 0."""
    after = spec.copy().compile()
    for key in spec.keys:
        qpos, qvel = np.array(key.qpos, dtype=float), np.array(key.qvel, dtype=float)
        ctrl = np.array(key.ctrl, dtype=float)
        if len(qpos) == before.nq:
            key.qpos = _moved(before, after, qpos, "qpos", after.qpos0)
        if len(qvel) == before.nv:
            key.qvel = _moved(before, after, qvel, "dof", np.zeros(after.nv))
        if len(ctrl) == before.nu:
            key.ctrl = np.concatenate([ctrl, np.zeros(after.nu - before.nu)])


def _moved(
    before: mujoco.MjModel, after: mujoco.MjModel, values: np.ndarray, kind: str, fill: np.ndarray
) -> np.ndarray:
    """`values` (qpos or dof-sized, of `before`) at the addresses `after` gives the same joints."""
    out = np.array(fill, dtype=float)
    adr, widths = ("jnt_qposadr", (7, 4, 1, 1)) if kind == "qpos" else ("jnt_dofadr", (6, 3, 1, 1))
    for j in range(before.njnt):
        width = widths[int(before.jnt_type[j])]
        old = int(getattr(before, adr)[j])
        new = int(getattr(after, adr)[after.joint(before.joint(j).name).id])
        out[new : new + width] = values[old : old + width]
    return out
