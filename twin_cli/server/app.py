"""HTTP API over one World (FastAPI): validated requests, twin's errors as 4xx JSON bodies.

Endpoints are plain `def` functions, so FastAPI runs them in its thread pool and the event
loop keeps answering while one waits for the world's lock (a spawn may convert for seconds).
The world steps in its own thread; nothing here does physics. `twin_cli.server.process` runs it.
"""

from __future__ import annotations

import dataclasses
import logging
import os
from typing import Any

from fastapi import APIRouter, FastAPI, Request

from twin_cli.server import (
    consumer_routes,
    control_routes,
    live_routes,
    ros_routes,
    sensor_routes,
    view_routes,
)
from twin_cli.server.body_limit import BodyLimit
from twin_cli.server.error_replies import ERROR_RESPONSES, install_handlers
from twin_cli.server.holder import WorldDep, WorldHolder
from twin_cli.server.models import (
    CommandBody,
    GravityBody,
    PathBody,
    PhysicsBody,
    PoseBody,
    PushBody,
    ResetBody,
    SaveBody,
    SpawnBatchBody,
    SpawnBody,
    StepBody,
)
from twin_cli.server.operations import Operations
from twin_cli.server.token_guard import TokenGuard

log = logging.getLogger("twin.server")
API_VERSION = "1"


router = APIRouter()


def _plain(value: Any) -> Any:
    """Dataclasses (and lists of them) as JSON-ready dicts."""
    if dataclasses.is_dataclass(value):
        return dataclasses.asdict(value)
    if isinstance(value, list):
        return [_plain(v) for v in value]
    return value


@router.get("/health")
def health(request: Request) -> dict:
    """Liveness probe: the world's name and the server's pid."""
    state = request.app.state
    return {"world": state.world_name, "pid": os.getpid(), "api": API_VERSION}


@router.get("/stats")
def stats(world: WorldDep) -> dict:
    """gz-stats figures: factor (last 20 samples of 0.2 s), sim_time [s], real_time [s]."""
    return _plain(world.stats())


@router.get("/entities")
def entities(world: WorldDep) -> list[dict]:
    return _plain(world.entities())


@router.post("/entities", status_code=201)
def spawn(body: SpawnBody, world: WorldDep, request: Request) -> dict:
    """Spawn a URDF/xacro/SDF/MJCF file or text; replies once the entity exists (gazebo_ros).

    A repeat with the same `Idempotency-Key` header gets the first request's outcome.
    """
    key = request.headers.get("idempotency-key")
    return request.app.state.operations.run(key, lambda: _spawn(body, world))


def _spawn(body: SpawnBody, world: Any) -> dict:
    result = world.spawn(body.request(), name=body.name, pose=_pose(body.pose))
    log.info("spawned %s from %s", result.name, body.source or "<xml>")
    return _plain(result)


@router.post("/entities/batch", status_code=201)
def spawn_batch(body: SpawnBatchBody, world: WorldDep, request: Request) -> list[dict]:
    """Spawn one file or text at many poses: one conversion, one recompile, all or nothing.

    A repeat with the same `Idempotency-Key` header gets the first request's outcome.
    """
    key = request.headers.get("idempotency-key")
    return request.app.state.operations.run(key, lambda: _spawn_batch(body, world))


def _spawn_batch(body: SpawnBatchBody, world: Any) -> list[dict]:
    poses = [_pose(p) for p in body.poses]
    results = world.spawn_batch(body.request(), poses=poses, names=body.names, base=body.name)
    log.info("spawned %d entities from %s", len(results), body.source or "<xml>")
    return _plain(results)


@router.delete("/entities/{name}")
def delete(name: str, world: WorldDep, request: Request) -> dict:
    """Delete an entity; a repeat with the same `Idempotency-Key` gets the first's outcome."""

    def work() -> dict:
        world.delete(name)
        log.info("deleted %s", name)
        return {"deleted": name}

    return request.app.state.operations.run(request.headers.get("idempotency-key"), work)


@router.get("/entities/{name}/pose")
def get_pose(name: str, world: WorldDep) -> dict:
    return world.get_pose(name).to_dict()


@router.put("/entities/{name}/pose")
def set_pose(name: str, body: PoseBody, world: WorldDep) -> dict:
    world.set_pose(name, _pose(body))
    return world.get_pose(name).to_dict()


def _pose(body: PoseBody) -> Any:
    """The world's Pose from a request pose (roll-pitch-yaw, or a quaternion x, y, z, w)."""
    from twin_cli.world import Pose

    if body.quat is None:
        return Pose(**body.model_dump(exclude={"quat"}))
    x, y, z, w = body.quat
    return Pose.from_quat(body.x, body.y, body.z, (w, x, y, z))


@router.get("/entities/{name}/joints")
def joints(name: str, world: WorldDep) -> list[dict]:
    return _plain(world.joint_states(name))


@router.get("/entities/{name}/links")
def links(name: str, world: WorldDep) -> dict:
    return {link: pose.to_dict() for link, pose in world.link_poses(name).items()}


@router.post("/entities/{name}/push")
def push(name: str, body: PushBody, world: WorldDep) -> dict:
    world.push(name, body.force, body.torque, link=body.link, duration=body.duration)
    return {
        "pushed": name,
        "link": body.link,
        "force": list(body.force),
        "torque": list(body.torque),
        "duration": body.duration,
    }


@router.post("/entities/{name}/command")
def command(name: str, body: CommandBody, world: WorldDep) -> dict:
    world.command(name, body.joint, mode=body.mode, value=body.value)
    return {"commanded": name, "joint": body.joint}


@router.get("/gravity")
def get_gravity(world: WorldDep) -> dict:
    return {"gravity": list(world.gravity())}


@router.put("/gravity")
def set_gravity(body: GravityBody, world: WorldDep) -> dict:
    from twin_cli.world import GRAVITY_PRESETS

    vector = GRAVITY_PRESETS[body.preset] if body.preset else body.vector
    world.set_gravity(tuple(float(v) for v in vector))
    log.info("gravity set to %s", vector)
    return {"gravity": list(world.gravity())}


@router.get("/physics")
def get_physics(world: WorldDep) -> dict:
    return world.physics()


@router.put("/physics")
def set_physics(body: PhysicsBody, world: WorldDep) -> dict:
    return world.set_physics(**body.model_dump())


@router.post("/pause")
def pause(world: WorldDep) -> dict:
    world.pause()
    return {"paused": True}


@router.post("/resume")
def resume(world: WorldDep) -> dict:
    world.resume()
    return {"paused": False}


@router.post("/step")
def step(body: StepBody, world: WorldDep) -> dict:
    world.step(body.n)
    return _plain(world.stats())


@router.post("/reset")
def reset(body: ResetBody, world: WorldDep) -> dict:
    world.reset(time_only=body.time_only)
    return _plain(world.stats())


@router.post("/save")
def save(body: SaveBody, world: WorldDep) -> dict:
    from twin_cli.world import savefile

    savefile.save(world, body.path, force=body.force)
    return {"saved": body.path}


@router.post("/load")
def load(body: PathBody, request: Request) -> dict:
    """Replace the served world by one read from a file: `twin save` JSON or an SDF world."""
    from twin_cli.world.sdf_world import load_world

    new_world = load_world(body.path, name=request.app.state.world_name)
    request.app.state.holder.replace(new_world)
    log.info("loaded world from %s", body.path)
    consumers = getattr(request.app.state, "consumers", None)  # recording, Foxglove stream
    followed = consumers.follow(new_world) if consumers is not None else {}
    ros = getattr(request.app.state, "ros", None)  # the ROS 2 bridge
    followed.update(ros.follow(new_world) if ros is not None else {})
    return {"loaded": body.path, "entities": [e.name for e in new_world.entities()], **followed}


@router.post("/shutdown")
def shutdown(request: Request) -> dict:
    """End the server after this reply (what `twin stop` asks)."""
    request.app.state.request_exit()
    return {"stopping": request.app.state.world_name}


def create_app(
    world: Any, *, world_name: str = "default", token: str | None = None, request_exit: Any = None
) -> FastAPI:
    """The HTTP API over `world` (a started or unstarted `twin_cli.world.engine.World`).

    Args:
        world: the world to serve.
        world_name: reported by `/health`; clients check it.
        token: bearer token required on TCP connections (None: TCP refused).
        request_exit: called by `POST /shutdown` to end the server.
    """
    app = FastAPI(
        title="twin world server",
        version=API_VERSION,
        description="One running MuJoCo world; see docs/api.md.",
    )
    app.state.holder = WorldHolder(world)
    app.state.operations = Operations()
    app.state.world_name = world_name
    app.state.request_exit = request_exit or (lambda: None)
    for routes in (
        router,
        consumer_routes.router,
        sensor_routes.router,
        control_routes.router,
        live_routes.router,
        ros_routes.router,
        view_routes.router,
    ):
        app.include_router(routes, responses=ERROR_RESPONSES)
    install_handlers(app)
    app.add_middleware(TokenGuard, token=token)
    app.add_middleware(BodyLimit)  # outermost: a huge body is refused before anything reads it
    return app
