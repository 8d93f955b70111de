"""The web viewer a world server runs (at most one), started and stopped by its routes.

Used by the server's `/view` routes and by `twin serve --view`; kept here so that the server
holds no viewer logic. A bind address other than loopback is allowed only when asked for, and
then logged as a warning: the page has no authentication, and whoever reaches it can drive the
world (pause, reset, push).
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable
from typing import Any

from twin_cli.errors import InvalidRequestError, RequestError
from twin_cli.view.host import LOOPBACK, WebHost

log = logging.getLogger("twin.view")
PUBLIC_WARNING = (
    "the viewer listens on {host}:{port}, not only on this machine: anyone who can reach that "
    "port can see the world and drive it (pause, reset, push); it has no password"
)


class ViewService:
    """One server's web viewer; start/stop are thread safe."""

    def __init__(self, current_world: Callable[[], Any]) -> None:
        self._current = current_world
        self._lock = threading.Lock()
        self.host: WebHost | None = None
        self._closed_once = False

    def start(self, *, host: str = LOOPBACK, port: int = 0) -> dict:
        """Starts the viewer (or reports the running one); returns `status()`.

        Raises:
            RequestError: the port is taken or cannot be bound.
        """
        with self._lock:
            if self.host is not None and self.host.running:
                return self.status()
            if self.host is not None:
                self.close()
            if self._closed_once:
                raise RequestError(
                    "viewer",
                    "MuJoCo 4.0's web viewer cannot start again in a server process where one "
                    "was closed (its extension crashes the process)",
                    "restart the world to view it again: `twin save F`, `twin stop`, "
                    "`twin load F`, then `twin view`",
                )
            web = WebHost(self._current, host=host, port=port)
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

    def status(self) -> dict:
        """`{url, host, port, public, syncs}`; raises when no viewer runs."""
        if self.host is None or self.host.address is None:
            raise InvalidRequestError("viewer", "none is running", "start one with `twin view`")
        address = self.host.address
        return {
            "url": address.url,
            "host": address.host,
            "port": address.port,
            "public": address.public,
            "syncs": self.host.syncs,
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
