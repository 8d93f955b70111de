"""gazebo_ros' world services, answered on the world the way `twin spawn`, `delete`, `list`,
`pose`, `pause` and `reset` act on it.

- `/spawn_entity` (gazebo_msgs/SpawnEntity): `xml` (URDF or SDF text) spawned as `twin spawn -`
  spawns a description read from stdin, named `name` (empty: twin's default name), at
  `initial_pose` in `reference_frame` ("", "world" or "map": the world; an entity's name: that
  entity's root). `robot_namespace` is not read: the entity's topics are under its name. The
  description is URDF or SDF (as gazebo_ros takes), and it may read only the world's package
  and model paths (`package_env.package_roots`): a peer is not the server's user.
- `/delete_entity`, `/get_model_list`: remove one entity; the entities' names, stamped.
- `/get_entity_state`, `/set_entity_state` (gazebo_ros_state's): an entity's root pose and twist
  in `reference_frame`, as gazebo_ros_state gives them: the pose relative to that entity's root,
  the velocities' differences turned into its frame (a twist is ignored on an entity fixed to
  the world, as Gazebo ignores it). Links (`model::link`) are refused, naming the entity.
- `/pause_physics`, `/unpause_physics`, `/reset_simulation`, `/reset_world` (std_srvs/Empty,
  gazebo_ros_init's): `twin pause`, `twin resume` and `twin reset`. twin's reset also returns
  sim time to 0, which Gazebo's `/reset_world` keeps.

Every handler takes the world and a request and returns the reply's fields; a refused request
says why (`status_message`, else the log) and leaves the world as it was.
"""

from __future__ import annotations

import logging
import math
from typing import TYPE_CHECKING, Any

from converters.errors import ConversionError
from twin_cli.errors import EntityNotFoundError, InvalidRequestError, TwinError
from twin_cli.files.package_env import package_roots
from twin_cli.physical_ranges import POSITION_M, SPEED
from twin_cli.ros.graph import idl_type
from twin_cli.spawn_request import SpawnRequest
from twin_cli.world.pose import Pose

if TYPE_CHECKING:
    from twin_cli.world.engine import World

log = logging.getLogger("twin.ros")
WORLD_FRAMES = ("", "world", "map")  # reference frames that mean the world, as gazebo_ros reads
EMPTY_REPLY = {"structure_needs_at_least_one_member": 0}  # rosidl's member of an empty message
Vector = tuple[float, float, float]


def spawn(world: World, request: Any) -> dict[str, Any]:
    try:
        pose = pose_in_world(world, request.initial_pose, request.reference_frame)
        result = world.spawn(peer_text(request.xml), name=request.name or None, pose=pose)
    except (TwinError, ConversionError) as exc:
        return {"success": False, "status_message": str(exc)}
    except Exception as exc:  # a caller must always get its answer
        log.exception("spawn_entity")
        return {"success": False, "status_message": f"spawn failed: {exc}"}
    log.info("spawned %s (/spawn_entity)", result.name)
    return {"success": True, "status_message": f"spawned entity [{result.name}]"}


def peer_text(text: str) -> SpawnRequest:
    """A DDS peer's description text as a spawn request confined to the world's package and
    model paths; its relative paths start at the first of them (the server's own folder is not
    the peer's, and may hold anything), or at `/` when there are none."""
    roots = package_roots()
    return SpawnRequest(xml=text, base_dir=roots[0] if roots else "/", read_roots=roots)


def delete(world: World, request: Any) -> dict[str, Any]:
    try:
        world.delete(request.name)
    except TwinError as exc:
        return {"success": False, "status_message": str(exc)}
    log.info("deleted %s (/delete_entity)", request.name)
    return {"success": True, "status_message": f"deleted entity [{request.name}]"}


def model_list(world: World, request: Any) -> dict[str, Any]:
    with world.lock:
        now, names = float(world.data.time), world.entity_names()
    return {"header": header(now, ""), "model_names": names, "success": True}


def get_state(world: World, request: Any) -> dict[str, Any]:
    """The entity's pose and twist in `reference_frame`; success false (and a zero state) for
    an unknown entity or frame, or a link."""
    frame = request.reference_frame
    with world.lock:
        now = float(world.data.time)
        try:
            pose, linear, angular = _state_of(world, _entity_name(world, request.name))
            if frame not in WORLD_FRAMES:
                pose, linear, angular = _relative(
                    (pose, linear, angular), _state_of(world, _entity_name(world, frame))
                )
        except TwinError as exc:
            log.warning("get_entity_state: %s", exc)
            return {"header": header(now, frame), "state": entity_state(request.name, frame),
                    "success": False}  # fmt: skip
    state = entity_state(request.name, frame, pose, linear, angular)
    return {"header": header(now, frame), "state": state, "success": True}


def set_state(world: World, request: Any) -> dict[str, Any]:
    """Puts the entity at `state.pose` with `state.twist`, both in `state.reference_frame`
    (the twist turned into the world's axes); all or nothing."""
    state = request.state
    try:
        name = _entity_name(world, state.name)
        pose = pose_in_world(world, state.pose, state.reference_frame)
        linear, angular = _twist_in_world(world, state.twist, state.reference_frame)
        moving = any(linear) or any(angular)
        with world.lock:
            free = world.index_of(name).free_qpos >= 0
            world.set_pose(name, pose)
            if moving and free:
                world.set_twist(name, linear, angular)
            elif moving:  # gazebo_ros_state sets what the entity can take
                log.info("set_entity_state: [%s] is fixed to the world; twist ignored", name)
    except TwinError as exc:
        log.warning("set_entity_state: %s", exc)
        return {"success": False}
    return {"success": True}


def pause(world: World, request: Any) -> dict[str, Any]:
    world.pause()
    return EMPTY_REPLY


def unpause(world: World, request: Any) -> dict[str, Any]:
    world.resume()
    return EMPTY_REPLY


def reset(world: World, request: Any) -> dict[str, Any]:
    world.reset()
    return EMPTY_REPLY


# ------------------------------------------------------------------ values
def header(time: float, frame: str) -> Any:
    """A std_msgs/Header stamped `time` [s] of sim time."""
    sec = math.floor(time)
    stamp = idl_type("builtin_interfaces/msg/Time")(sec=sec, nanosec=round((time - sec) * 1e9))
    return idl_type("std_msgs/msg/Header")(stamp=stamp, frame_id=frame)


def entity_state(
    name: str,
    frame: str,
    pose: Pose | None = None,
    linear: Vector = (0.0, 0.0, 0.0),
    angular: Vector = (0.0, 0.0, 0.0),
) -> Any:
    """A gazebo_msgs/EntityState (identity pose for None)."""
    pose = pose or Pose()
    x, y, z = pose.position()
    w, qx, qy, qz = pose.quat()
    msg = idl_type("geometry_msgs/msg/Pose")(
        position=idl_type("geometry_msgs/msg/Point")(x=x, y=y, z=z),
        orientation=idl_type("geometry_msgs/msg/Quaternion")(x=qx, y=qy, z=qz, w=w),
    )
    vector = idl_type("geometry_msgs/msg/Vector3")
    twist = idl_type("geometry_msgs/msg/Twist")(linear=vector(*linear), angular=vector(*angular))
    return idl_type("gazebo_msgs/msg/EntityState")(
        name=name, pose=msg, twist=twist, reference_frame=frame
    )


def pose_in_world(world: World, pose: Any, frame: str) -> Pose:
    """A geometry_msgs/Pose in `frame` (the world, or an entity's root) as a world pose.

    Raises: EntityNotFoundError: `frame` is neither the world nor an entity.
        InvalidRequestError: a coordinate is not finite or beyond POSITION_M, or the
            quaternion is zero."""
    p, q = pose.position, pose.orientation
    values = (p.x, p.y, p.z, q.w, q.x, q.y, q.z)
    if not all(math.isfinite(v) and abs(v) <= POSITION_M for v in values[:3]) or not all(
        math.isfinite(v) for v in values[3:]
    ):
        raise InvalidRequestError("pose", f"{values} is not finite or out of range",
                                  f"give coordinates within ±{POSITION_M:g} m")  # fmt: skip
    if math.hypot(*values[3:]) < 1e-9:
        raise InvalidRequestError("pose", "its quaternion is zero", "give a unit quaternion")
    local = Pose.from_quat(p.x, p.y, p.z, (q.w, q.x, q.y, q.z))
    if frame in WORLD_FRAMES:
        return local
    return compose(world.get_pose(_entity_name(world, frame)), local)


def compose(parent: Pose, child: Pose) -> Pose:
    """`child` given in `parent`'s frame, in the world's (MuJoCo's quaternion algebra)."""
    import numpy as np

    offset, quat = _turn(parent, child.position()), np.zeros(4)
    import mujoco

    mujoco.mju_mulQuat(quat, np.array(parent.quat()), np.array(child.quat()))
    return Pose.at(np.array(parent.position()) + np.array(offset), quat)


def _turn(frame: Pose, vector: Vector, inverse: bool = False) -> Vector:
    """`vector` turned by `frame`'s orientation (or back, `inverse`)."""
    import mujoco
    import numpy as np

    w, x, y, z = frame.quat()
    quat = np.array([w, -x, -y, -z] if inverse else [w, x, y, z])
    out = np.zeros(3)
    mujoco.mju_rotVecQuat(out, np.array(vector, dtype=float), quat)
    return float(out[0]), float(out[1]), float(out[2])


def _entity_name(world: World, name: str) -> str:
    """`name` if it is an entity; a link (`model::link`) or an unknown name is refused."""
    names = world.entity_names()
    if name in names:
        return name
    model = name.split("::", 1)[0]
    if "::" in name and model in names:
        raise InvalidRequestError(
            f"entity [{name}]", "is a link: twin answers for entities",
            f"ask for [{model}] (its root), or read its links with twin model {model}",
        )  # fmt: skip
    raise EntityNotFoundError(name, names)


def _state_of(world: World, name: str) -> tuple[Pose, Vector, Vector]:
    linear, angular = world.get_twist(name)
    return world.get_pose(name), linear, angular


def _relative(state: tuple, reference: tuple) -> tuple[Pose, Vector, Vector]:
    """`state` (pose, linear, angular in the world) seen from `reference`'s root frame."""
    import mujoco
    import numpy as np

    (pose, linear, angular), (ref, ref_linear, ref_angular) = state, reference
    offset = np.subtract(pose.position(), ref.position())
    w, x, y, z = ref.quat()
    quat = np.zeros(4)
    mujoco.mju_mulQuat(quat, np.array([w, -x, -y, -z]), np.array(pose.quat()))
    local = Pose.at(np.array(_turn(ref, tuple(offset), inverse=True)), quat)
    dv = tuple(np.subtract(linear, ref_linear))
    dw = tuple(np.subtract(angular, ref_angular))
    return local, _turn(ref, dv, inverse=True), _turn(ref, dw, inverse=True)


def _twist_in_world(world: World, twist: Any, frame: str) -> tuple[Vector, Vector]:
    """A geometry_msgs/Twist in `frame`'s axes, in the world's.

    Raises: InvalidRequestError: a value is not finite or beyond SPEED."""
    linear = (twist.linear.x, twist.linear.y, twist.linear.z)
    angular = (twist.angular.x, twist.angular.y, twist.angular.z)
    if not all(math.isfinite(v) and abs(v) <= SPEED for v in (*linear, *angular)):
        raise InvalidRequestError("twist", f"{(*linear, *angular)} is not finite or too large",
                                  f"give speeds within ±{SPEED:g} m/s or rad/s")  # fmt: skip
    if frame in WORLD_FRAMES:
        return linear, angular
    ref = world.get_pose(_entity_name(world, frame))
    return _turn(ref, linear), _turn(ref, angular)
