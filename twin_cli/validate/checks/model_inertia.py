"""Model checks on mass and inertia: present, physical, and plausible against the geometry."""

from __future__ import annotations

import numpy as np

from converters.report import Outcome
from twin_cli.validate.checks.base import RobotUnderTest, Status, judged, link_in_subject, result
from twin_cli.validate.checks.geometry import body_solid
from twin_cli.validate.scenario import Scenario

# Plausibility rule (stated in docs/scenarios.md): a uniform solid filling the link's collision
# geometry, with the link's own mass, has inertia trace T_geo. Real parts (shells, dense
# motors) land within ~0.2x-5x of T_geo; below 1% the numbers are placeholders or in the
# wrong units. Same for mass: below 1% of the geometry's volume × 1000 kg/m³ (water), i.e. an
# effective density under 10 kg/m³, lighter than any foam, is flagged.
REFERENCE_DENSITY = 1000.0  # [kg/m³]

# The converter's repair entries (converters/bodies.py): subject "link 'X' <inertial>"; a link
# given a mass says "without mass" in the detail, a patched tensor states what was wrong.
MASSLESS_WORDS = ("without mass", "no <inertial>")


def moving_bodies(model) -> list[int]:
    """Bodies that move relative to the world (not welded to it), as ids."""
    return [b for b in range(1, model.nbody) if int(model.body_weldid[b]) != 0]


def collision_geoms(model, body: int | None = None) -> list[int]:
    """Geoms that take part in contacts (contype/conaffinity set, or the `collision` group 3)."""
    out = []
    for g in range(model.ngeom):
        if body is not None and int(model.geom_bodyid[g]) != body:
            continue
        collides = int(model.geom_contype[g]) or int(model.geom_conaffinity[g])
        if collides or int(model.geom_group[g]) == 3:
            out.append(g)
    return out


def _repairs(robot: RobotUnderTest, massless: bool) -> list[tuple[str, str]]:
    """(link, detail) of the converter's inertial repairs: mass given, or tensor patched."""
    found = []
    for entry in robot.report.of(Outcome.REPAIRED):
        if "inertial" not in entry.subject.lower():
            continue
        if any(w in entry.detail.lower() for w in MASSLESS_WORDS) == massless:
            found.append((link_in_subject(entry.subject) or entry.subject, entry.detail))
    return found


def _repair_verdict(robot: RobotUnderTest, repairs: list[tuple[str, str]]) -> Status:
    if not repairs:
        return Status.PASS
    return Status.WARN if robot.repair_inertia else Status.FAIL


def check_inertial(robot: RobotUnderTest, scenario: Scenario, th: dict[str, float]):
    """Every moving link has an <inertial> with a positive mass."""
    model = robot.model
    repairs = _repairs(robot, massless=True)
    light = [
        model.body(b).name for b in moving_bodies(model) if model.body_mass[b] < th["min_mass"]
    ]
    hints = [
        f"link '{link}' has no usable <inertial> ({detail}): give it an <inertial> with a "
        "positive <mass>, or attach it with a fixed joint so it is lumped into its parent"
        for link, detail in repairs
    ]
    hints += [
        f"link '{b}' weighs under {th['min_mass']:g} kg: give it a real <mass>" for b in light
    ]
    status = Status.FAIL if light else _repair_verdict(robot, repairs)
    return result(
        "inertial",
        "model",
        status,
        f"{len(repairs) + len(light)} link(s) without mass",
        f"0 (mass ≥ {th['min_mass']:g} kg)",
        hints=hints,
        value=float(len(repairs) + len(light)),
    )


def check_inertia_tensor(robot: RobotUnderTest, scenario: Scenario, th: dict[str, float]):
    """Every inertia tensor is positive definite and obeys the triangle inequality."""
    model = robot.model
    repairs = _repairs(robot, massless=False)
    bad = []
    for b in moving_bodies(model):
        a, b2, c = sorted(float(v) for v in model.body_inertia[b])
        if a <= 0.0 or a + b2 < c * (1.0 - th["triangle_tol"]):
            bad.append(f"link '{model.body(b).name}': principal moments {a:.3g} {b2:.3g} {c:.3g}")
    hints = [
        f"link '{link}': non-physical inertia repaired by the converter ({detail}); fix "
        "<inertia> (positive definite, ixx+iyy ≥ izz etc.) from the CAD model"
        for link, detail in repairs
    ]
    hints += [f"{text}: not physical; fix <inertia>" for text in bad]
    status = Status.FAIL if bad else _repair_verdict(robot, repairs)
    count = len(repairs) + len(bad)
    return result(
        "inertia_tensor",
        "model",
        status,
        f"{count} non-physical tensor(s)",
        "0",
        hints=hints,
        value=float(count),
    )


def check_inertia_plausible(robot: RobotUnderTest, scenario: Scenario, th: dict[str, float]):
    """Mass and inertia are not suspiciously small for the link's collision geometry."""
    model = robot.model
    hints, details, worst = [], [], 1.0
    for b in moving_bodies(model):
        solid = body_solid(model, b, collision_geoms(model, b))
        if solid is None:
            continue
        volume, trace_per_mass = solid
        mass, name = float(model.body_mass[b]), model.body(b).name
        trace = float(np.sum(model.body_inertia[b]))
        mass_ratio = mass / (volume * REFERENCE_DENSITY)
        inertia_ratio = trace / (mass * trace_per_mass) if mass > 0 else 0.0
        worst = min(worst, mass_ratio, inertia_ratio)
        details.append(f"{name}: density {mass / volume:.3g} kg/m³, inertia {inertia_ratio:.3g}×")
        if mass_ratio < th["min_ratio"]:
            hints.append(
                f"link '{name}': {mass:.3g} kg for {volume * 1e6:.3g} cm³ of collision geometry "
                f"({mass / volume:.3g} kg/m³): the <mass> is probably a placeholder or in the "
                "wrong unit; weigh the part or take it from CAD"
            )
        if inertia_ratio < th["min_ratio"]:
            hints.append(
                f"link '{name}': inertia trace {trace:.3g} kg m² is {inertia_ratio * 100:.2g} % "
                f"of a solid of its geometry at {mass:.3g} kg ({mass * trace_per_mass:.3g} kg m²): "
                "the <inertia> is too small for this mass; compute it from CAD or the geometry"
            )
    return judged(
        "inertia_plausible",
        "model",
        f"lowest ratio {worst:.3g}",
        f"≥ {th['min_ratio']:g} of a solid of the geometry",
        hints,
        details=details,
        value=worst,
    )
