"""The skid steer's heading loop on a base whose turn is known: it turns at ω_wheels/χ* behind a
first-order lag (the sliding wheels' response). Oracle: the loop must learn χ* itself and leave
the base owing no heading; a base that cannot turn must not wind the loop up."""

from __future__ import annotations

import math

import pytest

from twin_cli.control.skid_trim import CHI_RANGE, HOLD_S, KP, MAX_LAG, SkidTrim

RATE = 250.0  # [Hz] the drive's update rate while its targets move
LAG_S = 0.02  # [s] the base's response time to a change of wheel speeds


def _drive(
    trim: SkidTrim, chi_true: float, omega_ref: float, seconds: float, heading: float = 0.0
) -> float:
    """Runs the loop on the model base from `heading` [rad], at rest; returns the heading it
    reached [rad]."""
    dt, turn = 1.0 / RATE, 0.0
    for _ in range(round(seconds * RATE)):
        wheels = trim.update(omega_ref, heading, dt)
        turn += (wheels / chi_true - turn) * dt / LAG_S
        heading += turn * dt
    return heading


@pytest.mark.parametrize("chi_true", [1.0, 1.8, 3.0, 4.5])
@pytest.mark.parametrize("omega_ref", [0.5, -0.3])
def test_the_loop_learns_the_track_multiplier_and_owes_no_heading(
    chi_true: float, omega_ref: float
) -> None:
    trim = SkidTrim()
    heading = _drive(trim, chi_true, omega_ref, 4.0)
    assert trim.chi == pytest.approx(chi_true, rel=0.01)
    assert heading == pytest.approx(omega_ref * 4.0, abs=0.01 * abs(omega_ref) * 4.0)
    # learned: the next turn starts right, with no catch-up to make
    again = _drive(trim, chi_true, omega_ref, 1.0, heading) - heading
    assert again == pytest.approx(omega_ref * 1.0, rel=0.01)


def test_a_base_that_cannot_turn_does_not_wind_the_loop_up() -> None:
    trim = SkidTrim()
    dt = 1.0 / RATE
    wheels = [trim.update(0.5, 0.0, dt) for _ in range(round(10 * RATE))]
    assert trim.chi == CHI_RANGE[1]
    assert trim.reference is not None and trim.reference - trim.heading <= MAX_LAG + 1e-12
    assert max(wheels) <= CHI_RANGE[1] * 0.5 + KP * MAX_LAG + 1e-9


def test_a_straight_line_holds_the_heading_and_learns_nothing() -> None:
    trim = SkidTrim(chi=2.0)
    trim.start(0.1)
    # the base was knocked 0.05 rad off its line: the wheels turn it back, χ unchanged
    assert trim.update(0.0, 0.05, 1.0 / RATE) > 0.0
    assert trim.chi == 2.0


def test_a_stopped_base_is_turned_back_then_left_alone() -> None:
    """It coasts past the commanded heading on its sliding wheels: turned back, for HOLD_S."""
    trim = SkidTrim()
    trim.update(0.0, 0.0, 1.0 / RATE)  # a command ran
    first = trim.hold(0.05, 1.0 / RATE)  # stopped, 0.05 rad past
    assert first is not None and first < 0.0
    # a base that does not answer is left alone once HOLD_S has passed, owing nothing
    answers = [trim.hold(0.05, 1.0 / RATE) for _ in range(round(2 * HOLD_S * RATE))]
    assert answers[-1] is None and trim.reference == trim.heading
    # one that answers is back at the commanded heading when the hold ends
    trim.start(0.0)
    trim.update(0.0, 0.0, 1.0 / RATE)
    heading, omega = 0.05, 0.0
    while omega is not None:
        omega = trim.hold(heading, 1.0 / RATE)
        heading += (omega or 0.0) / RATE
    assert abs(heading) < 1e-6


def test_a_base_never_commanded_or_already_settled_is_not_steered() -> None:
    """Only a stop after a command turns the base back: a push or a set pose on a stopped base
    stays, and a second stop owes nothing."""
    trim = SkidTrim()
    assert trim.hold(0.0, 1.0 / RATE) is None  # never commanded
    assert trim.hold(0.05, 1.0 / RATE) is None  # pushed 0.05 rad while stopped
    trim.update(0.5, 0.05, 1.0 / RATE)
    assert trim.hold(0.05, 1.0 / RATE) is not None  # the stop after a command
    for _ in range(round(2 * HOLD_S * RATE)):
        trim.hold(0.05, 1.0 / RATE)  # the base did not answer; the hold ran out
    assert trim.hold(0.2, 1.0 / RATE) is None  # later pushes are left alone


def test_a_moved_base_starts_over_and_a_turn_through_pi_is_one_turn() -> None:
    trim = SkidTrim()
    trim.start(math.pi - 0.001)
    # across +π the heading reads -π + ε: one small step, not a 2π jump
    omega = trim.update(0.5, -math.pi + 0.001, 1.0 / RATE)
    assert trim.heading == pytest.approx(math.pi + 0.001)
    assert abs(omega) < 1.0
    # a set pose (1 rad in one update) is not heading owed
    trim.update(0.5, -math.pi + 1.0, 1.0 / RATE)
    assert trim.reference is not None and abs(trim.reference - trim.heading) < 0.01


def test_a_straight_line_after_an_interrupted_hold_gives_the_next_stop_its_full_hold() -> None:
    trim = SkidTrim()
    trim.update(0.5, 0.0, 1.0 / RATE)
    for _ in range(round(0.8 * RATE)):
        trim.hold(0.1, 1.0 / RATE)  # interrupted 0.8 s into a hold
    for _ in range(round(2 * RATE)):
        trim.update(0.0, 0.1, 1.0 / RATE)  # a straight line
    assert trim.held == 0.0
