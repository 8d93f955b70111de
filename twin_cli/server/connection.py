"""Reaching a world's server from a client: connect (starting one in the background when
asked) and stop it, waiting until its process has ended.

Standard library only, as every client module: a command that finds its world running pays
for nothing else.
"""

from __future__ import annotations

import os
import signal
import sys
import time
from typing import Any

from twin_cli.errors import NoReplyError, NotRunningError
from twin_cli.server import runtime
from twin_cli.server.client import Client

STOP_TIMEOUT_S = 15.0  # [s] for the server to end after each of shutdown, SIGTERM, SIGKILL
# [s] for the server to take the shutdown request: one that does not (stopped, wedged) gets the
# signals, so `twin stop` always ends
SHUTDOWN_ASK_S = 5.0


def connect(
    world: str = runtime.DEFAULT_WORLD,
    *,
    start: bool = False,
    announce: Any = None,
    serve_args: tuple[str, ...] = (),
) -> Client:
    """A client of `world`'s server; with `start`, starts it in the background when none runs.

    Only `twin spawn` (and `twin load`, which names the world to run) start a world: every other
    command passes `start=False`, so a typo in --world or a dead server is reported, never
    replaced by a fresh empty world. A server that is alive (it holds its pid lock) but not yet
    answering is waited for.

    Args:
        world: world name.
        start: start the server when none answers (False: raise NotRunningError).
        announce: callable given one line to tell the user a server was started
            (default: write it to stderr).
        serve_args: extra `twin serve` arguments for a server started here (a world file).

    Raises:
        NotRunningError: none runs and `start` is False; its message says whether the world's
            server died (pid, how, when, log) and which worlds do run.
        ServerStartError: the background server did not come up.
    """
    from twin_cli.server import lifecycle

    client = Client(world)
    if client.alive():
        return client
    paths = client.paths
    if not start:
        if runtime.server_alive(paths):
            _await_answer(client)
            return client
        client.close()
        raise NotRunningError(world, lifecycle.not_running_detail(paths))
    say = announce or _stderr
    with runtime.start_lock(paths):
        if not runtime.server_alive(paths):
            runtime.clean_stale(paths)
            died = lifecycle.retire(paths)
            if died:
                say(f"twin: {died}")
            proc = runtime.launch_background(paths, list(serve_args))
            runtime.wait_until(paths, client.alive, proc, runtime.START_TIMEOUT_S)
            say(
                f"twin: started world [{world}] in the background "
                f"(pid {runtime.read_pid(paths)}); `twin stop` ends it"
            )
    _await_answer(client)
    return client


def _await_answer(client: Client) -> None:
    """Waits until the server answers `/health`, as long as its process lives (it holds its pid
    lock: busy on a loaded machine, or stopped for a moment) and `$TWIN_TIMEOUT` allows.

    Raises:
        NotRunningError: the server ended meanwhile.
        NoReplyError: the user's limit passed (exit 75).
    """
    from twin_cli.server import lifecycle, patience

    limit, start = patience.limit(), time.monotonic()
    while not client.alive():
        if not runtime.server_alive(client.paths):
            raise NotRunningError(client.world, lifecycle.not_running_detail(client.paths))
        if limit is not None and time.monotonic() - start > limit:
            raise NoReplyError(client.world, "GET /health", limit)
        time.sleep(runtime.START_POLL_S)


def _stderr(line: str) -> None:
    sys.stderr.write(line + "\n")
    sys.stderr.flush()


def stop(world: str = runtime.DEFAULT_WORLD, timeout: float = STOP_TIMEOUT_S) -> int | None:
    """Ask `world`'s server to shut down and wait until its process is gone.

    Escalates to SIGTERM, then SIGKILL, if it does not end within `timeout` seconds.

    Returns:
        The pid of the stopped server.

    Raises:
        NotRunningError: no server runs for this world.
    """
    paths = runtime.world_paths(world)
    pid = runtime.read_pid(paths)
    if not runtime.server_alive(paths):
        from twin_cli.server import lifecycle

        with runtime.start_lock(paths):
            detail = lifecycle.not_running_detail(paths)
            runtime.clean_stale(paths)
            lifecycle.forget(paths)  # reported here: `twin stop` acknowledges a dead server
        raise NotRunningError(world, detail)
    asked = True
    with Client(world) as client:
        try:
            client.request("POST", "/shutdown", timeout=SHUTDOWN_ASK_S)
        except NotRunningError:
            pass  # socket gone but process alive: fall through to signals
        except NoReplyError:
            asked = False  # stopped (Ctrl-Z) or wedged: straight to the signals
    # The server lets go of its pid lock as it shuts down, while a request thread (a render, a
    # conversion) may still be finishing: wait for the process itself to be gone as well.
    signals = (None, signal.SIGTERM, signal.SIGKILL) if asked else (signal.SIGTERM, signal.SIGKILL)
    for sig in signals:
        if sig is not None and pid:
            try:
                os.kill(pid, sig)
                os.kill(pid, signal.SIGCONT)  # a stopped process takes its signal only running
            except ProcessLookupError:
                break
        deadline = time.monotonic() + timeout
        while _running(paths, pid) and time.monotonic() < deadline:
            time.sleep(runtime.START_POLL_S)
        if not _running(paths, pid):
            break
    with runtime.start_lock(paths):
        runtime.clean_stale(paths)
    return pid


def _running(paths: runtime.WorldPaths, pid: int | None) -> bool:
    """The server holds its pid lock, or its process still exists (finishing its threads)."""
    if runtime.server_alive(paths):
        return True
    if not pid:
        return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return not _zombie(pid)


def _zombie(pid: int) -> bool:
    """An ended process its parent (the supervisor) has not reaped yet counts as gone."""
    try:
        with open(f"/proc/{pid}/stat", encoding="ascii") as handle:
            return handle.read().rsplit(")", 1)[1].split()[0] == "Z"
    except (OSError, IndexError):
        return False
