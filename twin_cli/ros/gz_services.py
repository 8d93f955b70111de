"""ros_gz's world services (ros_gz_interfaces, as ros_gz_bridge offers gz-sim's
`/world/<world>/...`), answered on the world as `twin spawn`, `delete`, `pose`, `pause`, `step`
and `reset` act on it. Replies carry only `success`; a refused request is logged with why.

- `create` (SpawnEntity, an EntityFactory): exactly one of `sdf` (SDF or URDF text),
  `sdf_filename` (an absolute path) and `clone_name` (an entity spawned again from its own
  request); `name` (empty: twin's default), `allow_renaming` (a taken name gets `_1`, `_2`, …
  as gz-sim renames), `pose` in `relative_to` ("" or "world": the world; else an entity).
  Text and files read only the world's package and model paths, as `/spawn_entity`'s do.
- `remove` (DeleteEntity) and `set_pose` (SetEntityPose): an Entity by name, of type MODEL (or
  NONE); ids are gz-sim's own and are refused.
- `control` (ControlWorld, a WorldControl): a rewind (`reset.all` or `time_only`: `twin reset`,
  the whole starting state, as gz-sim rewinds; `model_only`, which gz-sim does not support,
  is logged and ignored), then `pause` sets the paused state, then `step`/`multi_step` steps a
  paused world that many times; `run_to_sim_time` steps it to that time and leaves it paused.
"""

from __future__ import annotations

import logging
import math
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

from converters.errors import ConversionError
from twin_cli.errors import InvalidRequestError, TwinError
from twin_cli.files.package_env import package_roots
from twin_cli.ros.gazebo_services import peer_text, pose_in_world
from twin_cli.spawn_request import SpawnRequest

if TYPE_CHECKING:
    from twin_cli.world.engine import World

log = logging.getLogger("twin.ros")
ENTITY_NONE, ENTITY_MODEL = 0, 2  # ros_gz_interfaces/Entity's type constants
MAX_STEPS = 1_000_000  # steps one control request may ask for
STEP_CHUNK = 1000  # steps taken under the world's lock at once


def create(world: World, request: Any) -> dict[str, Any]:
    factory = request.entity_factory
    try:
        source = _source(world, factory)
        name = _name(world, factory.name, factory.allow_renaming)
        pose = pose_in_world(world, factory.pose, factory.relative_to)
        result = world.spawn(source, name=name, pose=pose)
    except (TwinError, ConversionError) as exc:
        log.warning("create: %s", exc)
        return {"success": False}
    log.info("spawned %s (/world/%s/create)", result.name, world.name)
    return {"success": True}


def remove(world: World, request: Any) -> dict[str, Any]:
    try:
        world.delete(_model_name(request.entity))
    except TwinError as exc:
        log.warning("remove: %s", exc)
        return {"success": False}
    return {"success": True}


def set_pose(world: World, request: Any) -> dict[str, Any]:
    try:
        world.set_pose(_model_name(request.entity), pose_in_world(world, request.pose, ""))
    except TwinError as exc:
        log.warning("set_pose: %s", exc)
        return {"success": False}
    return {"success": True}


def control(world: World, request: Any) -> dict[str, Any]:
    """gz-sim's order: a rewind (`reset.all` or `time_only`: the whole starting state, as
    gz-sim's rewind restores it; `model_only` gz-sim does not support: logged, nothing done),
    the paused state, then steps. A paused world steps `multi_step` (`step`: 1) at once; a
    `run_to_sim_time` ahead of now is stepped to, and the world is left paused there (gz-sim
    runs to it at its pace, then pauses). Checked first, so a refused request changes nothing.
    """
    wc = request.world_control
    with world.lock:
        now, h = float(world.data.time), float(world.model.opt.timestep)
    target = wc.run_to_sim_time.sec + wc.run_to_sim_time.nanosec * 1e-9
    rewind = bool(wc.reset.all or wc.reset.time_only)
    start = 0.0 if rewind else now
    steps = max(int(wc.multi_step), 1 if wc.step else 0)
    to_target = math.ceil((target - start) / h - 1e-9) if target > start else 0
    if max(steps, to_target) > MAX_STEPS:
        log.warning("control: %d steps asked, at most %d", max(steps, to_target), MAX_STEPS)
        return {"success": False}
    if wc.reset.model_only and not rewind:
        log.warning("control: a model-only reset is not supported (nor by gz-sim); ignored")
    if rewind:
        world.reset()
    if to_target > 0 or wc.pause:
        world.pause()
    else:
        world.resume()
    if world.paused:
        _step(world, max(steps, to_target))
    return {"success": True}


def _step(world: World, steps: int) -> None:
    """`steps` steps in chunks, the world's lock free between them (its server, viewers and
    publishers keep answering)."""
    while steps > 0:
        chunk = min(steps, STEP_CHUNK)
        world.step(chunk)
        steps -= chunk


def _source(world: World, factory: Any) -> SpawnRequest:
    """The spawn request of an EntityFactory's one source."""
    given = [f for f in ("sdf", "sdf_filename", "clone_name") if getattr(factory, f)]
    if len(given) != 1:
        raise InvalidRequestError(
            "entity_factory", f"sets {', '.join(given) or 'none'} of sdf, sdf_filename and "
            "clone_name", "set exactly one",
        )  # fmt: skip
    if factory.sdf:
        return peer_text(factory.sdf)
    if factory.sdf_filename:
        if not Path(factory.sdf_filename).is_absolute():
            raise InvalidRequestError(
                f"sdf_filename [{factory.sdf_filename}]", "is relative",
                "give an absolute path: the server's folder is not the caller's",
            )  # fmt: skip
        return SpawnRequest(factory.sdf_filename, read_roots=package_roots())
    return replace(world.entity(factory.clone_name).request)


def _name(world: World, name: str, allow_renaming: bool) -> str | None:
    """`name`, or with `allow_renaming` the first free `name_N` when it is taken."""
    if not name or not allow_renaming:
        return name or None
    taken = set(world.entity_names())
    n, free = 0, name
    while free in taken:
        n += 1
        free = f"{name}_{n}"
    return free


def _model_name(entity: Any) -> str:
    if entity.type not in (ENTITY_NONE, ENTITY_MODEL) or not entity.name:
        raise InvalidRequestError(
            f"entity [{entity.name or entity.id}]", "is not a model named by its name",
            "give the model's name, type MODEL (2)",
        )  # fmt: skip
    return entity.name
