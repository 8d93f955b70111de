"""The viewer's port serves each model as pieces keyed by content, and a page that uses them.

`PieceStore` keeps the pieces of the current model and of the one before (a page may still be
fetching it). `PieceRoutes` answers, ahead of MuJoCo's own routes on the same port (behind the
same guard): `/` (MuJoCo's page with `pieces.js` added), `/twin/pieces.js`,
`/twin/pieces_worker.js`, `/twin/current` (the newest model's crc32),
`/twin/manifest[?crc32=N]` (the pieces of a model, JSON, a few KiB) and
`/twin/pieces?keys=K,K,...` (the bytes of those pieces, in order) and
`/twin/renderer?name=R` (the page's WebGL renderer, which decides the fast look,
`twin_cli.view.look`). The page's worker fetches
only the pieces it lacks, in requests of its own, off the page's main thread: the `/state`
WebSocket, which carries the world's state, never waits for a model.
"""

from __future__ import annotations

import collections
import json
import logging
import re
import threading
import urllib.parse
from collections.abc import Callable
from importlib import resources
from pathlib import Path
from typing import Any

from twin_cli.view.pieces import Manifest, array_ranges, split_bundle

log = logging.getLogger("twin.view")

KEEP_MODELS = 2  # the current model and the one before it
MAX_KEYS = 256  # pieces one request may ask for
RENDERER_NAME = re.compile(r"[\x20-\x7e]{1,200}")  # a WebGL renderer's name: printable ASCII
PAGE_SCRIPT = '<script src="twin/pieces.js"></script>\n    <script async src="web_client.js">'
MUJOCO_SCRIPT = '<script async src="web_client.js">'

ProcessRequest = Callable[[Any, Any], Any]


class PieceStore:
    """The pieces of the last `KEEP_MODELS` models, by key; thread safe (the viewer thread
    publishes, the server thread reads)."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._models: collections.OrderedDict[int, tuple[Manifest, memoryview]] = (
            collections.OrderedDict()
        )
        self._pieces: dict[str, memoryview] = {}

    def publish(self, bundle: bytes, crc32: int, model: Any) -> Manifest:
        """Cuts `bundle` (the model MuJoCo now serves, with its crc32) into pieces."""
        manifest = split_bundle(bundle, crc32, array_ranges(bundle, model))
        view = memoryview(bundle)
        with self._lock:
            self._models.pop(crc32, None)
            self._models[crc32] = (manifest, view)
            while len(self._models) > KEEP_MODELS:
                self._models.popitem(last=False)
            self._pieces = {
                p.key: kept[p.start : p.start + p.size]
                for m, kept in self._models.values()
                for p in m.pieces
            }
        return manifest

    def manifest(self, crc32: int | None) -> Manifest | None:
        """The model with this crc32 (None: the newest), if still kept."""
        with self._lock:
            if crc32 is None:
                return next(reversed(self._models.values()))[0] if self._models else None
            kept = self._models.get(crc32)
            return kept[0] if kept else None

    def read(self, keys: list[str]) -> bytes | None:
        """The pieces' bytes in order; None when one is no longer kept."""
        with self._lock:
            parts = [self._pieces.get(k) for k in keys]
        if any(p is None for p in parts):
            return None
        return b"".join(p for p in parts if p is not None)


class PieceRoutes:
    """Twin's routes on the viewer's port, in front of MuJoCo's (`wrap`)."""

    def __init__(self, store: PieceStore, on_renderer: Callable[[str], None]) -> None:
        self.store = store
        self._on_renderer = on_renderer
        self._page: bytes | None = None

    def wrap(self, inner: ProcessRequest | None) -> ProcessRequest:
        def process_request(connection: Any, request: Any) -> Any:
            path, _, query = request.path.partition("?")
            handler = {
                "/": self._index,
                "/index.html": self._index,
                "/twin/pieces.js": self._script,
                "/twin/pieces_worker.js": self._script,
                "/twin/current": self._current,
                "/twin/manifest": self._manifest,
                "/twin/pieces": self._pieces,
            }.get(path)
            if path == "/twin/renderer":
                return self._renderer(request, urllib.parse.parse_qs(query))
            if handler is not None:
                return handler(path, urllib.parse.parse_qs(query))
            return inner(connection, request) if inner is not None else None

        return process_request

    def _index(self, _path: str, _query: dict) -> Any:
        if self._page is None:
            self._page = _patched_page()
        return _response(200, "text/html; charset=utf-8", self._page)

    def _script(self, path: str, _query: dict) -> Any:
        name = path.rsplit("/", 1)[1]
        script = resources.files("twin_cli.view").joinpath(name).read_bytes()
        return _response(200, "text/javascript", script)

    def _current(self, _path: str, _query: dict) -> Any:
        """The newest model's crc32: the page's worker polls it (a few bytes)."""
        manifest = self.store.manifest(None)
        return _response(200, "text/plain", str(manifest.crc32 if manifest else 0).encode())

    def _manifest(self, _path: str, query: dict) -> Any:
        try:
            crc32 = int(query["crc32"][0]) if "crc32" in query else None
        except ValueError:
            return _response(400, "text/plain", b"bad crc32\n")
        manifest = self.store.manifest(crc32)
        if manifest is None:
            return _response(404, "text/plain", b"model no longer kept\n")
        return _response(200, "application/json", json.dumps(manifest.as_json()).encode())

    def _renderer(self, request: Any, query: dict) -> Any:
        """The page's WebGL renderer, sent once when it loads. The only route that changes
        anything: a browser sends no Origin on another site's plain GET (an image, a link), so
        a request its browser marks as coming from another site (`Sec-Fetch-Site`) is
        refused too."""
        site = request.headers.get("Sec-Fetch-Site")
        if site is not None and site != "same-origin":
            return _response(403, "text/plain", b"only the viewer's own page reports\n")
        name = query.get("name", [""])[0]
        if not RENDERER_NAME.fullmatch(name):
            return _response(400, "text/plain", b"give name=RENDERER (printable ASCII)\n")
        self._on_renderer(name)
        return _response(204, "text/plain", b"")

    def _pieces(self, _path: str, query: dict) -> Any:
        keys = [k for k in query.get("keys", [""])[0].split(",") if k]
        if not keys or len(keys) > MAX_KEYS:
            return _response(400, "text/plain", f"give 1 to {MAX_KEYS} keys\n".encode())
        body = self.store.read(keys)
        if body is None:
            return _response(404, "text/plain", b"piece no longer kept\n")
        log.debug("viewer: %d pieces, %d bytes", len(keys), len(body))
        return _response(200, "application/octet-stream", body)


def _patched_page() -> bytes:
    """MuJoCo's page with twin's `pieces.js` loaded after its own script, before the WASM."""
    from mujoco.studio.web import web_server

    dist = Path(web_server.__file__).parent / "dist" / "index.html"
    page = dist.read_text()
    if MUJOCO_SCRIPT not in page:
        raise RuntimeError("MuJoCo's viewer page changed (no web_client.js script tag)")
    return page.replace(MUJOCO_SCRIPT, PAGE_SCRIPT, 1).encode()


def _response(status: int, content_type: str, body: bytes) -> Any:
    """A response with the headers MuJoCo's page needs (cross-origin isolated, never cached:
    the page keeps the pieces itself)."""
    from http import HTTPStatus

    from websockets.datastructures import Headers
    from websockets.http11 import Response

    headers = Headers()
    headers["Content-Type"] = content_type
    headers["Content-Length"] = str(len(body))
    headers["Cross-Origin-Opener-Policy"] = "same-origin"
    headers["Cross-Origin-Embedder-Policy"] = "require-corp"
    headers["Cache-Control"] = "no-store"
    return Response(status, HTTPStatus(status).phrase, headers, body)
