"""Divergence: find which entities went unstable in a batch (NaN/Inf, MuJoCo's bad-number
warnings, or a joint far faster than its velocity limit).

MuJoCo itself checks qpos, qvel and qacc at every step; on a bad value it warns (recording the
offending qpos or dof address in `warning.lastinfo`) and resets the *whole* data. The world
therefore snapshots the state before each batch, and when this module reports an offender, it
restores the snapshot and resets only the offending entities to their spawn state.

A blow-up can also stay finite: MuJoCo calls a number bad only past 1e10 (`mjMAXVAL`), and a
joint kicked by a full-effort step on a tiny inertia spins at 1e3-1e7 rad/s for as long as
nothing brakes it. So a dof whose speed exceeds `SPEED_FACTOR` times its joint's velocity limit
(or `UNLIMITED_SPEED` where the joint has none) counts as a divergence too (`SpeedBounds`).

MuJoCo's warnings (`mjtWarning`, raised in `engine_forward.c`, `engine_core_smooth.c` and the
collision and constraint stages) and which ones count, `DIVERGED`:
- mjWARN_BADQPOS, mjWARN_BADQVEL, mjWARN_BADQACC: NaN, Inf or |x| > 1e10 in the state or its
  acceleration, "The simulation is unstable". Counted.
- mjWARN_BADCTRL: NaN, Inf or |x| > 1e10 in `ctrl`; MuJoCo then zeroes every actuator's control
  in the whole world for the step, and keeps doing so while the value stays. twin's commands are
  finite and bounded, so such a value comes from a controller fed by a blown-up state (or a
  direct write); counted, and resetting its entity restores the entity's spawn `ctrl`.
- mjWARN_INERTIA: a pivot of M's factorization below 1e-15, clamped and stepped on. It depends
  on the posture and the masses, not on growth of the state: a near-massless chain raises it at
  every step from spawn, where a reset would pin the robot to its spawn pose forever. Not counted.
- mjWARN_CONTACTFULL, mjWARN_CNSTRFULL: the arena is full and contacts or constraints are
  dropped (a large pile of bodies); a capacity limit, not instability. Not counted.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np
from numpy.typing import ArrayLike

from twin_cli.world.entities import EntityIndex
from twin_cli.world.joint_control import limits_of

_W = mujoco.mjtWarning
_J = mujoco.mjtJoint
_HINGE, _SLIDE, _BALL, _FREE = (
    int(k) for k in (_J.mjJNT_HINGE, _J.mjJNT_SLIDE, _J.mjJNT_BALL, _J.mjJNT_FREE)
)
BAD_STATE = (_W.mjWARN_BADQPOS, _W.mjWARN_BADQVEL, _W.mjWARN_BADQACC)
DIVERGED = (*BAD_STATE, _W.mjWARN_BADCTRL)  # the warnings that count (see the module docstring)
_WARNED_FIELD = {  # EntityIndex field that `warning.lastinfo` addresses, and its name
    _W.mjWARN_BADQPOS: ("qpos", "qpos"),
    _W.mjWARN_BADQVEL: ("dofs", "dof"),
    _W.mjWARN_BADQACC: ("dofs", "dof"),
    _W.mjWARN_BADCTRL: ("actuators", "actuator"),
}
# A speed over this multiple of the joint's velocity limit is a blow-up. Gazebo's rule for an
# effort (`actuation.apply_command`) lets a joint pass its limit by one step's worth of effort,
# u·h/I, which can be many times the limit on a light link; a finite blow-up measured on solo12
# (1000 N m on legs of 7-150 g) reached 1.2e7 rad/s against its limit of 1000 rad/s.
SPEED_FACTOR = 100.0
# [rad/s or m/s] the bound of a dof whose joint has no velocity limit (free and ball joints, both
# linear and angular, and joints of hand-written models): 1.6 kHz of spin, 10 km/s of flight.
UNLIMITED_SPEED = 1e4


@dataclass(frozen=True)
class Divergence:
    """One entity reset for instability.

    Attributes:
        entity: entity name; sim_time: simulation time [s] of the batch start; reason: what was
        seen (e.g. "MuJoCo warning mjWARN_BADQACC at dof 8", "non-finite qvel", "joint 'knee'
        at 1.5e+03 rad/s, over its bound 100 rad/s (100 × its velocity limit 1 rad/s)").
    """

    entity: str
    sim_time: float
    reason: str


@dataclass(frozen=True, eq=False)
class SpeedBounds:
    """Each dof's speed bound in one compiled model, computed once per model.

    Attributes:
        model: the model they belong to (a recompile makes a new one, and new bounds).
        bound: (nv,) speed bound per dof [rad/s or m/s]; limit: (nv,) the joint's velocity limit
            from its control record [rad/s or m/s] (inf: none).
    """

    model: mujoco.MjModel
    bound: np.ndarray
    limit: np.ndarray


def speed_bounds(model: mujoco.MjModel, indices: dict[str, EntityIndex]) -> SpeedBounds:
    """`SPEED_FACTOR` × each hinge and slide joint's velocity limit (its control record,
    `joint_control.limits_of`), `UNLIMITED_SPEED` for every other dof.

    Measured: 0.04-0.3 ms for the bundled humanoid (12 joints, one JSON read each), paid at
    the first batch after each compile.
    """
    limit = np.full(model.nv, math.inf)
    for entity, ix in indices.items():
        for j in ix.joints.tolist():
            if int(model.jnt_type[j]) in (_HINGE, _SLIDE):
                name = model.joint(j).name.removeprefix(f"{entity}/")
                limit[model.jnt_dofadr[j]] = limits_of(model, entity, name).velocity
    bound = np.where(np.isfinite(limit), SPEED_FACTOR * limit, UNLIMITED_SPEED)
    return SpeedBounds(model, bound, limit)


def warning_counts(data: mujoco.MjData) -> tuple[int, ...]:
    """How many times each warning fired so far, indexed by `mujoco.mjtWarning` (one read)."""
    return tuple(data.warning.number.tolist())


def batch_healthy(data: mujoco.MjData, before: tuple[int, ...], bound: np.ndarray) -> bool:
    """True when no warning fired since `before` (from `warning_counts`), qpos is finite and
    every |qvel| is within `bound` (`SpeedBounds.bound`; a NaN fails the comparison too): the
    loop's per-batch test, so only a suspect batch pays for `find_divergent`.

    MuJoCo checks qpos, qvel and qacc at every step and warns on a bad value, so a divergence
    inside the batch always raises a warning; the finite test catches one made by the batch's
    last integration. A speed is checked at the batch's end only: a blow-up that lasts is seen,
    a spike that a joint limit stops within the batch is not. Measured on the humanoid with warm
    caches, medians of 15 interleaved runs: 3.7 µs with qvel's finite test, 4.1 µs with the
    speed test in its place (+0.4 µs); `find_divergent` 16-20 µs. Right after a batch of
    mj_step, caches are cold and the first Python code pays 25-80 µs whatever it is (which is
    why batches are long, see `realtime.BATCH_WALL_S`).
    """
    return (
        warning_counts(data) == before
        and bool(np.isfinite(data.qpos).all())
        and bool((np.abs(data.qvel) <= bound).all())
    )


def find_divergent(
    data: mujoco.MjData,
    before: tuple[int, ...],
    indices: dict[str, EntityIndex],
    bounds: SpeedBounds,
) -> dict[str, str]:
    """Entities that diverged since `before` (from `warning_counts`), with the reason.

    Returns:
        {entity: reason}; empty when the batch was healthy. A divergence that no entity owns
        is attributed to every entity. A bad number outranks a speed as the reason.
    """
    found: dict[str, str] = {}
    now = warning_counts(data)
    for kind in DIVERGED:
        if now[kind] > before[kind]:
            address = int(data.warning[kind].lastinfo)
            field, noun = _WARNED_FIELD[kind]
            reason = f"MuJoCo warning {kind.name} at {noun} {address}"
            found.update(dict.fromkeys(_owners(indices, field, [address]), reason))
    for field, values in (("qpos", data.qpos), ("dofs", data.qvel), ("dofs", data.qacc)):
        bad = np.flatnonzero(~np.isfinite(values))
        if bad.size:
            found.update(dict.fromkeys(_owners(indices, field, bad), f"non-finite {field}"))
    for owner, reason in _overspeed(data, indices, bounds).items():
        found.setdefault(owner, reason)
    if found and not set(found) <= set(indices):
        return dict.fromkeys(indices, next(iter(found.values())))
    return found


def _overspeed(
    data: mujoco.MjData, indices: dict[str, EntityIndex], bounds: SpeedBounds
) -> dict[str, str]:
    """{entity: reason} for the entities with a dof over its bound, naming the dof furthest
    over (as a multiple of its bound)."""
    speed = np.abs(data.qvel)
    over = np.flatnonzero(speed > bounds.bound)  # NaN is not over: it has its own reason
    found: dict[str, str] = {}
    if not over.size:
        return found
    for dof in over[np.argsort(-speed[over] / bounds.bound[over])].tolist():
        for owner in _owners(indices, "dofs", [dof]):
            if owner not in found:
                found[owner] = _speed_reason(bounds, dof, float(speed[dof]), owner)
    return found


def _speed_reason(bounds: SpeedBounds, dof: int, speed: float, entity: str) -> str:
    """E.g. "joint 'knee' at 1.5e+03 rad/s, over its bound 100 rad/s (100 × its velocity limit
    1 rad/s)"; a free joint's dof says which ("joint 'root' linear dof 2 at ...")."""
    model = bounds.model
    j = int(model.dof_jntid[dof])
    kind, offset = int(model.jnt_type[j]), dof - int(model.jnt_dofadr[j])
    linear = kind == _SLIDE or (kind == _FREE and offset < 3)
    unit = "m/s" if linear else "rad/s"
    part = ""
    if kind == _FREE:
        part = f" {'linear' if offset < 3 else 'angular'} dof {offset % 3}"
    elif kind == _BALL:
        part = f" dof {offset}"
    name = model.joint(j).name.removeprefix(f"{entity}/") or f"#{j}"  # an unnamed joint: its id
    limit = float(bounds.limit[dof])
    why = (
        f"{SPEED_FACTOR:g} × its velocity limit {limit:.3g} {unit}"
        if math.isfinite(limit)
        else "the bound of a joint without a velocity limit"
    )
    bound = float(bounds.bound[dof])
    return f"joint '{name}'{part} at {speed:.3g} {unit}, over its bound {bound:.3g} {unit} ({why})"


def _owners(indices: dict[str, EntityIndex], field: str, addresses: ArrayLike) -> list[str]:
    owners = [n for n, ix in indices.items() if np.isin(getattr(ix, field), addresses).any()]
    return owners or ["<world>"]
