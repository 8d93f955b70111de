"""A conversion a running world asks for: read in a bounded child, built once in the caller.

The child (`converters.isolated.bounded`) does everything that touches the description's files or
could run away on them: xacro (in its own sandboxed grandchild), URDF/SDF parsing, mesh reading,
collision hulls and CoACD, height images, controller parameter files; it makes no MjSpec. It
sends back the robot description, the report so far and the log of what it read
(`converters.isolated.replay`); the caller builds the MjSpec from those without opening a file
(< 0.03 s for a corpus robot), since an MjSpec itself cannot cross processes without losing
precision. The build compiles nothing for a robot without plugins; the world compiles the robot
in its own process in any case.
"""

from __future__ import annotations

import multiprocessing
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from converters.isolated import bounded
from converters.isolated.budget import XacroBudget
from converters.mjcf.builder import ConvertOptions
from converters.pipeline import (
    Conversion,
    build_description,
    read_build_files,
    read_file,
    read_text,
)
from converters.report import Report


@dataclass(frozen=True)
class ConversionJob:
    """One conversion as a value the child can take: a file (`path`) or a text (`text`).

    Attributes:
        source: the file, or a name for the text (`<xml>`), used in messages.
        base_dir: for a text, where relative mesh paths start.
        env: the package search variables to resolve in; None: the process's own.
        read_roots: the only folders the conversion may read (`converters.isolated.confine`);
            None: wherever this process may.
    """

    source: str
    path: str | None = None
    text: str | None = None
    base_dir: str | None = None
    args: tuple[tuple[str, str], ...] = ()
    package_paths: tuple[tuple[str, str], ...] = ()
    options: ConvertOptions = ConvertOptions()
    env: dict[str, str] | None = None
    read_roots: tuple[str, ...] | None = None


def convert_served(
    job: ConversionJob, budget: XacroBudget, cancel: threading.Event | None = None
) -> Conversion:
    """`job` converted under `budget`, with the world's process reading no description file.

    It converts in this process when bounded conversions are not enabled here (`bounded.enable`:
    a world server's choice), or in a daemonic worker process, which may not start children.

    Raises:
        ConversionBudgetError: over time or memory (which stage, how to raise the budget).
        ConversionStoppedError: the world began shutting down, or `cancel` was set, meanwhile.
        ConversionError: any subclass the conversion raised.
    """
    if not bounded.enabled() or multiprocessing.current_process().daemon:
        return convert_job(job)
    from converters.isolated import replay

    robot, report, reads = bounded.run(read_job, job, budget, job.source, cancel)
    with replay.replaying(reads):
        return build_description(robot, job.options, report)


def read_job(job: ConversionJob) -> tuple[Any, Report, dict]:
    """The child's work: the robot description, the report so far and the log of every file
    its build reads (`read_build_files`), read in `job.read_roots` only."""
    from converters.isolated import replay

    with replay.recording() as log, _confined(job):
        robot, report = _read(job)
        read_build_files(robot, job.options)
    return robot, report, log.entries


def convert_job(job: ConversionJob) -> Conversion:
    """The conversion `job` describes, in this process (reading only in `job.read_roots`)."""
    with _confined(job):
        robot, report = _read(job)
        return build_description(robot, job.options, report)


@contextmanager
def _confined(job: ConversionJob) -> Iterator[None]:
    """Reads confined to `job.read_roots` and the collision cache meanwhile (if it has any)."""
    if job.read_roots is None:
        yield
        return
    from converters.collision.cache import cache_root
    from converters.isolated.confine import confined

    with confined(job.read_roots, also=(str(cache_root()),)):  # collision parts are read there
        yield


def _read(job: ConversionJob) -> tuple[Any, Report]:
    packages = dict(job.package_paths)
    if job.text is not None:
        return read_text(
            job.text,
            source=job.source,
            base_dir=job.base_dir,
            package_paths=packages,
            options=job.options,
            env=job.env,
        )
    return read_file(
        Path(job.path or job.source),
        args=dict(job.args),
        package_paths=packages,
        options=job.options,
        env=job.env,
    )
