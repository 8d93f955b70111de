"""The world's services on the live graph, answered by a thread of their own: gazebo_ros'
(`/spawn_entity`, `/delete_entity`, `/get_model_list`, `/get_entity_state`,
`/set_entity_state`, `/pause_physics`, `/unpause_physics`, `/reset_simulation`, `/reset_world`:
`gazebo_services`) and ros_gz's (`/world/<world>/create`, `remove`, `set_pose`, `control`:
`gz_services`).

The thread takes the requests every POLL_S and answers each with the request's rmw header
(`service_types`), so the client matches its reply.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from twin_cli.ros import gazebo_services as gazebo
from twin_cli.ros import gz_services as gz
from twin_cli.ros import service_types as srv

if TYPE_CHECKING:
    from twin_cli.ros.participant import Participant
    from twin_cli.world.engine import World

log = logging.getLogger("twin.ros")
POLL_S = 0.05  # [s] wall between looks at the requests
REPLY_MATCH_S = 5.0  # [s] wall a reply waits for its client's reader to be discovered
Handler = Callable[["World", Any], dict[str, Any]]


def service_table(world_name: str) -> dict[str, tuple[str, Handler]]:
    """Service name → (service type, handler), gazebo_ros' first, then ros_gz's."""
    gz_world = f"/world/{world_name}"
    return {
        "/spawn_entity": (srv.SPAWN, gazebo.spawn),
        "/delete_entity": (srv.DELETE, gazebo.delete),
        "/get_model_list": (srv.MODEL_LIST, gazebo.model_list),
        "/get_entity_state": (srv.GET_STATE, gazebo.get_state),
        "/set_entity_state": (srv.SET_STATE, gazebo.set_state),
        "/pause_physics": (srv.EMPTY, gazebo.pause),
        "/unpause_physics": (srv.EMPTY, gazebo.unpause),
        "/reset_simulation": (srv.EMPTY, gazebo.reset),
        "/reset_world": (srv.EMPTY, gazebo.reset),
        f"{gz_world}/create": (srv.GZ_CREATE, gz.create),
        f"{gz_world}/remove": (srv.GZ_REMOVE, gz.remove),
        f"{gz_world}/set_pose": (srv.GZ_SET_POSE, gz.set_pose),
        f"{gz_world}/control": (srv.GZ_CONTROL, gz.control),
    }


class ServiceServer:
    """The entity services of `world` in `participant` (retargetable, as the listener)."""

    def __init__(self, world: World, participant: Participant) -> None:
        self._world = world
        self._table = service_table(world.name)
        self._endpoints = {
            name: participant.service(name, kind) for name, (kind, _) in self._table.items()
        }
        self._stopping = threading.Event()
        self._thread = threading.Thread(target=self._run, name="twin-ros-services", daemon=True)
        self.calls = 0  # requests answered so far

    @property
    def names(self) -> list[str]:
        return list(self._table)

    def start(self) -> ServiceServer:
        self._thread.start()
        return self

    def retarget(self, world: World) -> None:
        self._world = world

    def stop(self) -> None:
        self._stopping.set()
        if self._thread.is_alive():
            self._thread.join(timeout=2.0)

    def _run(self) -> None:
        while not self._stopping.wait(POLL_S):
            for name, (reader, writer) in self._endpoints.items():
                try:
                    for request in [r for r in reader.take(16) if hasattr(r, "__idl__")]:
                        reply = self._answer(name, request)
                        _await_reply_reader(reader, writer)
                        writer.write(reply)
                except Exception:  # one bad request must not end the server: the world goes on
                    log.exception("service %s", name)

    def _answer(self, name: str, request: Any) -> Any:
        """The reply to `request`: the handler's fields, with the request's rmw header. A
        handler that fails unexpectedly still answers, with a failure (a client waits for it)."""
        kind, handler = self._table[name]
        try:
            fields = handler(self._world, request)
        except Exception as exc:
            log.exception("service %s", name)
            fields = failure(kind, f"{name} failed: {exc}")
        self.calls += 1
        reply = srv.service_idl(kind, srv.RESPONSE)
        return reply(guid=request.guid, seq=request.seq, **fields)


def _await_reply_reader(reader: Any, writer: Any) -> None:
    """Waits (at most REPLY_MATCH_S) until the reply writer has matched a reader for every
    client whose request writer the request reader has matched: discovery is not symmetric,
    and a reply written before the client's reader is known is lost (rmw_cyclonedds_cpp's
    services wait for the client's response reader the same way)."""
    deadline = time.monotonic() + REPLY_MATCH_S
    while time.monotonic() < deadline:
        if len(writer.get_matched_subscriptions()) >= len(reader.get_matched_publications()):
            return
        time.sleep(0.01)


def failure(kind: str, message: str) -> dict[str, Any]:
    """A failure reply's fields for service type `kind`."""
    if kind == srv.EMPTY:
        return gazebo.EMPTY_REPLY
    if kind in (srv.SPAWN, srv.DELETE):
        return {"success": False, "status_message": message}
    if kind == srv.MODEL_LIST:
        return {"header": gazebo.header(0.0, ""), "model_names": [], "success": False}
    if kind == srv.GET_STATE:
        return {"header": gazebo.header(0.0, ""), "state": gazebo.entity_state("", ""),
                "success": False}  # fmt: skip
    return {"success": False}
