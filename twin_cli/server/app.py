"""HTTP API over one World (FastAPI): validated requests, twin's errors as 4xx JSON bodies.

Endpoints are plain `def` functions, so FastAPI runs them in its thread pool and the event
loop keeps answering while one waits for the world's lock (a spawn may convert for seconds).
The world steps in its own thread; nothing here does physics. `twin_cli.server.process` runs it.
"""

from __future__ import annotations

import dataclasses
import logging
import os
import secrets
from typing import Any

from fastapi import APIRouter, FastAPI, Request
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse
from pydantic import BaseModel
from starlette.exceptions import HTTPException as StarletteHTTPException

from converters.errors import ConversionError
from twin_cli.errors import (
    EntityExistsError,
    EntityNotFoundError,
    PartNotFoundError,
    RequestError,
    TwinError,
)
from twin_cli.server import consumer_routes, control_routes, sensor_routes, view_routes
from twin_cli.server.holder import WorldDep, WorldHolder
from twin_cli.server.models import (
    CommandBody,
    GravityBody,
    PathBody,
    PhysicsBody,
    PoseBody,
    PushBody,
    ResetBody,
    SpawnBatchBody,
    SpawnBody,
    StepBody,
)
from twin_cli.server.operations import Operations

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
def save(body: PathBody, world: WorldDep) -> dict:
    from twin_cli.world import savefile

    savefile.save(world, body.path)
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
    return {"loaded": body.path, "entities": [e.name for e in new_world.entities()], **followed}


@router.post("/shutdown")
def shutdown(request: Request) -> dict:
    """End the server after this reply (what `twin stop` asks)."""
    request.app.state.request_exit()
    return {"stopping": request.app.state.world_name}


# Status of each error class; other TwinError and ConversionError subclasses are 400.
ERROR_STATUS: dict[type[Exception], int] = {
    EntityNotFoundError: 404,
    PartNotFoundError: 404,
    EntityExistsError: 409,
}


class ErrorBody(BaseModel):
    """Every error reply: the error's class (the client raises it again) and one message."""

    error: str
    message: str


# Documented on every operation, so the OpenAPI schema is the whole contract (422 included:
# validation errors use this body too, not FastAPI's default).
ERROR_RESPONSES: dict[int | str, dict[str, Any]] = {
    status: {"model": ErrorBody, "description": text}
    for status, text in (
        (400, "bad request: the message names the value and the fix"),
        (401, "TCP request without the bearer token"),
        (404, "no such entity, joint, link or sensor"),
        (409, "the name is taken"),
        (422, "the body does not match the request schema"),
        (500, "internal error; the world keeps running"),
    )
}


def _error(status: int, name: str, message: str) -> JSONResponse:
    return JSONResponse(status_code=status, content={"error": name, "message": message})


def _known_error(request: Request, exc: Exception) -> JSONResponse:
    """TwinError/ConversionError: the class name and its message (what, where, fix)."""
    status = next((s for cls, s in ERROR_STATUS.items() if isinstance(exc, cls)), 400)
    log.info(
        "%s %s -> %d %s: %s", request.method, request.url.path, status, type(exc).__name__, exc
    )
    return _error(status, type(exc).__name__, str(exc))


def _validation_error(request: Request, exc: RequestValidationError) -> JSONResponse:
    """pydantic's findings as one line naming each bad field."""
    problems = "; ".join(
        f"{'.'.join(str(p) for p in err['loc'] if p != 'body') or 'body'}: "
        f"{err['msg'].removeprefix('Value error, ')}"
        for err in exc.errors()
    )
    message = str(
        RequestError(
            f"{request.method} {request.url.path}",
            problems,
            "see docs/api.md or /openapi.json for the request schema",
        )
    )
    return _error(422, "RequestError", message)


def _http_error(request: Request, exc: StarletteHTTPException) -> JSONResponse:
    """Starlette's own refusals (a body that is not JSON, an unknown path) in twin's error body."""
    message = str(
        RequestError(
            f"{request.method} {request.url.path}",
            str(exc.detail),
            "see docs/api.md or /openapi.json for the request schema",
        )
    )
    return _error(exc.status_code, "RequestError", message)


def _os_error(request: Request, exc: OSError) -> JSONResponse:
    """A file the request named cannot be read or written on the server's host."""
    where = exc.filename or request.url.path
    message = str(
        RequestError(
            str(where),
            exc.strerror or str(exc),
            "give a path that exists and is readable on the server's host",
        )
    )
    return _error(400, "RequestError", message)


def _value_error(request: Request, exc: ValueError) -> JSONResponse:
    message = str(
        RequestError(
            f"{request.method} {request.url.path}",
            str(exc),
            "check the values against `twin physics`/docs/api.md",
        )
    )
    return _error(400, "RequestError", message)


def _unexpected(request: Request, exc: Exception) -> JSONResponse:
    """Any other failure: logged with its traceback; the server and the world keep running."""
    log.exception("%s %s failed", request.method, request.url.path)
    message = str(
        RequestError(
            f"{request.method} {request.url.path}",
            f"internal error {type(exc).__name__}: {exc}",
            "see `twin logs`; the world is still running",
        )
    )
    return _error(500, "RequestError", message)


class TokenGuard:
    """ASGI middleware: requests that arrive over TCP must carry `Authorization: Bearer TOKEN`.

    Unix-socket requests pass (the 0700 directory and 0600 socket already restrict them to
    the user). uvicorn reports a Unix socket's scope["server"] as (path, None).
    """

    def __init__(self, app: Any, token: str | None) -> None:
        self.app = app
        self.expected = f"Bearer {token}".encode() if token else None

    async def __call__(self, scope: dict, receive: Any, send: Any) -> None:
        server = scope.get("server") or (None, None)
        if scope["type"] == "http" and server[1] is not None:
            given = dict(scope.get("headers") or []).get(b"authorization", b"")
            if self.expected is None or not secrets.compare_digest(given, self.expected):
                reply = _error(
                    401,
                    "RequestError",
                    "missing or wrong bearer token; send "
                    "`Authorization: Bearer <contents of the world's .token file>`",
                )
                await reply(scope, receive, send)
                return
        await self.app(scope, receive, send)


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
        view_routes.router,
    ):
        app.include_router(routes, responses=ERROR_RESPONSES)
    app.add_exception_handler(TwinError, _known_error)
    app.add_exception_handler(ConversionError, _known_error)
    app.add_exception_handler(RequestValidationError, _validation_error)
    app.add_exception_handler(StarletteHTTPException, _http_error)
    app.add_exception_handler(OSError, _os_error)
    app.add_exception_handler(ValueError, _value_error)
    app.add_exception_handler(Exception, _unexpected)
    app.add_middleware(TokenGuard, token=token)
    return app
