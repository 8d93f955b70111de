"""What a ROS 2 stack sends the twin: `cmd_vel` for each drive, and ros2_control's forward
command controllers, acted on through the calls `twin drive` and `twin command` make.

- Each entity with a drive gets one reader, of one type, on each cmd_vel topic its drive takes
  (`twin_cli.control.drive_names`): a gazebo_ros drive plugin's `/<entity>/cmd_vel` (or the
  name it gives) and a gz-sim drive system's `/model/<entity>/cmd_vel` (or its `<topic>`, the
  name ros_gz_bridge bridges it under), geometry_msgs/Twist as both subscribe; a
  diff_drive_controller's topic the type its `use_stamped_vel` chooses (`plugin_names`). A
  topic never carries two types (`ros2 topic echo` refuses such a topic). The newest command goes to
  `twin_cli.control.drive` with no duration: like the plugins, a base keeps its last command.
- Each entity whose joints offer a command mode (position, velocity, effort) gets
  `/<entity>/forward_<mode>_controller/commands` (std_msgs/Float64MultiArray, the controller
  names of ros2_control's demos), whose `data` holds one target per such joint in the order
  `twin joints` lists them; it goes to `World.command_joints` (all or none).
- With position joints, `/<entity>/joint_trajectory_controller/joint_trajectory`
  (trajectory_msgs/JointTrajectory) goes to `follow_trajectory`, as `twin trajectory` does.
- A gazebo_ros drive plugin's namespace and remapping rename `cmd_vel` (its drive record's
  `cmd_vel_topic`), a diff_drive_controller takes its own `cmd_vel` topics, and the controllers
  of the robot's ros2_control YAML replace the default controllers, with their joints in the
  YAML's order (`plugin_names`).

A thread of the bridge's own polls the readers every POLL_S and follows spawns and deletes. A
command that is refused (a sideways speed for a diff drive, a wrong number of targets) is
logged once per entity and kind, and the listener goes on.
"""

from __future__ import annotations

import logging
import threading
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from twin_cli.control import drive, follow_trajectory, trajectory_from_dict
from twin_cli.control.drive_names import cmd_vel_topic
from twin_cli.control.drives import CONTROLLERS
from twin_cli.errors import InvalidRequestError, TwinError
from twin_cli.live.catalogue import LiveTopic
from twin_cli.names import namespace
from twin_cli.ros.graph import DEFAULT_QOS, FLOAT64_ARRAY, TWIST
from twin_cli.ros.plugin_names import TRAJECTORY, Controller, plugin_names

JOINT_TRAJECTORY = "trajectory_msgs/msg/JointTrajectory"

if TYPE_CHECKING:
    from twin_cli.ros.participant import Participant
    from twin_cli.world.engine import World

log = logging.getLogger("twin.ros")
POLL_S = 0.02  # [s] wall between looks at the readers (a 50 Hz cmd_vel is taken as it comes)
FOLLOW_S = 0.5  # [s] wall between looks at the world's entities (spawns, deletes)
HOLONOMIC = "HolonomicDrive"
MODES = ("position", "velocity", "effort")


@dataclass(frozen=True)
class Input:
    """One topic the twin reads: `mode` None for cmd_vel (`drive` the kind of drive), else a
    forward command controller of that mode over `joints`."""

    topic: str
    type: str
    mode: str | None = None
    joints: tuple[str, ...] = ()
    drive: str = ""
    timeout: float | None = None  # [s] a cmd_vel holds (None: until the next)


def entity_inputs(world: World) -> dict[str, tuple[Input, ...]]:
    """Each entity's inputs now: cmd_vel for a drive, and its controllers (the description's,
    else a forward controller per command mode and a trajectory controller)."""
    with world.lock:
        return {name: _inputs(world, name) for name in world.entity_names()}


def _inputs(world: World, name: str) -> tuple[Input, ...]:
    entity = world.entity(name)
    drives = [p for p in entity.plugins if type(p).__name__ in CONTROLLERS]
    named = plugin_names(name, entity.description, _base_dir(entity))
    inputs = []
    if drives:
        kind, timeout = type(drives[0]).__name__, getattr(drives[0], "command_timeout", 0.0)
        own = cmd_vel_topic(name, drives[0])  # as its plugin names it
        plugin = ((own or f"{namespace(name)}/cmd_vel", TWIST),)
        topics = named.cmd_vel if named.cmd_vel and not own else plugin
        inputs += [
            Input(topic, message, drive=kind, timeout=timeout or None) for topic, message in topics
        ]
    if named.controllers:
        return (*inputs, *(_controller_input(c) for c in named.controllers))
    return (*inputs, *_default_controllers(name, world.joint_commands(name)))


def with_commands(topics: list[LiveTopic], world: World) -> list[LiveTopic]:
    """`topics` (`twin topics`' listing) with each entity's inputs after its own topics, marked
    `command` (twin reads them; rate 0: they come when a node sends them)."""
    inputs = entity_inputs(world)
    out = [t for t in topics if not t.entity]
    for entity in dict.fromkeys([*(t.entity for t in topics if t.entity), *inputs]):
        out += [t for t in topics if t.entity == entity]
        out += [LiveTopic(i.topic, i.type, 0.0, entity=entity, command=True)
                for i in inputs.get(entity, ())]  # fmt: skip
    return out


def _base_dir(entity: Any) -> str:
    """Where the entity's description's relative paths start: the folder a text description
    was sent from, else the description file's folder."""
    request = getattr(entity, "request", None)
    base = getattr(request, "base_dir", None) if getattr(request, "xml", None) else None
    return str(base) if base else str(Path(entity.source).parent)


def _default_controllers(name: str, rows: dict[str, Any]) -> list[Input]:
    """ros2_control demos' controller names, over every joint offering each mode."""
    inputs = []
    for mode in MODES:
        joints = tuple(j for j, row in rows.items() if mode in row["modes"])
        if joints:
            topic = f"{namespace(name)}/forward_{mode}_controller/commands"
            inputs.append(Input(topic, FLOAT64_ARRAY, mode, joints))
        if joints and mode == "position":
            topic = f"{namespace(name)}/joint_trajectory_controller/joint_trajectory"
            inputs.append(Input(topic, JOINT_TRAJECTORY, TRAJECTORY, joints))
    return inputs


def _controller_input(controller: Controller) -> Input:
    kind = JOINT_TRAJECTORY if controller.mode == TRAJECTORY else FLOAT64_ARRAY
    return Input(controller.topic, kind, controller.mode, controller.joints)


def twist_of(message: Any) -> tuple[float, float, float]:
    """Forward [m/s], sideways [m/s] and yaw rate [rad/s] of a Twist or TwistStamped object."""
    twist = getattr(message, "twist", message)
    return float(twist.linear.x), float(twist.linear.y), float(twist.angular.z)


def trajectory_doc(message: Any) -> dict[str, Any]:
    """A JointTrajectory object as the dict `twin trajectory` sends (empty vectors left out)."""

    def vector(values: Any) -> list[float] | None:
        return [float(v) for v in values] or None

    points = [
        {
            "positions": vector(p.positions),
            "velocities": vector(p.velocities),
            "accelerations": vector(p.accelerations),
            "time_from_start": {"sec": p.time_from_start.sec, "nanosec": p.time_from_start.nanosec},
        }
        for p in message.points
    ]
    return {"joint_names": list(message.joint_names), "points": points}


class CommandListener:
    """Readers of every entity's inputs in `participant`, acting on `world` (retargetable)."""

    def __init__(self, world: World, participant: Participant) -> None:
        self._world, self._participant = world, participant
        self._inputs: dict[str, tuple[Input, ...]] = {}
        self._readers: dict[str, list[tuple[Input, Any]]] = {}
        self._warned: set[tuple[str, str]] = set()
        self._stopping = threading.Event()
        self._thread = threading.Thread(target=self._run, name="twin-ros-commands", daemon=True)
        self.commands = 0  # commands acted on so far

    @property
    def topics(self) -> list[str]:
        """Every topic read now, once each."""
        names = [i.topic for readers in self._readers.values() for i, _ in readers]
        return list(dict.fromkeys(names))

    def start(self) -> CommandListener:
        self._follow()
        self._thread.start()
        return self

    def retarget(self, world: World) -> None:
        """Listens for the entities of `world` from now on (the server loaded another)."""
        self._world = world
        self._follow()

    def stop(self) -> None:
        self._stopping.set()
        if self._thread.is_alive():
            self._thread.join(timeout=2.0)

    def _run(self) -> None:
        waited = 0.0
        while not self._stopping.wait(POLL_S):
            waited += POLL_S
            try:
                if waited >= FOLLOW_S:
                    waited = 0.0
                    self._follow()
                self._take_all()
            except Exception:  # one bad look must not end the listener: the world goes on
                log.exception("command listener")

    def _take_all(self) -> None:
        """Acts on the newest message of each input (a writer that left sends an invalid
        sample, which carries no data)."""
        for entity, readers in list(self._readers.items()):
            for spec, reader in readers:
                valid = [s for s in reader.take(16) if hasattr(s, "__idl__")]
                if valid:
                    self._act(entity, spec, valid[-1])

    def _follow(self) -> None:
        """Opens readers for new or changed entities and drops those of deleted ones."""
        try:
            wanted = entity_inputs(self._world)
        except TwinError:  # the world went away under us: the next look will see
            return
        for entity in [e for e in self._readers if wanted.get(e) != self._inputs.get(e)]:
            for _, reader in self._readers.pop(entity):
                self._participant.drop_reader(reader)
        for entity, inputs in wanted.items():
            if entity not in self._readers and inputs:
                self._readers[entity] = [
                    (i, self._participant.reader(i.topic, i.type, DEFAULT_QOS)) for i in inputs
                ]
        self._inputs = wanted

    def _act(self, entity: str, spec: Input, message: Any) -> None:
        try:
            if spec.mode is None:
                linear, lateral, angular = twist_of(message)
                lateral = lateral if spec.drive == HOLONOMIC else 0.0
                drive(self._world, entity, linear, angular, spec.timeout, lateral=lateral)
            elif spec.mode == TRAJECTORY:
                follow_trajectory(
                    self._world, entity, trajectory_from_dict(trajectory_doc(message))
                )
            else:
                self._command(entity, spec, [float(v) for v in message.data])
            self.commands += 1
        except TwinError as exc:
            key = (entity, f"{spec.topic}:{type(exc).__name__}")
            if key not in self._warned:
                self._warned.add(key)
                log.warning("%s not acted on: %s", spec.topic, exc)

    def _command(self, entity: str, spec: Input, data: list[float]) -> None:
        if len(data) != len(spec.joints):
            raise InvalidRequestError(
                spec.topic,
                f"{len(data)} values for {len(spec.joints)} joints",
                f"send one {spec.mode} target per joint, in this order: {', '.join(spec.joints)}",
            )
        assert spec.mode is not None
        self._world.command_joints(
            entity, dict(zip(spec.joints, data, strict=True)), mode=spec.mode
        )
