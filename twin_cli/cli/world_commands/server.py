"""`twin stop`, `save`, `load`, `logs`: the world's server, its saved files and its log."""

from __future__ import annotations

import sys
from pathlib import Path

from twin_cli.cli import pairs
from twin_cli.cli.params import WORLD
from twin_cli.cli.registry import Arg, Opt, command, flag
from twin_cli.cli.world_client import connect_world, not_running


@command("stop", WORLD, help="Stop the world's server (waits until its process has ended).")
def stop(*, world: str) -> None:
    from twin_cli.errors import NotRunningError
    from twin_cli.server import connection

    try:
        pid = connection.stop(world)
    except NotRunningError as exc:
        raise not_running(exc) from None
    sys.stderr.write(f"twin: stopped world [{world}] (pid {pid})\n")


@command(
    "save",
    Arg("file", "Where to write the world.", Path),
    WORLD,
    flag("--force", dest="force", help="Replace FILE even if twin did not write it."),
    help="Save the world (entities, state, physics) to a file `twin load` reads.",
)
def save(*, file: Path, world: str, force: bool = False) -> None:
    with connect_world(world) as c:
        c.save(file, force=force)


@command(
    "load",
    Arg("file", "A file written by `twin save`.", Path, False),
    WORLD,
    flag("--last", dest="last", help="The world's last autosave (after a crash)."),
    help="Replace the running world by one saved with `twin save` (starts the world if none runs).",
)
def load(*, file: Path | None, world: str, last: bool = False) -> None:
    """Load a saved world (or with `last`, the last autosave) into the world's server.

    With no server running, starts one that serves the file (the user named the world it must
    hold, so nothing appears silently); with one, replaces its world.

    Raises:
        BadOption: neither or both of FILE and --last.
    """
    if (file is None) == (not last):
        raise pairs.BadOption("give a FILE written by `twin save`, or --last, not both")
    chosen = _last_autosave(world) if file is None else file
    path = str(Path(chosen).expanduser().absolute())
    started: list[str] = []

    def announce(line: str) -> None:
        started.append(line)
        sys.stderr.write(f"{line}\n")

    with connect_world(world, start=True, serve_args=(path,), announce=announce) as c:
        reply = None if any("started world" in line for line in started) else c.load(path)
    sys.stderr.write(f"twin: world [{world}] loaded from {path}\n")
    for consumer in ("recording", "foxglove", "ros"):  # they follow, or say they stopped
        if isinstance(reply, dict) and consumer in reply:
            sys.stderr.write(f"twin: {consumer} {reply[consumer]}\n")


def _last_autosave(world: str) -> Path:
    """The world's newest autosave; a dead server is reported (and retired) first."""
    from twin_cli.server import lifecycle, runtime

    paths = runtime.world_paths(world)
    with runtime.start_lock(paths):
        if not runtime.server_alive(paths):
            runtime.clean_stale(paths)
            died = lifecycle.retire(paths)
            if died:
                sys.stderr.write(f"twin: {died}\n")
    return lifecycle.last_autosave(paths)


@command(
    "logs",
    Opt(("-n", "--lines"), "lines", "Only the last N.", int),
    WORLD,
    help="Print the world server's log file.",
)
def logs(*, lines: int | None, world: str) -> None:
    from twin_cli.server import runtime

    paths = runtime.world_paths(world)
    if not paths.log.exists():
        from twin_cli.errors import start_fix

        sys.stderr.write(
            f"twin: no log for world [{world}] in {paths.directory}: no server has run for it. "
            f"{start_fix(world)}\n"
        )
        raise SystemExit(2)
    sys.stdout.write(runtime.log_tail(paths, lines))
