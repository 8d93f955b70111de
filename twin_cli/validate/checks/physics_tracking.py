"""Tracking check: can each actuated joint follow a position step and a sine within its limits?

Every joint that offers a position interface gets, at once, a step of STEP_FRACTION of its range
(at most MAX_STEP) held for the scenario's first half, then a SINE_HZ cosine between the step's
target and its start, followed through the trajectory controller (twin_cli.control, 100 Hz) for
the second half. Measured per joint: settling time of the step (last time outside SETTLE_BAND
of it), the sine's largest tracking error after its first period, and the peak speed against
the joint's velocity limit. A sine tracking error past its threshold fails: the sine's speed
stays within SINE_SPEED of the velocity limit, so a joint that cannot follow it lacks effort or
gains. A speed past the limit warns: a joint's own position servo (MuJoCo's, as the exported
file has it) has no speed limit, which MuJoCo cannot hold, and a step asks for its distance over
the servo's time constant, where Gazebo clamps the joint at its limit. A speed past
`max_runaway_ratio` of the limit (a servo that chatters), a MuJoCo warning or a NaN fails. Slow
settling of the step only warns, naming the joint: a step may be limited by the joint's velocity
limit by design (0.3 rad at 0.2 rad/s takes 1.5 s).
"""

from __future__ import annotations

import math

import numpy as np

from twin_cli.validate.checks.base import (
    CheckResult,
    RobotUnderTest,
    Status,
    bars,
    not_applicable,
    result,
)
from twin_cli.validate.checks.sim import ScenarioRun
from twin_cli.validate.scenario import Scenario

STEP_FRACTION = 0.25  # of the joint's range
MAX_STEP = 0.3  # [rad or m] largest step (and sine amplitude)
UNLIMITED_STEP = 0.2  # [rad or m] for a joint without range
SETTLE_BAND = 0.02  # settled when within 2 % of the step
SINE_HZ = 1.0  # [Hz]
SINE_SPEED = 0.8  # largest sine speed, as a fraction of the velocity limit


def _step_targets(run: ScenarioRun) -> dict[str, tuple[float, float]]:
    """Joint → (start, step) for each joint with a position interface."""
    from twin_cli.world.joint_control import limits_of

    model, out = run.world.model, {}
    q = run.qpos()
    for joint in run.joints:
        if not joint.effort or "position" not in limits_of(model, run.entity, joint.name).modes:
            continue
        start = float(q[joint.qpos])
        if model.jnt_limited[joint.joint]:
            lo, hi = (float(v) for v in model.jnt_range[joint.joint])
            size = min(MAX_STEP, STEP_FRACTION * (hi - lo))
            step = size if start + size <= hi else -size
        else:
            step = UNLIMITED_STEP
        out[joint.name] = (start, step)
    return out


def _sine(names: list[str], base: dict[str, float], amp: dict[str, float], t0: float, t1: float):
    from twin_cli.control import trajectory_from_dict

    times = np.arange(0.05, t1 - t0 + 1e-9, 0.05)
    w = 2 * math.pi * SINE_HZ
    points = [
        {
            "positions": [base[n] + amp[n] * math.cos(w * t) for n in names],
            "velocities": [-amp[n] * w * math.sin(w * t) for n in names],
            "time_from_start": float(t),
        }
        for t in times
    ]
    return trajectory_from_dict({"joint_names": names, "points": points})


def check_tracking(robot: RobotUnderTest, scenario: Scenario, th: dict[str, float]):
    """Each joint follows a position step and a sine within its limits (settling, error)."""
    from twin_cli.control import follow_trajectory

    run = ScenarioRun(robot, scenario)
    steps = _step_targets(run)
    if not steps:
        reason = (
            "no joint has a motor with a position interface and an effort limit "
            "(<ros2_control> position command, or the converter's default motors)"
        )
        return not_applicable("tracking", "physics", "no position interface", reason)
    names = list(steps)
    joints = {j.name: j for j in run.joints if j.name in steps}
    vmax = {n: (joints[n].velocity or math.inf) for n in names}
    targets = {n: s + d for n, (s, d) in steps.items()}
    run.world.command_joints(run.entity, targets, mode="position")
    half = scenario.duration / 2.0
    late, peak, sine_err = dict.fromkeys(names, 0.0), dict.fromkeys(names, 0.0), {}

    def sample(r: ScenarioRun) -> None:
        with r.world.lock:
            q, qd = r.world.data.qpos, r.world.data.qvel
            for n in names:
                j = joints[n]
                peak[n] = max(peak[n], abs(float(qd[j.dof])) / vmax[n])
                s, d = steps[n]
                if r.time <= half and abs(float(q[j.qpos]) - (s + d)) > SETTLE_BAND * abs(d):
                    late[n] = r.time

    run.run(half, sample, every=5)
    # A cosine between the step's target and its start (inside the range), from the target.
    # Its speed amplitude stays within SINE_SPEED of the velocity limit.
    w = 2 * math.pi * SINE_HZ
    amp = {
        n: math.copysign(min(abs(d) / 2, SINE_SPEED * vmax[n] / w), d)
        for n, (s, d) in steps.items()
    }
    base = {n: s + d - amp[n] for n, (s, d) in steps.items()}
    trajectory = _sine(names, base, amp, half, scenario.duration)
    follow_trajectory(run.world, run.entity, trajectory)
    t_sine = run.time

    def sample_sine(r: ScenarioRun) -> None:
        sample(r)
        t = r.time - t_sine
        if t < 1.0 / SINE_HZ:
            return
        ref = {n: base[n] + amp[n] * math.cos(2 * math.pi * SINE_HZ * t) for n in names}
        q = r.qpos()
        for n in names:
            err = abs(float(q[joints[n].qpos]) - ref[n])
            sine_err[n] = max(sine_err.get(n, 0.0), err)

    run.run(scenario.duration - half, sample_sine, every=5)
    return _verdict(run, names, steps, late, peak, sine_err, amp, th)


def _failures(
    run: ScenarioRun,
    peak: dict[str, float],
    sine_err: dict[str, float],
    amp: dict[str, float],
    th: dict[str, float],
) -> list[str]:
    """What breaks tracking: MuJoCo warnings, NaN, a speed past the limit, a sine not followed."""
    fails = [f"MuJoCo warnings: {run.warnings()}; lower the gains"] if run.warnings() else []
    if not np.isfinite(run.qpos()).all():
        fails.append("NaN in the state; the gains or limits make it diverge")
    fails += [
        f"joint '{n}': peak speed {ratio:.3g}× its velocity limit; report it (a twin bug)"
        for n, ratio in peak.items()
        if ratio > th["max_runaway_ratio"]
    ]
    fails += [
        f"joint '{n}': sine tracking error {e:.3g} is {e / abs(amp[n]):.0%} of the amplitude "
        f"{abs(amp[n]):.3g} (> {th['max_sine_error_fraction']:.0%}), at a speed within its "
        "velocity limit: raise its <limit effort> (or its pos_kp gain)"
        for n, e in sine_err.items()
        if e > th["max_sine_error_fraction"] * abs(amp[n])
    ]
    return fails


def _verdict(
    run: ScenarioRun,
    names: list[str],
    steps: dict[str, tuple[float, float]],
    late: dict[str, float],
    peak: dict[str, float],
    sine_err: dict[str, float],
    amp: dict[str, float],
    th: dict[str, float],
) -> CheckResult:
    fails = _failures(run, peak, sine_err, amp, th)
    warns = [
        f"joint '{n}': step of {steps[n][1]:.3g} settles after {late[n]:.3g} s; "
        "raise its effort limit, velocity limit or gains"
        for n in names
        if late[n] > th["max_settle_s"]
    ]
    warns += [
        f"joint '{n}': peak speed {peak[n]:.3g}× its velocity limit: its position servo has no "
        "speed limit (MuJoCo holds none; Gazebo clamps the joint at it); lower its pos_kp or "
        "move it by a trajectory"
        for n in names
        if th["max_speed_ratio"] < peak[n] <= th["max_runaway_ratio"]
    ]
    errors = {n: e / abs(amp[n]) for n, e in sine_err.items()}
    status = Status.FAIL if fails else Status.WARN if warns else Status.PASS
    return result(
        "tracking",
        "physics",
        status,
        f"settle ≤ {max(late.values()):.3g} s, sine error ≤ "
        f"{max(errors.values(), default=0.0):.1%} of amplitude, "
        f"peak speed {max(peak.values()):.3g}× limit ({len(names)} joints)",
        f"≤ {th['max_settle_s']:g} s, ≤ {th['max_sine_error_fraction']:.0%}, "
        f"≤ {th['max_speed_ratio']:g}× (≤ {th['max_runaway_ratio']:g}×)",
        hints=fails + warns,
        value=max(errors.values(), default=0.0),
        series=[
            bars("step settling time", "s", late, th["max_settle_s"], x_label="joint"),
            bars("sine error over amplitude", "1", errors, th["max_sine_error_fraction"],
                 x_label="joint"),
            bars("peak speed over limit", "1", peak, th["max_speed_ratio"], x_label="joint"),
        ],
    )  # fmt: skip
