"""A holonomic base run as a twin controller: gazebo_ros planar move, gz-sim MecanumDrive and
gz-sim VelocityControl.

These plugins set the model's planar velocity themselves. The converter gave the root link three
velocity servos (`converters.gazebo.drive_motors`: x, y and yaw, computed by MuJoCo at every
step); this controller ramps the command (vx, vy, ωz) into their `ctrl` (LINEAR_RAMP,
ANGULAR_RAMP; `planar_ctrl` maps VelocityControl's twist of the link origin onto the centre of
mass), waking the robot if it sleeps, and reports the world pose as odometry. A held command
costs no writes, and between commands the servos hold the plugin's resting twist, as the plugin
does: zero, or VelocityControl's initial one.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

from converters.gazebo.drive_motors import planar_controls
from twin_cli.control.drive_base import DriveController, Twist
from twin_cli.control.kinematics import ramp

if TYPE_CHECKING:
    from converters.gazebo.drive_records import HolonomicDrive
    from twin_cli.world import World


LINEAR_RAMP = 3.0  # [m/s²] twin's ramp of a new command (the plugin sets it at once)
ANGULAR_RAMP = 6.0  # [rad/s²]
"""Gazebo's planar move sets the new velocity in one step. A servo asked for 0.3 m/s at once
pushes the base with M·0.3/dt (2.4 kN for 8 kg) against its feet's friction, which kicks it off
the ground (measured: a 7 cm hop); ramped at 3 m/s² it reaches 0.3 m/s in 0.1 s without leaving
the ground. The ramp is applied per elapsed sim time, at the plugin's update rate."""


class HolonomicController(DriveController):
    """Drives an entity's base at (vx, vy, ωz) in its own frame."""

    plugin: HolonomicDrive
    current: tuple[float, float, float] = (0.0, 0.0, 0.0)  # written at the last update

    def goals(self) -> tuple[float, float, float]:
        """(vx [m/s], vy [m/s], ωz [rad/s]) within the plugin's limits."""
        p, t = self.plugin, self.twist
        top, spin = p.max_linear_velocity, p.max_angular_velocity
        return (_clip(t.linear, top), _clip(t.lateral, top), _clip(t.angular, spin))

    def _rest(self) -> Twist:
        """gz-sim VelocityControl's initial twist, which it drives until a command replaces it
        (zero for the others): reading odometry or a first drive starts from it."""
        vx, vy, wz = self.plugin.initial_twist
        return Twist(linear=vx, angular=wz, lateral=vy)

    def __init__(self, world: World, entity: str, plugin: HolonomicDrive) -> None:
        super().__init__(world, entity, plugin)  # made under the world's lock: no update yet
        self._reset_targets()  # the ramp starts from the twist the servos hold from load

    def _reset_targets(self) -> None:
        vx, vy, wz = self.plugin.initial_twist
        self.current = (float(vx), float(vy), float(wz))

    def _apply(self, dt: float, force: bool) -> None:
        goals = self.goals()
        limits = (LINEAR_RAMP, LINEAR_RAMP, ANGULAR_RAMP)
        now = tuple(ramp(c, g, a, dt) for c, g, a in zip(self.current, goals, limits, strict=True))
        if force or now != self.current:
            servos = planar_controls(self.world.model, self.entity, self.plugin, now)
            if servos is None:
                return  # a hand-written model without the servos: nothing to drive
            self.world.set_controls(*servos)
            self.current = now  # type: ignore[assignment]
        self._written = dict(self.world.commands())

    def _encoder_twist(self) -> tuple[float, float]:
        return self.goals()[0], self.goals()[2]

    def command_reply(self) -> dict[str, Any]:
        vx, vy, wz = self.goals()
        return {"base_twist": {"x": vx, "y": vy, "yaw": wz}}


def _clip(value: float, limit: float) -> float:
    return value if math.isinf(limit) else max(-limit, min(limit, value))
