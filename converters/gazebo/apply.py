"""Apply Gazebo extensions (and Gazebo's defaults) to a built robot MjSpec, reporting each tag.

Called by the converter core after every body, joint and geom exists. Surface tags act on the
collision geoms that came from the tagged link (also after lumping, through provenance), the
collision bitmasks as contype/conaffinity (`collide_bits`); link-level tags (gravity,
selfCollide, dampingFactor as joint damping, `damping`) act on the body that carries the link.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from converters.description.gazebo import GazeboExtensions, LinkExtension, Surface
from converters.gazebo import collide_bits, damping
from converters.gazebo.contact import (
    CONTACT_MU_MAX,
    DEFAULT_MU,
    ContactSoftness,
    contact_mu,
    contact_softness,
    friction_priority,
)
from converters.gazebo.friction_pairs import mark_anisotropic_surfaces
from converters.gazebo.joints import apply_joint_tags, report_blobs
from converters.gazebo.materials import gazebo_rgba
from converters.provenance import GeomOrigin, Provenance
from converters.report import Report

if TYPE_CHECKING:
    import mujoco

IGNORED_SURFACE = {  # Surface field -> (Gazebo tag, why MuJoCo does without it)
    "max_vel": ("maxVel", "MuJoCo has no cap on penetration-correction speed; solref sets it"),
    "max_contacts": ("maxContacts", "MuJoCo has no per-geom contact cap"),
    "laser_retro": ("laserRetro", "twin's ray sensors report ranges, not intensities; not used"),
    "restitution": ("restitution_coefficient", "no restitution in MuJoCo; kp/kd set bounce"),
}


@dataclass(frozen=True)
class BodyFlags:
    """Link-level Gazebo values merged onto one body (a body can carry lumped links)."""

    body: str
    links: tuple[str, ...]
    self_collide: bool
    feels_gravity: bool
    damping_factor: float | None


def apply_gazebo(
    spec: mujoco.MjSpec, ext: GazeboExtensions, provenance: Provenance, report: Report
) -> None:
    """Give a robot spec Gazebo's contact, collision, gravity and joint semantics.

    Args:
        spec: the robot's `mujoco.MjSpec`, bodies named after links, geoms listed in provenance.
        ext: the parsed `<gazebo>` extensions of the robot.
        provenance: which link/body each geom came from, which body carries each link.
        report: receives one entry per tag (mapped, approximated, ignored) and each warning.
    """
    masses = _BodyMasses(spec)
    for geom in provenance.geoms:
        if geom.role == "collision":
            _apply_surface(spec, geom, ext.surface_of(geom.link, geom.index), masses, report)
    _report_surfaces(ext, provenance, report)
    mark_anisotropic_surfaces(spec, ext, provenance, report)
    _apply_visuals(spec, ext, provenance, report)
    flags = body_flags(spec, ext, provenance)
    _apply_body_flags(spec, flags, masses, report)
    add_self_collision_excludes(spec, provenance, flags, model_self_collide=ext.self_collide)
    apply_joint_tags(spec, ext, provenance, report)
    report_blobs(ext, report)


class _BodyMasses:
    """Body masses [kg]: the spec's explicit mass, else the compiled model's (compiled once)."""

    def __init__(self, spec: mujoco.MjSpec) -> None:
        self.spec = spec
        self.model: mujoco.MjModel | None = None

    def of(self, body: str) -> float:
        mass = float(self.spec.body(body).mass)
        if mass > 0:
            return mass
        model = self.compiled()
        # the core reports uncompilable specs; 0 kg clamps to stiffest
        return 0.0 if model is None else float(model.body(body).mass[0])

    def compiled(self) -> mujoco.MjModel | None:
        """The spec compiled once (masses and inertias), or None if it does not compile."""
        if self.model is None:
            try:
                self.model = self.spec.copy().compile()
            except ValueError:
                return None
        return self.model


def _apply_surface(
    spec: mujoco.MjSpec, origin: GeomOrigin, surface: Surface, masses: _BodyMasses, report: Report
) -> None:
    geom = spec.geom(origin.geom)
    if geom is None:
        return
    mu = contact_mu(DEFAULT_MU if surface.mu1 is None else surface.mu1)
    friction = list(geom.friction)
    friction[0] = mu
    if surface.torsional is not None:
        friction[1] = surface.torsional
        geom.condim = max(int(geom.condim), 4)
    geom.friction = np.array(friction)
    geom.priority = friction_priority(mu)
    if mu <= 0.0:  # Gazebo's μ 0 is frictionless; a zero-width friction cone is singular
        geom.condim = 1
    if surface.declares_bitmask:  # `collide_bits` runs only for a surface that has one
        bits = collide_bits.collide_bits(surface.category_bitmask, surface.collide_bitmask)
        assert bits is not None
        geom.contype, geom.conaffinity = bits.contype, bits.conaffinity
    # Untagged surfaces get SDF's defaults (kp 1e12, kd 1): rigid, i.e. the stiffest S the
    # step resolves. MuJoCo's own default (solref 0.02 s) let ABB's wrist sink 23 mm.
    softness = contact_softness(surface.kp, surface.kd, masses.of(origin.body))
    geom.solref = np.array(softness.solref)
    geom.solimp = np.array(softness.solimp)
    if surface.kp is not None or surface.kd is not None:
        _report_softness(origin, surface, softness, masses.of(origin.body), report)


def _report_softness(
    origin: GeomOrigin,
    surface: Surface,
    softness: ContactSoftness,
    mass: float,
    report: Report,
) -> None:
    subject = f"link '{origin.link}' geom '{origin.geom}'"
    figures = (
        f"kp={surface.kp} N/m, kd={surface.kd} N s/m on body '{origin.body}' ({mass:.4g} kg): "
        f"solref={softness.solref[0]:.6g} {softness.solref[1]:.6g}; rest sinkage "
        f"{softness.sinkage * 1e3:.4g} mm (Gazebo {softness.sinkage_gazebo * 1e3:.4g} mm)"
    )
    if softness.clamped:
        report.approximated(
            subject,
            figures + "; stiffer than MuJoCo's rigid contact reproduces: clamped (sinks microns)",
            tag="kp",
        )
    elif softness.damping_ratio > softness.damping_ratio_gazebo * 1.001:
        report.approximated(
            subject,
            figures + f"; damping ratio {softness.damping_ratio_gazebo:.3g} raised to "
            f"{softness.damping_ratio:.3g}: ODE's velocity-level contact neither rings nor "
            "bounces (docs/contacts.md)",
            tag="kd",
        )
    else:
        report.mapped(subject, figures, tag="kp")


def _report_surfaces(ext: GazeboExtensions, provenance: Provenance, report: Report) -> None:
    for link, link_ext in ext.links.items():
        if link not in ext.unresolved and not link_ext.surface.is_empty():
            _report_surface(f"link '{link}'", link_ext.surface, report)
    for inline in ext.inline_surfaces:
        _report_surface(f"link '{inline.link}' collision {inline.index}", inline.surface, report)
    _report_gazebo_drops(ext, report)
    untagged = sum(
        1
        for g in provenance.geoms
        if g.role == "collision" and ext.surface_of(g.link, g.index).mu1 is None
    )
    report.mapped(
        "collision geoms",
        f"Gazebo default μ={DEFAULT_MU} (priority {friction_priority(DEFAULT_MU)}) on "
        f"{untagged} collision geoms without μ1",
        tag="mu1",
    )


def _report_surface(subject: str, surface: Surface, report: Report) -> None:
    """One report line per surface value: mapped, approximated or ignored, with the reason."""
    if surface.mu1 is not None and contact_mu(surface.mu1) < surface.mu1:
        report.approximated(
            subject,
            f"μ1={surface.mu1:g} → {CONTACT_MU_MAX:g}: in MuJoCo a larger μ lets the contact "
            f"sink (wheels to their axles at μ 100); μ {CONTACT_MU_MAX:g} already holds on a "
            "63° slope",
            tag="mu1",
        )
    elif surface.mu1 is not None:
        report.mapped(subject, f"μ1={surface.mu1}: friction, min-μ priority", tag="mu1")
    if surface.min_depth is not None:
        report.ignored(
            subject,
            f"minDepth={surface.min_depth} m: MuJoCo corrects any penetration (as 0)",
            tag="minDepth",
        )
    _report_bitmasks(subject, surface, report)
    _report_ignored_surface(subject, surface, report)


def _report_bitmasks(subject: str, surface: Surface, report: Report) -> None:
    if not surface.declares_bitmask:
        return
    bits = collide_bits.collide_bits(surface.category_bitmask, surface.collide_bitmask)
    assert bits is not None
    text = collide_bits.describe(bits)
    classic = surface.category_bitmask is not None and bits.category != bits.collide
    if classic:
        text += "; Gazebo Classic (ODE) ignores category_bitmask and tests collide & collide"
    tag = "category_bitmask" if surface.collide_bitmask is None else "collide_bitmask"
    if classic or bits.dropped:
        report.approximated(subject, text, tag=tag)
    else:
        report.mapped(subject, text, tag=tag)


def _report_gazebo_drops(ext: GazeboExtensions, report: Report) -> None:
    """What Gazebo's URDF parser leaves out, left out here too (see GazeboExtensions)."""
    for dropped in ext.dropped_surfaces:
        report.ignored(
            f"link '{dropped.link}' collision {dropped.index} <surface>",
            "Gazebo's URDF parser (sdformat) ignores a <surface> inside a URDF <collision>, so "
            "Gazebo simulates μ 1, kp 1e12 there; write it in <gazebo reference='"
            f"{dropped.link}'><collision>, or convert with --as-written to apply it",
            tag="surface",
        )
    for link, index in sorted(ext.named_collisions):
        if ext.link(link).surface.is_empty():
            continue
        report.ignored(
            f"link '{link}' collision {index}",
            "has a name attribute, so Gazebo gives it none of the link's <gazebo> surface values "
            "(sdformat issue 333); remove the name, or convert with --as-written to apply them",
            tag="surface",
        )


def _report_ignored_surface(subject: str, surface: Surface, report: Report) -> None:
    for name, (tag, reason) in IGNORED_SURFACE.items():
        value = getattr(surface, name)
        if value is not None:
            report.ignored(subject, f"{tag}={value}: {reason}", tag=tag)


def _apply_visuals(
    spec: mujoco.MjSpec, ext: GazeboExtensions, provenance: Provenance, report: Report
) -> None:
    for link, link_ext in ext.links.items():
        if link in ext.unresolved:
            continue
        rgba = link_ext.visual_rgba
        if link_ext.material is not None and rgba is None:
            rgba = gazebo_rgba(link_ext.material)
            if rgba is None:
                report.warn(
                    f"link '{link}'",
                    f"unknown Gazebo material '{link_ext.material}'; URDF colour kept",
                    tag="material",
                )
                continue
        if rgba is None:
            continue
        for origin in provenance.geoms_of_link(link, role="visual"):
            geom = spec.geom(origin.geom)
            if geom is not None:
                geom.rgba = np.array(rgba)
                geom.material = ""  # a Gazebo material replaces the URDF one, as in sdformat
        report.mapped(f"link '{link}'", f"visual colour rgba={rgba}", tag="material")


def body_flags(
    spec: mujoco.MjSpec, ext: GazeboExtensions, provenance: Provenance
) -> dict[str, BodyFlags]:
    """Merge the link-level tags of every link onto the body that carries it.

    sdformat moves the extensions of a lumped link to its parent, so a link-level tag of any
    link carried by a body applies to the whole body (gravity off if any link turns it off,
    self-collision if any link enables it, the largest dampingFactor).

    Returns:
        Flags for every body that carries at least one tagged link.
    """
    grouped: dict[str, list[LinkExtension]] = {}
    for link, link_ext in ext.links.items():
        body = provenance.body_of_link.get(link, link)
        if link not in ext.unresolved and spec.body(body) is not None:
            grouped.setdefault(body, []).append(link_ext)
    flags = {}
    for body, exts in grouped.items():
        factors = [e.damping_factor for e in exts if e.damping_factor is not None]
        flags[body] = BodyFlags(
            body=body,
            links=tuple(e.link for e in exts),
            self_collide=any(e.self_collide for e in exts),
            feels_gravity=all(e.feels_gravity for e in exts),
            damping_factor=max(factors) if factors else None,
        )
    return flags


def _apply_body_flags(
    spec: mujoco.MjSpec, flags: dict[str, BodyFlags], masses: _BodyMasses, report: Report
) -> None:
    for flag in flags.values():
        subject = f"body '{flag.body}' (links {', '.join(flag.links)})"
        if not flag.feels_gravity:
            spec.body(flag.body).gravcomp = 1.0
            report.mapped(subject, "gravity off: gravcomp=1 cancels its weight", tag="gravity")
        if flag.damping_factor is not None:
            _apply_damping_factor(spec, flag.body, flag.damping_factor, masses, subject, report)
        if flag.self_collide:
            report.mapped(
                subject, "selfCollide: collides with the robot's other links", tag="selfCollide"
            )


def _apply_damping_factor(
    spec: mujoco.MjSpec,
    body: str,
    fraction: float,
    masses: _BodyMasses,
    subject: str,
    report: Report,
) -> None:
    """Adds `dampingFactor` to the damping of the body's own joints (`damping`)."""
    model = masses.compiled()
    if model is None:
        return
    joints = damping.body_joint_damping(model, body, fraction)
    for j in joints:
        joint = spec.joint(j.joint)
        if joint is not None:
            joint.damping = joint.damping + np.array([j.damping, 0.0, 0.0])
    text, approximated = damping.describe(fraction, joints)
    (report.approximated if approximated else report.mapped)(subject, text, tag="dampingFactor")


def add_self_collision_excludes(
    spec: mujoco.MjSpec,
    provenance: Provenance,
    flags: dict[str, BodyFlags],
    model_self_collide: bool,
) -> int:
    """Gazebo's self-collision rule as `<exclude>` pairs between the robot's bodies.

    Two bodies of one model collide only when either has selfCollide (or the model has
    `<self_collide>`); bodies joined by a joint (parent and child) never collide. Excludes name
    bodies, so they survive `attach` prefixes and leave contacts with other entities alone.

    Returns:
        The number of excludes added.
    """
    bodies = sorted({g.body for g in provenance.geoms if g.role == "collision"})
    bodies = [b for b in bodies if spec.body(b) is not None and b != "world"]
    added = 0
    for i, first in enumerate(bodies):
        for second in bodies[i + 1 :]:
            if not _may_collide(spec, first, second, flags, model_self_collide):
                spec.add_exclude(bodyname1=first, bodyname2=second)
                added += 1
    return added


def _may_collide(
    spec: mujoco.MjSpec,
    first: str,
    second: str,
    flags: dict[str, BodyFlags],
    model_self_collide: bool,
) -> bool:
    if _parent_name(spec, first) == second or _parent_name(spec, second) == first:
        return False
    wants = [model_self_collide, *(f.self_collide for b in (first, second) if (f := flags.get(b)))]
    return any(wants)


def _parent_name(spec: mujoco.MjSpec, body: str) -> str | None:
    parent = spec.body(body).parent
    return None if parent is None else parent.name
