"""Gazebo's contact rules as MuJoCo settings: min-μ priorities, kp/kd → direct solref, ground.

Friction. Gazebo (ODE) combines two surfaces by min(μa, μb). MuJoCo takes the larger friction of
the two geoms when their priorities are equal, and the friction (and condim, solref, solimp) of
the geom with the higher priority otherwise. `friction_priority` makes priority a strictly
decreasing function of μ, quantised on log10 μ, so the lower-μ geom always wins: the pair's
friction is min(μ) for robot–ground, robot–robot and robot–obstacle pairs alike, provided every
geom of the world takes its priority from this one function.

Stiffness (see docs/contacts.md for the derivation). Gazebo's ODE does not run kp/kd as an
explicit spring: it turns them into ERP = h·kp/(h·kp + kd) and CFM = 1/(h·kp + kd) and solves
every contact at the velocity level, which is an implicit (backward Euler) spring-damper, and it
caps the speed at which it pushes a penetration out at the surface's `max_vel` (0.01 m/s by
default). So a Gazebo contact rests at m·g/kp without ringing and takes a drop without a bounce.
MuJoCo's contact with constant impedance d (solimp d0 = d1 = d) and direct solref (-S, -B) obeys
    a = (1 - d)·a0 - B·v - S·r,    rest penetration r = (1 - d)·a0 / S
(a0 the unconstrained acceleration; checked numerically). twin keeps Gazebo's rest penetration
m·g/kp exactly (S = (1 - d)·kp/m, m the mass of the geom's body) and its behaviour around it:
  - the correction rate h²·S stays at most MAX_CORRECTION_ERP per step, and at most ODE's own
    ERP: with ODE's ERP ≈ 1 and no `max_vel` cap, MuJoCo handed a 0.2 m drop back as a 65 mm
    bounce, and a resting box's normal force swung between 0 and 2·m·g;
  - B = 4·√S (damping ratio 2, = 1/h) at the correction cap, 2·√S (critical) below it:
    overdamped like ODE's capped correction, so a drop does not bounce (0.000 mm from 0.2 m,
    against 13.8 mm at the former ratio 0.5);
  - d = SOFT_IMPEDANCE, or higher when the correction cap binds (d = 1 - m·S/kp, at most
    HARD_IMPEDANCE): friction rows share d, and a body on a slope below its friction angle
    creeps as (1 - d)/B (3.1 mm in 10 s on a 34° slope at d 0.95; 0.06 mm at 0.999).
A contact through the centre of mass (a ball) reproduces kp exactly; a cube resting on a face
has m/4 at each corner (kp/4 each), as before.

Friction coefficient. The rule above is that of a single normal row, which is what a contact is
along its normal in twin's worlds at every μ: they use MuJoCo's elliptic friction cone
(`converters.mjcf.world_options.CONE`), whose friction rows have regularisers of their own.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    import mujoco

GROUND_MU = 100.0
"""μ of Gazebo's stock ground plane (`ground_plane` model, `surface/friction/ode/mu`)."""
DEFAULT_MU = 1.0
"""SDF default for `surface/friction/ode/mu` when a link sets none (`sdf/1.11/surface.sdf`)."""
DEFAULT_KP = 1e12
"""SDF default contact stiffness [N/m] (`surface.sdf`); only used when kd is set without kp."""
DEFAULT_KD = 1.0
"""SDF default contact damping [N s/m] (`surface.sdf`); only used when kp is set without kd."""
GAZEBO_STEP = 0.001
"""SDF default `max_step_size` [s]; the step the kp/kd mapping is checked for."""

CONTACT_MU_MAX = 2.0
"""Largest μ a robot's or model's geom gets. With a large μ MuJoCo's friction rows carry the
contact and it gives way along the normal: a 40 kg cart on four wheels rests 0.35 mm low at μ 10
and sinks to its axles at μ 100 (elliptic cone; on the pyramidal cone 0.24 mm at μ 5). Gazebo
robots write μ 100 or 1e5 to mean "no slip"; μ 2 already holds on a 63° slope. Gazebo's ground
plane keeps its μ 100: the min-μ rule lets the capped robot geom decide the pair."""
MU_MIN = 1e-6
MU_MAX = 1e9
PRIORITY_PER_DECADE = 1000
"""Priority steps per decade of μ: two μ closer than 0.23 % may share a priority (then max)."""

MAX_CORRECTION_ERP = 1.0 / 16.0
"""Largest fraction of a penetration a contact removes per step (h²·S). ODE's own ERP is ≈ 1
for stiff surfaces, but ODE caps the push-out speed at `max_vel`; MuJoCo has no such cap, and
at ERP 1 (or 1/4, MuJoCo's own bound τ = 2h) a drop came back as a bounce (65 mm, 3.1 mm from
0.2 m). At 1/16 a box dropped from 0.2 m, a 0.05 kg one and a 400 kg one rest with no bounce
and a normal force steady to 1e-4 of m·g."""
SOFT_IMPEDANCE = 0.9
"""Impedance d of a contact whose kp is soft enough to be reproduced below the correction cap;
MuJoCo's friction rows share it, and (1 - d) sets how fast a body creeps under a tangential
load it should hold."""
HARD_IMPEDANCE = 0.999
"""Impedance of a rigid surface (SDF's default kp 1e12). A body creeps 0.06 mm in 10 s on a slope
6° short of its friction angle. MuJoCo allows up to 0.9999 (0.006 mm on that slope), but there a
humanoid lying on the ground rang (its normal force's step-to-step spread rose from 0.03 N to
3.7 N) and crept 0.58 mm in 10 s against 0.084 mm at 0.999, and a limp arm whose links lie on the
ground turned 5.9 mrad against 0.0001 mrad (each in the posture it had come to rest in at 0.999)."""
DAMPING_RATIO = 2.0
"""B = 2·DAMPING_RATIO·√S on a surface at the correction cap (= 1/h there): overdamped, as ODE's
capped correction never pushes back fast. A softer surface is critically damped (ratio 1): it
does not bounce either, and settles at m·g/kp in about 4/√S (overdamped, a 5.5 kg crate on
kp 1e3 had not sunk to it after the 1 s a check waits)."""
SOLIMP_WIDTH = 0.001
"""solimp width [m]; irrelevant when d0 = d1, kept at MuJoCo's default."""
DEFAULT_LIMIT_ERP = 0.2
"""SDF default `joint/axis/limit` erp (ODE `stopErp`); Gazebo's default cfm there is 0 (hard)."""
LIMIT_SOLIMP = (0.9999, 0.9999, 0.001, 0.5, 2.0)
"""solimplimit of every joint: constant impedance d = 0.9999 (MuJoCo's largest, mjMAXIMP), the
nearest MuJoCo gets to ODE's cfm 0: the limit gives way by (1 − d)/d of what it resists."""


@dataclass(frozen=True)
class ContactSoftness:
    """MuJoCo settings for one Gazebo kp/kd pair on a body of a given mass.

    `solref` is direct (-S [1/s²], -B [1/s]); `clamped` is True when the surface is stiffer
    than HARD_IMPEDANCE reproduces; `damping_ratio_gazebo` is kd/(2·sqrt(kp·m)) and
    `damping_ratio` the one used, B/(2·√S); `sinkage` is MuJoCo's at rest under 9.8 m/s².
    """

    solref: tuple[float, float]
    solimp: tuple[float, float, float, float, float]
    clamped: bool
    damping_ratio_gazebo: float
    damping_ratio: float
    sinkage_gazebo: float
    sinkage: float


def contact_mu(mu: float) -> float:
    """The μ a geom gets for a Gazebo μ: capped at CONTACT_MU_MAX (see there)."""
    return min(mu, CONTACT_MU_MAX)


def friction_priority(mu: float) -> int:
    """Geom priority for a sliding coefficient μ: lower μ, higher priority.

    Args:
        mu: Coulomb coefficient (unitless); clamped to [MU_MIN, MU_MAX].

    Returns:
        A non-negative integer, strictly decreasing in μ at PRIORITY_PER_DECADE steps per decade.
    """
    clamped = min(max(mu, MU_MIN), MU_MAX)
    return round((math.log10(MU_MAX) - math.log10(clamped)) * PRIORITY_PER_DECADE)


def max_contact_stiffness(timestep: float = GAZEBO_STEP) -> float:
    """Stiffest S [1/s²] a contact gets at `timestep`: MAX_CORRECTION_ERP / h²."""
    return MAX_CORRECTION_ERP / timestep**2


def contact_softness(
    kp: float | None,
    kd: float | None,
    mass: float,
    timestep: float = GAZEBO_STEP,
) -> ContactSoftness:
    """Map Gazebo's kp/kd (ODE's ERP/CFM) onto MuJoCo's direct solref and solimp.

    Args:
        kp: contact stiffness [N/m] (SDF default 1e12 when None).
        kd: contact damping [N s/m] (SDF default 1 when None).
        mass: mass carried by the contact [kg] (twin uses the mass of the geom's body).
        timestep: simulation step [s] the result must be stable at.

    Returns:
        The settings, with the rest sinkage under 9.8 m/s² in Gazebo and in MuJoCo [m].
        `clamped` is True when Gazebo's surface is stiffer than HARD_IMPEDANCE reproduces (the
        sinkage is then larger than Gazebo's, still microns).
    """
    kp = DEFAULT_KP if kp is None else kp
    kd = DEFAULT_KD if kd is None else kd
    mass = max(mass, 1e-9)
    erp = timestep * kp / (timestep * kp + kd) if kp > 0 else 0.0
    limit = min(max_contact_stiffness(timestep), max(erp, 1e-9) / timestep**2)
    d = SOFT_IMPEDANCE
    stiffness = (1.0 - d) * kp / mass
    clamped, hard = False, stiffness >= limit
    if hard:
        stiffness = limit
        d = 1.0 - mass * stiffness / kp
        clamped = d > HARD_IMPEDANCE
        d = min(d, HARD_IMPEDANCE)
    stiffness = max(stiffness, 1e-9)
    ratio = DAMPING_RATIO if hard else 1.0
    damping = min(max(2.0 * ratio * math.sqrt(stiffness), kd / mass), 1.0 / timestep)
    zeta_gazebo = kd / (2.0 * math.sqrt(kp * mass)) if kp > 0 else math.inf
    return ContactSoftness(
        solref=(-stiffness, -damping),
        solimp=(d, d, SOLIMP_WIDTH, 0.5, 2.0),
        clamped=clamped,
        damping_ratio_gazebo=zeta_gazebo,
        damping_ratio=damping / (2.0 * math.sqrt(stiffness)),
        sinkage_gazebo=mass * 9.8 / kp if kp > 0 else math.inf,
        sinkage=(1.0 - d) * 9.8 / stiffness,
    )


def limit_solref(erp: float | None, timestep: float = GAZEBO_STEP) -> tuple[float, float]:
    """Joint-limit reference dynamics from ODE's stopErp: standard solreflimit (timeconst, ratio).

    ODE's limit row with cfm 0 is a hard velocity constraint: each step it sets the joint's
    velocity so that a fraction erp of the violation r is removed, v' = −erp·r/h. A MuJoCo limit
    with impedance d → 1 (`LIMIT_SOLIMP`) follows its reference acceleration
    aref = −b·v − k·r with b = 2/(d·τ), k = 1/(d·τ²·ζ²) (MuJoCo "Solver parameters"), and
    semi-implicit Euler gives v' = v + h·aref. Choosing τ = 2h and ζ = 1/(2·√erp) makes
    b = 1/h and k = erp/h², so v' = −erp·r/h: ODE's rule, step for step (the violation decays
    by (1 − erp) per step, the impact velocity is removed in one step). τ = 2h is also MuJoCo's
    refsafe bound, which MuJoCo re-applies at a larger world timestep, so the rule still holds
    there (b = 1/h, k = erp/h² at that h).

    Args:
        erp: ODE error-reduction parameter in (0, 1]; SDF default 0.2 when None or ≤ 0.
        timestep: the Gazebo step [s] the mapping is exact for.

    Returns:
        (timeconst [s], dampratio).
    """
    erp = DEFAULT_LIMIT_ERP if erp is None or erp <= 0 else min(erp, 1.0)
    return (2.0 * timestep, 1.0 / (2.0 * math.sqrt(erp)))


def add_gazebo_ground(spec: mujoco.MjSpec) -> None:
    """Add Gazebo's stock ground plane: an infinite plane geom "ground", μ=100 (μ2=50).

    MuJoCo geoms are isotropic, so the plane carries μ=GROUND_MU; its priority comes from
    `friction_priority`, so any robot geom with a lower μ decides the pair's friction (min rule).

    Args:
        spec: a `mujoco.MjSpec`; the geom is added to its world body.
    """
    import mujoco

    geom = spec.worldbody.add_geom(
        name="ground",
        type=mujoco.mjtGeom.mjGEOM_PLANE,
        size=[0.0, 0.0, 1.0],
        rgba=[0.8, 0.8, 0.8, 1.0],
    )
    geom.friction = np.array([GROUND_MU, 0.005, 0.0001])
    geom.priority = friction_priority(GROUND_MU)
    geom.condim = 3
