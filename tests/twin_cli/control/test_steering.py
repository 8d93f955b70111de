"""Steered-base kinematics against geometry: every wheel of an Ackermann base points at one turning
centre and rolls at its distance from it times the yaw rate (no slip)."""

from __future__ import annotations

import math

import pytest

from twin_cli.control.steering import (
    ackermann_angles,
    axle_speeds,
    bicycle_phi,
    steering_for_curvature,
    steering_for_yaw_rate,
    yaw_rate,
)

L, K, B = 0.4, 0.3, 0.3  # wheel base, kingpin width, track [m]


@pytest.mark.parametrize("phi", [-0.5, -0.1, 0.05, 0.3, 0.6])
def test_each_steered_wheel_points_at_the_bicycles_turning_centre(phi: float) -> None:
    radius = L / math.tan(phi)  # centre at (0, R) from the fixed axle's midpoint
    left, right = ackermann_angles(phi, L, K)
    for angle, y in ((left, K / 2), (right, -K / 2)):
        # the wheel at (L, y) points along its angle: its normal passes through (0, R)
        assert math.tan(angle) == pytest.approx(L / (radius - y), rel=1e-12)
    assert bicycle_phi(left, right, L, K) == pytest.approx(phi, abs=1e-12), "inverse"


@pytest.mark.parametrize("phi", [-0.4, 0.0, 0.2, 0.5])
def test_fixed_axle_wheels_roll_at_their_distance_from_the_centre_times_the_yaw_rate(
    phi: float,
) -> None:
    v = 0.3
    left, right = axle_speeds(v, phi, L, B)
    w = yaw_rate(v, phi, L)
    assert (left + right) / 2 == pytest.approx(v, abs=1e-12), "the midpoint moves at v"
    assert (right - left) / B == pytest.approx(w, abs=1e-12), "the axle turns at ω"


def test_commands_become_bicycle_angles_within_the_limit() -> None:
    assert steering_for_curvature(1.0, L, 0.6) == pytest.approx(math.atan(L))
    assert steering_for_curvature(10.0, L, 0.6) == 0.6, "clipped at the limit"
    assert steering_for_yaw_rate(0.3, 0.5, L, 0.6) == pytest.approx(math.atan(L * 0.5 / 0.3))
    assert steering_for_yaw_rate(0.0, 0.5, L, 0.6) == 0.6, "at rest: full lock towards ω"
    assert steering_for_yaw_rate(-0.3, 0.5, L, 0.6) < 0, "reversing: the wheels turn the other way"
    assert steering_for_yaw_rate(0.3, 1e-4, L, 0.6) == 0.0, "below gz-sim's threshold: straight"
