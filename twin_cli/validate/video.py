"""`twin validate --video DIR`: one short MP4 per physics scenario, rendered in-process.

While `filming(directory)` is active, every `ScenarioRun` a check builds is filmed
(`twin_cli.view.video.WorldVideo`, following the robot); `scenario(name)` closes that scenario's
video when its check returns. A check that builds several runs (friction probes) gets one file
per run after the first (`NAME-2.mp4`, ...).
"""

from __future__ import annotations

import contextlib
import re
from collections.abc import Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from twin_cli.world.engine import World

_directory: Path | None = None
_open: list[Any] = []
_name: str | None = None
written: list[Path] = []


@contextlib.contextmanager
def filming(directory: str | Path | None) -> Iterator[None]:
    """Films the scenarios run inside the block into `directory` (None: nothing is filmed)."""
    global _directory
    if directory is None:
        yield
        return
    from twin_cli.view.offscreen import use_egl

    use_egl()
    _check_offscreen()
    _directory = Path(directory)
    _directory.mkdir(parents=True, exist_ok=True)
    written.clear()
    try:
        yield
    finally:
        _directory = None


@contextlib.contextmanager
def scenario(name: str) -> Iterator[None]:
    """Names the videos of one scenario's runs and closes them when the check returns."""
    global _name
    _name = name
    try:
        yield
    finally:
        for video in _open:
            video.close()
            written.append(Path(video.path))
        _open.clear()
        _name = None


def active() -> bool:
    """Whether scenario runs are being filmed (`--video`)."""
    return _directory is not None


def film(world: World, entity: str) -> None:
    """Starts filming a new scenario run's world, when filming is on."""
    if _directory is None or _name is None:
        return
    from twin_cli.view.video import WorldVideo

    slug = re.sub(r"[^A-Za-z0-9_.-]+", "_", _name)
    suffix = f"-{len(_open) + 1}" if _open else ""
    _open.append(WorldVideo(world, entity, str(_directory / f"{slug}{suffix}.mp4")))


def _check_offscreen() -> None:
    """Fails before any check runs when there is no offscreen GL (exit 2, what to install)."""
    import mujoco

    from twin_cli.view.offscreen import renderer

    renderer(mujoco.MjModel.from_xml_string("<mujoco/>"), 8, 8).close()
