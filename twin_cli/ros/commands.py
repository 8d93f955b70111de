"""What a ROS 2 stack sends the twin: `cmd_vel` for each drive, acted on as `twin drive` acts.

Each entity with a drive plugin gets readers on `/<entity>/cmd_vel` for geometry_msgs/Twist (as
gazebo_ros' drive plugins subscribe) and TwistStamped (as Jazzy's controllers and Nav2 publish
with stamped commands); both types may share the topic. A thread of the bridge's own polls the
readers every POLL_S, follows spawns and deletes, and hands the newest command of each entity to
`twin_cli.control.drive` with no duration: like the plugins, a base keeps its last command until
the next one. A command the drive refuses (a sideways speed for a diff drive) is logged once per
entity and kind, and the listener goes on.
"""

from __future__ import annotations

import logging
import threading
from typing import TYPE_CHECKING, Any

from twin_cli.control import drive
from twin_cli.control.drives import CONTROLLERS
from twin_cli.errors import TwinError
from twin_cli.ros.graph import DEFAULT_QOS, TWIST, TWIST_STAMPED

if TYPE_CHECKING:
    from twin_cli.ros.participant import Participant
    from twin_cli.world.engine import World

log = logging.getLogger("twin.ros")
POLL_S = 0.02  # [s] wall between looks at the readers (a 50 Hz cmd_vel is taken as it comes)
FOLLOW_S = 0.5  # [s] wall between looks at the world's entities (spawns, deletes)
HOLONOMIC = "HolonomicDrive"


def drive_entities(world: World) -> dict[str, str]:
    """Each entity with a drive plugin → the kind of its first drive (`control.drives`)."""
    with world.lock:
        out = {}
        for name in world.entity_names():
            kinds = [type(p).__name__ for p in world.entity(name).plugins]
            drives = [k for k in kinds if k in CONTROLLERS]
            if drives:
                out[name] = drives[0]
        return out


def twist_of(message: Any) -> tuple[float, float, float]:
    """Forward [m/s], sideways [m/s] and yaw rate [rad/s] of a Twist or TwistStamped object."""
    twist = getattr(message, "twist", message)
    return float(twist.linear.x), float(twist.linear.y), float(twist.angular.z)


class CommandListener:
    """Readers of every drive's `cmd_vel` in `participant`, acting on `world` (retargetable)."""

    def __init__(self, world: World, participant: Participant) -> None:
        self._world, self._participant = world, participant
        self._readers: dict[str, list[Any]] = {}
        self._kinds: dict[str, str] = {}
        self._warned: set[tuple[str, str]] = set()
        self._stopping = threading.Event()
        self._thread = threading.Thread(target=self._run, name="twin-ros-commands", daemon=True)
        self.commands = 0  # commands acted on so far

    @property
    def topics(self) -> list[str]:
        """The `cmd_vel` topics listened to now."""
        return [f"/{entity}/cmd_vel" for entity in self._readers]

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
                log.exception("cmd_vel listener")

    def _take_all(self) -> None:
        """Acts on the newest command of each entity (a writer that left sends an invalid
        sample, which carries no data)."""
        for entity, readers in list(self._readers.items()):
            newest = None
            for reader in readers:
                valid = [s for s in reader.take(16) if hasattr(s, "__idl__")]
                newest = valid[-1] if valid else newest
            if newest is not None:
                self._act(entity, newest)

    def _follow(self) -> None:
        """Opens readers for new drive entities and drops those of deleted ones."""
        try:
            kinds = drive_entities(self._world)
        except TwinError:  # the world went away under us: the next look will see
            return
        for entity in [e for e in self._readers if e not in kinds]:
            for reader in self._readers.pop(entity):
                self._participant.drop_reader(reader)
        for entity in kinds:
            if entity not in self._readers:
                topic = f"/{entity}/cmd_vel"
                self._readers[entity] = [
                    self._participant.reader(topic, kind, DEFAULT_QOS)
                    for kind in (TWIST, TWIST_STAMPED)
                ]
        self._kinds = kinds

    def _act(self, entity: str, message: Any) -> None:
        linear, lateral, angular = twist_of(message)
        holonomic = self._kinds.get(entity) == HOLONOMIC
        try:
            drive(self._world, entity, linear, angular, lateral=lateral if holonomic else 0.0)
            self.commands += 1
        except TwinError as exc:
            key = (entity, type(exc).__name__)
            if key not in self._warned:
                self._warned.add(key)
                log.warning("cmd_vel of [%s] not acted on: %s", entity, exc)
