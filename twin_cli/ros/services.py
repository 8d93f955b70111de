"""gazebo_ros' entity services on the live graph: `/spawn_entity`, `/delete_entity` and
`/get_model_list` (gazebo_msgs/srv), answered through the calls `twin spawn`, `twin delete` and
`twin list` make.

- SpawnEntity: `xml` (URDF or SDF text) is spawned as `twin spawn -` spawns a description read
  from stdin, named `name` (empty: twin's default name), at `initial_pose` in the frame of
  `reference_frame` ("", "world" or "map": the world; an entity's name: that entity's root).
  The reply comes once the entity exists, as gazebo_ros' does; a refused spawn (bad XML, a taken
  name, an unknown reference frame) replies `success: false` with the reason and leaves the
  world as it was. `robot_namespace` is not read: the entity's topics are under its name.
- DeleteEntity: removes entity `name`.
- GetModelList: the entities' names, stamped with the sim time.

A thread of its own takes the requests every POLL_S and answers each with the request's rmw
header (`service_types`), so the client matches its reply.
"""

from __future__ import annotations

import logging
import math
import threading
from typing import TYPE_CHECKING, Any

from converters.errors import ConversionError
from twin_cli.errors import EntityNotFoundError, TwinError
from twin_cli.ros.graph import idl_type
from twin_cli.ros.service_types import DELETE, MODEL_LIST, RESPONSE, SPAWN, service_idl
from twin_cli.spawn_request import SpawnRequest
from twin_cli.world.pose import Pose

if TYPE_CHECKING:
    from twin_cli.ros.participant import Participant
    from twin_cli.world.engine import World

log = logging.getLogger("twin.ros")
POLL_S = 0.05  # [s] wall between looks at the requests
SERVICES = {"/spawn_entity": SPAWN, "/delete_entity": DELETE, "/get_model_list": MODEL_LIST}
WORLD_FRAMES = ("", "world", "map")  # reference frames that mean the world, as gazebo_ros reads


class ServiceServer:
    """The entity services of `world` in `participant` (retargetable, as the listener)."""

    def __init__(self, world: World, participant: Participant) -> None:
        self._world = world
        self._endpoints = {name: participant.service(name, t) for name, t in SERVICES.items()}
        self._handlers = {SPAWN: self._spawn, DELETE: self._delete, MODEL_LIST: self._list}
        self._stopping = threading.Event()
        self._thread = threading.Thread(target=self._run, name="twin-ros-services", daemon=True)
        self.calls = 0  # requests answered so far

    @property
    def names(self) -> list[str]:
        return list(SERVICES)

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
                    for request in [s for s in reader.take(16) if hasattr(s, "__idl__")]:
                        writer.write(self._answer(SERVICES[name], request))
                except Exception:  # one bad request must not end the server: the world goes on
                    log.exception("service %s", name)

    def _answer(self, service_type: str, request: Any) -> Any:
        """The reply to `request`: the handler's fields, with the request's rmw header."""
        fields = self._handlers[service_type](request)
        self.calls += 1
        reply = service_idl(service_type, RESPONSE)
        return reply(guid=request.guid, seq=request.seq, **fields)

    # ------------------------------------------------------------ the three services
    def _spawn(self, request: Any) -> dict[str, Any]:
        try:
            pose = self._pose_in_world(request.initial_pose, request.reference_frame)
            spawn = SpawnRequest(xml=request.xml).absolute()
            result = self._world.spawn(spawn, name=request.name or None, pose=pose)
        except (TwinError, ConversionError) as exc:
            return {"success": False, "status_message": str(exc)}
        except Exception as exc:  # a caller must always get its answer
            log.exception("spawn_entity")
            return {"success": False, "status_message": f"spawn failed: {exc}"}
        log.info("spawned %s (/spawn_entity)", result.name)
        return {"success": True, "status_message": f"spawned entity [{result.name}]"}

    def _delete(self, request: Any) -> dict[str, Any]:
        try:
            self._world.delete(request.name)
        except TwinError as exc:
            return {"success": False, "status_message": str(exc)}
        log.info("deleted %s (/delete_entity)", request.name)
        return {"success": True, "status_message": f"deleted entity [{request.name}]"}

    def _list(self, request: Any) -> dict[str, Any]:
        world = self._world
        with world.lock:
            now, names = float(world.data.time), world.entity_names()
        sec = math.floor(now)
        stamp = idl_type("builtin_interfaces/msg/Time")(sec=sec, nanosec=round((now - sec) * 1e9))
        header = idl_type("std_msgs/msg/Header")(stamp=stamp, frame_id="")
        return {"header": header, "model_names": names, "success": True}

    def _pose_in_world(self, pose: Any, frame: str) -> Pose:
        """A geometry_msgs/Pose in `frame` (the world, or an entity's root) as a world pose.

        Raises: EntityNotFoundError: `frame` is neither the world nor an entity."""
        p, q = pose.position, pose.orientation
        local = Pose.from_quat(p.x, p.y, p.z, (q.w, q.x, q.y, q.z))
        if frame in WORLD_FRAMES:
            return local
        if frame not in self._world.entity_names():
            raise EntityNotFoundError(frame, self._world.entity_names())
        return _compose(self._world.get_pose(frame), local)


def _compose(parent: Pose, child: Pose) -> Pose:
    """`child` given in `parent`'s frame, in the world's (MuJoCo's quaternion algebra)."""
    import mujoco
    import numpy as np

    q_parent, q_child = np.array(parent.quat()), np.array(child.quat())
    offset, quat = np.zeros(3), np.zeros(4)
    mujoco.mju_rotVecQuat(offset, np.array(child.position()), q_parent)
    mujoco.mju_mulQuat(quat, q_parent, q_child)
    return Pose.at(np.array(parent.position()) + offset, quat)
