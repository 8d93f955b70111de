"""gz-math's PID on a joint's speed error, integrated by hand: the velocity PID tests' oracle."""

from __future__ import annotations

import math


def pid_law(
    target: float,
    p: float,
    i: float,
    t: float,
    *,
    inertia: float = 0.01,
    cmd_max: float = 2.0,
    cmd_min: float | None = None,
    start: float = 0.0,
) -> float:
    """The disc's speed t s after a step from `start` to `target` [rad/s] under gz-math's PID on
    the speed error, p·e + i·∫e with gz-sim JointController's integral limit ±1 N m, the sum
    clamped to [cmd_min, cmd_max] [N m] (cmd_min -cmd_max unless given), integrated in 10 µs
    steps."""
    low = -cmd_max if cmd_min is None else cmd_min
    speed, integral, dt = start, 0.0, 1e-5
    for _ in range(round(t / dt)):
        error = target - speed
        integral = min(max(integral + i * error * dt, -1.0), 1.0)
        speed += min(max(p * error + integral, low), cmd_max) / inertia * dt
    return speed


def gz_position_pid(
    target: float,
    gains: tuple[float, float, float],
    t: float,
    *,
    inertia: float = 0.01,
    step: float = 1e-3,
) -> list[float]:
    """A disc's angle [rad] after each step of `step` s for t s, from rest at 0, under gz-sim's
    JointPositionController: gz-math's PID (p, i, d) on the error q − target, run once a step
    with the derivative of the error (a kick when the target jumps), the integral within ±1 and
    the output within ±1000 N m (their defaults), integrated semi-implicitly as gz-physics does."""
    p, i, d = gains
    angle, speed, last, integral, angles = 0.0, 0.0, 0.0, 0.0, []
    for _ in range(round(t / step)):
        error = angle - target
        integral = min(max(integral + i * step * error, -1.0), 1.0)
        force = -p * error - integral - d * (error - last) / step
        last = error
        speed += min(max(force, -1000.0), 1000.0) / inertia * step
        angle += speed * step
        angles.append(angle)
    return angles


def gz_held_bar(
    gains: tuple[float, float, float],
    integral_limit: float | None,
    t: float,
    *,
    inertia: float,
    load: float,
    step: float = 1e-3,
    start: tuple[float, float] = (0.0, 0.0),
    every: float = 1.0,
    offset: float = 0.0,
    output: tuple[float, float] = (-1000.0, 1000.0),
) -> list[float]:
    """A bar's angle [rad] every `every` s for t s, from `start` (angle, speed) with an empty
    integral (rest at 0 unless given), under gravity's torque load·cos q and gz-sim's
    JointPositionController holding 0: gz-math's PID (p, i, d) on the error q, the integral term
    within ±integral_limit (None: unbounded), `offset` (`cmd_offset`) added and the sum within
    `output` ([cmd_min, cmd_max]), integrated semi-implicitly as gz-physics does. The target
    never jumps, so there is no kick."""
    p, i, d = gains
    (angle, speed), integral, angles = start, 0.0, []
    per_second = round(every / step)
    for k in range(round(t / step)):
        integral += i * step * angle
        if integral_limit is not None:
            integral = min(max(integral, -integral_limit), integral_limit)
        force = min(max(offset - p * angle - integral - d * speed, output[0]), output[1])
        speed += (load * math.cos(angle) + force) / inertia * step
        angle += speed * step
        if (k + 1) % per_second == 0:
            angles.append(angle)
    return angles
