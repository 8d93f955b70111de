"""Seeing a running world: MuJoCo's web viewer on the served world, and offscreen snapshots.

A consumer of the world, like `twin_cli.record`: it reads the world under its lock
and acts on it only through `World`'s methods. Modules: `bridge` (the page's actions → World),
`host` (the viewer thread, its bind address, the sync thread), `guard` (the Host, Origin and
token checks on its port), `pieces` and `piece_routes` (each model as pieces keyed by
content, so the page fetches only what it lacks), `look` (the fast look a software-rendered
page is sent), `service` (the server's one viewer),
`offscreen` (PNG snapshots with mujoco.Renderer on EGL). Exports load lazily, so that
importing the package imports neither mujoco nor the viewer.
"""

from __future__ import annotations

from twin_cli.lazy import lazy_getattr

_WHERE = {
    "WorldBridge": "twin_cli.view.bridge",
    "WebHost": "twin_cli.view.host",
    "ViewAddress": "twin_cli.view.host",
    "ViewGuard": "twin_cli.view.guard",
    "ViewService": "twin_cli.view.service",
    "Manifest": "twin_cli.view.pieces",
    "split_bundle": "twin_cli.view.pieces",
    "PieceStore": "twin_cli.view.piece_routes",
    "CameraView": "twin_cli.view.offscreen",
    "snapshot_png": "twin_cli.view.offscreen",
}
__getattr__ = lazy_getattr(__name__, _WHERE)
__all__ = sorted(_WHERE)
