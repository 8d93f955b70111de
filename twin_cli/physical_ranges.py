"""The range of every number a client or a save file gives the world, in one place.

JSON carries any finite double, and a finite value can still take the world down: a timestep of
2^64 s made the real-time factor 1.8e22, a push of 1e308 N and a pose at x = 1e308 m turned the
state into infinities a step later. Each quantity gets the widest range that is still physics:
beyond it a request is refused (422 over the API, a named field in a save file), and the world
is left as it was. The request bodies (`twin_cli.server.models`) and the save schema
(`twin_cli.world.save_schema`) both build their fields from these types.
"""

from __future__ import annotations

from typing import Annotated

from pydantic import AfterValidator, Field

MAX_VALUE = 1e10
"""MuJoCo's mjMAXVAL: a state value beyond it is reported as bad and the simulation reset."""
POSITION_M = 1e6
"""[m] a pose's coordinates: 1000 km; MuJoCo's doubles still resolve 0.1 nm there."""
ANGLE_RAD = 1e4
"""[rad] a roll, pitch or yaw (any angle is one within ±π; this bounds typing errors)."""
GRAVITY_M_S2 = 1e3
"""[m/s²] each gravity component: about 100 g."""
FORCE_N = 1e9
"""[N] or [N m] a push's force and torque components."""
COMMAND = 1e9
"""A joint command [rad, m, rad/s, m/s, N m or N]; a position is further held to the joint's
range by the world."""
SPEED = 1e4
"""[m/s] or [rad/s] a twist a client sets on an entity: one 1 ms step moves it at most 10 m."""
GAIN = 1e12
"""A saved servo's stiffness [N m/rad] or damping [N m s/rad]."""
TIMESTEP_S = (1e-6, 1.0)
"""[s] the physics step: under 1 µs the real-time pacer's steps per second overflow (a 5e-324 s
step divided by zero); over 1 s no contact or joint resolves."""
RATE_HZ = 1e7
"""[Hz] the real-time pace; 0 is unthrottled."""
ITERATIONS = 1_000_000
"""Solver iterations per step."""


def _bounded(low: float, high: float, unit: str) -> object:
    return Field(ge=low, le=high, allow_inf_nan=False, description=f"[{unit}] {low:g} to {high:g}")


Position = Annotated[float, _bounded(-POSITION_M, POSITION_M, "m")]
Angle = Annotated[float, _bounded(-ANGLE_RAD, ANGLE_RAD, "rad")]
Acceleration = Annotated[float, _bounded(-GRAVITY_M_S2, GRAVITY_M_S2, "m/s²")]
Force = Annotated[float, _bounded(-FORCE_N, FORCE_N, "N or N m")]
CommandValue = Annotated[float, _bounded(-COMMAND, COMMAND, "rad, m, rad/s, m/s, N m or N")]
Gain = Annotated[float, _bounded(-GAIN, GAIN, "per rad or m")]
StateValue = Annotated[float, _bounded(-MAX_VALUE, MAX_VALUE, "state")]
Timestep = Annotated[float, _bounded(TIMESTEP_S[0], TIMESTEP_S[1], "s")]
MIN_RATE_HZ = 1e-6
"""[Hz] the slowest pace other than 0 (unthrottled): one step in about 12 days of wall time."""


def _rate(value: float) -> float:
    if 0.0 < value < MIN_RATE_HZ:
        raise ValueError(f"a rate is 0 (unthrottled) or at least {MIN_RATE_HZ:g} Hz")
    return value


Rate = Annotated[float, _bounded(0.0, RATE_HZ, "Hz"), AfterValidator(_rate)]
Iterations = Annotated[int, Field(ge=1, le=ITERATIONS)]
