"""What a conversion is doing now (a step and its file), for progress and for budget messages.

The converter names its stages with `stage` ("reading mesh …/base.obj (96.0 MB)", "expanding xacro
…", "preparing 7 collision meshes"). In a bounded child (`converters.isolated.bounded`) each goes
to a buffer shared with the caller, which names the last one when the budget runs out and serves
it as progress; in any process it also goes to a `listening` callback (a CLI's display). The
converter itself never writes to a stream.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

STAGE_BYTES = 512  # the stage text shared with the caller (a long path is cut)
STARTING = "starting"

_current = STARTING
_board: Any = None  # in a bounded child: the buffer shared with the caller
_listener: Callable[[str | None], None] | None = None


def stage(what: str, *, own_progress: bool = False) -> None:
    """Say what the conversion is doing now. `own_progress`: the stage shows a progress bar of
    its own (collision meshes), so a listener's display gets None and makes way."""
    global _current
    _current = what
    board, listener = _board, _listener
    if board is not None:  # a write to shared memory: no system call, cheap for every mesh
        board.value = what.encode(errors="replace")[: STAGE_BYTES - 1]
    if listener is not None:
        listener(None if own_progress else what)


def current() -> str:
    """The stage said last in this process."""
    return _current


def share(board: Any) -> None:
    """From now on, write each stage to `board` (a bounded child's buffer shared with its
    caller: a ctypes char array of STAGE_BYTES)."""
    global _board
    _board = board


def read(board: Any) -> str:
    """The stage in a shared `board` (read without a lock: a torn read is only text)."""
    return board.value.decode(errors="replace") or STARTING


@contextmanager
def listening(listener: Callable[[str | None], None]) -> Iterator[None]:
    """Call `listener` with each stage of a conversion in this process meanwhile."""
    global _listener
    previous, _listener = _listener, listener
    try:
        yield
    finally:
        _listener = previous
