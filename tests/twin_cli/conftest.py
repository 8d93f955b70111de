"""Fixtures for the world server tests: a real `twin serve` on a temporary runtime directory."""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
import sys
from collections.abc import Callable, Iterator
from contextlib import AbstractContextManager, contextmanager
from pathlib import Path

import pytest

from twin_cli.server import runtime
from twin_cli.server.client import Client

START_TIMEOUT_S = 60.0  # [s] a cold start imports mujoco and FastAPI on a loaded CI machine


@contextmanager
def served_world(
    runtime_dir: Path, world: str, *serve_args: str, new_session: bool = False
) -> Iterator[tuple[Client, subprocess.Popen]]:
    """Runs `twin serve --world <world> <serve_args>` with its runtime files in `runtime_dir`.

    Yields a connected client and the server process; on exit closes the client, sends SIGTERM
    and waits for the process (its output goes to `runtime_dir/serve.out`). `new_session`: the
    server leads its own process group (what a terminal's Ctrl-C reaches), and the whole group,
    encoder included, is killed on exit whatever the test did to it.
    """
    runtime_dir.mkdir(parents=True, exist_ok=True)
    patch = pytest.MonkeyPatch()
    patch.setenv(runtime.RUNTIME_ENV, str(runtime_dir))
    env = {**os.environ, runtime.RUNTIME_ENV: str(runtime_dir)}
    with open(runtime_dir / "serve.out", "wb") as log:
        proc = subprocess.Popen(
            [sys.executable, "-m", "twin_cli.cli.app", "serve", "--world", world, *serve_args],
            stdout=log,
            stderr=log,
            env=env,
            start_new_session=new_session,
        )
    client = Client(world)
    try:
        runtime.wait_until(client.paths, client.alive, proc, START_TIMEOUT_S)
        yield client, proc
    finally:
        client.close()
        if new_session:
            with contextlib.suppress(ProcessLookupError):
                os.killpg(proc.pid, signal.SIGKILL)
        else:
            proc.terminate()
        proc.wait(timeout=20)
        patch.undo()


@pytest.fixture(scope="session")
def serve_world() -> Callable[..., AbstractContextManager[tuple[Client, subprocess.Popen]]]:
    """`served_world` (see above), for module- and function-scoped server fixtures."""
    return served_world
