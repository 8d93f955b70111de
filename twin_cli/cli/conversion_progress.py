"""What a long conversion is doing, on a terminal: a rich status line with the stage and time.

A 2-million-triangle mesh took minutes with nothing on the screen. The converter names each stage
(`converters.isolated.stages.stage`: "reading mesh …/base.obj (96.0 MB)", "preparing 7 collision
meshes"); `twin convert` hears them in its own process, `twin spawn` asks the world for its
running conversions (`GET /conversions`) while its request waits. The line appears only after
SHOW_AFTER_S, so a quick spawn prints nothing, and only when stderr is a terminal: piped or
redirected output gets nothing at all.
"""

from __future__ import annotations

import sys
import threading
from types import TracebackType
from typing import Any, TextIO

SHOW_AFTER_S = 0.5  # [s] a conversion shorter than this shows nothing
POLL_S = 0.25  # [s] how often `twin spawn` asks the world


class StageDisplay:
    """One transient line on `stream` (stderr), if it is a terminal: a spinner, the stage and the
    time it has run; else nothing. It appears SHOW_AFTER_S after the first stage."""

    def __init__(self, stream: TextIO | None = None) -> None:
        self.stream = stream or sys.stderr
        self.enabled = bool(getattr(self.stream, "isatty", lambda: False)())
        self.stage: str | None = None
        self._bar: Any = None
        self._task: Any = None
        self._timer: threading.Timer | None = None
        self._closed = False
        self._lock = threading.Lock()

    def show(self, stage: str | None, seconds: float = 0.0) -> None:
        """Show `stage`, which has run `seconds` [s] so far; None clears the line for good (a
        stage with a progress bar of its own follows)."""
        if not self.enabled:
            return
        if stage is None:
            self.close()
            return
        with self._lock:
            self.stage = stage
            if self._closed:
                return
            if self._bar is not None:
                self._bar.update(self._task, description=stage)
            elif self._timer is None:
                self._timer = threading.Timer(max(0.0, SHOW_AFTER_S - seconds), self._appear)
                self._timer.daemon = True
                self._timer.start()

    def _appear(self) -> None:
        from rich.console import Console
        from rich.progress import Progress, SpinnerColumn, TextColumn, TimeElapsedColumn

        with self._lock:
            if self._closed or self._bar is not None:
                return
            self._bar = Progress(
                SpinnerColumn(),
                TextColumn("{task.description}"),
                TimeElapsedColumn(),
                console=Console(file=self.stream),
                transient=True,
            )
            self._bar.start()
            self._task = self._bar.add_task(self.stage or "", total=None)

    def close(self) -> None:
        with self._lock:
            self._closed = True
            if self._timer is not None:
                self._timer.cancel()
            if self._bar is not None:
                self._bar.stop()
                self._bar = None


class LocalProgress:
    """`twin convert`: the stages of the conversion running in this process."""

    def __enter__(self) -> LocalProgress:
        from converters.isolated.stages import listening

        self.display = StageDisplay()
        self._listening = listening(self.display.show)
        self._listening.__enter__()
        return self

    def __exit__(
        self, kind: type[BaseException] | None, exc: BaseException | None, tb: TracebackType | None
    ) -> None:
        self._listening.__exit__(kind, exc, tb)
        self.display.close()


class WorldProgress:
    """`twin spawn`: the world's conversion of `source` (any, for a text), asked every POLL_S."""

    def __init__(self, world: str, source: str | None) -> None:
        self.world = world
        self.source = source
        self.display = StageDisplay()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._poll, name="twin-progress", daemon=True)

    def __enter__(self) -> WorldProgress:
        if self.display.enabled:
            self._thread.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self._stop.set()
        if self._thread.is_alive():
            self._thread.join(timeout=2 * POLL_S)
        self.display.close()

    def _poll(self) -> None:
        """Ask the world on a connection of its own; a failure ends the display, never the spawn."""
        from twin_cli.cli.world_client import connect_world

        try:
            with connect_world(self.world) as client:
                while not self._stop.wait(POLL_S):
                    for row in client.request("GET", "/conversions"):
                        if self.source is None or row["source"] == self.source:
                            self.display.show(row["stage"], row["seconds"])
        except Exception:  # noqa: BLE001 (progress is best effort: an old server, a closed world)
            return
