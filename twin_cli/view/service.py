"""The web viewer a world server runs (at most one), started and stopped by its routes.

Used by the server's `/view` routes and by `twin serve --view`; kept here so that the server
holds no viewer logic. On loopback the page needs no token (the Host and Origin checks keep other
sites' pages out); on any other address every request must carry a token (the world's `--tcp`
token, else one made for the viewer), which the reply and its URL give.
"""

from __future__ import annotations

import ipaddress
import logging
import secrets
import threading
from collections.abc import Callable
from typing import Any

from twin_cli.errors import InvalidRequestError, RequestError
from twin_cli.view.host import LOOPBACK, WebHost
from twin_cli.view.look import check_quality

log = logging.getLogger("twin.view")
PUBLIC_WARNING = (
    "the viewer listens on {host}:{port}, not only on this machine: it needs its token (in the "
    "URL, ?token=...), and anyone who can reach that port with the URL can see the world and "
    "drive it (pause, reset, push)"
)


class ViewConflictError(InvalidRequestError):
    """A viewer runs with other options than those asked for (the route answers 409)."""


class ViewService:
    """One server's web viewer; start/stop are thread safe.

    Args:
        current_world: returns the served world.
        world_token: returns the world's bearer token (`twin serve --tcp`), or None.
    """

    def __init__(
        self,
        current_world: Callable[[], Any],
        world_token: Callable[[], str | None] = lambda: None,
    ) -> None:
        self._current = current_world
        self._world_token = world_token
        self._lock = threading.Lock()
        self.host: WebHost | None = None
        self._closed_once = False

    def start(self, *, host: str = LOOPBACK, port: int = 0, quality: str | None = None) -> dict:
        """Starts the viewer (or reports the running one, asked with the same options); a
        `quality` (`twin_cli.view.look.QUALITIES`, None: auto for a new viewer) applies to the
        running one as well.

        Raises:
            ViewConflictError: a viewer runs on another host or port.
            RequestError: the host is not an IP address, or the port cannot be bound.
        """
        public = _is_public(host)
        with self._lock:
            if self.host is not None and self.host.running:
                self._check_same(host, port)
                if quality is not None:
                    self.host.look.quality = check_quality(quality)
                return self.status()
            if self.host is not None:
                self.close()
            self._refuse_restart()
            token = (self._world_token() or secrets.token_urlsafe(32)) if public else None
            web = WebHost(
                self._current, host=host, port=port, token=token, quality=quality or "auto"
            )
            try:
                web.start()
            except (RuntimeError, OSError) as exc:
                web.close()
                raise RequestError(
                    f"viewer port {host}:{port}", str(exc), "give another --port (0 picks one)"
                ) from exc
            self.host = web
            status = self.status()
            if status["public"]:
                log.warning(PUBLIC_WARNING.format(host=host, port=status["port"]))
            return status

    def _check_same(self, host: str, port: int) -> None:
        """Another host or port than the running viewer's is an error, not its old URL."""
        address = self.host.address if self.host is not None else None
        if address is None:
            return
        same_host = ipaddress.ip_address(host) == ipaddress.ip_address(address.host)
        if same_host and port in (0, address.port):
            return
        raise ViewConflictError(
            f"viewer at {address.host}:{address.port}",
            f"already running; {host}:{port} was asked for",
            "close it first with `twin view --stop`, or ask with the same options "
            f"(`twin view --host {address.host} --port {address.port}`)",
        )

    def _refuse_restart(self) -> None:
        if self._closed_once:
            raise RequestError(
                "viewer",
                "MuJoCo 4.0's web viewer cannot start again in a server process where one "
                "was closed (its extension crashes the process)",
                "restart the world to view it again: `twin save F`, `twin stop`, "
                "`twin load F`, then `twin view`",
            )

    def status(self) -> dict:
        """`{url, host, port, public, token_required, token, syncs, look, warning}` (`look`:
        `twin_cli.view.look.PageLook.status`); raises when no viewer runs."""
        if self.host is None or self.host.address is None:
            raise InvalidRequestError("viewer", "none is running", "start one with `twin view`")
        address = self.host.address
        return {
            "url": address.url,
            "host": address.host,
            "port": address.port,
            "public": address.public,
            "token_required": address.token is not None,
            "token": address.token,
            "syncs": self.host.syncs,
            "look": self.host.look.status(),
            "warning": PUBLIC_WARNING.format(host=address.host, port=address.port)
            if address.public
            else None,
        }

    def stop(self) -> dict:
        with self._lock:
            status = self.status()
            self.close()
            return {"stopped": status["url"]}

    def close(self) -> None:
        """Closes the viewer (server shutdown); the page shows that the world went away."""
        if self.host is not None:
            self.host.close()
            self.host = None
            self._closed_once = True


def _is_public(host: str) -> bool:
    """Whether `host` is reachable from other machines (anything but loopback)."""
    try:
        return not ipaddress.ip_address(host).is_loopback
    except ValueError as exc:
        raise RequestError(
            f"viewer host {host!r}",
            "is not an IP address",
            "give --host 127.0.0.1 (this machine only) or the address of one interface",
        ) from exc
