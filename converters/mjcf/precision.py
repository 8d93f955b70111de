"""Full-precision numbers in written MJCF: MuJoCo's `to_xml` rounds to 6 significant digits.

solo12's base mass 1.16115091 kg came out as 1.16115 (the written model's total mass off by
1.8e-6 relative). Each numeric attribute of a named element is written again from the spec
value it came from, as the shortest text that reads back as the same double. A value is only
replaced when the rounded text and the spec value agree to the rounding, so an attribute that
maps to something else is left exactly as MuJoCo wrote it.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    import mujoco

# Spec attribute names where the XML attribute name differs, by (element tag, attribute).
ALIASES = {
    ("inertial", "pos"): "ipos",
    ("inertial", "quat"): "iquat",
    ("inertial", "diaginertia"): "inertia",
    ("joint", "solreflimit"): "solref_limit",
    ("joint", "solimplimit"): "solimp_limit",
    ("joint", "solreffriction"): "solref_friction",
    ("joint", "solimpfriction"): "solimp_friction",
}
# Element tags and the spec lookup that finds their object by name.
FINDERS = {
    "body": "body",
    "geom": "geom",
    "joint": "joint",
    "freejoint": "joint",
    "site": "site",
    "mesh": "mesh",
    "key": "key",
    "motor": "actuator",
    "position": "actuator",
    "velocity": "actuator",
    "general": "actuator",
    "equality": "equality",
    "light": "light",
}
# Relative agreement that proves a written number is the rounding of a spec value (6 digits).
ROUNDING = 5e-6
# Below this (relative to 1 or to its vector's largest component, at 1e-6) MuJoCo may write
# 0: 6e-17 from a rotated frame is such a zero.
TINY = 1e-10


def restore_precision(xml: str, spec: mujoco.MjSpec) -> str:
    """`xml` (from `spec.to_xml()`) with every recognised number at full double precision."""
    from lxml import etree

    # Keep CDATA: MuJoCo writes custom <text> data as a CDATA section and reads no plain text.
    root = etree.fromstring(xml.encode(), etree.XMLParser(strip_cdata=False))
    for element in root.iter():
        if not isinstance(element.tag, str):
            continue
        target = _spec_object(spec, element)
        if target is not None:
            _rewrite(element, target)
    return etree.tostring(root, encoding="unicode") + "\n"


def _spec_object(spec: mujoco.MjSpec, element: Any) -> object | None:
    if element.tag == "inertial":
        parent = element.getparent()
        return _find(spec, "body", parent.get("name")) if parent is not None else None
    kind = FINDERS.get(element.tag)
    if kind is None and element.getparent() is not None and element.getparent().tag == "equality":
        kind = "equality"
    return _find(spec, kind, element.get("name")) if kind else None


def _find(spec: mujoco.MjSpec, kind: str, name: str | None) -> object | None:
    if not name:
        return None
    try:
        return getattr(spec, kind)(name)
    except (TypeError, ValueError, KeyError):
        return None


def _rewrite(element: Any, target: object) -> None:
    for attribute, text in element.attrib.items():
        name = ALIASES.get((element.tag, attribute)) or attribute
        if name == "name" or not hasattr(target, name):
            continue
        written = _numbers(text)
        exact, single = _values(getattr(target, name))
        if written is None or exact is None or len(written) > len(exact):
            continue
        exact = exact[: len(written)]
        scale = max(abs(e) for e in exact) if exact else 0.0
        if all(_rounds_to(w, e, scale) for w, e in zip(written, exact, strict=True)):
            element.set(attribute, " ".join(_shortest(v, single) for v in exact))


def _numbers(text: str) -> list[float] | None:
    try:
        return [float(v) for v in text.split()]
    except ValueError:
        return None


def _values(value: Any) -> tuple[list[float] | None, bool]:
    """The numbers of a spec value, and whether the spec stores them as float32 (colours)."""
    if isinstance(value, bool) or isinstance(value, str):
        return None, False
    if isinstance(value, int | float):
        return [float(value)], False
    try:
        single = getattr(value, "dtype", None) is not None and value.dtype.itemsize == 4
        return [float(v) for v in value], single
    except (TypeError, ValueError):
        return None, False


def _rounds_to(written: float, exact: float, scale: float) -> bool:
    """True when `written` is `exact` rounded to 6 digits; MuJoCo writes a component that is
    tiny beside the others of its vector (7e-14 in a unit quaternion) as 0."""
    return abs(written - exact) <= ROUNDING * max(abs(exact), TINY * max(scale, 1.0), 1e-6 * scale)


def _shortest(value: float, single: bool = False) -> str:
    """The shortest decimal text that reads back as exactly `value` (no trailing `.0`); for a
    float32 field, the shortest that reads back as the same float32."""
    if single:
        import numpy as np

        text = repr(float(str(np.float32(value))))
    else:
        text = repr(float(value))
    return text[:-2] if text.endswith(".0") else text
