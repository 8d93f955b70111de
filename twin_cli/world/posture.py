"""Initial joint positions (Gazebo's `spawn_model -J JOINT POS`): checked, with mimics followed.

A spawn may set the positions of an entity's hinge and slide joints by their URDF names. Each
value must be finite and inside the joint's range (MuJoCo's `jnt_range` where `jnt_limited`);
a mimic follower is not set directly but follows its leader through the joint equality the
converter wrote (`converters.mjcf.actuators.add_mimics`): q_f − q0_f = Σ cₖ·(q_l − q0_l)ᵏ, k = 0..4,
and must land inside its own range too. Pure functions of the compiled model: no state changes.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from twin_cli.errors import InvalidRequestError, PartNotFoundError
from twin_cli.world.entities import element_names

ONE_DOF = (int(mujoco.mjtJoint.mjJNT_HINGE), int(mujoco.mjtJoint.mjJNT_SLIDE))
_HINGE = int(mujoco.mjtJoint.mjJNT_HINGE)
_JOINT_EQ = int(mujoco.mjtEq.mjEQ_JOINT)
RANGE_TOL = 1e-9  # [rad] or [m] a value this far past a bound still counts as inside


def joint_targets(
    model: mujoco.MjModel,
    joint_ids: np.ndarray,
    prefix: str,
    requested: dict[str, float],
    entity: str,
) -> dict[int, float]:
    """qpos address → position [rad] or [m] for each requested joint and its mimic followers.

    Args:
        model: the compiled model that holds the entity.
        joint_ids: the entity's joint ids in `model`.
        prefix: the entity's element prefix ("<name>/", or "" for a robot compiled alone).
        requested: joint name without prefix → position [rad] (hinge) or [m] (slide).
        entity: the entity's name, for messages.

    Raises:
        PartNotFoundError: a name is not one of the entity's hinge or slide joints (lists them).
        InvalidRequestError: a value is not finite, is outside the joint's range (names the
            range), or sets a mimic follower (names its leader).
    """
    names = element_names(model, model.name_jntadr[joint_ids])
    movable = {
        n.removeprefix(prefix): int(j)
        for n, j in zip(names, joint_ids, strict=True)
        if int(model.jnt_type[j]) in ONE_DOF
    }
    leaders = mimic_leaders(model, set(movable.values()))
    targets: dict[int, float] = {}
    for name, value in requested.items():
        if name not in movable:
            raise PartNotFoundError(entity, "joint", name, list(movable))
        joint = movable[name]
        if joint in leaders:
            leader = model.joint(leaders[joint][0]).name.removeprefix(prefix)
            raise InvalidRequestError(
                f"joint [{name}] of [{entity}]",
                f"it is a mimic follower of [{leader}]",
                f"set [{leader}] instead; [{name}] follows it",
            )
        _check_value(model, joint, name, float(value), entity)
        targets[int(model.jnt_qposadr[joint])] = float(value)
    _follow_mimics(model, leaders, targets, prefix, entity)
    return targets


def mimic_leaders(model: mujoco.MjModel, joints: set[int]) -> dict[int, tuple[int, np.ndarray]]:
    """follower joint id → (leader joint id, polynomial coefficients) of active joint equalities."""
    out: dict[int, tuple[int, np.ndarray]] = {}
    for e in range(model.neq):
        follower, leader = int(model.eq_obj1id[e]), int(model.eq_obj2id[e])
        is_joint = int(model.eq_type[e]) == _JOINT_EQ and bool(model.eq_active0[e])
        if is_joint and follower in joints and leader in joints:
            out[follower] = (leader, np.array(model.eq_data[e][:5], dtype=float))
    return out


def _follow_mimics(
    model: mujoco.MjModel,
    leaders: dict[int, tuple[int, np.ndarray]],
    targets: dict[int, float],
    prefix: str,
    entity: str,
) -> None:
    """Adds each follower whose leader has a target (chains too: at most one pass per mimic)."""
    for _ in range(len(leaders)):
        added = False
        for follower, (leader, coef) in leaders.items():
            f_adr, l_adr = int(model.jnt_qposadr[follower]), int(model.jnt_qposadr[leader])
            if l_adr not in targets or f_adr in targets:
                continue
            dq = targets[l_adr] - float(model.qpos0[l_adr])
            value = float(model.qpos0[f_adr]) + float(np.polyval(coef[::-1], dq))
            name = model.joint(follower).name.removeprefix(prefix)
            _check_value(model, follower, name, value, entity, leader_of=leader, prefix=prefix)
            targets[f_adr] = value
            added = True
        if not added:
            return


def _check_value(
    model: mujoco.MjModel,
    joint: int,
    name: str,
    value: float,
    entity: str,
    *,
    leader_of: int | None = None,
    prefix: str = "",
) -> None:
    unit = "rad" if int(model.jnt_type[joint]) == _HINGE else "m"
    what = f"joint [{name}] of [{entity}]"
    if not math.isfinite(value):
        raise InvalidRequestError(what, f"position {value} is not finite", "give a number")
    if not model.jnt_limited[joint]:
        return
    lower, upper = (float(v) for v in model.jnt_range[joint])
    if lower - RANGE_TOL <= value <= upper + RANGE_TOL:
        return
    why = f"position {value:g} {unit} is outside its range [{lower:g}, {upper:g}] {unit}"
    fix = f"give a position within [{lower:g}, {upper:g}] {unit}"
    if leader_of is not None:
        leader = model.joint(leader_of).name.removeprefix(prefix)
        why += f" (it follows [{leader}] as a mimic)"
        fix = f"give [{leader}] a position that keeps [{name}] within [{lower:g}, {upper:g}] {unit}"
    raise InvalidRequestError(what, why, fix)


def apply_targets(q: np.ndarray, qpos_adr: np.ndarray, targets: dict[int, float]) -> np.ndarray:
    """A copy of the entity's qpos `q` (laid out as `qpos_adr`) with `targets` written in."""
    out = np.array(q, dtype=float)
    where = {int(a): i for i, a in enumerate(qpos_adr)}
    for adr, value in targets.items():
        out[where[adr]] = value
    return out
