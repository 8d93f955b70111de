"""Autosave: the served world written to `<world>.autosave.json` every few seconds, atomically.

A crash (SIGKILL, out of memory, a power cut) then loses at most one interval: `twin load
--last` reads the file back. Each save is `World.save` (`twin_cli.world.savefile`): the world's
lock is held only while the state is copied and encoded, a few ms for a handful of robots, and
the file is written to a temporary name, fsynced and renamed, so a reader never sees half a file.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable
from pathlib import Path
from typing import Any

log = logging.getLogger("twin.server")
# [s] default interval: a crash loses at most this much; one save of a humanoid world takes ~2 ms.
DEFAULT_INTERVAL_S = 10.0


class Autosaver:
    """A daemon thread that saves `current()` (the served world) to `path` every `interval` s."""

    def __init__(self, current: Callable[[], Any], path: Path, interval: float) -> None:
        self._current = current
        self.path = path
        self.interval = interval
        self.saves = 0
        self._stop = threading.Event()
        self._last_error: str | None = None
        self._thread = threading.Thread(target=self._run, name="twin-autosave", daemon=True)

    def start(self) -> None:
        """Start saving (nothing happens when the interval is 0: autosave is off)."""
        if self.interval > 0:
            self._thread.start()
            log.info("autosaving to %s every %g s", self.path, self.interval)

    def _run(self) -> None:
        while not self._stop.wait(self.interval):
            self.save_now()

    def save_now(self) -> bool:
        """One save; a failure is logged once (until it changes) and never ends the server."""
        from twin_cli.world import savefile

        try:
            savefile.save(self._current(), self.path, wait_s=0.0)  # the next one has the parts
        except Exception as exc:  # noqa: BLE001 - an autosave must never take the world down
            message = f"{type(exc).__name__}: {exc}"
            if message != self._last_error:
                log.warning("autosave to %s failed: %s", self.path, message)
            self._last_error = message
            return False
        self._last_error = None
        self.saves += 1
        return True

    def close(self) -> None:
        """Stop the thread and write a last save (an orderly stop loses nothing)."""
        if self.interval <= 0:
            return
        self._stop.set()
        if self._thread.is_alive():
            self._thread.join()
        self.save_now()
