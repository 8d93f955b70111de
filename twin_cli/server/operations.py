"""Idempotent spawns and deletes: a repeat (same `Idempotency-Key`) gets the first's outcome.

A client that gave up waiting (`twin_cli.server.patience`) cannot know whether its spawn or
delete happened; its repeat carries the same key. If the first request is still running, the
repeat waits for it; if it has finished, the repeat gets its result or its error again. Nothing
is done twice, and no repeat reports "already exists" for the entity its own first try made.
The last `KEEP` keys are remembered (a few hundred small results).
"""

from __future__ import annotations

import threading
from collections import OrderedDict
from collections.abc import Callable
from typing import Any

KEEP = 512


class _Operation:
    def __init__(self) -> None:
        self.done = threading.Event()
        self.result: Any = None
        self.error: BaseException | None = None


class Operations:
    """Runs keyed work at most once per key, replaying its outcome to repeats."""

    def __init__(self, keep: int = KEEP) -> None:
        self._keep = keep
        self._lock = threading.Lock()
        self._ops: OrderedDict[str, _Operation] = OrderedDict()

    def run(self, key: str | None, work: Callable[[], Any]) -> Any:
        """`work()` once for `key` (every time for None); repeats get the same result or error."""
        if not key:
            return work()
        with self._lock:
            op = self._ops.get(key)
            first = op is None
            if first:
                op = self._ops[key] = _Operation()
                while len(self._ops) > self._keep:
                    self._ops.popitem(last=False)
        if not first:
            op.done.wait()
            if op.error is not None:
                raise op.error
            return op.result
        try:
            op.result = work()
        except BaseException as exc:
            op.error = exc
            raise
        finally:
            op.done.set()
        return op.result
