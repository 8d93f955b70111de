"""The twin's topics live over the Foxglove WebSocket protocol (foxglove-sdk), on 127.0.0.1.

Each topic is a channel with its `ros2msg` schema and CDR messages, the same bytes as in a
recording, so Foxglove decodes them as it decodes a ROS 2 bag. The server advertises the `Time`
capability and broadcasts sim time, so Foxglove's clock is the world's. Channels open and close
as entities are spawned and deleted. A latched topic's last message is sent again when a client
subscribes to it (the WebSocket protocol has no transient-local durability).

What guards it: foxglove-sdk's server (0.30) has no authentication and no Host or Origin check
(only TLS), and no hook to add one. So the SDK listens on 127.0.0.1 at a port browsers refuse to
open (`INNER_PORTS`), and the port the user asked for is a relay in its own process that checks
Host and Origin first (`twin_cli.view.foxglove_guard`): a page of another site or a DNS-rebound
name is refused, Foxglove's app and scripts get through. Any other address than loopback is
refused unless the caller passes `allow_public`. Clients can only read: no capability that acts
on the world is advertised (no client publish, parameters or services).
"""

from __future__ import annotations

import ipaddress
import logging
import os
import select
import subprocess
import sys
import threading
from typing import Any

from twin_cli.errors import RequestError
from twin_cli.record import messages as ros
from twin_cli.record.topics import Message, Topic

log = logging.getLogger("twin.foxglove")
DEFAULT_PORT = 8765  # Foxglove's own default
LOOPBACK = "127.0.0.1"
# Loopback ports every mainstream browser refuses to connect to (Chromium's and Firefox's "unsafe
# ports") that an unprivileged process may bind: the SDK listens on the first free one, so no
# page can reach it past the guard, whatever name it uses.
INNER_PORTS = (6665, 6666, 6667, 6668, 6669, 6679, 6697, 10080, 6566, 4190, 3659, 4045, 1719)
GUARD_START_S = 20.0  # [s] for the guard process to import and bind
PUBLIC_WARNING = (
    "the Foxglove stream listens on {host}:{port}, not only on this machine: it has no "
    "password, and anyone who reaches that port can watch the world's topics"
)


class _Subscriptions:
    """foxglove-sdk ServerListener: remembers topics whose latched message must be re-sent."""

    def __init__(self) -> None:
        self.lock = threading.Lock()
        self.resend: set[str] = set()

    def on_subscribe(self, client: Any, channel: Any) -> None:
        with self.lock:
            self.resend.add(channel.topic)

    def on_unsubscribe(self, client: Any, channel: Any) -> None:
        """Nothing to forget: a latched message is re-sent on the next subscription."""

    def take(self) -> set[str]:
        with self.lock:
            topics, self.resend = self.resend, set()
        return topics


class LiveStream:
    """A Foxglove WebSocket server carrying the world's topics (a recording sink)."""

    def __init__(
        self,
        port: int = DEFAULT_PORT,
        host: str = LOOPBACK,
        name: str = "twin",
        *,
        allow_public: bool = False,
    ) -> None:
        """Raises: RequestError: the port is in use, the address is not valid, or it is not
        loopback and `allow_public` is not given."""
        import foxglove
        from foxglove.websocket import Capability

        _check_address(host, port, allow_public=allow_public)
        self._context = foxglove.Context()
        self._listener = _Subscriptions()
        self._server = self._start_inner(
            lambda inner: foxglove.start_server(
                name=name,
                host=LOOPBACK,
                port=inner,
                capabilities=[Capability.Time],
                server_listener=self._listener,
                supported_encodings=["cdr"],
                context=self._context,
            )
        )
        try:
            self._guard, self._port = _start_guard(host, port, int(self._server.port))
        except RequestError:
            self._server.stop()
            raise
        self.warning: str | None = None  # what the reply and the terminal must say
        if not ipaddress.ip_address(host).is_loopback:
            self.warning = PUBLIC_WARNING.format(host=host, port=self.port)
            log.warning(self.warning)
        self._channels: dict[str, Any] = {}
        self._latched: dict[str, bytes] = {}
        self._last_time = -1

    @staticmethod
    def _start_inner(start: Any) -> Any:
        """The SDK's server on the first free port of INNER_PORTS."""
        errors = []
        for inner in INNER_PORTS:
            try:
                return start(inner)
            except Exception as exc:  # the SDK raises its own error types for bind failures
                errors.append(f"{inner}: {exc}")
        raise RequestError(
            "Foxglove stream",
            f"found no free loopback port for its server ({'; '.join(errors[-2:])})",
            "stop what listens on 127.0.0.1 ports 6665-6669",
        )

    @property
    def port(self) -> int:
        """The port the stream listens on, its guard's (useful with port 0)."""
        return self._port

    @property
    def inner_port(self) -> int:
        """The SDK server's own loopback port, behind the guard (one of INNER_PORTS)."""
        return int(self._server.port)

    def set_topics(self, topics: list[Topic]) -> None:
        """Opens channels for new topics and closes those of entities that are gone."""
        wanted = {t.name: t for t in topics}
        for name in [n for n in self._channels if n not in wanted]:
            self._channels.pop(name).close()
            self._latched.pop(name, None)
        for name, topic in wanted.items():
            if name not in self._channels:
                self._channels[name] = self._open(topic)

    def _open(self, topic: Topic) -> Any:
        return ros2_channel(topic, self._context)

    def write(self, message: Message) -> None:
        """Sends one message (and any latched message a new subscriber has not had)."""
        stamp = ros.nanoseconds(message.time)
        if stamp != self._last_time:
            self._server.broadcast_time(stamp)
            self._last_time = stamp
        self._resend(stamp)
        channel = self._channels.get(message.topic)
        if channel is None:
            return
        data = message.cdr()
        if message.topic in ("/tf_static",) or message.topic.endswith("/robot_description"):
            self._latched[message.topic] = data
        channel.log(data, log_time=stamp)

    def _resend(self, stamp: int) -> None:
        for topic in self._listener.take():
            if topic in self._latched and topic in self._channels:
                self._channels[topic].log(self._latched[topic], log_time=stamp)

    def close(self) -> None:
        """Closes every channel and stops the server."""
        for channel in self._channels.values():
            channel.close()
        self._channels.clear()
        if self._guard.stdin is not None:
            self._guard.stdin.close()  # the guard's signal to end
        self._server.stop()
        try:
            self._guard.wait(timeout=5)
        except subprocess.TimeoutExpired:
            self._guard.kill()
            self._guard.wait()


def _start_guard(host: str, port: int, inner: int) -> tuple[subprocess.Popen, int]:
    """Starts the guard process on host:port (`twin_cli.view.foxglove_guard`); its bound port.

    Raises:
        RequestError: it could not bind (the port is in use) or did not start in time.
    """
    command = [sys.executable, "-m", "twin_cli.view.foxglove_guard", host, str(port), str(inner)]
    guard = subprocess.Popen(
        command,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        stdin=subprocess.PIPE,  # held open until close(): its end ends the guard
        env={**os.environ, "PYTHONUNBUFFERED": "1"},
    )
    assert guard.stdout is not None and guard.stderr is not None
    ready, _, _ = select.select([guard.stdout], [], [], GUARD_START_S)
    line = guard.stdout.readline().strip() if ready else b""
    if line.isdigit():
        for stream in (guard.stdout, guard.stderr):  # one reader each: neither pipe fills
            threading.Thread(target=_drain, args=(stream,), daemon=True).start()
        return guard, int(line)
    guard.kill()
    detail = guard.stderr.read().decode(errors="replace").strip().splitlines()
    raise RequestError(
        f"Foxglove port {host}:{port}",
        f"cannot be opened ({detail[-1] if detail else 'its guard did not start'})",
        "choose another port (e.g. --port 8766), or stop what listens there",
    )


def _drain(stream: Any) -> None:
    """Reads one of the guard's outputs to its end, logging it, so a full pipe never blocks it."""
    for line in stream:
        log.debug("foxglove guard: %s", line.decode(errors="replace").rstrip())


def ros2_channel(topic: Topic, context: Any, metadata: dict[str, str] | None = None) -> Any:
    """A foxglove-sdk channel of `topic` in `context`: its `ros2msg` schema (rosbags'
    definition) and CDR messages, as Foxglove and rosbag2 expect them (live or in a file)."""
    import foxglove

    d = ros.definition(topic.type)
    schema = foxglove.Schema(name=d.name, encoding="ros2msg", data=d.text.encode())
    return foxglove.Channel(
        topic.name, schema=schema, message_encoding="cdr", context=context, metadata=metadata
    )


def _check_address(host: str, port: int, *, allow_public: bool) -> None:
    try:
        address = ipaddress.ip_address(host)
    except ValueError as exc:
        raise RequestError(
            f"Foxglove host {host}", "is not an IP address", "use 127.0.0.1"
        ) from exc
    if not 0 <= port <= 65535:
        raise RequestError(f"Foxglove port {port}", "is out of range", "use 1-65535 (0: any)")
    if not address.is_loopback and not allow_public:
        raise RequestError(
            f"Foxglove host {host}",
            "is not loopback, and the stream has no password or Origin check: anyone who "
            "reaches the port could watch the world",
            "use 127.0.0.1 and reach it through a tunnel (`ssh -L 8765:127.0.0.1:8765 HOST`)",
        )
