"""The world on the live ROS 2 graph: its topics published over DDS, its drives commanded.

A bridge samples the world as a bag recording does (`live_recording.RosRecording`): the
stepping thread copies the state at RATE Hz of sim time into shared memory, and a publisher
process (`publisher`) builds the ROS messages with the recorder's code and publishes their CDR
bytes from a participant of its own (node `/twin`). So the live topics, types, frame names and
stamps are those of a recording, sensors included; `/tf_static` and `robot_description` are
sent when an entity comes or goes, and a paused world's state is sent again every half second
(`/tf` only once per stamp, as tf2 takes it: `tf_repeats`).
The publisher sends only the newest sample, at most WALL_SPEEDUP × RATE a wall second: a world
up to twice as fast as real time loses no message, a faster one is thinned (as `twin topics
echo`; from four times real time the stepping thread takes only every k-th sample,
`live_recording.stride`), and none of this holds the loop's interpreter. `CommandListener`
takes `cmd_vel` and the controllers' topics the other way, and `ServiceServer` answers
gazebo_ros' entity services, through the server's participant (node `/twin_commands`).
"""

from __future__ import annotations

import threading
from typing import TYPE_CHECKING, Any

from twin_cli.errors import InvalidRequestError, RequestError
from twin_cli.live.budget import WALL_SPEEDUP
from twin_cli.live.catalogue import STATE_RATE
from twin_cli.record import messages as ros_messages
from twin_cli.ros.commands import CommandListener
from twin_cli.ros.live_recording import RosRecording
from twin_cli.ros.node import COMMANDS_NODE_NAME
from twin_cli.ros.participant import Participant
from twin_cli.ros.scope import Scope, scope_from
from twin_cli.ros.services import ServiceServer

if TYPE_CHECKING:
    from twin_cli.world.engine import World

RATE = STATE_RATE  # [Hz] of sim time: /clock, /tf, joint_states and odom (Gazebo's default 100)
STOP_PATIENCE_S = 10.0  # [s] for the publisher to leave the graph


class RosBridge:
    """`world`'s topics published in `scope` at `rate` [Hz] of sim time, and its cmd_vel read."""

    def __init__(
        self,
        world: World,
        scope: Scope,
        *,
        rate: float = RATE,
        frame_prefix: str | None = None,
        services: bool = False,
    ) -> None:
        """`services`: answer gazebo_ros' entity services, which let any DDS peer in the scope
        spawn and delete entities (ROS 2 without SROS2 has no access control); off unless asked.

        Raises: RequestError: Cyclone DDS cannot start in that scope."""
        # rosbags' types (the node's announcement), built here rather than by the command
        # thread beside a running loop: the build holds the interpreter for ~0.1 s
        ros_messages.typestore()
        self.scope = scope
        self.participant = Participant(scope, COMMANDS_NODE_NAME)
        try:
            self.recording = RosRecording(
                world, scope, rate=rate, max_wall_rate=WALL_SPEEDUP * rate,
                frame_prefix=frame_prefix,
            )  # fmt: skip
            self.commands = CommandListener(world, self.participant)
            self.services = ServiceServer(world, self.participant) if services else None
        except BaseException:
            self.participant.close()
            raise

    def start(self) -> RosBridge:
        """Starts the publisher process and waits until it is on the graph.

        Raises: RequestError: the publisher could not start (its cause)."""
        self.recording.start()
        if not self.recording.ready():
            error = self.recording.stop(patience=STOP_PATIENCE_S).error
            self.participant.close()
            raise RequestError(
                f"ROS 2 publisher ({self.scope.describe()})",
                f"did not start ({error or 'no answer'})",
                "see the server log (`twin logs`)",
            )
        self.commands.start()
        if self.services is not None:
            self.services.start()
        return self

    def retarget(self, world: World) -> None:
        """Follows the world the server loaded (its entities' topics and drives)."""
        self.recording.retarget(world)
        self.commands.retarget(world)
        if self.services is not None:
            self.services.retarget(world)

    def stop(self) -> dict[str, Any]:
        """Stops listening and publishing; both participants leave the graph."""
        status = self.status()
        self.commands.stop()
        if self.services is not None:
            self.services.stop()
        self.recording.stop(patience=STOP_PATIENCE_S)
        self.participant.close()
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
            "stride": self.recording.stride,
            "error": recording.error,
            "inputs": self.commands.topics,
            "commands": self.commands.commands,
            "services": [] if self.services is None else self.services.names,
            "service_calls": 0 if self.services is None else self.services.calls,
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
        services: bool = False,
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
            self.bridge = RosBridge(world, scope, services=services).start()
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
