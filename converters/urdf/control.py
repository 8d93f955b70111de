"""`<ros2_control>` joints and `<transmission>` hardware interfaces → description.JointControl.

ros2_control (hardware_interface's component parser, gazebo_ros2_control's GazeboSystem): each
`<joint>` of a `<ros2_control>` block lists `<command_interface name=...>` elements, optionally
with `<param name="min">`/`<param name="max">`; `position_pid`/`velocity_pid` interfaces take their
gains from the joint's `pos_kp`/`pos_ki`/`pos_kd` (`vel_*`) params. A ROS 1 `<transmission>` names
a `<hardwareInterface>` per joint (or, deprecated, on its `<actuator>`), written with or without
the `hardware_interface/` prefix. Interfaces twin cannot drive (acceleration, gpio...) are kept
by name so the builder can report them.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET

from converters.description import (
    HARDWARE_INTERFACES,
    MODES,
    CommandInterface,
    JointControl,
    PidGains,
    merge_controls,
)
from converters.errors import URDFStructureError

# `*_pid` interface → (mode, prefix of its gain params on the joint) (gazebo_system.hpp).
PID_INTERFACES = {"position_pid": ("position", "pos_"), "velocity_pid": ("velocity", "vel_")}


def read_controls(root: ET.Element, source: str) -> tuple[JointControl, ...]:
    """Every joint's declared command interfaces, all of them: `<ros2_control>` first, then
    transmissions, merged per joint (`merge_controls`), since a joint may be named by several
    transmissions and by both tags.

    Raises:
        URDFStructureError: a `min`/`max`/gain param that is not a number.
    """
    declared: dict[str, list[JointControl]] = {}
    for block in root.iter("ros2_control"):
        where = f"<ros2_control name='{block.get('name', '')}'>"
        for joint in block.findall("joint"):
            control = _ros2_joint(joint, where, source)
            declared.setdefault(control.joint, []).append(control)
    for block in root.iter("transmission"):
        where = f"<transmission name='{block.get('name', '')}'>"
        for control in _transmission(block, where):
            declared.setdefault(control.joint, []).append(control)
    return tuple(merge_controls(parts) for parts in declared.values())


def _number(value: str | None, source: str, subject: str) -> float | None:
    if value is None:
        return None
    try:
        number = float(value)
    except ValueError:
        number = math.nan
    if math.isnan(number):
        raise URDFStructureError(
            source, subject, f"{value.strip()!r} is not a number", "write a decimal number"
        )
    return number


def _params(element: ET.Element) -> dict[str, str]:
    return {p.get("name", ""): (p.text or "").strip() for p in element.findall("param")}


def _ros2_joint(joint: ET.Element, where: str, source: str) -> JointControl:
    name = joint.get("name", "")
    subject = f"{where} joint '{name}'"
    interfaces, gains, ignored = [], [], []
    for element in joint.findall("command_interface"):
        kind = element.get("name", "")
        params = _params(element)
        low = _number(params.get("min"), source, f"{subject} <command_interface {kind}> min")
        high = _number(params.get("max"), source, f"{subject} <command_interface {kind}> max")
        if kind in PID_INTERFACES:
            mode, prefix = PID_INTERFACES[kind]
            interfaces.append(CommandInterface(mode, low, high, pid=True))
            gains.append((mode, _gains(_params(joint), prefix, source, subject)))
        elif kind in MODES:
            interfaces.append(CommandInterface(kind, low, high))
        else:
            ignored.append(kind)
    return JointControl(
        name, "ros2_control", tuple(interfaces), tuple(gains), where, tuple(ignored)
    )


def _gains(params: dict[str, str], prefix: str, source: str, subject: str) -> PidGains:
    values = {
        k: _number(params.get(prefix + k), source, f"{subject} param {prefix}{k}") or 0.0
        for k in ("kp", "ki", "kd")
    }
    return PidGains(**values)


def _transmission(block: ET.Element, where: str) -> list[JointControl]:
    actuator = [(h.text or "").strip() for h in block.iter("hardwareInterface")]
    out = []
    for joint in block.findall("joint"):
        named = [(h.text or "").strip() for h in joint.findall("hardwareInterface")]
        modes = {h: _mode(h) for h in (named or actuator)}
        interfaces = tuple(
            CommandInterface(m) for m in dict.fromkeys(m for m in modes.values() if m)
        )
        ignored = tuple(h for h, m in modes.items() if m is None and h)
        name = joint.get("name", "")
        out.append(JointControl(name, "transmission", interfaces, (), where, ignored))
    return out


def _mode(interface: str) -> str | None:
    """`hardware_interface/PositionJointInterface` (or `position`) → "position"; else None."""
    short = interface.rsplit("/", 1)[-1]
    return HARDWARE_INTERFACES.get(short) or (short if short in MODES else None)
