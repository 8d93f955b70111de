"""Who may use the viewer's port: its Host and Origin checks, and its token off loopback."""

from __future__ import annotations

import hmac
import ipaddress
import socket
import urllib.parse
import weakref
from collections.abc import Callable
from dataclasses import dataclass
from http import HTTPStatus
from typing import Any

LOOPBACK_NAMES = frozenset({"localhost", "127.0.0.1", "::1"})
WILDCARDS = frozenset({"0.0.0.0", "::"})
COOKIE = "twin_view_token_{port}"  # cookies ignore ports: one name per viewer port

ProcessRequest = Callable[[Any, Any], Any]


@dataclass(frozen=True)
class ViewGuard:
    """The checks on every request to a viewer bound to `host:port`.

    Host must name the bound address (DNS rebinding: a foreign name resolved to it is refused);
    an Origin, when sent, must be the page's own (a page of another site is refused); off
    loopback the request must carry `token` (query `?token=`, the cookie set on the first page
    load, or `Authorization: Bearer`).
    """

    host: str
    port: int
    token: str | None = None

    def refusal(self, request: Any) -> str | None:
        """Why `request` (a websockets `Request`) is refused, or None."""
        hosts, origins = request.headers.get_all("Host"), request.headers.get_all("Origin")
        given = hosts[0] if len(hosts) == 1 else None
        if given is None or not self.host_allowed(given):
            return f"Host {given!r} is not this viewer's address; open {self.example_url()}"
        if origins and (len(origins) > 1 or origins[0].lower() != f"http://{given}".lower()):
            return f"Origin {origins!r} is not this viewer's page; open {self.example_url()}"
        if self.token is not None and not self._token_given(request):
            return "this viewer needs its token: open the URL `twin view` printed (?token=...)"
        return None

    def example_url(self) -> str:
        name = "localhost" if self.host in LOOPBACK_NAMES else self.host
        name = f"[{name}]" if ":" in name else name
        return f"http://{name}:{self.port}/"

    def cookie(self) -> str:
        """The cookie that lets the page's own requests and WebSockets carry the token."""
        name = COOKIE.format(port=self.port)
        return f"{name}={self.token}; Path=/; HttpOnly; SameSite=Strict"

    def host_allowed(self, header: str) -> bool:
        """Whether a Host header names this address and port."""
        try:
            split = urllib.parse.urlsplit(f"//{header}")
            name, port = (split.hostname or ""), (split.port or 80)
        except ValueError:
            return False
        return port == self.port and name in self._names(name)

    def _names(self, asked: str) -> frozenset[str]:
        """Host names this viewer answers to (`asked` decides only for a wildcard bind)."""
        if self.host in LOOPBACK_NAMES:
            return LOOPBACK_NAMES
        if self.host in WILDCARDS:
            known = LOOPBACK_NAMES | {socket.gethostname().lower()}
            return known | ({asked} if _is_ip(asked) else frozenset())
        return frozenset({self.host.lower()})

    def _token_given(self, request: Any) -> bool:
        query = urllib.parse.parse_qs(urllib.parse.urlsplit(request.path).query)
        cookies = _cookies(request.headers.get("Cookie", ""))
        bearer = request.headers.get("Authorization", "").removeprefix("Bearer ")
        candidates = [*query.get("token", []), cookies.get(COOKIE.format(port=self.port)), bearer]
        return any(c and hmac.compare_digest(c.encode(), self.token.encode()) for c in candidates)

    def wrap(self, inner: ProcessRequest | None) -> ProcessRequest:
        """MuJoCo's `process_request` behind these checks; sets the token cookie on pages."""

        def process_request(connection: Any, request: Any) -> Any:
            why = self.refusal(request)
            if why is not None:
                return connection.respond(HTTPStatus.FORBIDDEN, f"twin viewer: {why}\n")
            response = inner(connection, request) if inner is not None else None
            if response is not None and self.token is not None:
                response.headers["Set-Cookie"] = self.cookie()
            return response

        return process_request


def _is_ip(name: str) -> bool:
    try:
        ipaddress.ip_address(name)
    except ValueError:
        return False
    return True


def _cookies(header: str) -> dict[str, str]:
    pairs = (part.strip().partition("=") for part in header.split(";"))
    return {name: value for name, _, value in pairs if name}


# Guards by the listening socket they protect. MuJoCo's web server builds its `serve(...)` call
# inside a private function with a local `process_request` and no option to add checks; twin
# wraps the module's `serve` name in this process only (mujoco's files are untouched), and only
# sockets registered here get the checks, so any other viewer in the process is left as it was.
_GUARDS: weakref.WeakKeyDictionary[socket.socket, ViewGuard] = weakref.WeakKeyDictionary()
_ARMED: weakref.WeakSet[socket.socket] = weakref.WeakSet()  # the sockets served behind a guard
# Twin's own routes on a guarded socket, tried before MuJoCo's (behind the same guard).
_ROUTES: weakref.WeakKeyDictionary[
    socket.socket, Callable[[ProcessRequest | None], ProcessRequest]
] = weakref.WeakKeyDictionary()


def armed(sock: socket.socket) -> bool:
    """Whether the server on `sock` was built with its guard (False: MuJoCo's server changed
    how it starts, and the viewer must not run unguarded)."""
    return sock in _ARMED


def protect(
    sock: socket.socket,
    guard: ViewGuard,
    routes: Callable[[ProcessRequest | None], ProcessRequest] | None = None,
) -> None:
    """Puts `guard` in front of the viewer server that will listen on `sock`, and behind it
    `routes` (wraps MuJoCo's `process_request` with twin's own paths), if given."""
    from mujoco.studio.web import web_server

    _GUARDS[sock] = guard
    if routes is not None:
        _ROUTES[sock] = routes
    if not getattr(web_server.serve, "twin_guarded", False):
        web_server.serve = _guarded_serve(web_server.serve)


def _guarded_serve(original: Callable[..., Any]) -> Callable[..., Any]:
    def serve(handler: Any, *args: Any, **kwargs: Any) -> Any:
        sock = kwargs.get("sock")
        guard = _GUARDS.get(sock) if sock is not None else None
        if guard is not None and sock is not None:
            inner = kwargs.get("process_request")
            routes = _ROUTES.get(sock)
            kwargs["process_request"] = guard.wrap(routes(inner) if routes else inner)
            _ARMED.add(sock)
        return original(handler, *args, **kwargs)

    serve.twin_guarded = True  # type: ignore[attr-defined]
    return serve
