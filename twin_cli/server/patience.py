"""How a client waits for a long request (spawn, delete, load, step): while the server lives.

A spawn converts and recompiles, a delete recompiles, and either may queue behind a long `twin
step` for the world's lock: a fixed client timeout turned such a wait into a wrong answer (an
error, while the server deleted the entity 23 s later). So the client waits as long as the
server process is alive (it holds its pid lock) and the user's limit (`TWIN_TIMEOUT` [s], none
by default) allows, with a progress line on a terminal. When the limit is reached the outcome is
unknown, and the request's idempotency key is kept in the runtime directory under the
operation's identity (a digest of the exact request): the same command run again sends the same
key, and the server answers it with the first request's outcome instead of doing it twice. A
key is taken back by that repeat; the keys a dead server can no longer answer go with its other
runtime files (`runtime.clean_stale`).
Standard library only (a client module).
"""

from __future__ import annotations

import hashlib
import os
import sys
import uuid
from pathlib import Path

from twin_cli.server import runtime

TIMEOUT_ENV = "TWIN_TIMEOUT"
KEY_HEADER = "Idempotency-Key"
PROGRESS_AFTER_S = 1.0  # [s] quick requests print nothing


def limit() -> float | None:
    """The user's limit [s] from `$TWIN_TIMEOUT`, or None (wait while the server lives)."""
    text = os.environ.get(TIMEOUT_ENV, "").strip()
    try:
        value = float(text) if text else None
    except ValueError:
        value = None
    return value if value is not None and value > 0 else None


def _pending_file(paths: runtime.WorldPaths, operation: str) -> Path:
    digest = hashlib.sha1(operation.encode("utf-8")).hexdigest()[:16]
    return paths.pending(digest)


def take_key(paths: runtime.WorldPaths, operation: str | None) -> str:
    """The key of an earlier request of this operation whose outcome is unknown, else a new one
    (always a new one for an operation that is never replayed: None)."""
    if operation is None:
        return uuid.uuid4().hex
    path = _pending_file(paths, operation)
    try:
        key = path.read_text().strip()
        path.unlink()
    except OSError:
        key = ""
    return key or uuid.uuid4().hex


def keep_key(paths: runtime.WorldPaths, operation: str | None, key: str) -> None:
    """Remember `key` for the next request of this operation (its outcome is unknown)."""
    if operation is None:
        return
    path = _pending_file(paths, operation)
    fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
    with os.fdopen(fd, "w") as handle:
        handle.write(key + "\n")


class Waiter:
    """The `patience` callback of a long request; draws the progress line on a terminal."""

    def __init__(self, paths: runtime.WorldPaths | None, what: str, limit_s: float | None) -> None:
        self.paths = paths
        self.what = what
        self.limit_s = limit_s
        self.tty = sys.stderr.isatty()
        self.drawn = False

    def __call__(self, elapsed: float) -> bool:
        if self.tty and elapsed >= PROGRESS_AFTER_S:
            sys.stderr.write(f"\r\x1b[Ktwin: {self.what}: waiting for the world, {elapsed:.0f} s")
            sys.stderr.flush()
            self.drawn = True
        if self.paths is not None and not runtime.server_alive(self.paths):
            return True  # the server is gone: its socket closes and the read reports it
        return self.limit_s is None or elapsed < self.limit_s

    def done(self) -> None:
        """Clear the progress line."""
        if self.drawn:
            sys.stderr.write("\r\x1b[K")
            sys.stderr.flush()
