"""The world on the live ROS 2 graph: its topics published over DDS, its drives commanded.

A bridge is a live recording (`twin_cli.record.Recording`, the one that feeds the Foxglove
stream) whose sink is the DDS participant: the stepping thread only copies a sample at RATE Hz
of sim time (a world observer); the recording's worker builds the ROS messages with the
recorder's code and the participant publishes their CDR bytes. So the live topics, types, frame
names and stamps are those of a recording, sensors included, `/tf_static` and
`robot_description` are sent when an entity comes or goes, and a paused world's state is sent
again every half second. The worker keeps only the newest sample while it is busy, so the loop
never waits for DDS, and takes at most WALL_SPEEDUP × RATE samples per wall second: a world up
to twice as fast as real time loses no message, a faster one is thinned (as `twin topics
echo`), so building messages never takes the interpreter from the loop in proportion to its
speed. `CommandListener` takes `cmd_vel` and forward controller commands the other way.
"""

from __future__ import annotations

import threading
from typing import TYPE_CHECKING, Any

from twin_cli.errors import InvalidRequestError
from twin_cli.live.budget import WALL_SPEEDUP
from twin_cli.live.catalogue import STATE_RATE
from twin_cli.record.recorder import Recording
from twin_cli.ros.commands import CommandListener
from twin_cli.ros.participant import Participant
from twin_cli.ros.scope import Scope, scope_from

if TYPE_CHECKING:
    from twin_cli.world.engine import World

RATE = STATE_RATE  # [Hz] of sim time: /clock, /tf, joint_states and odom (Gazebo's default 100)


class RosBridge:
    """`world`'s topics published in `scope` at `rate` [Hz] of sim time, and its cmd_vel read."""

    def __init__(
        self, world: World, scope: Scope, *, rate: float = RATE, frame_prefix: str | None = None
    ) -> None:
        """Raises: RequestError: Cyclone DDS cannot start in that scope."""
        self.scope = scope
        self.participant = Participant(scope)
        try:
            self.recording = Recording(
                world, [self.participant], rate=rate, latest_only=True,
                frame_prefix=frame_prefix, max_wall_rate=WALL_SPEEDUP * rate,
            )  # fmt: skip
        except BaseException:
            self.participant.close()
            raise
        self.commands = CommandListener(world, self.participant)

    def start(self) -> RosBridge:
        self.recording.start()
        self.commands.start()
        return self

    def retarget(self, world: World) -> None:
        """Follows the world the server loaded (its entities' topics and drives)."""
        self.recording.retarget(world)
        self.commands.retarget(world)

    def stop(self) -> dict[str, Any]:
        """Stops listening and publishing; the participant leaves the graph."""
        status = self.status()
        self.commands.stop()
        self.recording.stop()  # closes its sink: the participant
        return status

    def status(self) -> dict[str, Any]:
        recording = self.recording.status()
        return {
            "domain_id": self.scope.domain_id,
            "range": self.scope.range,
            "local_only": self.scope.local_only,
            "loopback_device": self.participant.on_loopback_device,
            "scope": self.scope.describe(),
            "rate": self.recording.rate,
            "samples": recording.samples,
            "error": recording.error,
            "inputs": self.commands.topics,
            "commands": self.commands.commands,
        }


class RosService:
    """A server's bridge (at most one); start and stop are thread safe."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self.bridge: RosBridge | None = None

    def start(
        self,
        world: World,
        *,
        interface: str | None = None,
        environment: dict[str, str] | None = None,
    ) -> dict[str, Any]:
        """Joins the ROS 2 graph in the scope ROS's variables and `interface` ask (the variables
        of `environment`, the client's, else this process's).

        Raises:
            InvalidRequestError: a bridge runs already, or a ROS_* variable cannot be read.
            RequestError: Cyclone DDS cannot start.
        """
        with self._lock:
            if self.bridge is not None:
                raise InvalidRequestError(
                    "ROS 2 bridge",
                    f"already publishing ({self.bridge.scope.describe()})",
                    "stop it first with `twin ros stop`",
                )
            scope = scope_from(environment, interface)
            self.bridge = RosBridge(world, scope).start()
            return self.bridge.status()

    def status(self) -> dict[str, Any]:
        with self._lock:
            if self.bridge is None:
                raise InvalidRequestError("ROS 2 bridge", "none runs", "start it: twin ros start")
            return self.bridge.status()

    def stop(self) -> dict[str, Any]:
        with self._lock:
            if self.bridge is None:
                raise InvalidRequestError("ROS 2 bridge", "none runs", "start it: twin ros start")
            bridge, self.bridge = self.bridge, None
        return bridge.stop()

    def follow(self, world: World) -> dict[str, str]:
        """Moves the bridge to `world` (the server loaded another): the `/load` reply's part."""
        with self._lock:
            if self.bridge is None:
                return {}
            self.bridge.retarget(world)
            return {"ros": "moved"}

    def close(self) -> None:
        """Ends the bridge (server shutdown)."""
        with self._lock:
            bridge, self.bridge = self.bridge, None
        if bridge is not None:
            bridge.stop()
