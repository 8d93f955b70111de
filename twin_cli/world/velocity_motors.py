"""Gazebo's velocity motor of a joint in a running world: on for velocity commands, off for the
others, and the effort it puts on its joint.

The converter gives each joint whose tags offer velocity commands a rotor and a tendon whose dry
friction, bounded by the joint's effort, couples the joint to the rotor's speed
(`converters.mjcf.velocity_motors`). A velocity command writes the rotor's ctrl and the tendon's
`frictionloss` (= the effort limit, or UNBOUNDED_EFFORT for a joint without one); the joint's
own motor pushes nothing. A position or effort command switches the friction off
(frictionloss 0: no constraint row at all) and runs the joint's motor as before
(`twin_cli.world.servos`, `native_servos`): the rotor is a speed reference, and a position servo
on top of it would need an outer loop in Python at every step.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import mujoco
import numpy as np

from converters.mjcf.export_servos import VELOCITY_MOTOR
from converters.mjcf.velocity_motors import SUFFIX, UNBOUNDED_EFFORT, is_rotor, rotor_name

RULE = "Gazebo's joint motor: a velocity constraint within ±effort"  # what `twin joints` shows
_ACTUATOR = mujoco.mjtObj.mjOBJ_ACTUATOR
MODELS_KEPT = 2  # compiled models whose motor lookups are kept: the world's and the one before

__all__ = ["RULE", "Rotor", "is_rotor", "rotor_name"]  # is_rotor: for the record and validate


@dataclass(frozen=True)
class Rotor:
    """A joint motor's velocity motor in one compiled model: its rotor actuator and tendon ids."""

    actuator: int
    tendon: int


def rotor_of(model: mujoco.MjModel, a: int) -> Rotor | None:
    """The velocity motor of joint motor `a`, or None if its joint has none."""
    return _motors(model).get(a)


@lru_cache(maxsize=MODELS_KEPT)
def _motors(model: mujoco.MjModel) -> dict[int, Rotor]:
    """Joint motor id → its velocity motor, for one compiled model: looked up once, not by name
    at every command (gz-sim's Ackermann commands its steering joints at every step)."""
    out = {}
    for t in range(model.ntendon):
        name = model.tendon(t).name
        if not is_rotor(name):
            continue
        a = mujoco.mj_name2id(model, _ACTUATOR, name.removesuffix(SUFFIX))
        r = mujoco.mj_name2id(model, _ACTUATOR, name)
        if a >= 0 and r >= 0:
            out[a] = Rotor(r, t)
    return out


def engage(
    model: mujoco.MjModel, data: mujoco.MjData, rotor: Rotor, speed: float, effort: float
) -> None:
    """Runs the joint at `speed` [rad/s or m/s] within ±`effort` [N m or N]; an infinite effort
    (a joint without an effort limit) is the export's UNBOUNDED_EFFORT on the tendon."""
    model.tendon_frictionloss[rotor.tendon] = min(effort, UNBOUNDED_EFFORT)
    data.ctrl[rotor.actuator] = speed


def disengage(model: mujoco.MjModel, data: mujoco.MjData, rotor: Rotor) -> None:
    """Frees the joint from its rotor (and stops the rotor, which then turns alone)."""
    model.tendon_frictionloss[rotor.tendon] = 0.0
    data.ctrl[rotor.actuator] = 0.0


def engaged_at_load(record: dict | None) -> float | None:
    """The effort [N m or N] a joint's velocity motor holds it with from load (velocity is its
    first mode, as the exported file has it; inf for a joint without an effort limit), or None."""
    motor = record.get(VELOCITY_MOTOR) if record else None
    if not motor or not motor.get("engaged"):
        return None
    return math.inf if motor["effort"] is None else float(motor["effort"])


@lru_cache(maxsize=MODELS_KEPT)
def effort_dofs(model: mujoco.MjModel) -> tuple[np.ndarray, np.ndarray]:
    """(joint dofs, rotor dofs) of every velocity motor of `model`: the tendon's force on the
    joint is the opposite of its force on the rotor, the only constraint the rotor has."""
    joints, rotors = [], []
    for t in range(model.ntendon):
        if not is_rotor(model.tendon(t).name) or model.tendon_num[t] != 2:
            continue
        adr = int(model.tendon_adr[t])
        joint, rotor = (int(model.wrap_objid[adr + k]) for k in (0, 1))
        joints.append(int(model.jnt_dofadr[joint]))
        rotors.append(int(model.jnt_dofadr[rotor]))
    return np.array(joints, dtype=np.int64), np.array(rotors, dtype=np.int64)


def joint_efforts(model: mujoco.MjModel, data: mujoco.MjData) -> np.ndarray:
    """Each dof's motor effort [N m or N]: `qfrc_actuator`, plus on a joint driven by its
    velocity motor the tendon's constraint force (ODE reports its motor's force alike)."""
    forces = data.qfrc_actuator.copy()
    joints, rotors = effort_dofs(model)
    if len(joints):
        forces[joints] -= data.qfrc_constraint[rotors]
    return forces
