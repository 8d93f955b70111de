"""HTTP client of a world server over its Unix socket; server errors come back as the same class.

Imports the standard library only (`http.client` through `transport`): never mujoco, numpy,
trimesh, coacd, fastapi, uvicorn or httpx, so a client command costs little more than Python's
own start-up.
"""

from __future__ import annotations

import json
import os
from collections.abc import Generator, Iterator
from dataclasses import replace
from pathlib import Path
from typing import Any

from twin_cli import errors as twin_errors
from twin_cli.errors import NoReplyError, NotRunningError, RequestError
from twin_cli.files.package_env import package_env
from twin_cli.server import runtime
from twin_cli.server.transport import NOT_ANSWERING, Http, path_segment
from twin_cli.spawn_request import SpawnRequest, as_request, body_key

# Seconds: most requests are a lock and a copy; spawn, delete and load wait in `long_request`.
DEFAULT_TIMEOUT_S = 10.0
HEALTH_TIMEOUT_S = 2.0  # [s] one look at /health; a live server is looked at again until it answers


def _error_class(name: str) -> type[Exception] | None:
    """The TwinError/ConversionError subclass called `name`, from the two errors modules.

    `converters` is imported only on this error path, so a client command that succeeds
    never loads the converter package.
    """
    cls = getattr(twin_errors, name, None)
    if isinstance(cls, type) and issubclass(cls, twin_errors.TwinError):
        return cls
    from converters import errors as conversion_errors

    cls = getattr(conversion_errors, name, None)
    if isinstance(cls, type) and issubclass(cls, conversion_errors.ConversionError):
        return cls
    return None


def rebuild_error(status: int, body: Any) -> Exception:
    """Turn a server's error body `{"error": class, "message": text}` into that exception.

    The class's constructor takes facts, not a message, so the instance is made without it
    and given the server's message, which already names the subject and the fix.
    """
    if not isinstance(body, dict) or "message" not in body:
        return RequestError(f"HTTP {status}", str(body)[:500], "see `twin logs`")
    cls = _error_class(str(body.get("error", "")))
    if cls is None:
        return RequestError(str(body.get("error", "request")), body["message"], "see `twin logs`")
    exc = cls.__new__(cls)
    Exception.__init__(exc, body["message"])
    return exc


class Client:
    """One world server, reached through its Unix socket (or TCP with a bearer token)."""

    def __init__(
        self,
        world: str = runtime.DEFAULT_WORLD,
        *,
        url: str | None = None,
        token: str | None = None,
    ) -> None:
        """Args:
        world: world name; selects the socket in the runtime directory.
        url: `http://host:port` to use TCP instead of the socket (needs `token`).
        token: bearer token for TCP (the server's `<world>.token` file).
        """
        self.world = world
        self.paths = runtime.world_paths(world)
        headers = {"Authorization": f"Bearer {token}"} if token else {}
        self._url = url
        self._http = Http(
            socket_path=None if url else str(self.paths.socket),
            url=url,
            headers=headers,
            timeout=DEFAULT_TIMEOUT_S,
        )

    def close(self) -> None:
        """Release the transport (each request has its own connection)."""
        self._http.close()

    def __enter__(self) -> Client:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def request(
        self, method: str, path: str, *, body: Any = None, timeout: float | None = None
    ) -> Any:
        """Send one request and return the decoded JSON reply.

        Without `timeout`, a client on the world's socket waits as long as the server process
        lives (a loaded machine may answer late) and `$TWIN_TIMEOUT` allows
        (`twin_cli.server.patience`); over TCP, whose server's process cannot be seen, it waits
        DEFAULT_TIMEOUT_S.

        Raises:
            NotRunningError: no server listens for this world, or it ended before replying.
            NoReplyError: no reply within `timeout` or the user's limit [s]; the outcome is
                unknown (exit 75).
            TwinError | ConversionError: the server's error, as the same class.
        """
        from twin_cli.server import patience

        waiter = None
        if timeout is None and self._url is None:
            waiter = patience.Waiter(self.paths, f"{method} {path}", patience.limit())
        fixed = timeout if timeout is not None else DEFAULT_TIMEOUT_S
        try:
            reply = self._http.request(
                method, path, json=body, timeout=None if waiter else fixed, patience=waiter
            )
        except TimeoutError as exc:
            waited = fixed if waiter is None else (waiter.limit_s or 0.0)
            raise NoReplyError(self.world, f"{method} {path}", waited) from exc
        except NOT_ANSWERING as exc:
            raise NotRunningError(self.world) from exc
        finally:
            if waiter is not None:
                waiter.done()
        return _decoded(reply)

    def long_request(
        self,
        method: str,
        path: str,
        *,
        body: Any = None,
        what: str,
        repeat: str,
        repeatable: bool = True,
    ) -> Any:
        """A request that may take long (spawn, delete, load, step): waited for while the server
        lives, up to `$TWIN_TIMEOUT` seconds if set (`twin_cli.server.patience`).

        Its idempotency key is kept when the outcome is unknown, under the identity of the exact
        request (method, path and body), so that the same command run again is answered with
        the first one's outcome, and any other request is not.

        Args:
            what: the request for people, e.g. "delete [box]".
            repeat: the command line that repeats it.
            repeatable: False for a request that, run again, is meant to act again (a step).

        Raises:
            OutcomeUnknownError: the limit passed without a reply; a repeat is safe.
            NotRunningError: the server is gone (died before replying).
        """
        from twin_cli.errors import OutcomeUnknownError
        from twin_cli.server import lifecycle, patience

        operation = body_key(method, path, body) if repeatable else None
        key = patience.take_key(self.paths, operation)
        waiter = patience.Waiter(None if self._url else self.paths, what, patience.limit())
        try:
            reply = self._http.request(
                method, path, json=body, headers={patience.KEY_HEADER: key}, patience=waiter
            )
        except TimeoutError as exc:
            patience.keep_key(self.paths, operation, key)
            raise OutcomeUnknownError(self.world, what, waiter.limit_s or 0, repeat) from exc
        except NOT_ANSWERING as exc:
            raise NotRunningError(self.world, lifecycle.not_running_detail(self.paths)) from exc
        finally:
            waiter.done()
        return _decoded(reply)

    def alive(self) -> bool:
        """True when the server answers `/health` for this world within HEALTH_TIMEOUT_S (a busy
        server that answers later is waited for by `connection.connect`)."""
        try:
            reply = self.request("GET", "/health", timeout=HEALTH_TIMEOUT_S)
        except (NotRunningError, RequestError, NoReplyError):
            return False
        return reply.get("world") == self.world

    def stream(self, path: str) -> Generator[dict, None, None]:
        """The JSON objects of a streamed reply (`/topics/echo`), one per line, as they come;
        heartbeat lines are skipped. Closing the iterator closes the connection.

        Raises:
            NotRunningError: no server listens. TwinError: the server's error, as its class.
        """
        try:
            error, lines = self._http.lines(path)
        except TimeoutError as exc:
            raise NoReplyError(self.world, f"GET {path}", DEFAULT_TIMEOUT_S) from exc
        except NOT_ANSWERING as exc:
            raise NotRunningError(self.world) from exc
        if error is not None:
            _decoded(error)
        return self._objects(lines)

    def _objects(self, lines: Iterator[bytes]) -> Generator[dict, None, None]:
        try:
            for line in lines:
                if not line.strip():
                    continue
                item = json.loads(line)
                if "error" in item and "topic" not in item:  # the stream's last line
                    raise rebuild_error(500, item)
                yield item
        except NOT_ANSWERING as exc:  # the server ended mid-stream (`twin stop`)
            raise NotRunningError(self.world) from exc
        finally:
            close = getattr(lines, "close", None)
            if close is not None:
                close()

    # World commands, one per endpoint (see docs/api.md).
    def stats(self) -> dict:
        return self.request("GET", "/stats")

    def entities(self) -> list[dict]:
        return self.request("GET", "/entities")

    def spawn(
        self,
        request: SpawnRequest | str | os.PathLike,
        *,
        name: str | None = None,
        pose: dict[str, Any] | None = None,
    ) -> dict:
        """Spawn the request's file or text as `name` at `pose` (the server's reply).

        Paths are made absolute here (the server has its own working directory), and this
        process's package search variables go along (`twin_cli.files.package_env`).
        """
        body = {**self._request_body(request), "name": name, "pose": pose or {}}
        label = name or as_request(request).label
        return self.long_request(
            "POST",
            "/entities",
            body=body,
            what=f"spawn [{label}]",
            repeat="the same twin spawn command",
        )

    def spawn_batch(
        self,
        request: SpawnRequest | str | os.PathLike,
        *,
        poses: list[dict[str, Any]],
        names: list[str] | None = None,
        base: str | None = None,
    ) -> list[dict]:
        """Spawn the request at every pose in one request, all or nothing: entities `names`,
        else `base_0`, `base_1`, … Returns one result per pose, in order."""
        body = {**self._request_body(request), "name": base, "poses": poses, "names": names}
        label = ",".join(names) if names else base or as_request(request).label
        return self.long_request(
            "POST",
            "/entities/batch",
            body=body,
            what=f"spawn of {len(poses)} entities [{label}]",
            repeat="the same twin spawn ... --at ... command",
        )

    @staticmethod
    def _request_body(request: SpawnRequest) -> dict[str, Any]:
        return replace(as_request(request), env=package_env()).absolute().to_body()

    def delete(self, name: str) -> dict:
        return self.long_request(
            "DELETE",
            f"/entities/{_seg(name)}",
            what=f"delete [{name}]",
            repeat=f"twin delete {name} --world {self.world}",
        )

    def pose(self, name: str) -> dict:
        return self.request("GET", f"/entities/{_seg(name)}/pose")

    def set_pose(self, name: str, pose: dict[str, float]) -> dict:
        return self.request("PUT", f"/entities/{_seg(name)}/pose", body=pose)

    def joints(self, name: str) -> list[dict]:
        return self.request("GET", f"/entities/{_seg(name)}/joints")

    def command_joints(self, name: str, targets: dict[str, float], mode: str) -> dict:
        body = {"mode": mode, "targets": targets}
        return self.request("POST", f"/entities/{_seg(name)}/commands", body=body)

    def joint_control(self, name: str) -> list[dict]:
        return self.request("GET", f"/entities/{_seg(name)}/control")

    def trajectory(self, name: str, trajectory: dict, rate: float = 100.0) -> dict:
        body = {**trajectory, "rate": rate}
        return self.request("POST", f"/entities/{_seg(name)}/trajectory", body=body)

    def trajectory_status(self, name: str) -> dict:
        return self.request("GET", f"/entities/{_seg(name)}/trajectory")

    def links(self, name: str) -> dict:
        return self.request("GET", f"/entities/{_seg(name)}/links")

    def push(
        self,
        name: str,
        force: tuple,
        torque: tuple,
        *,
        link: str | None = None,
        duration: float = 0.1,
    ) -> dict:
        body = {"force": list(force), "torque": list(torque), "link": link, "duration": duration}
        return self.request("POST", f"/entities/{_seg(name)}/push", body=body)

    def command(self, name: str, joint: str, *, mode: str, value: float) -> dict:
        body = {"joint": joint, "mode": mode, "value": value}
        return self.request("POST", f"/entities/{_seg(name)}/command", body=body)

    def gravity(self) -> dict:
        return self.request("GET", "/gravity")

    def set_gravity(self, *, preset: str | None = None, vector: tuple | None = None) -> dict:
        body = {"preset": preset, "vector": list(vector) if vector is not None else None}
        return self.request("PUT", "/gravity", body=body)

    def physics(self) -> dict:
        return self.request("GET", "/physics")

    def set_physics(self, **changes: Any) -> dict:
        return self.request("PUT", "/physics", body=changes)

    def pause(self) -> dict:
        return self.request("POST", "/pause")

    def resume(self) -> dict:
        return self.request("POST", "/resume")

    def step(self, n: int = 1) -> dict:
        return self.long_request(
            "POST",
            "/step",
            body={"n": n},
            what=f"step {n}",
            repeat=f"twin step {n}",
            repeatable=False,  # a step run again is another step, never a replay
        )

    def reset(self, *, time_only: bool = False) -> dict:
        return self.request("POST", "/reset", body={"time_only": time_only})

    def save(self, path: str | os.PathLike, *, force: bool = False) -> dict:
        body = {"path": str(Path(path).absolute()), "force": force}
        return self.request("POST", "/save", body=body)

    def load(self, path: str | os.PathLike) -> dict:
        body = {"path": str(Path(path).absolute())}
        return self.long_request(
            "POST",
            "/load",
            body=body,
            what=f"load {body['path']}",
            repeat=f"twin load {body['path']}",
        )


def _decoded(reply: Any) -> Any:
    """A reply's JSON (or text); an error reply raised as the server's exception class."""
    try:
        payload = reply.json()
    except ValueError:
        payload = reply.text
    if reply.is_error:
        raise rebuild_error(reply.status_code, payload)
    return payload


def _seg(name: str) -> str:
    """An entity name as one URL path segment."""
    return path_segment(name)
