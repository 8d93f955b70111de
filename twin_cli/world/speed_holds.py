"""A velocity command of 0 as the joint's dry friction: Gazebo's joint motor at zero speed.

Gazebo's joint motor is a velocity constraint bounded by the effort limit (ODE's FMax). At speed
0 MuJoCo has that constraint itself: a joint's `frictionloss` is a velocity-0 constraint bounded
by a force. So a velocity servo commanded to 0 (a stopped wheel, a drive plugin's hold from load)
becomes the joint's own dry friction plus its effort limit, with the actuator pushing nothing: it
holds a load within the limit, slips at exactly the limit beyond it, and remembers nothing, so a
wheel stopped after a drive does not turn back and one pushed past its limit does not spring
back. A joint without an effort limit holds up to UNLIMITED. Measured on a 7 kg two-wheel base
parked on 5° for 10 s (wheels 5 N m): 0.041 mm of creep with HOLD_SOLIMP (the integral servo
it replaces: 0.023 mm; MuJoCo's default friction impedance: 190 mm).

The joint's own friction and its impedance are kept in its motor's `dynprm` (an integrator
ignores them; `servos.MARK_SLOT` marks the motor as twin's), so lifting a hold restores them on
the compiled model alone, after any number of commands.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

OWN_LOSS, OWN_SOLREF, OWN_SOLIMP = 1, slice(2, 4), slice(4, 9)  # dynprm slots of the joint's own
HOLD_SOLIMP = (0.9999, 0.9999, 0.001, 0.5, 2.0)
"""The stiffest impedance MuJoCo allows (mjMAXIMP), so the hold yields as little as it can."""
UNLIMITED = 1e6
"""[N m or N] the bound of a hold on a joint without an effort limit (Gazebo's unbounded motor):
far beyond any load a robot's own weight puts on a joint, yet a finite box for the solver."""
HOLD_TIME_CONSTANTS = 2.0  # the hold's solref time constant, in time steps (MuJoCo's minimum)
_FRICTION_DOF = int(mujoco.mjtConstraint.mjCNSTR_FRICTION_DOF)


def remember_own(actuator: mujoco.MjsActuator, joint: mujoco.MjsJoint) -> None:
    """Keeps `joint`'s own dry friction and its impedance in its motor's spare `dynprm`."""
    actuator.dynprm[OWN_LOSS] = joint.frictionloss
    actuator.dynprm[OWN_SOLREF] = joint.solref_friction
    actuator.dynprm[OWN_SOLIMP] = joint.solimp_friction


def is_hold(mode: str, target: float) -> bool:
    """Whether a command is a hold: a velocity of 0."""
    return mode == "velocity" and target == 0.0


def write(model: mujoco.MjModel, a: int, effort: float) -> None:
    """Makes the joint of motor `a` hold at speed 0 with `effort` [N m or N] on top of its own
    friction (kept in its `dynprm`); the motor itself pushes nothing (gain and bias 0)."""
    hold(model, a, float(model.actuator_dynprm[a, OWN_LOSS]), effort)


def hold(model: mujoco.MjModel, a: int, own_loss: float, effort: float) -> None:
    """The hold of actuator `a`'s joint: its dry friction `own_loss` plus `effort` [N m or N],
    at the stiffest impedance, the actuator's gain and bias 0."""
    dof = _dof(model, a)
    bound = effort if math.isfinite(effort) else UNLIMITED
    model.dof_frictionloss[dof] = own_loss + bound
    model.dof_solref[dof] = (HOLD_TIME_CONSTANTS * model.opt.timestep, 1.0)
    model.dof_solimp[dof] = HOLD_SOLIMP
    model.actuator_gainprm[a, 0] = 0.0
    model.actuator_biasprm[a, :3] = 0.0


def lift(model: mujoco.MjModel, a: int) -> None:
    """Gives the joint of motor `a` its own friction back (a no-op when it holds nothing)."""
    dof = _dof(model, a)
    model.dof_frictionloss[dof] = model.actuator_dynprm[a, OWN_LOSS]
    model.dof_solref[dof] = model.actuator_dynprm[a, OWN_SOLREF]
    model.dof_solimp[dof] = model.actuator_dynprm[a, OWN_SOLIMP]


def held_force(model: mujoco.MjModel, data: mujoco.MjData, a: int) -> float:
    """The force [N m or N] the joint's dry friction applies now (its rows of the last step)."""
    if data.nefc == 0:
        return 0.0
    kinds, ids = np.asarray(data.efc_type), np.asarray(data.efc_id)
    rows = (kinds == _FRICTION_DOF) & (ids == _dof(model, a))
    return float(np.asarray(data.efc_force)[rows].sum())


def _dof(model: mujoco.MjModel, a: int) -> int:
    return int(model.jnt_dofadr[model.actuator_trnid[a, 0]])
