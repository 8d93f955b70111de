"""Steered-base kinematics: the bicycle model and Ackermann's wheel angles and speeds.

Pure functions of numbers. A base with wheel base L (steered axle to the fixed axle) moving at
v [m/s] (the fixed axle's midpoint) with bicycle steering angle φ turns at ω = v·tan φ / L about
a centre at R = L / tan φ. Each steered wheel points at that centre: tan δ = L / (R ∓ k/2) for
the left/right pivot (k the kingpin width), and a fixed-axle wheel rolls at v·(1 ∓ b·tan φ/(2L))
(b its track), both as gz-sim's AckermannSteering and gazebo_ros_ackermann_drive compute them.
A tricycle's steered wheel rolls at v / cos φ.
"""

from __future__ import annotations

import math

STRAIGHT = 1e-3  # [rad/s] gz-sim's AckermannSteering drives straight below this yaw rate


def steering_for_yaw_rate(linear: float, angular: float, wheel_base: float, limit: float) -> float:
    """The bicycle angle φ [rad] that turns at ω [rad/s] at speed v [m/s], within ±limit;
    at v = 0 the full lock towards ω (the base cannot turn without moving)."""
    if abs(angular) < STRAIGHT:
        return 0.0
    if linear == 0.0:
        return math.copysign(limit, angular)
    return clip(math.atan(wheel_base * angular / linear), limit)


def steering_for_curvature(curvature: float, wheel_base: float, limit: float) -> float:
    """The bicycle angle φ [rad] of a path curvature κ [1/m], within ±limit."""
    return clip(math.atan(curvature * wheel_base), limit)


def clip(value: float, limit: float) -> float:
    """`value` within ±limit."""
    return max(-limit, min(limit, value))


def ackermann_angles(phi: float, wheel_base: float, kingpin_width: float) -> tuple[float, float]:
    """Left and right steered wheels' angles [rad] for a bicycle angle φ [rad]."""
    t = math.tan(phi)
    half = kingpin_width / 2.0
    return (
        math.atan2(wheel_base * t, wheel_base - half * t),
        math.atan2(wheel_base * t, wheel_base + half * t),
    )


def axle_speeds(linear: float, phi: float, wheel_base: float, track: float) -> tuple[float, float]:
    """Left and right fixed-axle wheels' rim speeds [m/s] rolling without slip."""
    turn = track * math.tan(phi) / (2.0 * wheel_base)
    return linear * (1.0 - turn), linear * (1.0 + turn)


def yaw_rate(linear: float, phi: float, wheel_base: float) -> float:
    """ω [rad/s] of a bicycle at speed v [m/s] and angle φ [rad]."""
    return linear * math.tan(phi) / wheel_base


def bicycle_phi(left: float, right: float, wheel_base: float, kingpin_width: float) -> float:
    """The bicycle angle [rad] that the two steered wheels' angles [rad] imply (the mean of
    the turning radii each one points at)."""
    if abs(left) < 1e-9 and abs(right) < 1e-9:
        return 0.0
    half = kingpin_width / 2.0
    radii = []
    if abs(left) > 1e-9:
        radii.append(wheel_base / math.tan(left) + half)
    if abs(right) > 1e-9:
        radii.append(wheel_base / math.tan(right) - half)
    return math.atan(wheel_base / (sum(radii) / len(radii)))
