"""Progress of collision-mesh preparation on stderr: a rich bar on a terminal, lines when piped.

This is the one place in `converters` that writes to a stream, and only when the caller asked
for progress (`CollisionSettings.progress`); findings still go into the `Report`.
"""

from __future__ import annotations

import sys
import time
from typing import Any, TextIO


class MeshProgress:
    """Meshes done / total, the mesh just finished, and elapsed time.

    Use as a context manager; `enabled=False` makes every call a no-op.
    """

    def __init__(self, total: int, *, enabled: bool, stream: TextIO | None = None) -> None:
        self.total = total
        self.enabled = enabled and total > 0
        self.stream = stream or sys.stderr
        self.done = 0
        self._started = time.perf_counter()
        self._bar: Any = None
        self._task: Any = None

    def __enter__(self) -> MeshProgress:
        if self.enabled and getattr(self.stream, "isatty", lambda: False)():
            from rich.console import Console
            from rich.progress import (
                BarColumn,
                MofNCompleteColumn,
                Progress,
                TextColumn,
                TimeElapsedColumn,
            )

            self._bar = Progress(
                TextColumn("collision"),
                BarColumn(),
                MofNCompleteColumn(),
                TimeElapsedColumn(),
                TextColumn("{task.description}"),
                console=Console(file=self.stream),
                transient=True,
            )
            self._bar.start()
            self._task = self._bar.add_task("", total=self.total)
        return self

    def advance(self, label: str) -> None:
        """One more mesh finished; `label` names it and how (e.g. "arm/0 coacd 3 parts")."""
        if not self.enabled:
            return
        self.done += 1
        if self._bar is not None:
            self._bar.update(self._task, advance=1, description=label)
            return
        elapsed = time.perf_counter() - self._started
        self.stream.write(f"collision {self.done}/{self.total} {elapsed:6.1f} s  {label}\n")
        self.stream.flush()

    def __exit__(self, *exc: object) -> None:
        if self._bar is not None:
            self._bar.stop()
