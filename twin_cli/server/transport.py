"""HTTP/1.1 requests over a Unix socket or TCP with the standard library's `http.client`.

The client's transport, chosen for start-up cost: every `twin` world command is a new process
that sends one or two small requests. Measured with `python -X importtime` on the 2-core machine:
httpx (httpcore, h11, anyio, idna, certifi) 69 ms, 36 ms with its command line stubbed out;
`http.client` 21 ms (most of it the email parser and ssl it imports). httpx's connection pool,
HTTP/2 and async support buy nothing for one request to a local socket. With this and the fast
path (`twin_cli.cli.fast`), `twin gravity --moon` went from 339 to 115 ms median wall.
Each request opens its own connection (~0.1 ms over a Unix socket), so no request ever meets a
connection the server closed while it was idle.
"""

from __future__ import annotations

import http.client
import json as jsonlib
import select
import socket
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import Any
from urllib.parse import quote, urlsplit

# Errors that mean nobody answered: no socket file, refused, reset or closed before a reply, or
# not HTTP at all (httpx's ConnectError and RemoteProtocolError). Catch TimeoutError, an OSError
# too, before these: it means a server that is there but busy.
NOT_ANSWERING = (OSError, http.client.HTTPException)
# Characters left as they are in a path segment: RFC 3986 pchar, less '/' (names are one
# segment) and '%' (names are data, never pre-encoded).
PATIENCE_TICK_S = 0.5  # [s] how often a patient wait looks at the server and the clock
_SEGMENT_SAFE = "".join(chr(i) for i in range(0x21, 0x7F) if chr(i) not in '"#<>?`{}/%')


def path_segment(text: str) -> str:
    """`text` percent-encoded as one URL path segment."""
    return quote(text, safe=_SEGMENT_SAFE)


@dataclass(frozen=True)
class Reply:
    """A response: status code and body bytes (the subset of httpx.Response twin uses)."""

    status_code: int
    content: bytes

    @property
    def text(self) -> str:
        return self.content.decode("utf-8", errors="replace")

    @property
    def is_error(self) -> bool:
        return self.status_code >= 400

    def json(self) -> Any:
        """The body decoded as JSON; raises ValueError when it is not JSON."""
        return jsonlib.loads(self.content)


def _await_reply(sock: socket.socket, patience: Callable[[float], bool]) -> None:
    """Wait until `sock` has something to read (a reply, or the server closing it).

    Raises:
        TimeoutError: `patience` gave up.
    """
    start = time.monotonic()
    while not select.select([sock], [], [], PATIENCE_TICK_S)[0]:
        if not patience(time.monotonic() - start):
            raise TimeoutError("no reply yet")


class _UnixConnection(http.client.HTTPConnection):
    """http.client over a Unix domain socket (AF_UNIX) instead of TCP."""

    def __init__(self, socket_path: str, timeout: float) -> None:
        super().__init__("twin", timeout=timeout)
        self._socket_path = socket_path

    def connect(self) -> None:
        sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        sock.settimeout(self.timeout)
        try:
            sock.connect(self._socket_path)
        except BaseException:
            sock.close()
            raise
        self.sock = sock


class Http:
    """One server's address and default headers; `request` sends one request and reads the reply.

    Raises what the socket raises: NOT_ANSWERING errors when nobody answers, TimeoutError when
    no reply came within the timeout [s].
    """

    def __init__(
        self, *, socket_path: str | None, url: str | None, headers: dict[str, str], timeout: float
    ) -> None:
        self._socket_path = socket_path
        self._url = urlsplit(url) if url else None
        self._headers = headers
        self._timeout = timeout

    def _connection(self, timeout: float) -> http.client.HTTPConnection:
        if self._url is None:
            return _UnixConnection(str(self._socket_path), timeout)
        if self._url.scheme == "https":
            return http.client.HTTPSConnection(self._url.netloc, timeout=timeout)
        return http.client.HTTPConnection(self._url.netloc, timeout=timeout)

    def request(
        self,
        method: str,
        path: str,
        *,
        json: Any = None,
        content: bytes | None = None,
        headers: dict[str, str] | None = None,
        timeout: float | None = None,
        patience: Callable[[float], bool] | None = None,
    ) -> Reply:
        """Send `method path` with a JSON body (`json`) or raw bytes (`content`).

        JSON is encoded as httpx encodes it (UTF-8, compact, NaN refused with ValueError).
        `patience(elapsed [s])`, if given, is asked about once a second while no reply has come
        and replaces `timeout` for the wait: it returns False to give up (TimeoutError).
        """
        sent = {**self._headers, **(headers or {})}
        if json is not None:
            text = jsonlib.dumps(json, ensure_ascii=False, separators=(",", ":"), allow_nan=False)
            content = text.encode("utf-8")
            sent.setdefault("Content-Type", "application/json")
        connection = self._connection(self._timeout if timeout is None else timeout)
        try:
            connection.request(method, path, body=content, headers=sent)
            if patience is not None:
                _await_reply(connection.sock, patience)
            response = connection.getresponse()
            return Reply(response.status, response.read())
        finally:
            connection.close()

    def lines(
        self, path: str, *, timeout: float | None = None
    ) -> tuple[Reply | None, Iterator[bytes]]:
        """`GET path` whose reply is streamed line by line (`/topics/echo`).

        Returns (the error reply, nothing) when the status is an error, else (None, the body's
        lines as they arrive, each with its newline; a blank line is the server's heartbeat).
        `timeout` [s] bounds the connection and the wait for the reply's head; lines are
        then waited for without a limit. The connection closes when the iterator ends or is
        closed.
        """
        connection = self._connection(self._timeout if timeout is None else timeout)
        try:
            connection.request("GET", path, headers=dict(self._headers))
            response = connection.getresponse()
        except BaseException:
            connection.close()
            raise
        if response.status >= 400:
            try:
                return Reply(response.status, response.read()), iter(())
            finally:
                connection.close()
        if connection.sock is not None:
            connection.sock.settimeout(None)  # a paused world may send nothing for long
        return None, _lines(connection, response)

    def close(self) -> None:
        """Nothing to release: connections close after each request."""


def _lines(connection: http.client.HTTPConnection, response: Any) -> Iterator[bytes]:
    try:
        while line := response.readline():
            yield line
    finally:
        connection.close()
