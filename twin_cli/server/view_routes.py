"""Routes of the world's pictures: the web viewer (`/view`) and offscreen snapshots.

Kept apart from the world routes (`app.py`); the viewer and the renderer live in `twin_cli.view`.
"""

from __future__ import annotations

import logging
from typing import Any

from fastapi import APIRouter, Request

from twin_cli.server.error_replies import error_reply
from twin_cli.server.holder import WorldDep
from twin_cli.server.models import SnapshotBody, ViewBody

log = logging.getLogger("twin.server")
router = APIRouter()


def views(request: Request) -> Any:
    """The server's web viewer service (`twin_cli.view.service.ViewService`)."""
    return view_service(request.app.state)


def view_service(state: Any) -> Any:
    """The viewer service kept on the app's `state`, made on first use."""
    if getattr(state, "views", None) is None:
        from twin_cli.view.service import ViewService

        holder = state.holder
        state.views = ViewService(lambda: holder.world, lambda: _world_token(state))
    return state.views


def _world_token(state: Any) -> str | None:
    """The world's bearer token, when it serves TCP (`--tcp` writes it to a 0600 file)."""
    from twin_cli.server import runtime

    path = runtime.world_paths(getattr(state, "world_name", "default")).token
    try:
        return path.read_text().strip() or None
    except FileNotFoundError:
        return None


@router.post("/view", status_code=201)
def start_view(body: ViewBody, request: Request) -> Any:
    """Serve MuJoCo's web viewer on this world (`twin view`); replies with its URL (and the
    token it needs off loopback); 409 when one runs with another host or port."""
    from twin_cli.view.service import ViewConflictError

    try:
        status = views(request).start(host=body.host, port=body.port, quality=body.quality)
    except ViewConflictError as exc:
        return error_reply(409, "InvalidRequestError", str(exc))
    log.info("viewer on %s:%d", status["host"], status["port"])  # the URL may carry the token
    return status


@router.get("/view")
def view_status(request: Request) -> dict:
    return views(request).status()


@router.delete("/view")
def stop_view(request: Request) -> dict:
    return views(request).stop()


PICTURE_MODE = 0o644  # a picture holds no world state, unlike a save (0600)


@router.post("/snapshot")
def snapshot(body: SnapshotBody, world: WorldDep) -> dict:
    """Render the world offscreen into a PNG at `path` (atomically); reply with the camera."""
    from twin_cli.errors import RequestError
    from twin_cli.files.output_files import OutputFileError, checked_target, write_atomically
    from twin_cli.view.offscreen import is_twin_png, snapshot_png

    try:
        # before rendering: a bad target costs no frame
        checked_target(body.path, ours=is_twin_png, force=body.force)
        png, camera = snapshot_png(world, entity=body.entity, width=body.width, height=body.height)
        write_atomically(body.path, png, mode=PICTURE_MODE, ours=is_twin_png, force=body.force)
    except OutputFileError as exc:
        raise RequestError(f"snapshot {exc.filename}", exc.problem, exc.fix) from exc
    return {"path": body.path, "bytes": len(png), "camera": camera}
