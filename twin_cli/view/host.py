"""MuJoCo's web viewer hosted on a running world: the page, its bind address, the sync thread.

The viewer (`mujoco.studio`, shipped in the mujoco wheel: page, WASM renderer and fonts are served
from the wheel, no internet) runs in its own daemon thread and renders in the browser. The world
keeps stepping in its own thread; a sync thread here calls `ViewerHandle.sync` at `SYNC_HZ` of
wall time, holding the world's lock only for that call (0.25-0.6 ms measured), so the page sees
the world ~30 times a second and the stepping loop never runs Python per step for it. When a
spawn or delete has recompiled the world, `sync` is given the new model and sends it; the page
swaps it in place (no reload) and keeps its camera, since the model path stays "". The model
sent is the world's own, or its copy with the fast look for a software-rendered page
(`twin_cli.view.look`).
"""

from __future__ import annotations

import contextlib
import io
import ipaddress
import logging
import queue
import socket
import threading
import time
import urllib.parse
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from mujoco.studio import messages

from twin_cli.view.bridge import WorldBridge
from twin_cli.view.guard import ViewGuard, armed, protect
from twin_cli.view.look import PageLook
from twin_cli.view.piece_routes import PieceRoutes, PieceStore

log = logging.getLogger("twin.view")

SYNC_HZ = 30.0  # [Hz] of wall time; the page renders at the browser's rate in between
START_TIMEOUT_S = 30.0  # [s] for the viewer thread to bind its port and start its server
CLOSE_TIMEOUT_S = 20.0  # [s] for the viewer thread to end after its exit event
LOOPBACK = "127.0.0.1"


@dataclass(frozen=True)
class ViewAddress:
    """Where the page is served: `host` as bound, `port`, the token it needs (off loopback),
    and the URL to open (with the token in its query)."""

    host: str
    port: int
    token: str | None = None

    @property
    def url(self) -> str:
        query = f"?{urllib.parse.urlencode({'token': self.token})}" if self.token else ""
        return ViewGuard(self.host, self.port).example_url() + query

    @property
    def public(self) -> bool:
        """Whether other machines may reach it (anything but a loopback address)."""
        return not ipaddress.ip_address(self.host).is_loopback


def _viewer_class(
    host: str, token: str | None, store: PieceStore, on_renderer: Callable[[str], None]
) -> type:
    """`WebViewer` bound to `host` instead of the "::" (all interfaces) it hard-codes, its
    server behind twin's Host, Origin and token checks (`twin_cli.view.guard`), each model it
    serves also cut into `store`'s pieces (`twin_cli.view.piece_routes`).

    `WebViewer.__init__` assigns `self._host = "::"` and binds right after; a class property
    whose setter ignores that assignment makes it bind `host` (MuJoCo 4.0.0 has no option).
    """
    from mujoco.studio import web_viewer

    class BoundWebViewer(web_viewer.WebViewer):
        @property
        def _host(self) -> str:
            return host

        @_host.setter
        def _host(self, _ignored: str) -> None:
            pass

        def _start_server(self) -> None:
            """Registers the guard for the bound socket before MuJoCo's server starts on it."""
            guard = ViewGuard(host, self._http_port, token)
            protect(self._http_sock, guard, PieceRoutes(store, on_renderer).wrap)
            super()._start_server()
            # Only the current bundle is kept: the page never goes back to an old one by crc,
            # and MuJoCo's page would otherwise download every earlier model in the background.
            if self._web_server is not None:
                self._web_server.model_cache_bytes = 0
            self._publish()

        @messages.handler(priority=messages.Priority.INTERNAL)
        def _on_post_model(self, event: messages.PostModelEvent) -> None:
            """Serves the new model as pieces; the page swaps it in place (MuJoCo's prints)."""
            self._update_model()
            self._publish()

        def _publish(self) -> None:
            server = self._web_server
            if server is None or not server.mjb_data:
                return  # stopped, or MuJoCo found no page files to serve
            started = time.perf_counter()
            manifest = store.publish(server.mjb_data, self._model_crc32, self.model)
            log.info(
                "viewer: model %d, %.1f MiB in %d pieces (%.0f ms)",
                manifest.crc32,
                manifest.size / 2**20,
                len(manifest.pieces),
                (time.perf_counter() - started) * 1e3,
            )

    return BoundWebViewer


def _wait_listening(sock: socket.socket) -> None:
    """Returns once MuJoCo's server thread listens on `sock`: the URL twin prints then works
    (the socket is bound before that thread starts, and a request in between is refused)."""
    deadline = time.monotonic() + START_TIMEOUT_S
    while not sock.getsockopt(socket.SOL_SOCKET, socket.SO_ACCEPTCONN):
        if time.monotonic() > deadline:
            raise RuntimeError(f"the viewer did not listen within {START_TIMEOUT_S:.0f} s")
        time.sleep(0.01)


class WebHost:
    """One web viewer on a world: started by `start`, ended by `close`.

    Args:
        current_world: returns the served world (the server may swap it on `/load`).
        host: address to bind; 127.0.0.1 unless the user asked otherwise.
        port: TCP port; 0 takes the first free one from 8080 on (MuJoCo's rule).
        rate: syncs per second of wall time.
        token: what every request must carry (None: no token, for loopback).
        quality: the page's look, `twin_cli.view.look.QUALITIES`.
    """

    def __init__(
        self,
        current_world: Callable[[], Any],
        *,
        host: str = LOOPBACK,
        port: int = 0,
        rate: float = SYNC_HZ,
        token: str | None = None,
        quality: str = "auto",
    ) -> None:
        self._current = current_world
        self.look = PageLook(quality)
        self._host, self._port, self._period = host, port, 1.0 / rate
        self._token = token
        self._bridge = WorldBridge(current_world())
        self.pieces = PieceStore()
        self._handle: Any = None
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self.address: ViewAddress | None = None
        self.syncs = 0

    def start(self) -> ViewAddress:
        """Binds the port, starts the viewer and the sync thread; returns where to look.

        Raises:
            RuntimeError: the port is taken (MuJoCo's message), or the viewer did not start.
        """
        from mujoco.studio import app as studio_app
        from mujoco.studio import launch_thread, viewer_protocol

        bound: queue.Queue[Any] = queue.Queue()
        viewer_class = _viewer_class(self._host, self._token, self.pieces, self.look.report)
        config = viewer_protocol.ViewerConfig(gfx="web", http_port=self._port, title="twin")

        def run(endpoint: Any) -> None:
            try:
                # MuJoCo prints a banner (URL, "Ctrl+C to quit") on stdout: twin prints its own.
                with contextlib.redirect_stdout(io.StringIO()):
                    viewer = viewer_class(config, endpoint, plugins=[studio_app.App()])
            except BaseException as exc:
                bound.put(exc)
                raise
            bound.put(viewer._http_sock)  # noqa: SLF001 (the socket it bound; no public name)
            viewer_protocol.run_viewer_loop(viewer)

        self._handle = launch_thread.launch_thread(run, sim_plugins=[self._bridge])
        reply = bound.get(timeout=START_TIMEOUT_S)
        if isinstance(reply, BaseException):
            self._handle = None
            raise RuntimeError(str(reply)) from reply
        _wait_listening(reply)
        if not armed(reply):
            raise RuntimeError(
                "MuJoCo's viewer server started without twin's Host/Origin checks (its "
                "web_server module changed); not serving it: use the mujoco version twin pins"
            )
        self.address = ViewAddress(self._host, int(reply.getsockname()[1]), self._token)
        world = self._current()
        with world.lock:
            self._handle.set_model(self.look.model_for(world.page_model()), data=world.data)
        self._thread = threading.Thread(target=self._run, name="twin-view-sync", daemon=True)
        self._thread.start()
        log.info("viewer on port %d (bound to %s)", self.address.port, self._host)
        return self.address

    @property
    def running(self) -> bool:
        return self._thread is not None and self._thread.is_alive()

    def _run(self) -> None:
        """Syncs at the wall-clock rate until closed or the viewer thread ends."""
        due = time.monotonic()
        try:
            while not self._stop.is_set() and self._handle.is_running():
                self.sync_once()
                due = max(due + self._period, time.monotonic())
                self._stop.wait(max(0.0, due - time.monotonic()))
        except Exception:
            log.exception("viewer sync ended")

    def sync_once(self) -> None:
        """One sync: page actions in, the world's model (if new, or its look changed) and state
        out; lock held."""
        world = self._current()
        self._bridge.world = world
        self.look.prepare(world.page_model())  # a new model's copy, outside the world's lock
        with world.lock:
            self._bridge.show_pause_state()
            self._handle.sync(self.look.model_for(world.page_model()), world.data)
        self.syncs += 1

    def close(self) -> None:
        """Stops syncing and closes the viewer (the page shows it ended); idempotent."""
        self._stop.set()
        if self._thread is not None:
            self._thread.join()
            self._thread = None
        handle, self._handle = self._handle, None
        if handle is None:
            return
        try:
            handle.close()
        except Exception:
            log.exception("viewer closed with an error")
        # `close` waits only 5 s for the viewer thread; its ImGui context is process-global, and
        # a viewer started while the old thread still draws crashes in MuJoCo's extension
        # (seen on a loaded machine). Wait until the thread has really ended.
        alive = getattr(handle, "_is_alive_fn", None)
        deadline = time.monotonic() + CLOSE_TIMEOUT_S
        while alive is not None and alive() and time.monotonic() < deadline:
            time.sleep(0.05)
