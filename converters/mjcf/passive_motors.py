"""Passive joints keep a motor at zero effort, so `twin command` can still drive them.

In Gazebo a revolute or continuous joint that no control tag or plugin names is passive: nothing
applies a force to it unless a plugin calls `SetForce`/`SetVelocity`. twin keeps it passive (its
motor holds zero effort until commanded, and a zero-effort motor changes no force), but gives it
a motor in effort and velocity mode, so a user can still turn a wheel that its vendor's plugin
would have driven (`twin command base wheel_left_joint=4 --mode velocity`). Its record's source
is "passive": the world and `twin command` say that Gazebo would not drive it. The force is
bounded by the joint's `<limit effort>` when it has one; mimic followers get none (their
equality drives them).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from converters.control_text import set_control_record
from converters.description import RobotDescription
from converters.report import Report

if TYPE_CHECKING:
    import mujoco

PASSIVE_KINDS = ("revolute", "continuous")
PASSIVE_MODES = ["effort", "velocity"]
PASSIVE_SOURCE = "passive"


def add_passive_motors(spec: mujoco.MjSpec, robot: RobotDescription, report: Report) -> None:
    """A zero-effort motor on every revolute or continuous joint that has none (one report
    line listing them)."""
    import mujoco

    driven = {a.target for a in spec.actuators}
    passive = [
        j
        for j in robot.joints
        if j.kind in PASSIVE_KINDS
        and j.mimic is None
        and j.name not in driven
        and spec.joint(j.name) is not None
    ]
    for joint in passive:
        motor = spec.add_actuator(name=joint.name, target=joint.name)
        motor.trntype = mujoco.mjtTrn.mjTRN_JOINT
        effort = joint.limit.effort if joint.limit and joint.limit.effort else 0.0
        if effort > 0:
            motor.ctrllimited = mujoco.mjtLimited.mjLIMITED_TRUE
            motor.ctrlrange = np.array([-effort, effort])
        velocity = joint.limit.velocity if joint.limit and joint.limit.velocity else None
        record = {
            "modes": PASSIVE_MODES,
            "source": PASSIVE_SOURCE,
            "where": "",
            "bounds": {},
            "pid": {},
            "velocity_limit": velocity,
            "plugin": None,
        }
        set_control_record(spec, joint.name, record)
    if passive:
        names = ", ".join(j.name for j in passive)
        report.mapped(
            "passive joints",
            f"{names}: no control tag or drive plugin names them, so Gazebo leaves them "
            "passive; twin keeps a zero-effort motor on each, for `twin command --mode "
            "effort|velocity`",
        )
