"""Steered bases run as twin controllers: Ackermann (gazebo_ros, gz-sim) and tricycle.

Each update turns the command into a base speed v and a bicycle steering angle φ
(`steering.steering_for_yaw_rate`, `steering_for_curvature`, or the angle given), ramps v by the
plugin's acceleration limit (and a tricycle's φ by its steering speed), and writes the joints'
targets through the world's joint command API:

- Ackermann: each driven wheel a velocity target at its no-slip speed v·(1 ∓ b·tan φ/(2L))/r
  (gz-sim's partial differential; gazebo_ros' one PID force on both rear wheels is an open
  differential, which settles at the same speeds), each steered wheel its own Ackermann angle
  for the kingpin width: a position target (gazebo_ros), or, as gz-sim's update does, the speed
  `steering_gain`·(angle − joint angle) at every update after its speed limiters bound v and ω;
- tricycle: the steered wheel a velocity target v/(cos φ·r) and its steering joint a position
  target φ (the plugin sets the angle directly, twin through a position servo).

Encoder odometry integrates the driven wheels' speed and the steering joints' angles (gz-sim's
AckermannSteering) or the two encoder wheels as a diff drive (the tricycle).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

from twin_cli.control.drive_base import DriveController
from twin_cli.control.kinematics import body_twist, limit_change, ramp
from twin_cli.control.steering import (
    ackermann_angles,
    axle_speeds,
    bicycle_phi,
    clip,
    steering_for_curvature,
    steering_for_yaw_rate,
    yaw_rate,
)

if TYPE_CHECKING:
    from converters.gazebo.drive_records import AckermannDrive, TricycleDrive
    from twin_cli.world.engine import World

TRICYCLE_LOCK = math.pi / 2  # [rad] gazebo_ros_tricycle_drive truncates its angle here


class SteeredDriveController(DriveController):
    """Drives an Ackermann or tricycle base from speed and steering (or yaw rate) commands.

    Args:
        world: the `twin_cli.world.World`; entity: entity name; plugin: its `AckermannDrive` or
            `TricycleDrive` record.
    """

    plugin: AckermannDrive | TricycleDrive

    def __init__(self, world: World, entity: str, plugin: AckermannDrive | TricycleDrive) -> None:
        self.tricycle = type(plugin).__name__ == "TricycleDrive"
        self.speed, self.phi = 0.0, 0.0  # written at the last update: v [m/s], φ [rad]
        self.limited = (0.0, 0.0)  # gz-sim's last limited (v [m/s], ω [rad/s])
        super().__init__(world, entity, plugin)

    # ------------------------------------------------------------------ geometry
    @property
    def wheel_base(self) -> float:
        """Steered axle to fixed axle [m]."""
        return self.plugin.wheel_base

    @property
    def limit(self) -> float:
        """The largest bicycle angle [rad] a command may ask for."""
        if self.tricycle:
            return TRICYCLE_LOCK
        p = self.plugin
        # gz-sim clamps the turning radius at L/sin(limit) when it turns a yaw rate into one
        from_rate = self.twist.steering is None and self.twist.curvature is None
        gz_rate = p.family == "gz_ackermann_steering" and from_rate
        return math.atan(math.sin(p.steering_limit)) if gz_rate else p.steering_limit

    def goals(self) -> tuple[float, float]:
        """The command's base speed v [m/s] and bicycle angle φ [rad], within the limits."""
        return self._bicycle(*self._bounded_twist())

    def _bounded_twist(self) -> tuple[float, float]:
        """The command's (v, ω) within the plugin's speed bounds (gz-sim bounds ω too)."""
        t = self.twist
        bounds = None if self.tricycle else self.plugin.twist_bounds
        if bounds is None:
            top = math.inf if self.tricycle else self.plugin.max_velocity
            return clip(t.linear, top), t.angular
        low, high = bounds[:2]
        return min(max(t.linear, low), high), min(max(t.angular, low), high)

    def _bicycle(self, v: float, angular: float) -> tuple[float, float]:
        """(v, the bicycle angle φ [rad]) of a speed and the command's way of steering."""
        t = self.twist
        if t.steering is not None:
            return v, clip(t.steering, self.limit)
        if t.curvature is not None:
            return v, steering_for_curvature(t.curvature, self.wheel_base, self.limit)
        return v, steering_for_yaw_rate(v, angular, self.wheel_base, self.limit)

    # ------------------------------------------------------------------ the update
    def _reset_targets(self) -> None:
        self.speed, self.phi = 0.0, 0.0
        self.limited = (0.0, 0.0)

    def _apply(self, dt: float, force: bool) -> None:
        if not self.tricycle and self.plugin.twist_bounds is not None:
            self._apply_limited(dt, force)
            return
        v_goal, phi_goal = self.goals()
        speed = ramp(self.speed, v_goal, self._acceleration(v_goal), dt)
        turn_rate = 0.0 if not self.tricycle else self.plugin.max_steering_speed
        phi = ramp(self.phi, phi_goal, turn_rate, dt)
        if (speed, phi) != (self.speed, self.phi) or force:
            self.speed, self.phi = speed, phi
            wheels, steering = self._targets(speed, phi)
            self._write(wheels, "velocity")
            self._write(steering, "position")

    def _apply_limited(self, dt: float, force: bool) -> None:
        """gz-sim's update: v and ω through its speed limiters (each change bounded on its
        own), the wheels' speeds from them, and each steering joint commanded a speed
        proportional to how far it is from its angle (`steering_gain`), at every update."""
        low, high = self.plugin.twist_bounds[2:]
        goal, last = self._bounded_twist(), self.limited
        self.limited = (
            limit_change(last[0], goal[0], low, high, dt),
            limit_change(last[1], goal[1], low, high, dt),
        )
        speed, phi = self._bicycle(*self.limited)
        wheels, steering = self._targets(speed, phi)
        if (speed, phi) != (self.speed, self.phi) or force:
            self.speed, self.phi = speed, phi
            self._write(wheels, "velocity")
        gain = self.plugin.steering_gain
        rates = {j: gain * (angle - self.joint_position(j)) for j, angle in steering.items()}
        self._write(rates, "velocity")

    def _acceleration(self, goal: float) -> float:
        """The speed ramp's limit [m/s²] (0 = none)."""
        p = self.plugin
        if not self.tricycle:
            return p.max_acceleration
        radius = p.actuated_wheel_diameter / 2.0
        speeding_up = abs(goal) > abs(self.speed)
        wheel = p.max_wheel_acceleration if speeding_up else p.max_wheel_deceleration
        return wheel * radius  # the plugin limits the wheel's joint speed [rad/s²]

    def _targets(self, speed: float, phi: float) -> tuple[dict[str, float], dict[str, float]]:
        """Velocity targets [rad/s] of the driven wheels and angles [rad] of the steering."""
        p = self.plugin
        if self.tricycle:
            wheel = speed / max(math.cos(phi), 1e-3) / (p.actuated_wheel_diameter / 2.0)
            return {p.actuated_wheel_joint: wheel}, {p.steering_joint: phi}
        left, right = axle_speeds(speed, phi, p.wheel_base, p.wheel_separation)
        wheels = {j: left / p.wheel_radius for j in p.left_joints}
        wheels.update({j: right / p.wheel_radius for j in p.right_joints})
        angle_l, angle_r = ackermann_angles(phi, p.wheel_base, p.kingpin_width)
        steering = {j: angle_l for j in p.left_steering_joints}
        steering.update({j: angle_r for j in p.right_steering_joints})
        return wheels, steering

    # ------------------------------------------------------------------ odometry
    def _encoder_twist(self) -> tuple[float, float]:
        p = self.plugin
        if self.tricycle:
            left = self.joint_speed(p.encoder_left_joint)
            right = self.joint_speed(p.encoder_right_joint)
            return body_twist(left, right, p.encoder_wheel_diameter / 2.0, p.wheel_separation)
        wheels = [self.joint_speed(j) for j in p.left_joints + p.right_joints]
        v = sum(wheels) / len(wheels) * p.wheel_radius
        left = self.joint_position(p.left_steering_joints[0])
        right = self.joint_position(p.right_steering_joints[0])
        return v, yaw_rate(v, bicycle_phi(left, right, p.wheel_base, p.kingpin_width), p.wheel_base)

    def command_reply(self) -> dict[str, Any]:
        v, phi = self.goals()
        wheels, steering = self._targets(v, phi)
        return {
            "speed": v,
            "steering_angle": phi,
            "yaw_rate": yaw_rate(v, phi, self.wheel_base),
            "wheel_speeds": wheels,
            "steering_angles": steering,
        }
