"""Differential-drive kinematics: (v, ω) → wheel speeds, the acceleration ramp, odometry.

Pure functions of numbers, testable without a world. The rules are gazebo_ros_diff_drive's:
rim speeds v ∓ ω·b/2 for the left/right wheel (b the wheel separation); the commanded rim speed
moves towards its target by at most `max_wheel_acceleration`·dt per update (0 = at once); the
encoder odometry integrates the wheels' travel with the heading taken at the middle of the
update (Siegwart, Autonomous Mobile Robots, 2011, p. 337).
"""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class Pose2D:
    """A planar pose: x, y [m] and heading theta [rad]."""

    x: float = 0.0
    y: float = 0.0
    theta: float = 0.0


def rim_speeds(linear: float, angular: float, separation: float) -> tuple[float, float]:
    """Left and right wheel rim speeds [m/s] for a body twist (v [m/s], ω [rad/s])."""
    half = angular * separation / 2.0
    return linear - half, linear + half


def ramp(current: float, target: float, acceleration: float, dt: float) -> float:
    """`current` moved towards `target` by at most acceleration·dt [m/s]; 0 = no limit."""
    if acceleration <= 0.0:
        return target
    step = acceleration * dt
    if abs(target - current) <= step:
        return target  # exactly: the controller compares rim speeds with their goals
    return current + math.copysign(step, target - current)


def limit_change(current: float, target: float, lowest: float, highest: float, dt: float) -> float:
    """`target`, its change from `current` bounded to [lowest·dt, highest·dt] (signed rates: a
    deceleration bound is negative; ±inf: none), as a speed limiter bounds a command."""
    change = target - current
    if lowest * dt <= change <= highest * dt:
        return target  # exactly: the controller compares what it writes with what it wrote
    return current + min(max(change, lowest * dt), highest * dt)


def signed_bounds(
    last: float,
    forward: tuple[float, float],
    reverse: tuple[float, float, float, float] | None,
    at: int,
) -> tuple[float, float]:
    """The (min, max) rate [per s] bounding a command's change after `last`: `forward` while it
    is forward (> 0); `reverse[at:at + 2]` while backward (< 0), and from 0 that min with the
    forward max, as ros2_controllers' rate limiter picks them; `forward` always when `reverse`
    is None."""
    if reverse is None or last > 0.0:
        return forward[0], forward[1]
    if last < 0.0:
        return reverse[at], reverse[at + 1]
    return reverse[at], forward[1]


def body_twist(left: float, right: float, radius: float, separation: float) -> tuple[float, float]:
    """Forward speed [m/s] and yaw rate [rad/s] from wheel joint speeds [rad/s]."""
    v_left, v_right = left * radius, right * radius
    return (v_left + v_right) / 2.0, (v_right - v_left) / separation


def integrate_twist(pose: Pose2D, linear: float, angular: float, dt: float) -> Pose2D:
    """The pose after moving at (v [m/s], ω [rad/s]) for `dt` [s], heading at mid-update."""
    heading = pose.theta + angular * dt / 2.0
    return Pose2D(
        pose.x + linear * dt * math.cos(heading),
        pose.y + linear * dt * math.sin(heading),
        pose.theta + angular * dt,
    )
