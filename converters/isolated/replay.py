"""What a conversion read from files (meshes, collision parts, height images, controller files),
kept so that the MjSpec can be built in another process without reading anything.

A served conversion reads in a bounded child process (`converters.isolated.bounded`), and an
MjSpec could not leave a process losslessly anyway: `to_xml` rounds every number to about 7
digits and took 0.2-0.4 s for a small robot. So the child sends the robot description and this
log of its reads, and the world builds the spec from them (a warm build of a corpus robot takes
< 0.03 s) with every read answered from the log. A read the log does not hold is a defect,
never a fallback to the file: the world process must not parse a file.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass, field
from typing import Any, TypeVar

T = TypeVar("T")


@dataclass
class ReadLog:
    """Reads by (kind, key) → value; `replaying`: answer from `entries` instead of reading."""

    entries: dict[tuple, Any] = field(default_factory=dict)
    replaying: bool = False


class NotRecordedError(RuntimeError):
    """A build asked for a read its reading stage never made (a converter defect)."""


_LOG: ContextVar[ReadLog | None] = ContextVar("converters_read_log", default=None)


def read_once(
    kind: str,
    key: tuple,
    read: Callable[[], T],
    *,
    pack: Callable[[T], Any] | None = None,
    unpack: Callable[[Any], T] | None = None,
) -> T:
    """`read()`, recorded under (kind, key) while recording, answered from the log while
    replaying, and simply called otherwise.

    Args:
        pack, unpack: turn the value into what is kept and back (identity by default), for
            values whose object identity matters to the builder.

    Raises:
        NotRecordedError: replaying, and (kind, key) was never read.
    """
    log = _LOG.get()
    if log is None:
        return read()
    entry = (kind, *key)
    if log.replaying:
        if entry not in log.entries:
            raise NotRecordedError(f"{kind} {key} was not read by the conversion's reading stage")
        kept = log.entries[entry]
        return unpack(kept) if unpack else kept
    value = read()
    log.entries[entry] = pack(value) if pack else value
    return value


@contextmanager
def recording() -> Iterator[ReadLog]:
    """Record every `read_once` of this context (thread or task) meanwhile."""
    log = ReadLog()
    token = _LOG.set(log)
    try:
        yield log
    finally:
        _LOG.reset(token)


@contextmanager
def replaying(entries: dict[tuple, Any]) -> Iterator[None]:
    """Answer every `read_once` of this context meanwhile from `entries`."""
    token = _LOG.set(ReadLog(entries, replaying=True))
    try:
        yield
    finally:
        _LOG.reset(token)
