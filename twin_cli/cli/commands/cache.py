"""`twin cache info` and `twin cache clear`: the on-disk cache of collision decompositions.

Thin: each command calls one function of `converters.collision.cache` (imported inside the command,
so `twin --help` loads neither numpy nor trimesh) and hands the result to `Output`.
"""

from __future__ import annotations

import typer

from twin_cli.cli.options import JsonOpt
from twin_cli.cli.output import Output

cache_app = typer.Typer(
    name="cache",
    help="The collision-mesh cache (convex decompositions); location from $TWIN_CACHE_DIR.",
    no_args_is_help=True,
)


def _size_text(size: int) -> str:
    for unit in ("B", "KiB", "MiB", "GiB"):
        if size < 1024 or unit == "GiB":
            return f"{size:.0f} {unit}" if unit == "B" else f"{size:.1f} {unit}"
        size /= 1024
    return f"{size} B"


@cache_app.command("info")
def info(json_mode: JsonOpt = False) -> None:
    """Where the cache is, how many entries it holds and their size on disk."""
    from converters.collision import cache as mesh_cache

    facts = mesh_cache.info()
    out = Output(json_mode)
    if json_mode:
        out.data({"path": str(facts.path), "entries": facts.entries, "bytes": facts.bytes})
        return
    rows = [
        ("path", str(facts.path)),
        ("entries", facts.entries),
        ("size", _size_text(facts.bytes)),
    ]
    out.table("twin cache", ("field", "value"), rows)


@cache_app.command("clear")
def clear(json_mode: JsonOpt = False) -> None:
    """Remove every cached decomposition and stored mesh (the next conversion redoes them)."""
    from converters.collision import cache as mesh_cache
    from converters.resources import mesh_store

    removed, meshes = mesh_cache.clear(), mesh_store.clear()
    out = Output(json_mode)
    if json_mode:
        path = str(mesh_cache.collision_dir())
        out.data({"path": path, "removed": removed, "meshes_removed": meshes})
        return
    out.line(
        f"Removed {removed} cached decompositions from {mesh_cache.collision_dir()} "
        f"and {meshes} stored meshes from {mesh_store.store_dir()}"
    )


def register(app: typer.Typer) -> None:
    """Add the `cache` group to the twin app."""
    app.add_typer(cache_app, name="cache")
