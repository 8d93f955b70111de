"""A conversion a running world asks for: read in a bounded child, built again in the caller.

The child (`converters.isolated.bounded`) does everything that touches the description's files or
could run away on them: xacro (in its own sandboxed grandchild), URDF/SDF parsing, mesh reading,
collision hulls and CoACD, and the build. It sends back the robot description, the report and the
log of what it read (`converters.isolated.replay`); the caller builds the MjSpec from those
without opening a file (< 0.1 s for a corpus robot), since an MjSpec itself cannot cross processes
without losing precision.
"""

from __future__ import annotations

import multiprocessing
import threading
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from converters.isolated import bounded, replay
from converters.isolated.budget import XacroBudget
from converters.mjcf.builder import ConvertOptions
from converters.pipeline import Conversion, build_description, convert_full, convert_text
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
    robot, report, reads = bounded.run(read_and_build, job, budget, job.source, cancel)
    with replay.replaying(reads):
        done = build_description(robot, job.options, Report(source=report.source))
    return replace(done, report=report)


def read_and_build(job: ConversionJob) -> tuple[Any, Report, dict]:
    """The child's work: convert, keeping the description, the report and the read log."""
    with replay.recording() as log:
        done = convert_job(job)
    return done.description, done.report, log.entries


def convert_job(job: ConversionJob) -> Conversion:
    """The conversion `job` describes, in this process (reading only in `job.read_roots`)."""
    if job.read_roots is None:
        return _convert(job)
    from converters.collision.cache import cache_root
    from converters.isolated.confine import confined

    with confined(job.read_roots, also=(str(cache_root()),)):  # collision parts are read there
        return _convert(job)


def _convert(job: ConversionJob) -> Conversion:
    packages = dict(job.package_paths)
    if job.text is not None:
        return convert_text(
            job.text,
            source=job.source,
            base_dir=job.base_dir,
            package_paths=packages,
            options=job.options,
            env=job.env,
        )
    return convert_full(
        Path(job.path or job.source),
        args=dict(job.args),
        package_paths=packages,
        options=job.options,
        env=job.env,
    )
