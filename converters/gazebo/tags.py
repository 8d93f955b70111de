"""Reading `<gazebo>` values: text or `value=` attribute, typed readers, the tag tables."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from collections.abc import Callable
from typing import Any

from converters.errors import GazeboTagError

TRUE_WORDS = frozenset({"true", "yes", "1"})
FALSE_WORDS = frozenset({"false", "no", "0"})


class ValueContext:
    """Facts for error messages while reading one block."""

    def __init__(self, source: str, reference: str) -> None:
        self.source = source
        self.reference = reference

    def fail(self, tag: str, value: str, expected: str) -> GazeboTagError:
        return GazeboTagError(self.source, self.reference, tag, value, expected)


def text_of(el: ET.Element) -> str:
    value = el.get("value")
    return (value if value is not None else (el.text or "")).strip()


def read_float(ctx: ValueContext, tag: str, raw: str) -> float:
    """A finite number (nan and ±inf are not physical values)."""
    try:
        value = float(raw)
    except ValueError as exc:
        raise ctx.fail(tag, raw, "a number") from exc
    if not math.isfinite(value):
        raise ctx.fail(tag, raw, "a number")
    return value


def read_positive(ctx: ValueContext, tag: str, raw: str) -> float:
    """A finite number > 0: a contact stiffness of 0 would let bodies fall through."""
    value = read_float(ctx, tag, raw)
    if value <= 0:
        raise ctx.fail(tag, raw, "a number > 0")
    return value


def read_magnitude(ctx: ValueContext, tag: str, raw: str) -> float:
    """A finite number ≥ 0: friction coefficients, stiffness, damping, speeds, depths."""
    value = read_float(ctx, tag, raw)
    if value < 0:
        raise ctx.fail(tag, raw, "a number ≥ 0")
    return value


def read_int(ctx: ValueContext, tag: str, raw: str) -> int:
    try:
        return int(raw, 0) if raw.lower().startswith("0x") else int(float(raw))
    except ValueError as exc:
        raise ctx.fail(tag, raw, "an integer") from exc


def read_bool(ctx: ValueContext, tag: str, raw: str) -> bool:
    word = raw.lower()
    if word in TRUE_WORDS:
        return True
    if word in FALSE_WORDS:
        return False
    raise ctx.fail(tag, raw, "a boolean (true/false/1/0)")


def read_vec3(ctx: ValueContext, tag: str, raw: str) -> tuple[float, float, float]:
    parts = raw.split()
    if len(parts) != 3:
        raise ctx.fail(tag, raw, "three numbers")
    x, y, z = (read_float(ctx, tag, p) for p in parts)
    return (x, y, z)


def read_str(ctx: ValueContext, tag: str, raw: str) -> str:
    return raw


Reader = Callable[[ValueContext, str, str], Any]

# tag -> (group, field, reader). group "surface" = collision level, "link" = link level.
LINK_TAGS: dict[str, tuple[str, str, Reader]] = {
    "mu1": ("surface", "mu1", read_magnitude),
    "mu2": ("surface", "mu2", read_magnitude),
    "fdir1": ("surface", "fdir1", read_vec3),
    "kp": ("surface", "kp", read_positive),
    "kd": ("surface", "kd", read_magnitude),
    "maxVel": ("surface", "max_vel", read_magnitude),
    "minDepth": ("surface", "min_depth", read_magnitude),
    "maxContacts": ("surface", "max_contacts", read_int),
    "laserRetro": ("surface", "laser_retro", read_float),
    "selfCollide": ("link", "self_collide", read_bool),
    "self_collide": ("link", "self_collide", read_bool),
    "turnGravityOff": ("link", "turn_gravity_off", read_bool),
    "gravity": ("link", "gravity", read_bool),
    "dampingFactor": ("link", "damping_factor", read_magnitude),
    "material": ("link", "material", read_str),
}

JOINT_TAGS: dict[str, tuple[str, Reader]] = {
    "stopErp": ("stop_erp", read_float),
    "stopCfm": ("stop_cfm", read_float),
    "springStiffness": ("spring_stiffness", read_magnitude),
    "springReference": ("spring_reference", read_float),
    "fudgeFactor": ("fudge_factor", read_float),
    "provideFeedback": ("provide_feedback", read_bool),
    "implicitSpringDamper": ("implicit_spring_damper", read_bool),
    "cfmDamping": ("implicit_spring_damper", read_bool),
    "preserveFixedJoint": ("preserve_fixed_joint", read_bool),
    "disableFixedJointLumping": ("disable_fixed_joint_lumping", read_bool),
}

# Paths inside an SDF <surface> (or a <collision> block) -> (Surface field, reader).
SURFACE_PATHS: dict[str, tuple[str, Reader]] = {
    "surface/friction/ode/mu": ("mu1", read_magnitude),
    "surface/friction/ode/mu1": ("mu1", read_magnitude),
    "surface/friction/ode/mu2": ("mu2", read_magnitude),
    "surface/friction/ode/fdir1": ("fdir1", read_vec3),
    "surface/friction/torsional/coefficient": ("torsional", read_magnitude),
    "surface/contact/ode/kp": ("kp", read_positive),
    "surface/contact/ode/kd": ("kd", read_magnitude),
    "surface/contact/ode/max_vel": ("max_vel", read_magnitude),
    "surface/contact/ode/min_depth": ("min_depth", read_magnitude),
    "surface/contact/category_bitmask": ("category_bitmask", read_int),
    "surface/contact/collide_bitmask": ("collide_bitmask", read_int),
    "surface/bounce/restitution_coefficient": ("restitution", read_float),
    "max_contacts": ("max_contacts", read_int),
    "laser_retro": ("laser_retro", read_float),
}


def to_xml(el: Any) -> str:
    if isinstance(el, ET.Element):
        return ET.tostring(el, encoding="unicode").strip()
    from lxml import etree  # an lxml element: serialise with its own library

    return etree.tostring(el, encoding="unicode").strip()


def children_of(el: ET.Element) -> list[ET.Element]:
    """Element children only (lxml also yields comments and processing instructions)."""
    return [c for c in el if isinstance(c.tag, str)]
