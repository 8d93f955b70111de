"""Gazebo's two friction coefficients (`mu1`, `mu2`) as MuJoCo contact pairs with the world.

Gazebo's rule (Gazebo Classic `ODEPhysics::Collide`, ODE `dxJointContact::getInfo2`): a contact
gets μ = min(mu of the two surfaces) along a first friction direction t1 and μ2 = min(mu2 of the
two) along t2 = n × t1, each bounded on its own (ODE's friction pyramid, `dContactApprox1`).
t1 is `fdir1` of the first collision of the pair rotated into the world by that collision's
pose (`fdir1` of the second is read but never used), else ODE's `dPlaneSpace(n)`: for a normal
n with |n_z| > √½ the unit vector ⟂ n in the y-z plane, so on a flat ground t1 = ±world y and
t2 = ±world x whatever the body's heading. SDF's default for an unset `mu2` is 1, as for `mu`.

MuJoCo's geom has one sliding coefficient for both tangents; a `<pair>` has two, applied along
the rows 1 and 2 of the contact frame. For a plane against a sphere, ellipsoid, box, cylinder
or mesh, MuJoCo builds that frame from the normal alone (`mju_makeFrame`: row 1 = world y made
⟂ n), measured: t1 = world y, t2 = world x on a flat ground for any heading and wheel angle —
Gazebo's default directions. A capsule's row 1 follows its axis instead. So:
  - no `fdir1`, μ1 ≠ μ2, a collider whose frame is built from the normal: explicit pairs with
    the world body's geoms, friction (μ1, μ2), exact on a ground plane (and on one tilted about a
    world axis, where `dPlaneSpace` and `mju_makeFrame` agree);
  - `fdir1` along the axis of a cylinder, capsule or round ellipsoid (a wheel's axle): the same
    pairs, made by a capsule on that axis, whose plane frame follows it (`friction_axis`);
  - any other `fdir1` (a direction that turns with the link), or a capsule without one: no
    MuJoCo frame follows it, so μ1 stays isotropic and the report says "approximated", naming
    μ1, μ2 and `fdir1`.

Explicit pairs come on top of MuJoCo's own contacts, so the body's contacts with the world body
are excluded and every colliding geom of the body gets its pair with every colliding geom of
the world body (the min-μ rule written out). The robot spec carries a custom numeric per
anisotropic geom; `add_friction_pairs` builds the pairs on the world spec before each compile,
named after the entity, so deleting the entity deletes them.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from converters.gazebo.contact import DEFAULT_MU, contact_mu
from converters.gazebo.friction_axis import along_axis, axis_capsule, stands_for

if TYPE_CHECKING:
    import mujoco

    from converters.description.gazebo import GazeboExtensions, Surface
    from converters.provenance import GeomOrigin, Provenance
    from converters.report import Report

ANISOTROPIC_PREFIX = "anisotropic_friction:"
"""Custom numeric `anisotropic_friction:<geom>` = (μ1, μ2) of a geom the world pairs."""
PAIR_MARK = "friction_pair:"
"""In the name of every pair and exclude `add_friction_pairs` makes (after the entity prefix)."""
DEFAULT_MU2 = 1.0
"""SDF default for `surface/friction/ode/mu2` (`sdf/1.11/surface.sdf`)."""
SAME_MU = 1e-9
"""μ1 and μ2 closer than this are one isotropic μ."""
FRAME_FROM_NORMAL = ("sphere", "ellipsoid", "box", "cylinder", "mesh", "sdf")
"""Geom types whose contact with a plane has MuJoCo's frame from the normal (measured)."""


def mark_anisotropic_surfaces(
    spec: mujoco.MjSpec, ext: GazeboExtensions, provenance: Provenance, report: Report
) -> None:
    """Marks each collision geom with μ1 ≠ μ2 and no `fdir1` for pairs; reports every case.

    A surface that sets `mu1` alone has SDF's default μ2 = 1 in Gazebo, so it is anisotropic
    unless its μ1 is 1 (as it is for a `mu2` alone, with μ1 = 1).

    Args:
        spec: the robot spec (geoms named as in provenance).
        ext: the robot's Gazebo extensions; provenance: where each geom came from.
        report: one line per tagged geom: mapped (pairs) or approximated (isotropic μ1).
    """
    for origin in provenance.geoms:
        if origin.role != "collision":
            continue
        surface = ext.surface_of(origin.link, origin.index)
        geom = spec.geom(origin.geom)
        tagged = (surface.mu1, surface.mu2, surface.fdir1) != (None, None, None)
        if geom is not None and tagged:
            _mark(spec, geom, origin, surface, report)


def _mark(
    spec: mujoco.MjSpec,
    geom: mujoco.MjsGeom,
    origin: GeomOrigin,
    surface: Surface,
    report: Report,
) -> None:
    mu1 = contact_mu(DEFAULT_MU if surface.mu1 is None else surface.mu1)
    mu2 = contact_mu(DEFAULT_MU2 if surface.mu2 is None else surface.mu2)
    subject = f"link '{origin.link}' geom '{origin.geom}'"
    fdir1 = surface.fdir1 if surface.fdir1 is not None and any(surface.fdir1) else None
    if abs(mu1 - mu2) <= SAME_MU:
        if fdir1 is not None:
            report.mapped(subject, f"fdir1={fdir1}: μ1 = μ2 = {mu1:g}, no direction", tag="fdir1")
        return
    kind = _type_name(geom)
    if fdir1 is not None and along_axis(geom, fdir1) and min(mu1, mu2) > 0.0:
        capsule = axis_capsule(spec, geom)
        spec.add_numeric(name=f"{ANISOTROPIC_PREFIX}{capsule}", data=[mu1, mu2], size=2)
        report.mapped(
            subject,
            f"μ1={mu1:g} along fdir1={fdir1} (the {kind}'s axis), μ2={mu2:g} across it, turning "
            f"with the link as in Gazebo: contact pairs of the capsule '{capsule}' on that axis "
            f"with the world's geoms; contacts with other entities use μ1={mu1:g}",
            tag="mu2",
        )
        return
    why = _why_isotropic(kind, fdir1, min(mu1, mu2))
    if why:
        report.approximated(
            subject,
            f"μ1={mu1:g}, μ2={mu2:g}: {why}; twin uses μ1={mu1:g} in every direction "
            "(docs/contacts.md)",
            tag="mu2",
        )
        return
    spec.add_numeric(name=f"{ANISOTROPIC_PREFIX}{origin.geom}", data=[mu1, mu2], size=2)
    unset = " (SDF's default, mu2 unset)" if surface.mu2 is None else ""
    report.mapped(
        subject,
        f"μ1={mu1:g} along world y, μ2={mu2:g}{unset} along world x on the ground (Gazebo's "
        "directions without fdir1): contact pairs with the world's geoms; contacts with "
        f"other entities use μ1={mu1:g}",
        tag="mu2",
    )


def _why_isotropic(kind: str, fdir1: tuple[float, ...] | None, low_mu: float) -> str:
    """Why pairs cannot give this geom Gazebo's two directions ("" when they can)."""
    if fdir1 is not None:
        return (
            f"fdir1={fdir1} is not along the {kind}'s axis: it turns with the link as no MuJoCo "
            "contact frame does"
        )
    if kind not in FRAME_FROM_NORMAL:
        return f"a {kind}'s contact frame follows its axis, not Gazebo's world directions"
    if low_mu <= 0.0:
        return "one direction frictionless: MuJoCo's friction cone needs both μ > 0"
    return ""


def _type_name(geom: mujoco.MjsGeom) -> str:
    import mujoco

    return mujoco.mjtGeom(int(geom.type)).name.removeprefix("mjGEOM_").lower()


@dataclass(frozen=True)
class PairPlan:
    """One `<pair>`: names, Gazebo's min μ per direction, and the deciding geom's settings."""

    name: str
    geom1: str
    geom2: str
    friction: tuple[float, ...]
    condim: int
    solref: tuple[float, float]
    solimp: tuple[float, ...]
    margin: float
    gap: float


@dataclass(frozen=True)
class ExcludePlan:
    """One `<exclude>`: a marked body's own contacts with the world body."""

    name: str
    body1: str
    body2: str


def add_friction_pairs(spec: mujoco.MjSpec) -> int:
    """Rebuilds the pairs and excludes of every marked geom on a world spec (idempotent).

    Args:
        spec: a world spec with entities attached (their numerics, geoms and bodies prefixed
            alike, or none of them).

    Returns:
        The number of pairs made.
    """
    for element in list(spec.pairs) + list(spec.excludes):
        if PAIR_MARK in element.name:
            spec.delete(element)
    excludes, pairs = plan_pairs(spec, static_bodies(spec))
    for exclude in excludes:
        spec.add_exclude(name=exclude.name, bodyname1=exclude.body1, bodyname2=exclude.body2)
    for plan in pairs:
        pair = spec.add_pair(name=plan.name, geomname1=plan.geom1, geomname2=plan.geom2)
        pair.friction = np.array(plan.friction)
        pair.condim = plan.condim
        pair.solref = np.array(plan.solref)
        pair.solimp = np.array(plan.solimp)
        pair.margin, pair.gap = plan.margin, plan.gap
    return len(pairs)


def contact_xml(robot: mujoco.MjSpec, world_geoms: list[mujoco.MjsGeom]) -> str:
    """The `<contact>` block a scene that includes `robot` after `world_geoms` needs: the same
    pairs and excludes a World builds for it (empty when the robot marks no geom).

    Args:
        robot: the exported robot spec (unprefixed names, as its file has them).
        world_geoms: the scene's world-body geoms, in the scene's order (the ground).
    """
    excludes, pairs = plan_pairs(robot, static_bodies(robot), world_geoms, world="world")
    if not pairs:
        return ""
    lines = [
        f'    <exclude name="{e.name}" body1="{e.body1}" body2="{e.body2}"/>' for e in excludes
    ]
    lines += [
        f'    <pair name="{p.name}" geom1="{p.geom1}" geom2="{p.geom2}" condim="{p.condim}" '
        f'friction="{_numbers(p.friction)}" solref="{_numbers(p.solref)}" '
        f'solimp="{_numbers(p.solimp)}" margin="{p.margin!r}" gap="{p.gap!r}"/>'
        for p in pairs
    ]
    return "  <contact>\n" + "\n".join(lines) + "\n  </contact>\n"


def _numbers(values: Iterable[float]) -> str:
    """Floats as Python writes them: the shortest text that reads back to the same double."""
    return " ".join(repr(float(v)) for v in values)


def static_bodies(spec: mujoco.MjSpec) -> list[mujoco.MjsBody]:
    """The world body and every body welded to it (no joint on the way up, not mocap): a
    static SDF model's links, a fixed-base robot's root. MuJoCo moves none of them, so their
    geoms are the world's for contact."""
    out = [spec.worldbody]
    for body in spec.worldbody.find_all("body"):
        chain, welded = body, True
        while chain is not None and chain.name != spec.worldbody.name:
            if chain.mocap or any(True for _ in chain.joints):
                welded = False
                break
            chain = chain.parent
        if welded:
            out.append(body)
    return out


def plan_pairs(
    spec: mujoco.MjSpec,
    statics: list[mujoco.MjsBody],
    scene_geoms: list[mujoco.MjsGeom] | None = None,
    world: str | None = None,
) -> tuple[list[ExcludePlan], list[PairPlan]]:
    """The excludes and pairs for every marked geom of `spec` against the static geoms: those of
    the world body and of the bodies welded to it, but not the marked body's own entity's (its
    self-collision stays its own rule's).

    Args:
        spec: the spec holding the marks and the marked geoms' bodies.
        statics: `static_bodies(spec)`, the world body first. scene_geoms: geoms a scene file
            adds to the world body before the spec's (the ground). world: the world body's
            name in the file the plans are written to (default: the spec's).
    """
    marked = list(_marked(spec))
    excludes: list[ExcludePlan] = []
    pairs: list[PairPlan] = []
    done: set[str] = set()
    static_names = {b.name for b in statics}
    for prefix, geom, _ in marked:
        body = geom.parent
        if body.name in static_names or body.name in done:
            continue  # a static body's contacts with the world are no contacts at all
        done.add(body.name)
        mus = {g.name: m for _, g, m in marked if g.parent.name == body.name}
        others = [statics[0]] + [b for b in statics[1:] if prefix and not b.name.startswith(prefix)]
        world_geoms = list(scene_geoms or []) + [g for b in others for g in b.geoms]
        for i, static in enumerate(others):
            other = (world or static.name) if i == 0 else static.name
            tag = "" if i == 0 else f"@{static.name}"
            excludes.append(ExcludePlan(f"{prefix}{PAIR_MARK}{body.name}{tag}", other, body.name))
        for own, source in _contact_geoms(spec, body):
            for other in _colliding(world_geoms):
                if _filtered(source, other):
                    pairs.append(_pair(prefix, own, other, mus.get(own.name)))
    return excludes, pairs


def _contact_geoms(
    spec: mujoco.MjSpec, body: mujoco.MjsBody
) -> list[tuple[mujoco.MjsGeom, mujoco.MjsGeom]]:
    """(geom that touches the world, geom whose collision bits decide) for each of the body's
    colliding geoms: itself, or the axis capsule that stands for it (`friction_axis`)."""
    stand_ins = {}
    for geom in body.geoms:
        source = stands_for(spec, geom)
        if source is not None:
            stand_ins[source.name] = geom
    return [(stand_ins.get(g.name, g), g) for g in _colliding(body.geoms)]


def _marked(spec: mujoco.MjSpec) -> Iterable[tuple[str, mujoco.MjsGeom, tuple[float, float]]]:
    """(entity prefix, geom, (μ1, μ2)) of every marked geom the spec still has."""
    for numeric in spec.numerics:
        prefix, mark, name = numeric.name.partition(ANISOTROPIC_PREFIX)
        geom = spec.geom(prefix + name) if mark else None
        if geom is not None:
            yield prefix, geom, (float(numeric.data[0]), float(numeric.data[1]))


def _colliding(geoms: Iterable[mujoco.MjsGeom]) -> list[mujoco.MjsGeom]:
    return [g for g in geoms if int(g.contype) or int(g.conaffinity)]


def _filtered(a: mujoco.MjsGeom, b: mujoco.MjsGeom) -> bool:
    """MuJoCo's contype/conaffinity test: whether the two would collide without the exclude."""
    return bool((int(a.contype) & int(b.conaffinity)) or (int(b.contype) & int(a.conaffinity)))


def _pair(
    prefix: str, own: mujoco.MjsGeom, world: mujoco.MjsGeom, mus: tuple[float, float] | None
) -> PairPlan:
    """One pair: Gazebo's min μ per direction; the rest from the geom MuJoCo would let decide
    (the higher priority, the robot's on a tie), as without the pair."""
    mu1, mu2 = mus if mus is not None else (float(own.friction[0]),) * 2
    wmu = float(world.friction[0])
    ruler = world if int(world.priority) > int(own.priority) else own
    spin, roll = float(ruler.friction[1]), float(ruler.friction[2])
    return PairPlan(
        name=f"{prefix}{PAIR_MARK}{own.name}|{world.name}",
        geom1=world.name,
        geom2=own.name,
        friction=(min(mu1, wmu), min(mu2, wmu), spin, roll, roll),
        condim=int(ruler.condim),
        solref=(float(ruler.solref[0]), float(ruler.solref[1])),
        solimp=tuple(float(v) for v in ruler.solimp),
        margin=max(float(own.margin), float(world.margin)),
        gap=max(float(own.gap), float(world.gap)),
    )


def follow_geom_solrefs(model: mujoco.MjModel) -> None:
    """Gives each friction pair of a compiled model the solref its deciding geom has now.

    A world caps every geom's direct solref at its timestep, and uncaps it when the step
    shortens again; a pair holds a copy, so it must follow, or a longer step integrates it
    unstably (measured: a plate on a 4 ms step was thrown 11 m up by its uncapped pair).

    Args:
        model: a compiled model; `pair_solref` is changed in place.
    """
    for i in range(model.npair):
        if PAIR_MARK not in model.pair(i).name:
            continue
        g1, g2 = int(model.pair_geom1[i]), int(model.pair_geom2[i])
        ruler = g1 if model.geom_priority[g1] > model.geom_priority[g2] else g2
        model.pair_solref[i] = model.geom_solref[ruler]
