"""Vendor plugins that are differential drives under another name, read as gazebo_ros' diff drive.

Robot vendors ship their own base plugins (kobuki's `libgazebo_ros_kobuki.so` names
`<wheel_left_joint_name>`, `<wheel_right_joint_name>`, `<wheel_separation>`, `<wheel_diameter>`).
A plugin twin does not know is read as a diff drive when its parameters name a left and a right
wheel joint, a wheel separation and a wheel diameter or radius; every tag is reported, with the
meaning twin gave it or as ignored, so the approximation is visible tag by tag.
"""

from __future__ import annotations

from collections.abc import Callable

from converters.description.gazebo import Blob
from converters.gazebo.drive_notes import ROS_NOTE, ROS_TOPICS
from converters.gazebo.drive_records import DEFAULT_RATE, DEFAULT_TORQUE, DiffDrive
from converters.gazebo.plugin_params import Params

# (meaning, test on the lower-case tag); the first match wins, so order matters.
ROLES: tuple[tuple[str, Callable[[str], bool]], ...] = (
    ("left wheel joint", lambda t: "left" in t and "joint" in t and "steer" not in t),
    ("right wheel joint", lambda t: "right" in t and "joint" in t and "steer" not in t),
    ("wheel separation [m]", lambda t: "separation" in t or ("track" in t and "kingpin" not in t)),
    ("wheel diameter [m]", lambda t: "diameter" in t),
    ("wheel radius [m]", lambda t: "radius" in t),
    ("max wheel torque [N m]", lambda t: "torque" in t),
    ("max wheel acceleration [m/s²]", lambda t: "accel" in t),
    ("update rate [Hz]", lambda t: "update" in t and "rate" in t),
    ("odometry frame", lambda t: "odom" in t and "frame" in t),
    ("robot base frame", lambda t: "base" in t and "frame" in t),
)


def roles_of(p: Params) -> dict[str, str]:
    """Each parameter tag → the role twin reads it as (tags with no role are left out)."""
    out: dict[str, str] = {}
    for tag in p.given():
        for role, test in ROLES:
            if test(tag.lower()) and role not in out.values():
                out[tag] = role
                break
    return out


def is_vendor_diff_drive(p: Params) -> bool:
    """Whether the plugin names two wheel joints, a separation and a wheel size."""
    roles = set(roles_of(p).values())
    wheels = {"left wheel joint", "right wheel joint", "wheel separation [m]"}
    return wheels <= roles and bool(roles & {"wheel diameter [m]", "wheel radius [m]"})


def read_vendor_diff_drive(p: Params, blob: Blob) -> DiffDrive:
    """The plugin as a gazebo_ros diff drive; its notes say, tag by tag, what each became."""
    by_role = {role: tag for tag, role in roles_of(p).items()}

    def number(role: str, default: float) -> float:
        return p.number(default, by_role[role]) if role in by_role else default

    diameter = number("wheel diameter [m]", 0.0) or 2.0 * number("wheel radius [m]", 0.0)
    roles = roles_of(p)
    notes = tuple(
        f"<{tag}>{value}: read as the {roles[tag]}" if tag in roles else _unused(tag)
        for tag, value in p.given().items()
    )
    return DiffDrive(
        name=blob.name or "vendor_drive",
        where=blob.where,
        left_joints=p.names(by_role["left wheel joint"]),
        right_joints=p.names(by_role["right wheel joint"]),
        wheel_separation=number("wheel separation [m]", 0.0),
        wheel_diameter=diameter,
        max_wheel_torque=number("max wheel torque [N m]", DEFAULT_TORQUE),
        max_wheel_acceleration=number("max wheel acceleration [m/s²]", 0.0),
        update_rate=number("update rate [Hz]", DEFAULT_RATE),
        family=f"vendor:{(blob.kind or '').rsplit('/', 1)[-1]}",
        odometry_frame=_frame(p, by_role, "odometry frame", "odom"),
        robot_base_frame=_frame(p, by_role, "robot base frame", "base_footprint"),
        notes=notes,
    )


def _unused(tag: str) -> str:
    if any(word in tag.lower() for word in ROS_TOPICS):
        return f"<{tag}>: {ROS_NOTE}"
    return f"<{tag}>: ignored"


def _frame(p: Params, by_role: dict[str, str], role: str, default: str) -> str:
    return p.text(default, by_role[role]) if role in by_role else default
