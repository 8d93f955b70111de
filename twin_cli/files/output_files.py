"""Writing a user's output file (a save, a snapshot) safely: atomically, to a regular file only.

`os.replace` puts a new file where the target was, whatever the target was: run as root, a save
to `/dev/null` once replaced the machine's null device with a regular file. So the target is
checked first: it may be absent or a regular file; a directory, device, FIFO or socket is
refused. A symlink is written through: its target (a regular file, or absent) is replaced, and
the link stays. The file is written beside its target, flushed to disk and renamed into place,
so a reader never sees half of it; it is created 0600, since it may hold a world's state. An
existing file twin did not write (a writer's predicate reads its first bytes) is replaced only
when the user says so (`--force`): a path typed wrong must not cost someone's file.
Standard library only.
"""

from __future__ import annotations

import os
import stat
import tempfile
from collections.abc import Callable
from pathlib import Path

PRIVATE = 0o600  # a save or snapshot: a world's state
HEAD_BYTES = 4096  # what `checked_target` reads of an existing file to tell whose it is
REPORT = 0o644  # a report (JUnit, Markdown): meant to be read by CI and colleagues


class OutputFileError(OSError):
    """The target cannot take the output: not a regular file, or not writable."""

    def __init__(self, path: Path, problem: str, fix: str) -> None:
        super().__init__(f"{path}: {problem}; {fix}")
        self.filename = str(path)
        self.problem = problem
        self.fix = fix

    def __str__(self) -> str:  # OSError's own would show "[Errno None]"
        return f"{self.filename}: {self.problem}; {self.fix}"


def checked_target(
    path: str | os.PathLike, *, ours: Callable[[bytes], bool] | None = None, force: bool = False
) -> Path:
    """The file to write for `path`: symlinks followed; absent or a regular file.

    Args:
        ours: tells from a file's first bytes whether twin wrote it (a save, a snapshot); an
            existing, non-empty file it does not recognise is not replaced unless `force`.

    Raises:
        OutputFileError: a directory, device, FIFO or socket, a folder that does not exist, or
            a file of someone else's that `ours` does not recognise.
    """
    target = Path(path).expanduser().resolve()
    try:
        mode = target.stat().st_mode
    except FileNotFoundError:
        if not target.parent.is_dir():
            raise OutputFileError(target, "its folder does not exist", "create it first") from None
        return target
    if not stat.S_ISREG(mode):
        kind = "a directory" if stat.S_ISDIR(mode) else "not a regular file (a device or pipe)"
        raise OutputFileError(target, f"is {kind}", "give the path of a regular file")
    if (
        ours is not None
        and not force
        and (head := _head(target)) != b""
        and not (head is not None and ours(head))
    ):
        raise OutputFileError(
            target,
            "exists and is not a file twin wrote",
            "choose another name, or pass --force to replace it",
        )
    return target


def _head(path: Path) -> bytes | None:
    """The file's first HEAD_BYTES (b"": empty, nothing to keep; None: unreadable, so whose it
    is cannot be told and it is kept)."""
    try:
        with path.open("rb") as stream:
            return stream.read(HEAD_BYTES)
    except OSError:
        return None


def write_atomically(
    path: str | os.PathLike,
    payload: bytes,
    mode: int = PRIVATE,
    *,
    ours: Callable[[bytes], bool] | None = None,
    force: bool = False,
) -> Path:
    """Writes `payload` to `path` (see the module docstring); returns the file written.

    Raises:
        OutputFileError: the target is not a regular file or someone else's (`checked_target`),
            or the folder is not writable.
    """
    target = checked_target(path, ours=ours, force=force)
    try:
        fd, temp = tempfile.mkstemp(dir=target.parent, prefix=f".{target.name}.", suffix=".tmp")
    except OSError as exc:
        problem = f"cannot write ({exc.strerror})"
        raise OutputFileError(target, problem, "choose a writable folder") from exc
    try:
        with os.fdopen(fd, "wb") as handle:
            os.fchmod(handle.fileno(), mode)
            handle.write(payload)
            handle.flush()
            os.fsync(handle.fileno())
        os.replace(temp, target)
    except BaseException:
        Path(temp).unlink(missing_ok=True)
        raise
    return target
