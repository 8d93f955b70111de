"""A holonomic base run as a twin controller: gazebo_ros planar move and gz-sim MecanumDrive.

Gazebo's planar move sets the model's planar velocity itself. The converter gave the root link
three velocity servos in its own frame (`converters.gazebo.drive_motors`: x, y and yaw, computed
by MuJoCo at every step); this controller writes the command (vx, vy, ωz) into their `ctrl` once
per change, waking the robot if it sleeps, and reports the world pose as odometry. A held command
costs no writes, and the servos hold a zero twist between commands, as the plugin does.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import mujoco

from converters.gazebo.drive_motors import planar_actuator
from twin_cli.control.drive_base import DriveController
from twin_cli.world.sleeping import wake_actuated

if TYPE_CHECKING:
    from converters.gazebo.drive_records import HolonomicDrive


class HolonomicController(DriveController):
    """Drives an entity's base at (vx, vy, ωz) in its own frame."""

    plugin: HolonomicDrive

    def goals(self) -> tuple[float, float, float]:
        """(vx [m/s], vy [m/s], ωz [rad/s]) within the plugin's limits."""
        p, t = self.plugin, self.twist
        top, spin = p.max_linear_velocity, p.max_angular_velocity
        return (_clip(t.linear, top), _clip(t.lateral, top), _clip(t.angular, spin))

    def _apply(self, dt: float, force: bool) -> bool:
        goals = self.goals()
        m, d = self.world.model, self.world.data
        ids = [
            mujoco.mj_name2id(
                m,
                mujoco.mjtObj.mjOBJ_ACTUATOR,
                f"{self.entity}/{planar_actuator(self.plugin.name, a)}",
            )
            for a in ("vx", "vy", "wz")
        ]
        if any(a < 0 for a in ids):
            return True  # a hand-written model without the servos: nothing to drive
        if force or [float(d.ctrl[a]) for a in ids] != list(goals):
            wake_actuated(m, d, ids)
            for a, value in zip(ids, goals, strict=True):
                d.ctrl[a] = value
        self._written = dict(self.world.commands())
        return True

    def _encoder_twist(self) -> tuple[float, float]:
        return self.goals()[0], self.goals()[2]

    def command_reply(self) -> dict[str, Any]:
        vx, vy, wz = self.goals()
        return {"base_twist": {"x": vx, "y": vy, "yaw": wz}}


def _clip(value: float, limit: float) -> float:
    return value if math.isinf(limit) else max(-limit, min(limit, value))
