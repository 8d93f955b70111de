"""Each motor's command modes and limits → one custom text `control` the world reads.

A MuJoCo motor knows its force range (ctrlrange = forcerange = ±effort, or a PID's) but not
the joint's velocity limit, the modes its `<ros2_control>`/`<transmission>` tags allow, their
`min`/`max` bounds or their PID gains. The world needs them at command time to write the
actuator's gain, bias and force range (twin_cli.world.actuation), so they travel in the model as
one JSON text mapping each motor's joint to its record; attaching an entity prefixes the name
(`<entity>/control`) like any element. One text per model, not one per motor: deleting an
element from a world spec costs MuJoCo a pass over the whole world (~23 ms with 50 humanoids),
so a delete's cost would otherwise grow with the robot's motor count.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from converters.control_text import set_control_record
from converters.description import MODES, Joint, JointControl, RobotDescription, is_control_plugin
from converters.report import Report

if TYPE_CHECKING:
    import mujoco


def control_record(joint: Joint, control: JointControl | None, enabled: str | None) -> dict:
    """The JSON-able record of one motor's modes, bounds, gains and velocity limit."""
    velocity = joint.limit.velocity if joint.limit else None
    if control is None or not control.interfaces:
        return {"modes": list(MODES), "source": "default", "velocity_limit": velocity}
    bounds = {
        i.mode: [i.minimum, i.maximum]
        for i in control.interfaces
        if i.minimum is not None or i.maximum is not None
    }
    gains = {mode: [g.kp, g.ki, g.kd] for mode, g in control.gains}
    return {
        "modes": list(control.modes),
        "source": control.source,
        "where": control.where,
        "bounds": bounds,
        "pid": gains,
        "velocity_limit": velocity,
        "plugin": enabled,
    }


def add_control_data(
    spec: mujoco.MjSpec,
    joints: list[Joint],
    motors: set[str],
    robot: RobotDescription,
    report: Report,
) -> None:
    """Each motor's record in the `control` text, and report lines saying which modes each
    joint offers and which rule applies: one line per group of joints whose lines would read
    the same (a Panda's seven arm joints are one line, not seven)."""
    controls = {c.joint: c for c in robot.controls}
    plugins = [p.kind for p in robot.gazebo.plugins if is_control_plugin(p.kind)]
    enabled = plugins[0] if plugins else None
    groups: dict[str, list[str]] = {}
    ignored: dict[tuple[str, ...], list[str]] = {}
    for joint in joints:
        if joint.name not in motors:
            continue
        control = controls.get(joint.name)
        record = control_record(joint, control, enabled)
        set_control_record(spec, joint.name, record)
        groups.setdefault(_rule_text(record, control), []).append(joint.name)
        if control is not None and control.ignored:
            ignored.setdefault(control.ignored, []).append(joint.name)
    for text, names in groups.items():
        report.mapped(f"{_joints_text(names)} command modes", text)
    for interfaces, names in ignored.items():
        report.ignored(
            f"{_joints_text(names)} interfaces {', '.join(interfaces)}",
            "not a command interface twin drives (position, velocity and effort are)",
        )


def _joints_text(names: list[str]) -> str:
    quoted = ", ".join(f"'{name}'" for name in names)
    return f"joint {quoted}" if len(names) == 1 else f"{len(names)} joints {quoted}"


def _rule_text(record: dict, control: JointControl | None) -> str:
    modes = ", ".join(_mode_text(mode, record.get("bounds", {})) for mode in record["modes"])
    if record["source"] == "default":
        why = "no control tag" if control is None else "its tags declare none twin drives"
        return f"{modes} ({why}); servo gains from the reflected inertia"
    gains = ", ".join(_pid_text(mode, g) for mode, g in record["pid"].items())
    rule = gains or "servo gains from the reflected inertia"
    plugin = record["plugin"] or "no gazebo_ros(2)_control plugin: Gazebo would not drive it"
    tags = " and ".join(f"<{kind}>" for kind in record["source"].split("+"))
    return f"{modes} from {tags}; {rule}; {plugin}"


def _pid_text(mode: str, gains: tuple) -> str:
    """A tag PID as twin runs it: a position PID's kp and kd; a velocity PID's p on the speed
    error (`export_servos._to_velocity_pid`); the gains it does not run named."""
    p, i, d = gains
    if mode == "velocity":
        unused = ", ".join(f"{k}={v:g}" for k, v in (("ki", i), ("kd", d)) if v)
        return f"velocity PID kp={p:g}" + (f" ({unused} not run)" if unused else "")
    return f"{mode} PID kp={p:g} kd={d:g}" + (f" (ki={i:g} not run)" if i else "")


def _mode_text(mode: str, bounds: dict) -> str:
    low, high = bounds.get(mode, (None, None))
    if low is None and high is None:
        return mode
    low_text = "-inf" if low is None else f"{low:g}"
    high_text = "inf" if high is None else f"{high:g}"
    return f"{mode} (min/max [{low_text}, {high_text}] declared, not applied by Gazebo's hardware)"
