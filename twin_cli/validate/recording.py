"""`twin validate --record DIR`: one rosbag2 MCAP file per physics scenario run, for CI.

Each `ScenarioRun` (one in-process world per physics scenario) asks `attach` when it is built;
while `recording_into(DIR)` is active, that starts the recorder the server uses
(`twin_cli.record.BagRecording`) on the run's world, at `RATE` Hz of sim time, into
`DIR/<scenario>.mcap` (`<scenario>-2.mcap`... when a check runs several worlds). `finish`,
called by the runner after each check, closes the files. A recording failure never changes a
check's result: it is logged and the file is left out.
"""

from __future__ import annotations

import contextlib
import logging
import re
from collections.abc import Iterator
from contextvars import ContextVar
from pathlib import Path
from typing import TYPE_CHECKING, Any

from twin_cli.errors import RequestError

if TYPE_CHECKING:
    from twin_cli.world.engine import World

log = logging.getLogger("twin.validate")
RATE = 100.0  # [Hz] of sim time, `twin record`'s default

_target: ContextVar[Path | None] = ContextVar("twin_validate_record", default=None)
_open: list[Any] = []  # recordings started during the current check
written: list[Path] = []  # files of the last `recording_into` block


@contextlib.contextmanager
def recording_into(folder: Path | None) -> Iterator[None]:
    """Records every scenario run inside the block into `folder` (None: no recording).

    Raises:
        RequestError: `folder` cannot be created.
    """
    if folder is None:
        yield
        return
    folder = Path(folder).expanduser()
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise RequestError(
            f"recording folder {folder}",
            f"cannot be created ({exc.strerror or exc})",
            "give a writable directory to --record",
        ) from exc
    written.clear()
    token = _target.set(folder)
    try:
        yield
    finally:
        finish()
        _target.reset(token)


def active() -> bool:
    """Whether scenario runs are being recorded (`--record`)."""
    return _target.get() is not None


def attach(world: World, scenario: str) -> None:
    """Starts recording `world` (a scenario run's) when a recording folder is set."""
    folder = _target.get()
    if folder is None:
        return
    from twin_cli.record import BagRecording

    path = _free_name(folder, scenario)
    try:
        _open.append(BagRecording(world, path, rate=RATE).start())
        written.append(path)
    except Exception as exc:  # a bag is an artifact, never a check's outcome
        log.warning("not recording scenario %s: %s", scenario, exc)


def finish() -> None:
    """Closes the files of the runs started since the last call."""
    while _open:
        status = _open.pop().stop()
        if status.error:
            log.warning("recording ended with an error: %s", status.error)


def _free_name(folder: Path, scenario: str) -> Path:
    stem = re.sub(r"[^A-Za-z0-9_.-]+", "_", scenario) or "scenario"
    path, k = folder / f"{stem}.mcap", 1
    while path.exists() or path in written:
        k += 1
        path = folder / f"{stem}-{k}.mcap"
    return path
