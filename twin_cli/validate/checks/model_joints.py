"""Model check on joint definitions: limits ordered, efforts and velocities positive."""

from __future__ import annotations

import json

from twin_cli.validate.checks.base import DeclaredJoint, RobotUnderTest, judged
from twin_cli.validate.scenario import Scenario

HINGE, SLIDE = 3, 2  # mjtJoint codes
JOINT_TRANSMISSION = 0  # mjtTrn mjTRN_JOINT


def joint_effort(model, joint: int) -> float | None:
    """The effort limit [N m] or [N] of a joint: its motor's force/ctrl range, else actfrcrange."""
    for a in range(model.nu):
        if int(model.actuator_trntype[a]) != JOINT_TRANSMISSION:
            continue
        if int(model.actuator_trnid[a][0]) != joint:
            continue
        gear = abs(float(model.actuator_gear[a][0])) or 1.0
        if model.actuator_forcelimited[a]:
            return float(max(abs(v) for v in model.actuator_forcerange[a]))
        if model.actuator_ctrllimited[a]:
            return float(max(abs(v) for v in model.actuator_ctrlrange[a])) * gear
    if model.jnt_actfrclimited[joint]:
        return float(max(abs(v) for v in model.jnt_actfrcrange[joint]))
    return None


def has_actuator(model, joint: int) -> bool:
    """True when a motor drives this joint (a passive joint's zero-effort motor does not: no
    tag asks for one, so no effort limit is missing)."""
    if model.joint(joint).name in passive_joints(model):
        return False
    return any(
        int(model.actuator_trntype[a]) == JOINT_TRANSMISSION
        and int(model.actuator_trnid[a][0]) == joint
        for a in range(model.nu)
    )


def passive_joints(model) -> set[str]:
    """Joints whose motor the converter added only so that they can be commanded (record
    source "passive" in the model's `control` text)."""
    import mujoco

    out: set[str] = set()
    for t in range(model.ntext):
        name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_TEXT, t) or ""
        if name != "control" and not name.endswith("/control"):
            continue
        start = model.text_adr[t]
        try:
            records = json.loads(bytes(model.text_data[start : start + model.text_size[t] - 1]))
        except ValueError:
            continue
        prefix = name.removesuffix("control")
        out |= {prefix + j for j, r in records.items() if r.get("source") == "passive"}
    return out


def limited_range(model, joint: int) -> tuple[float, float] | None:
    """The joint's declared range [rad] or [m], whether or not MuJoCo enforces it."""
    lo, hi = (float(v) for v in model.jnt_range[joint])
    return (lo, hi) if (lo, hi) != (0.0, 0.0) else None


def _joint_problems(model, joint: int) -> list[str]:
    name = model.joint(joint).name
    problems = []
    rng = limited_range(model, joint)
    if model.jnt_limited[joint] and rng and rng[0] >= rng[1]:
        problems.append(
            f"joint '{name}': lower limit {rng[0]:.4g} ≥ upper {rng[1]:.4g}; swap them in <limit>"
        )
    if rng and not model.jnt_limited[joint]:
        problems.append(
            f"joint '{name}': range {rng[0]:.4g}..{rng[1]:.4g} is declared but not enforced; "
            "make it revolute/prismatic with <limit>, or check stopErp/stopCfm"
        )
    effort = joint_effort(model, joint)
    if has_actuator(model, joint) and (effort is None or effort <= 0.0):
        problems.append(
            f"joint '{name}': effort limit {effort} is not positive; set <limit effort>"
        )
    return problems


def _declared_problems(joint: DeclaredJoint) -> list[str]:
    """What the URDF itself gets wrong: limits reversed, effort or velocity not positive."""
    if joint.type not in ("revolute", "prismatic", "continuous"):
        return []
    problems = []
    name = f"joint '{joint.name}'"
    if joint.type != "continuous" and joint.lower is not None and joint.upper is not None:
        if joint.lower >= joint.upper:
            problems.append(
                f"{name}: <limit lower={joint.lower:g} upper={joint.upper:g}> is not ordered, "
                "so the joint is left unlimited; give lower < upper"
            )
    for field, unit in (("effort", "N m or N"), ("velocity", "rad/s or m/s")):
        value = getattr(joint, field)
        if value is not None and value <= 0.0 and not joint.mimic:
            problems.append(
                f"{name}: <limit {field}={value:g}> must be positive [{unit}]; "
                + ("no motor can drive it" if field == "effort" else "set the real top speed")
            )
    return problems


def check_joint_definitions(robot: RobotUnderTest, scenario: Scenario, th: dict[str, float]):
    """Limits ordered and enforced, efforts and velocities positive (as the URDF declares)."""
    model = robot.model
    hints = []
    checked = 0
    for j in range(model.njnt):
        if int(model.jnt_type[j]) not in (HINGE, SLIDE):
            continue
        checked += 1
        hints += _joint_problems(model, j)
    for joint in robot.declared_joints:
        hints += _declared_problems(joint)
    return judged(
        "joint_definitions",
        "model",
        f"{len(hints)} problem(s) in {checked} joint(s)",
        "0",
        hints,
        value=float(len(hints)),
    )
