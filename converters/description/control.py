"""How a joint may be driven: the command interfaces its `<ros2_control>`/`<transmission>` give.

Format-free records. A `JointControl` lists the modes a joint can be commanded in (position,
velocity, effort), each with the interface's own `min`/`max` bounds when the file gives them, and
the PID gains of a `position_pid`/`velocity_pid` interface (gazebo_ros2_control reads them from
the joint's `pos_kp`, `pos_ki`, `pos_kd` and `vel_*` params). The MuJoCo builder carries them into
the model (`converters.mjcf.control_data`); the running world turns them into actuator gains,
bias and force ranges at command time.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

# The modes a joint can be driven in, in the order a joint without tags offers them.
MODES = ("position", "velocity", "effort")

# ROS 1 hardware interfaces of a `<transmission>` joint → the mode they command
# (gazebo_ros_control's DefaultRobotHWSim, gazebo_ros2_control's GazeboSystem).
HARDWARE_INTERFACES = {
    "EffortJointInterface": "effort",
    "PositionJointInterface": "position",
    "VelocityJointInterface": "velocity",
}

# Plugins that run `<ros2_control>` / `<transmission>` interfaces in Gazebo.
CONTROL_PLUGINS = (
    "libgazebo_ros2_control.so",
    "gazebo_ros2_control",
    "libgazebo_ros_control.so",
    "gz_ros2_control-system",
    "libgz_ros2_control-system.so",
    "ign_ros2_control-system",
    "libign_ros2_control-system.so",
)


def is_control_plugin(filename: str | None) -> bool:
    """Whether a `<plugin>` filename (with or without its folder) is a ros2_control plugin."""
    return (filename or "").rsplit("/", 1)[-1] in CONTROL_PLUGINS


@dataclass(frozen=True)
class CommandInterface:
    """One mode a joint accepts, with the interface's own bounds.

    Attributes:
        mode: one of `MODES`.
        minimum, maximum: the interface's `min`/`max` params [rad, m, rad/s, m/s, N m or N];
            None when not given (the joint's own limits still apply).
        pid: a `position_pid`/`velocity_pid` interface (the joint's PID params give its gains).
    """

    mode: str
    minimum: float | None = None
    maximum: float | None = None
    pid: bool = False


@dataclass(frozen=True)
class PidGains:
    """PID gains of a `*_pid` interface: force = kp·e + ki·∫e + kd·ė [N m or N per unit error]."""

    kp: float = 0.0
    ki: float = 0.0
    kd: float = 0.0


@dataclass(frozen=True)
class JointControl:
    """The command interfaces one joint declares.

    Attributes:
        joint: the joint's name.
        source: "ros2_control" or "transmission" (which tag declared it); both, joined by
            "+", once `merge_controls` has combined a joint's tags.
        interfaces: the modes it accepts, first one first (the tag's order).
        gains: mode → PID gains from the tag (position_pid / velocity_pid only).
        where: the tag, for messages (e.g. `<ros2_control name='arm'>`).
        ignored: interfaces it declares that twin does not drive (acceleration, gpio,
            franka_hw/FrankaStateInterface...), as written, for the report.
    """

    joint: str
    source: str
    interfaces: tuple[CommandInterface, ...]
    gains: tuple[tuple[str, PidGains], ...] = ()
    where: str = ""
    ignored: tuple[str, ...] = ()

    @property
    def modes(self) -> tuple[str, ...]:
        """The modes, in the tag's order, without repeats."""
        return tuple(dict.fromkeys(i.mode for i in self.interfaces))


def merge_controls(parts: Sequence[JointControl]) -> JointControl:
    """One joint's declarations, from every tag that names it, as one record offering them all.

    ros2_control's resource manager exports every command interface a joint declares and lets
    a controller claim any one, so franka_description's three `<transmission>`s per joint
    (position, velocity, effort) give three modes, not the first one. A mode declared twice
    keeps its first declaration's bounds and gains (document order: `<ros2_control>` blocks,
    then transmissions). Tags that declare no mode twin drives (franka_hw's state interface)
    add only their names to `ignored`.

    Args:
        parts: the joint's records, one per tag, in document order (at least one).
    """
    interfaces: dict[str, CommandInterface] = {}
    gains: dict[str, PidGains] = {}
    for part in parts:
        for interface in part.interfaces:
            interfaces.setdefault(interface.mode, interface)
        for mode, pid in part.gains:
            gains.setdefault(mode, pid)
    declaring = [p for p in parts if p.interfaces] or list(parts[:1])
    return JointControl(
        parts[0].joint,
        "+".join(dict.fromkeys(p.source for p in declaring)),
        tuple(interfaces.values()),
        tuple(gains.items()),
        ", ".join(dict.fromkeys(p.where for p in declaring)),
        tuple(dict.fromkeys(name for p in parts for name in p.ignored)),
    )
