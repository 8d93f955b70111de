"""Per-user runtime files of world servers: socket, pid, log, token; liveness, cleanup, start-up."""

from __future__ import annotations

import contextlib
import fcntl
import glob
import os
import re
import stat
import sys
import tempfile
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from twin_cli.errors import ServerStartError, TwinError, WorldRunningError

if TYPE_CHECKING:
    import subprocess

RUNTIME_ENV = "TWIN_RUNTIME_DIR"
DEFAULT_WORLD = "default"
# A world name becomes a file name; keep it to characters every file system accepts.
WORLD_NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.-]{0,63}$")
# sockaddr_un.sun_path is 108 bytes on Linux, including the terminating NUL.
MAX_SOCKET_PATH = 107
# Cold start of a server: Python + mujoco import + world compile; ~1-2 s idle, more on a busy box.
START_TIMEOUT_S = 60.0
START_POLL_S = 0.05


class RuntimeDirError(TwinError):
    """The runtime directory cannot be used safely."""

    def __init__(self, path: Path, problem: str, fix: str) -> None:
        super().__init__(f"runtime directory {path}: {problem}; {fix}")
        self.path = path


class WorldNameError(TwinError):
    """A world name that cannot name runtime files."""

    def __init__(self, name: str) -> None:
        super().__init__(
            f"world name {name!r} is not allowed; use 1-64 letters, digits, '_', '.' or '-' "
            "starting with a letter or digit"
        )
        self.name = name


@dataclass(frozen=True)
class WorldPaths:
    """The runtime files of one world's server."""

    world: str
    directory: Path

    def _file(self, suffix: str) -> Path:
        return self.directory / f"{self.world}.{suffix}"

    @property
    def socket(self) -> Path:
        """Unix socket the server listens on (mode 0600)."""
        return self._file("sock")

    @property
    def pid(self) -> Path:
        """Pid file; the live server holds an exclusive flock on it for its whole life."""
        return self._file("pid")

    @property
    def log(self) -> Path:
        """Server log (kept after the server ends, so `twin logs` can show why it stopped)."""
        return self._file("log")

    @property
    def token(self) -> Path:
        """Bearer token for the TCP listener (mode 0600), present only with `--tcp`."""
        return self._file("token")

    @property
    def tcp(self) -> Path:
        """`host:port` of the TCP listener, present only with `--tcp`."""
        return self._file("tcp")

    @property
    def start_lock(self) -> Path:
        """Serialises starting and cleaning up, so two clients never start two servers."""
        return self._file("start.lock")

    def pending(self, digest: str) -> Path:
        """An idempotency key kept by a client whose request's outcome is unknown."""
        return self._file(f"pending-{digest}")

    def transient(self) -> tuple[Path, ...]:
        """Files that belong to a live server and are stale once it is gone: a new server
        cannot answer the old one's idempotency keys either."""
        pending = tuple(self.directory.glob(f"{glob.escape(self.world)}.pending-*"))
        return (self.socket, self.token, self.tcp, self.pid, *pending)


def runtime_dir() -> Path:
    """Return the per-user runtime directory, created with mode 0700.

    `$TWIN_RUNTIME_DIR` if set, else `$XDG_RUNTIME_DIR/twin`, else `/tmp/twin-<uid>`.

    Raises:
        RuntimeDirError: the directory belongs to another user or cannot be created.
    """
    if os.environ.get(RUNTIME_ENV):
        path = Path(os.environ[RUNTIME_ENV])
    elif os.environ.get("XDG_RUNTIME_DIR") and Path(os.environ["XDG_RUNTIME_DIR"]).is_dir():
        path = Path(os.environ["XDG_RUNTIME_DIR"]) / "twin"
    else:
        path = Path(tempfile.gettempdir()) / f"twin-{os.getuid()}"
    try:
        path.mkdir(mode=0o700, parents=True, exist_ok=True)
        info = path.lstat()
    except OSError as exc:
        raise RuntimeDirError(
            path, f"cannot create it ({exc.strerror})", f"set {RUNTIME_ENV}"
        ) from exc
    if not stat.S_ISDIR(info.st_mode) or info.st_uid != os.getuid():
        raise RuntimeDirError(
            path, "is not a directory owned by you", f"remove it or set {RUNTIME_ENV} elsewhere"
        )
    if stat.S_IMODE(info.st_mode) != 0o700:
        path.chmod(0o700)
    return path


def world_paths(world: str = DEFAULT_WORLD) -> WorldPaths:
    """Return the runtime files of `world`, checking the name and the socket path length.

    Raises:
        WorldNameError: the name is not a safe file name.
        RuntimeDirError: the socket path would exceed the Unix limit of 107 bytes.
    """
    if not WORLD_NAME.match(world):
        raise WorldNameError(world)
    paths = WorldPaths(world, runtime_dir())
    if len(os.fsencode(paths.socket)) > MAX_SOCKET_PATH:
        raise RuntimeDirError(
            paths.directory,
            f"socket path {paths.socket} is longer than {MAX_SOCKET_PATH} bytes",
            f"set {RUNTIME_ENV} to a shorter directory or use a shorter world name",
        )
    return paths


def server_alive(paths: WorldPaths) -> bool:
    """True while a server process holds the lock on the world's pid file.

    The kernel drops the flock when the process dies, even by SIGKILL, so this never
    mistakes a recycled pid for a live server.
    """
    try:
        fd = os.open(paths.pid, os.O_RDONLY)
    except FileNotFoundError:
        return False
    try:
        fcntl.flock(fd, fcntl.LOCK_SH | fcntl.LOCK_NB)
    except BlockingIOError:
        return True
    finally:
        os.close(fd)
    return False


def read_pid(paths: WorldPaths) -> int | None:
    """The pid written in the pid file, or None when there is none."""
    try:
        return int(paths.pid.read_text().strip())
    except (FileNotFoundError, ValueError):
        return None


def clean_stale(paths: WorldPaths) -> list[Path]:
    """Remove the transient files of a dead server; call with `start_lock` held.

    Returns:
        The files removed (empty when a server is alive or nothing was left behind).
    """
    if server_alive(paths):
        return []
    removed = []
    for path in paths.transient():
        with contextlib.suppress(FileNotFoundError):
            path.unlink()
            removed.append(path)
    return removed


@contextlib.contextmanager
def start_lock(paths: WorldPaths, timeout: float = START_TIMEOUT_S) -> Iterator[None]:
    """Hold the world's start lock (blocking up to `timeout` seconds)."""
    fd = os.open(paths.start_lock, os.O_RDWR | os.O_CREAT, 0o600)
    try:
        deadline = time.monotonic() + timeout
        while True:
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                break
            except BlockingIOError:
                if time.monotonic() > deadline:
                    raise ServerStartError(
                        paths.world, paths.log, "another start is stuck"
                    ) from None
                time.sleep(START_POLL_S)
        yield
    finally:
        os.close(fd)


@contextlib.contextmanager
def hold_pid_file(paths: WorldPaths) -> Iterator[None]:
    """Own the world for the server's lifetime: lock the pid file, write our pid, clean up after.

    Raises:
        WorldRunningError: another live server already owns this world.
    """
    fd = os.open(paths.pid, os.O_RDWR | os.O_CREAT, 0o600)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        os.close(fd)
        raise WorldRunningError(paths.world, read_pid(paths)) from None
    try:
        os.ftruncate(fd, 0)
        os.write(fd, f"{os.getpid()}\n".encode())
        yield
    finally:
        for path in paths.transient():  # unlink before unlocking: no one sees a half-dead server
            with contextlib.suppress(FileNotFoundError):
                path.unlink()
        os.close(fd)


def open_log(paths: WorldPaths) -> int:
    """Open the world's log for appending (created 0600: it names files and entities)."""
    return os.open(paths.log, os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o600)


def launch_background(paths: WorldPaths, serve_args: list[str]) -> subprocess.Popen:
    """Start `twin serve` for this world detached (new session, no terminal), logging to a file.

    Call with `start_lock` held; the child is told so and does not take it.
    """
    import subprocess  # here, not at the top: world commands that find a server never need it

    cmd = [sys.executable, "-m", "twin_cli", "serve", "--world", paths.world, "--background"]
    # Under a supervisor that records how the server ended (twin_cli.server.lifecycle).
    exit_file = paths.directory / f"{paths.world}.exit.json"
    supervisor = [sys.executable, "-m", "twin_cli.server.supervisor", str(exit_file), "--"]
    with os.fdopen(open_log(paths), "ab") as log:
        return subprocess.Popen(
            supervisor + cmd + serve_args,
            stdin=subprocess.DEVNULL,
            stdout=log,
            stderr=log,
            start_new_session=True,
            close_fds=True,
            env={**os.environ, RUNTIME_ENV: str(paths.directory)},
        )


def wait_until(
    paths: WorldPaths, ready: Callable[[], bool], proc: subprocess.Popen | None, timeout: float
) -> None:
    """Poll `ready()` until it is true; fail early if the started process exits.

    Raises:
        ServerStartError: the process exited, or `timeout` seconds passed.
    """
    deadline = time.monotonic() + timeout
    while not ready():
        if proc is not None and proc.poll() is not None:
            raise ServerStartError(paths.world, paths.log, f"it exited with code {proc.returncode}")
        if time.monotonic() > deadline:
            raise ServerStartError(paths.world, paths.log, f"it did not answer in {timeout:.0f} s")
        time.sleep(START_POLL_S)


def log_tail(paths: WorldPaths, lines: int | None = None) -> str:
    """The server log, or its last `lines` lines; empty when there is no log yet."""
    try:
        text = paths.log.read_text(errors="replace")
    except FileNotFoundError:
        return ""
    if lines is None:
        return text
    return "".join(text.splitlines(keepends=True)[-lines:]) if lines > 0 else ""
