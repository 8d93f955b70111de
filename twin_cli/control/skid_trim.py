"""A skid steer's heading loop: the wheel differential trimmed until the base turns as asked.

A base with several wheels a side must slide them sideways to turn. Even with friction that acts
along the slip (Coulomb's; twin's skid-steer wheels, `converters/gazebo/skid_wheels.py` and
`skid_contacts`), wheels run at the unicycle's speeds turn it at ω/(1 + (a/c)²), a half the
wheel base and c half the track: the drive's moment against the wheels' sideways friction. ROS
users correct the track by hand for that; the drive here measures the base's heading at each
update and runs the wheels at the yaw rate that makes it follow the commanded one:

    ω_wheels = χ·ω_ref + KP·e,      e = θ_ref − θ (the heading the base owes),
    χ' = KI·e / ω_ref               (only while |ω_ref| ≥ MIN_TURN)

χ is the effective-track multiplier that ROS users set by hand for skid steers
(`wheel_separation_multiplier`): started at Coulomb's 1 + (a/c)² by the drive, learned online,
kept across commands, used by the encoder odometry. For a constant ω_ref and a base that turns
at ω_wheels/χ*, the heading error obeys e'' + (KP/χ*)·e' + (KI/χ*)·e = 0: it returns to zero,
critically damped at χ* = 1 and with a damping ratio of 1/√χ* above, in about a second. Pure
arithmetic on numbers; the controller calls it in sim time, at its update rate.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

KP = 32.0
"""[1/s] heading error → extra yaw rate of the wheels."""
KI = 256.0
"""[1/s²] heading error → change of χ (normalised by ω_ref)."""
MIN_TURN = 0.05
"""[rad/s] commanded yaw rate below which χ is not learned (a straight line teaches nothing)."""
CHI_RANGE = (0.5, 5.0)
"""Bounds of χ: a base that cannot turn (held, or its wheels in the air) stops learning there."""
MAX_LAG = 0.3
"""[rad] most heading the loop owes: a base held from turning does not store a spin for later."""
HOLD_S = 1.0
"""[s] how long a base is held at the heading it was commanded to after a command stops: it
coasts on its sliding wheels after a turn, for longer than the stop takes."""


JUMP = 0.1
"""[rad] heading change between two updates that no drive makes (25 rad/s at 250 Hz): the base
was moved (`twin set-pose`, a respawn), so the loop starts over from where it is."""


@dataclass
class SkidTrim:
    """The loop's state: χ, the reference heading and the base's heading at the last update."""

    chi: float = 1.0
    reference: float | None = None  # θ_ref [rad]
    heading: float = 0.0  # θ at the last update [rad], unwrapped
    held: float = 0.0  # [s] since the command stopped
    armed: bool = False  # a command ran since the last stop: the stop may turn the base back
    learning: bool = True  # the last update's wheels were delivered (no acceleration bound cut
    # them), so the heading they left owed says something about χ

    def start(self, heading: float) -> None:
        """Owes nothing from the base's heading now [rad] (a reset, a stop, a new drive)."""
        self.reference = self.heading = heading
        self.held, self.armed = 0.0, False

    def update(self, omega_ref: float, heading: float, dt: float) -> float:
        """The wheels' yaw rate [rad/s] for the commanded `omega_ref` [rad/s], given the base's
        world `heading` [rad] now, `dt` [s] after the last update."""
        omega = self._step(omega_ref, heading, dt)
        self.held, self.armed = 0.0, True
        return omega

    def hold(self, heading: float, dt: float) -> float | None:
        """After a stop: the wheels' yaw rate [rad/s] that brings the base back to the heading
        it was commanded to, or None (and nothing owed any more) once HOLD_S has passed or when
        no command ran since the last stop (a stopped base is never steered)."""
        self.held += dt
        if not self.armed or self.held > HOLD_S:
            self.start(heading)
            return None
        return self._step(0.0, heading, dt)

    def _step(self, omega_ref: float, heading: float, dt: float) -> float:
        if self.reference is None:
            self.start(heading)
        turned = math.remainder(heading - self.heading, 2.0 * math.pi)
        if abs(turned) > JUMP:
            self.start(heading)
            turned = 0.0
        assert self.reference is not None
        self.heading += turned
        self.reference += omega_ref * dt
        lag = self.reference - self.heading
        if abs(lag) > MAX_LAG:
            lag = math.copysign(MAX_LAG, lag)
            self.reference = self.heading + lag
        if self.learning and abs(omega_ref) >= MIN_TURN and dt > 0.0:
            chi = self.chi + KI * lag * dt / omega_ref
            self.chi = min(max(chi, CHI_RANGE[0]), CHI_RANGE[1])
        return self.chi * omega_ref + KP * lag
