"""gz-math's PID on a joint's speed error, integrated by hand: the velocity PID tests' oracle."""

from __future__ import annotations


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
