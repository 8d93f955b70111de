"""Life records of world servers: started, ended, died; so that no world vanishes silently.

A server writes `<world>.run.json` when it takes its world (pid, start time, log, autosave) and
removes it when it ends in order (`twin stop`, SIGTERM, Ctrl-C). A background server runs under
a supervisor (`twin_cli.server.supervisor`) that writes `<world>.exit.json` with the exit code or
the signal and the time once the server process is gone, whatever killed it: a SIGKILLed
process writes nothing itself, but its parent still reaps its status. So a run record whose
server no longer holds the pid lock means the server died, and the exit record says how.

Standard library only: every client command reads these files to explain "not running".
"""

from __future__ import annotations

import contextlib
import json
import os
import signal
import time
from pathlib import Path
from typing import Any

from twin_cli.server import runtime


def run_record(paths: runtime.WorldPaths) -> Path:
    """Written by a live server, removed when it ends in order."""
    return paths.directory / f"{paths.world}.run.json"


def exit_record(paths: runtime.WorldPaths) -> Path:
    """Written by the supervisor of a background server once the server process has ended."""
    return paths.directory / f"{paths.world}.exit.json"


def autosave_path(paths: runtime.WorldPaths) -> Path:
    """The world's last autosave (a `twin save` file; `twin load --last` reads it)."""
    return paths.directory / f"{paths.world}.autosave.json"


def write_json(path: Path, document: dict[str, Any]) -> None:
    """Write `document` to `path` atomically (a temporary file in the same folder, then rename)."""
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
    with os.fdopen(fd, "w") as handle:
        json.dump(document, handle)
        handle.flush()
        os.fsync(handle.fileno())
    os.replace(tmp, path)


def read_json(path: Path) -> dict[str, Any] | None:
    """The JSON object in `path`, or None when it is missing or unreadable."""
    try:
        value = json.loads(path.read_text())
    except (OSError, ValueError):
        return None
    return value if isinstance(value, dict) else None


def utc(stamp: float) -> str:
    """A Unix time [s] as `YYYY-MM-DD HH:MM:SS UTC`."""
    return time.strftime("%Y-%m-%d %H:%M:%S UTC", time.gmtime(stamp))


def started(paths: runtime.WorldPaths, *, autosave: Path | None, supervised: bool) -> None:
    """Record that this process now serves the world (call with the pid lock held)."""
    exit_record(paths).unlink(missing_ok=True)
    write_json(
        run_record(paths),
        {
            "world": paths.world,
            "pid": os.getpid(),
            "started": time.time(),
            "log": str(paths.log),
            "autosave": str(autosave) if autosave else None,
            "supervised": supervised,
        },
    )


def ended_in_order(paths: runtime.WorldPaths) -> None:
    """Remove the run record: the server stopped because it was asked to."""
    run_record(paths).unlink(missing_ok=True)


def how_it_ended(returncode: int) -> str:
    """`exited with code 3` or `was killed by signal 9 (SIGKILL)` from a Popen returncode."""
    if returncode >= 0:
        return f"exited with code {returncode}"
    try:
        name = signal.Signals(-returncode).name
    except ValueError:
        name = "unknown signal"
    return f"was killed by signal {-returncode} ({name})"


def death(paths: runtime.WorldPaths) -> str | None:
    """One paragraph on the world's dead server (which, pid, how, when, log, autosave), or None.

    None when a server is alive, or when the last one ended in order (or none ever ran).
    """
    if runtime.server_alive(paths):
        return None
    run = read_json(run_record(paths))
    if run is None:
        return None
    ended = read_json(exit_record(paths))
    what = f"world [{paths.world}] (pid {run.get('pid')}, started {utc(run.get('started', 0))})"
    if ended is not None and ended.get("pid") == run.get("pid"):
        how = f"{how_it_ended(int(ended['returncode']))} at {utc(ended['ended'])}"
    else:
        how = (
            "died without an exit status (killed by SIGKILL, or its supervisor was); "
            f"last heard of at {utc(_last_sign_of_life(paths))}"
        )
    lines = [f"{what} {how}; its log: {run.get('log')} (`twin logs --world {paths.world}`)"]
    saved = autosave_path(paths)
    if saved.is_file():
        lines.append(
            f"its last autosave ({utc(saved.stat().st_mtime)}) is {saved}; "
            f"`twin load --last --world {paths.world}` restores it"
        )
    return "\n".join(lines)


def _last_sign_of_life(paths: runtime.WorldPaths) -> float:
    """The newest modification time [s] of the world's log and autosave."""
    times = [0.0]
    for path in (paths.log, autosave_path(paths), run_record(paths)):
        with contextlib.suppress(OSError):
            times.append(path.stat().st_mtime)
    return max(times)


def forget(paths: runtime.WorldPaths) -> None:
    """Drop the records of a dead server (its death has been reported; a new one starts)."""
    for path in (run_record(paths), exit_record(paths)):
        path.unlink(missing_ok=True)


def running_worlds() -> list[str]:
    """Names of the worlds whose servers are alive in this runtime directory, sorted."""
    directory = runtime.runtime_dir()
    names = []
    for pid_file in directory.glob("*.pid"):
        world = pid_file.name[: -len(".pid")]
        if runtime.WORLD_NAME.match(world) and runtime.server_alive(
            runtime.WorldPaths(world, directory)
        ):
            names.append(world)
    return sorted(names)


def not_running_detail(paths: runtime.WorldPaths) -> str:
    """What to say after gz's "not running" line: the death, if any, and the worlds that run.

    Empty when nothing died and no other world runs, so the plain case stays gz's one line.
    """
    lines = []
    died = death(paths)
    if died:
        lines.append(f"twin: {died}")
    others = [w for w in running_worlds() if w != paths.world]
    if others:
        lines.append(
            f"twin: no world [{paths.world}] runs; running worlds: {', '.join(others)} "
            "(choose one with --world)"
        )
    return "\n".join(lines)


def retire(paths: runtime.WorldPaths) -> str | None:
    """Before a new server takes the world: report a dead predecessor and keep its autosave.

    The dead server's autosave is renamed `<world>.died-<time>.json`, so the new server's own
    autosaves never overwrite the state the crash left. Call with the start lock held.

    Returns:
        A paragraph for the user, or None when the last server ended in order.
    """
    died = death(paths)
    if died is None:
        forget(paths)
        return None
    saved = autosave_path(paths)
    if saved.is_file():
        stamp = time.strftime("%Y%m%d-%H%M%S", time.gmtime(saved.stat().st_mtime))
        kept = paths.directory / f"{paths.world}.died-{stamp}.json"
        os.replace(saved, kept)
        died = died.split("\n")[0] + f"\nits last autosave is kept as {kept}; `twin load {kept}`"
    forget(paths)
    return f"the previous server of {died}"


def last_autosave(paths: runtime.WorldPaths) -> Path:
    """The newest autosave of the world: its live one, or one a dead server left.

    Raises:
        WorldFileError: the world has no autosave.
    """
    from twin_cli.errors import WorldFileError

    found = [p for p in paths.directory.glob(f"{paths.world}.died-*.json") if p.is_file()]
    if autosave_path(paths).is_file():
        found.append(autosave_path(paths))
    if not found:
        raise WorldFileError(
            autosave_path(paths),
            f"world [{paths.world}] has no autosave",
            "a server autosaves every 10 s unless started with --no-autosave; "
            "load a file written by `twin save` instead",
        )
    return max(found, key=lambda p: p.stat().st_mtime)
