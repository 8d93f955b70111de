"""Per-body mass properties after lumping: validation against physics, optional repair."""

from __future__ import annotations

import numpy as np

from converters.description import RobotDescription
from converters.description.robot import Inertial
from converters.errors import InertiaError
from converters.mjcf import inertia as inr
from converters.mjcf.geometry import GeomPlan
from converters.mjcf.lumping import WORLDBODY, BodyPlan
from converters.report import Report


def link_inertias(robot: RobotDescription, repair: bool, report: Report) -> dict[str, inr.Inertia]:
    """Each link's inertia in its own frame, checked; links without `<inertial>` are absent.

    Raises:
        InertiaError: a link with mass > 0 and a non-physical tensor, or a negative mass
            (unless `repair`, which bounds the tensor and reports the link).
    """
    out: dict[str, inr.Inertia] = {}
    for link in robot.links:
        value = inr.from_inertial(link.inertial)
        if value is None:
            continue
        if value.mass == 0 and not np.any(value.tensor):
            out[link.name] = value
            continue
        wild = inr.out_of_range(value)
        if wild is not None:
            fix = "give its <inertial> the mass [kg] and inertia [kg m²] of a real part"
            raise InertiaError(robot.source, link.name, wild, _declared(link.inertial), fix)
        trouble = inr.problem(value)
        if trouble is not None and value.mass > 0 and repair:
            fixed = inr.repair_tensor(value)
            report.repaired(
                f"link '{link.name}' <inertial>",
                f"{trouble}: {inr.describe(value)} → {inr.describe(fixed)}",
            )
            value = fixed
        elif trouble is not None and (value.mass != 0 or not repair):
            raise InertiaError(robot.source, link.name, trouble, inr.describe(value))
        out[link.name] = value
    return out


def _declared(inertial: Inertial | None) -> str:
    """The values as the file gives them (the turned ones may have overflowed)."""
    if inertial is None:
        return "no <inertial>"
    return inr.describe(inr.Inertia(inertial.mass, np.zeros(3), inertial.inertia))


def body_inertias(
    robot: RobotDescription, plan: BodyPlan, geoms: list[GeomPlan], repair: bool, report: Report
) -> dict[str, inr.Inertia]:
    """Merged inertia of every body (its link plus the links lumped into it), in body frame.

    A moving body (one with a joint, or the floating base) needs mass; without it conversion
    fails, or with `repair` it gets a solid box of 1000 kg/m³ spanning its collision geometry.
    """
    links = link_inertias(robot, repair, report)
    parts: dict[str, list[inr.Inertia]] = {}
    for name, value in links.items():
        placement = plan.placements[name]
        parts.setdefault(placement.body, []).append(value.transformed(placement.T_body_link))
    moving = {b.name for b in plan.bodies if b.joint is not None}
    if plan.floating:
        moving.add(plan.root_body)
    out: dict[str, inr.Inertia] = {}
    for body in plan.bodies:
        merged = inr.combine(parts.get(body.name, [])) if body.name in parts else inr.Inertia.zero()
        if body.name in moving and merged.mass <= 0:
            merged = _massless(robot, body.name, links, geoms, repair, report)
        out[body.name] = merged
    out.pop(WORLDBODY, None)
    return out


def _massless(
    robot: RobotDescription,
    body: str,
    links: dict[str, inr.Inertia],
    geoms: list[GeomPlan],
    repair: bool,
    report: Report,
) -> inr.Inertia:
    if not repair:
        value = links.get(body, inr.Inertia.zero())
        problem = f"moving link with mass {value.mass:g} kg"
        if body not in links:
            dropped = ", ".join(_subtree(robot, body))
            problem = f"moving link has no <inertial>; Gazebo would silently drop {dropped}"
        raise InertiaError(robot.source, body, problem, inr.describe(value))
    own = [g for g in geoms if g.body == body and g.role == "collision"] or [
        g for g in geoms if g.body == body
    ]
    if own:
        bounds = [g.aabb() for g in own]
        lo = np.min([b[0] for b in bounds], axis=0)
        hi = np.max([b[1] for b in bounds], axis=0)
    else:
        lo = hi = np.zeros(3)
    value = inr.from_box(lo, hi)
    report.repaired(
        f"link '{body}' <inertial>",
        f"moving link without mass: given {value.mass:.4g} kg, a solid box of "
        f"{inr.REPAIR_DENSITY:g} kg/m³ over its geometry ({inr.describe(value)})",
    )
    return value


def _subtree(robot: RobotDescription, link: str) -> list[str]:
    """`link` and every link below it, depth first (what sdformat drops with a massless link)."""
    children = robot.children()
    out, stack = [], [link]
    while stack:
        name = stack.pop()
        out.append(name)
        stack.extend(reversed([j.child for j in children.get(name, [])]))
    return out
