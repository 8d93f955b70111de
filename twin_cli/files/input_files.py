"""Reading a file a user names (a save, a world file) safely: a regular file, up to a size cap.

`Path.read_text` on `/dev/zero` reads until memory runs out (a served world grew to 16 GB and
the kernel's out-of-memory killer ended it), and on a FIFO it waits for a writer that may never
come, holding the request. So the path is checked to be a regular file before it is opened (an
open of a device may act), opened without blocking, checked to be the same file through the
open descriptor (a rename between the check and the open cannot swap it), refused when
it is larger than the cap, and read no further than the cap (a file that grows while it is read
is refused too). Standard library only.
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

MAX_INPUT_BYTES = 64 * 1024 * 1024
"""Largest save or world file read [bytes]. A save of 1000 humanoids is about 5 MB and the
largest SDF world of gz-sim's examples under 1 MB; 64 MiB leaves room and bounds memory."""
_CHUNK = 1024 * 1024


class InputFileError(OSError):
    """The path names no regular file twin reads, or one too large; `strerror` says which."""

    def __init__(self, path: Path, problem: str) -> None:
        super().__init__(None, problem, str(path))
        self.strerror = problem

    def __str__(self) -> str:  # OSError's own would show "[Errno None]"
        return f"{self.filename}: {self.strerror}"


def read_text(path: str | os.PathLike, limit: int = MAX_INPUT_BYTES) -> str:
    """The text of the regular file `path` (UTF-8), at most `limit` bytes.

    Raises:
        InputFileError: a directory, device, FIFO or socket, or a file over `limit` bytes.
        OSError: the file cannot be opened or read (missing, no permission).
        UnicodeDecodeError: not UTF-8.
    """
    path = Path(path)
    named = os.stat(path)  # a device is refused before it is opened (an open may act)
    if not stat.S_ISREG(named.st_mode):
        raise InputFileError(path, f"not a regular file ({_kind(named.st_mode)})")
    fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | os.O_CLOEXEC)
    try:
        facts = os.fstat(fd)
        if (facts.st_dev, facts.st_ino) != (named.st_dev, named.st_ino):
            raise InputFileError(path, "replaced while it was opened")
        if facts.st_size > limit:
            raise InputFileError(path, f"larger than {limit // (1024 * 1024)} MiB")
    except BaseException:
        os.close(fd)
        raise
    with os.fdopen(fd, "rb") as stream:
        data = bytearray()
        while chunk := stream.read(min(_CHUNK, limit + 1 - len(data))):
            data += chunk
            if len(data) > limit:
                raise InputFileError(path, f"larger than {limit // (1024 * 1024)} MiB")
    return data.decode("utf-8")


def _kind(mode: int) -> str:
    kinds = (
        (stat.S_ISDIR, "a directory"),
        (stat.S_ISFIFO, "a FIFO"),
        (stat.S_ISCHR, "a character device"),
        (stat.S_ISBLK, "a block device"),
        (stat.S_ISSOCK, "a socket"),
    )
    return next((name for test, name in kinds if test(mode)), "a special file")
