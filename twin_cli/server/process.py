"""Runs one world server process: owns its runtime files, binds sockets, serves until stopped."""

from __future__ import annotations

import contextlib
import ipaddress
import logging
import os
import secrets
import signal
import socket
import sys
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from twin_cli.errors import RequestError
from twin_cli.server import runtime
from twin_cli.server.autosave import DEFAULT_INTERVAL_S

log = logging.getLogger("twin.server")
LOG_FORMAT = "%(asctime)s %(levelname)s %(name)s: %(message)s"


@dataclass(frozen=True)
class ServeOptions:
    """What `twin serve` was asked for.

    Attributes:
        world: world name (one server per name).
        world_file: a Gazebo SDF world, an MJCF scene, a world saved by `twin save`, or None
            (empty world).
        rate: real-time update rate [Hz]; 0 = unthrottled; None = the world's default.
        step: physics timestep [s]; None = the world's default.
        paused: start paused.
        tcp: `HOST:PORT` or `PORT` for an extra TCP listener with a bearer token.
        background: started by a client that holds the world's start lock.
        record: a rosbag2 MCAP file to record into from the start (100 Hz), or None.
        foxglove: a port for a live Foxglove WebSocket stream (127.0.0.1), or None.
        ros: publish on the ROS 2 graph over DDS from the start (`twin_cli.ros`).
        ros_interface: the network interface the ROS 2 participant uses (None: loopback).
        ros_services: answer gazebo_ros' entity services (spawn, delete) over DDS too.
        autosave: seconds between autosaves to `<world>.autosave.json`; 0 turns it off.
        view: serve MuJoCo's web viewer on 127.0.0.1 from the start.
        package_paths: package or model name → directory for an SDF world's `model://` and
            `package://` (`--package`), searched before GAZEBO_MODEL_PATH and the rest.
    """

    world: str = runtime.DEFAULT_WORLD
    world_file: str | None = None
    rate: float | None = None
    step: float | None = None
    paused: bool = False
    tcp: str | None = None
    background: bool = False
    record: str | None = None
    foxglove: int | None = None
    autosave: float = DEFAULT_INTERVAL_S
    view: bool = False
    package_paths: dict[str, str] | None = None
    ros: bool = False
    ros_interface: str | None = None
    ros_services: bool = False


def parse_tcp(text: str) -> tuple[str, int]:
    """`HOST:PORT` or `PORT` (loopback) as (host, port).

    Raises:
        RequestError: not a host and port.
    """
    host, _, port = text.rpartition(":")
    host = host.strip("[]") or "127.0.0.1"
    host = "127.0.0.1" if host == "localhost" else host
    try:
        number = int(port)
        ipaddress.ip_address(host)
    except ValueError as exc:
        raise RequestError(
            f"--tcp {text}",
            "is not HOST:PORT with an IP address",
            "use e.g. --tcp 127.0.0.1:8765 or --tcp 8765",
        ) from exc
    if not 0 <= number <= 65535:
        raise RequestError(f"--tcp {text}", f"port {number} is out of range", "use 0-65535")
    return host, number


def bind_unix(path: Path) -> socket.socket:
    """A listening Unix socket at `path`, created with mode 0600 (no window where it is wider)."""
    with contextlib.suppress(FileNotFoundError):
        path.unlink()  # a stale socket of a dead server; we own the pid lock here
    sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    old_umask = os.umask(0o177)
    try:
        sock.bind(str(path))
    finally:
        os.umask(old_umask)
    path.chmod(0o600)
    return sock


def bind_tcp(host: str, port: int) -> socket.socket:
    """A TCP socket bound to (host, port); port 0 picks a free one."""
    family = socket.AF_INET6 if ":" in host else socket.AF_INET
    sock = socket.socket(family, socket.SOCK_STREAM)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    sock.bind((host, port))
    return sock


def write_private(path: Path, text: str) -> None:
    """Write `text` to a file created with mode 0600."""
    fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
    with os.fdopen(fd, "w") as handle:
        handle.write(text)


MAX_NOTES = 20  # world-file notes printed by a foreground serve; all go to the log


def build_world(opts: ServeOptions) -> Any:
    """The world to serve, loaded or empty, with the requested rate, step and pause state."""
    from twin_cli.world import World, WorldSettings
    from twin_cli.world.sdf_world import load_world

    changes = {k: v for k, v in (("timestep", opts.step), ("rate", opts.rate)) if v is not None}
    if opts.world_file:
        world = load_world(opts.world_file, name=opts.world, package_paths=opts.package_paths)
        for k, note in enumerate(world.file_notes):  # in the log, and where the user looks
            log.warning("%s: %s", opts.world_file, note)
            if not opts.background and k < MAX_NOTES:
                sys.stderr.write(f"twin: {note}\n")
        if not opts.background and len(world.file_notes) > MAX_NOTES:
            more = len(world.file_notes) - MAX_NOTES
            sys.stderr.write(f"twin: … {more} more notes on the world file: twin logs\n")
        if changes:
            world.set_physics(**changes)
    else:
        world = World(WorldSettings(**changes), name=opts.world)
    if opts.paused:
        world.pause()
    return world


def configure_logging(paths: runtime.WorldPaths) -> None:
    """Send the server's and uvicorn's logs to the world's log file."""
    os.close(runtime.open_log(paths))  # create it private before logging opens it
    handler = logging.FileHandler(paths.log)
    handler.setFormatter(logging.Formatter(LOG_FORMAT))
    root = logging.getLogger()
    root.addHandler(handler)
    root.setLevel(logging.INFO)


def _terminate(signum: int, frame: Any) -> None:
    """SIGTERM: unwind through every `finally`, so files are removed and the world stopped."""
    raise SystemExit(0)


@contextlib.contextmanager
def owned_world(paths: runtime.WorldPaths, background: bool) -> Iterator[None]:
    """Hold the world's pid lock; a foreground server also takes the start lock to get it.

    A dead predecessor is reported (log, and stderr in the foreground) before this server's run
    record replaces its own (`twin_cli.server.lifecycle`).
    """
    from twin_cli.server import lifecycle

    with contextlib.ExitStack() as stack:
        if background:  # our starter holds the start lock until we answer
            stack.enter_context(runtime.hold_pid_file(paths))
            died = lifecycle.retire(paths)
        else:
            with runtime.start_lock(paths):
                stack.enter_context(runtime.hold_pid_file(paths))
                died = lifecycle.retire(paths)
        if died:
            log.warning("%s", died)
            if not background:
                sys.stderr.write(f"twin: {died}\n")
        yield


@contextlib.contextmanager
def run_recorded(paths: runtime.WorldPaths, opts: ServeOptions) -> Iterator[Path | None]:
    """Write the run record; remove it only when the server ends in order.

    Yields:
        The autosave file, or None when autosave is off.
    """
    from converters.errors import ConversionError
    from twin_cli.errors import TwinError
    from twin_cli.server import lifecycle

    autosave = lifecycle.autosave_path(paths) if opts.autosave > 0 else None
    lifecycle.started(paths, autosave=autosave, supervised=opts.background)
    try:
        yield autosave
    except (KeyboardInterrupt, SystemExit) as exc:
        if not isinstance(exc, SystemExit) or exc.code in (0, None):
            lifecycle.ended_in_order(paths)
        raise
    except (ConversionError, TwinError) as exc:  # refused its world or options: an orderly end
        log.error("world [%s] not served: %s", opts.world, exc)
        lifecycle.ended_in_order(paths)
        raise
    else:
        lifecycle.ended_in_order(paths)


def serve(opts: ServeOptions) -> None:
    """Serve one world until `twin stop`, SIGTERM or SIGINT; always clean up runtime files.

    Raises:
        WorldRunningError: a server for this world already runs.
    """
    from twin_cli.view.offscreen import use_egl

    use_egl()  # before mujoco's first import: snapshots render offscreen on EGL
    import uvicorn

    from twin_cli.server.app import create_app

    paths = runtime.world_paths(opts.world)
    signal.signal(signal.SIGTERM, _terminate)
    configure_logging(paths)
    tcp = parse_tcp(opts.tcp) if opts.tcp else None
    token = secrets.token_urlsafe(32) if tcp else None
    with owned_world(paths, opts.background), run_recorded(paths, opts) as autosave_file:
        _bound_conversions()  # before the world file: its models' CoACD goes to the background
        world = build_world(opts)
        app = create_app(
            world,
            world_name=opts.world,
            token=token,
            request_exit=lambda: setattr(server, "should_exit", True),
        )
        config = uvicorn.Config(
            app, log_config=None, access_log=False, lifespan="off", timeout_graceful_shutdown=5
        )
        server = uvicorn.Server(config)
        app.state.exiting = lambda: server.should_exit  # streamed replies end on their own
        _end_conversions_on_exit(server)
        consumers = _start_consumers(app, world, opts)
        saver = _autosaver(app, autosave_file, opts.autosave)
        try:
            world.start()
            saver.start()
            sockets = _listen(paths, tcp, token)
            log.info("serving world [%s] on %s (pid %d)", opts.world, paths.socket, os.getpid())
            if not opts.background:
                sys.stderr.write(
                    f"twin: serving world [{opts.world}] on {paths.socket}; log {paths.log}\n"
                )
            if opts.view:
                _start_view(app)
            with contextlib.suppress(KeyboardInterrupt):
                server.run(sockets=sockets)
        finally:
            # already ending: a second SIGTERM (twin stop's) must not cut the cleanup short
            signal.signal(signal.SIGTERM, signal.SIG_IGN)
            _close_views(app)
            _close_ros(app)
            consumers.close()
            saver.close()
            app.state.holder.world.stop()
            log.info("world [%s] stopped", opts.world)


def _bound_conversions() -> None:
    """Conversions are bounded from now on (`converters.isolated.bounded.enable`): their fork
    server starts now, so that the first spawn finds it warm, and a world file's models leave
    their CoACD meshes to the background (`world.world_models`)."""
    from converters.isolated import bounded

    try:
        bounded.enable()
    except (OSError, RuntimeError, ValueError) as exc:  # no fork server: convert here, as before
        log.warning("conversions run in the server process: %s", exc)


def _end_conversions_on_exit(server: Any) -> None:
    """Once the server is asked to exit (twin stop, SIGTERM, Ctrl-C), stop every conversion
    still running: the requests waiting on them end, and the process with them."""
    import threading

    from converters.isolated import bounded
    from converters.urdf.xacro_worker import stop_all

    def watch() -> None:
        while not server.should_exit:
            time.sleep(0.1)
        bounded.stop_all()
        stop_all()

    threading.Thread(target=watch, name="twin-conversion-stop", daemon=True).start()


def _start_consumers(app: Any, world: Any, opts: ServeOptions) -> Any:
    """`--record` and `--foxglove`: started before the world steps, so nothing is missed."""
    from twin_cli.record.service import Consumers

    consumers = app.state.consumers = Consumers()
    try:
        if opts.record:
            consumers.record(world, opts.record)
        if opts.foxglove is not None:
            url = consumers.stream(world, port=opts.foxglove)["url"]
            sys.stderr.write(f"twin: Foxglove stream on {url}\n")
        if opts.ros or opts.ros_interface is not None or opts.ros_services:
            _start_ros(app, world, opts.ros_interface, opts.ros_services)
    except BaseException:
        _close_ros(app)
        consumers.close()
        raise
    return consumers


SERVICES_OPEN = (
    "gazebo_ros' /spawn_entity and /delete_entity answer every DDS peer in this scope (ROS 2 "
    "has no access control without SROS2)"
)


def _start_ros(app: Any, world: Any, interface: str | None, services: bool) -> None:
    """`--ros`: the world on the ROS 2 graph; its scope (and open services) on stderr."""
    from twin_cli.server.ros_routes import ros_service

    status = ros_service(app.state).start(world, interface=interface, services=services)
    sys.stderr.write(f"twin: on the ROS 2 graph: {status['scope']}\n")
    if services:
        sys.stderr.write(f"twin: {SERVICES_OPEN}\n")


def _close_ros(app: Any) -> None:
    service = getattr(app.state, "ros", None)
    if service is not None:
        service.close()


def _listen(paths: runtime.WorldPaths, tcp: tuple[str, int] | None, token: str | None) -> list:
    """The Unix socket, plus a TCP listener whose address and token go to 0600 files."""
    sockets = [bind_unix(paths.socket)]
    if tcp is None or token is None:
        return sockets
    sock = bind_tcp(*tcp)
    sockets.append(sock)
    host, port = sock.getsockname()[:2]
    write_private(paths.token, token + "\n")
    write_private(paths.tcp, f"{host}:{port}\n")
    if not ipaddress.ip_address(host).is_loopback:
        log.warning("TCP listener on non-loopback %s:%d; every request needs the token", host, port)
    return sockets


def _autosaver(app: Any, path: Path | None, interval: float) -> Any:
    """Saves whichever world the server holds (`/load` may swap it) every `interval` s."""
    from twin_cli.server.autosave import Autosaver

    saver = Autosaver(lambda: app.state.holder.world, path or Path(os.devnull), interval)
    app.state.autosaver = saver
    return saver


def _start_view(app: Any) -> None:
    """`--view`: the web viewer on 127.0.0.1; its URL on stderr."""
    from twin_cli.server.view_routes import view_service

    url = view_service(app.state).start()["url"]
    sys.stderr.write(f"twin: viewer on {url}\n")


def _close_views(app: Any) -> None:
    """Closes the web viewer, if one runs, so the page says the world went away."""
    service = getattr(app.state, "views", None)
    if service is not None:
        service.close()
