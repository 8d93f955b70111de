"""Validation sweeps: the checklist on every robot × parameter variant, on a pool or Ray.

`--sweep NAME=LO:HI:N` gives N evenly spaced values from LO to HI (both included); several
sweeps make the grid of every combination. Each robot × variant is one task, independent and
deterministic (MuJoCo steps the same inputs to the same numbers), so a process pool and a Ray
cluster return identical results.
"""

from __future__ import annotations

import itertools
import math
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path

from twin_cli.errors import TwinError
from twin_cli.validate.checks.base import EXIT_CODES, CheckResult
from twin_cli.validate.margins import MARGINS
from twin_cli.validate.sweep_errors import SweepError
from twin_cli.validate.variants import PARAMETERS, ROBOT_PARAMETERS


class VariantError(TwinError):
    """Bad input found inside a worker (a robot that does not convert, a bad start joint),
    carried back as its message: the converter's errors take several constructor arguments
    and would not survive pickling between processes."""

    def __init__(self, message: str) -> None:
        super().__init__(message)


@dataclass(frozen=True)
class Axis:
    """One swept parameter: `values` from LO to HI, in the parameter's unit."""

    name: str
    values: tuple[float, ...]


def parse_axis(text: str) -> Axis:
    """`NAME=LO:HI:N` → an Axis with N evenly spaced values (N = 1: just LO, and LO = HI).

    Raises:
        SweepError: unknown NAME, malformed text, N < 1, an empty or reversed range, or a
            value outside the parameter's range (a scale or μ must be > 0).
    """
    form = "write --sweep NAME=LO:HI:N, e.g. foot_mu=0.1:1.0:10"
    name, sep, rest = text.partition("=")
    name = name.strip()
    if not sep:
        raise SweepError(f"--sweep {text}", "no '='", form)
    if name not in PARAMETERS:
        raise SweepError(
            f"--sweep {text}", f"unknown parameter {name!r}", f"use one of {', '.join(PARAMETERS)}"
        )
    parts = rest.split(":")
    try:
        lo, hi, n = float(parts[0]), float(parts[1]), int(parts[2])
        if len(parts) != 3:
            raise ValueError
    except (ValueError, IndexError) as exc:
        raise SweepError(f"--sweep {text}", "not LO:HI:N (numbers, N an integer)", form) from exc
    _check_range(text, PARAMETERS[name], lo, hi, n)
    values = (lo,) if n == 1 else tuple(lo + (hi - lo) * i / (n - 1) for i in range(n))
    return Axis(name, tuple(round(v, 12) for v in values))


def _check_range(text: str, param, lo: float, hi: float, n: int) -> None:
    given = f"--sweep {text}"
    if not (math.isfinite(lo) and math.isfinite(hi)):
        raise SweepError(given, "LO and HI must be finite numbers", "give finite values")
    if n < 1:
        raise SweepError(given, f"N = {n} values", "give N ≥ 1")
    if hi < lo:
        raise SweepError(
            given, f"reversed range {lo:g} > {hi:g}", f"write {param.name}={hi:g}:{lo:g}:{n}"
        )
    if hi == lo and n > 1:
        raise SweepError(
            given, f"empty range {lo:g}:{hi:g} for {n} values", "give HI > LO, or N = 1"
        )
    low_ok = lo >= param.minimum if param.inclusive else lo > param.minimum
    if not low_ok:
        bound = "≥" if param.inclusive else ">"
        raise SweepError(
            given, f"{param.name} {lo:g} is out of range", f"give values {bound} {param.minimum:g}"
        )


def grid(axes: list[Axis]) -> list[dict[str, float]]:
    """Every combination of the axes' values, first axis slowest; [{}] without axes.

    Raises:
        SweepError: the same parameter is swept twice.
    """
    names = [a.name for a in axes]
    for name in names:
        if names.count(name) > 1:
            raise SweepError(f"--sweep {name}", "swept twice", "give each parameter once")
    return [
        dict(zip(names, combo, strict=True))
        for combo in itertools.product(*(a.values for a in axes))
    ]


@dataclass(frozen=True)
class Task:
    """One robot × variant: everything a worker needs (plain values, picklable)."""

    robot: str
    values: dict[str, float]
    options: dict = field(default_factory=dict)


@dataclass(frozen=True)
class VariantRun:
    """One robot × variant's results (series left out: they stay in the worker)."""

    robot: str
    source: str
    values: dict[str, float]
    results: tuple[CheckResult, ...]
    seconds: float
    limits: dict[str, float] = field(default_factory=dict)

    @property
    def passed(self) -> bool:
        """No check failed and none crashed."""
        return not any(r.failed or r.errored for r in self.results)

    @property
    def exit_code(self) -> int:
        """0 passed, 1 a check failed, 70 a check crashed (as `ValidationRun.exit_code`)."""
        return max((EXIT_CODES.get(r.status, 0) for r in self.results), default=0)

    def to_dict(self) -> dict:
        return {
            "robot": self.robot,
            "source": self.source,
            "values": self.values,
            "passed": self.passed,
            "seconds": round(self.seconds, 3),
            "limits": self.limits,
            "checks": [r.to_dict() for r in self.results],
        }


def run_task(task: Task) -> VariantRun:
    """Convert one robot with one variant applied and run the planned checks (in a worker).

    Raises:
        VariantError: the robot does not convert or a start posture is bad (exit 2).
    """
    from converters.errors import ConversionError

    try:
        return _run_task(task)
    except (ConversionError, TwinError) as exc:
        raise VariantError(str(exc)) from None


def _run_task(task: Task) -> VariantRun:
    from twin_cli.validate.runner import check_start_postures, plan, run_all
    from twin_cli.validate.scenario import with_joints
    from twin_cli.validate.variants import apply_to_scenario, ground_friction

    start = time.perf_counter()
    opts = task.options
    joints = opts.get("joints") or {}
    todo = [
        apply_to_scenario(with_joints(sc, joints), task.values)
        for sc in plan(opts.get("scenarios"), opts.get("only"), opts.get("skip"))
    ]
    robot = load_variant(task.robot, task.values, opts)
    check_start_postures(robot, todo, joints)
    with ground_friction(task.values):
        results = tuple(replace(r, series=()) for r in run_all(robot, todo))
    seconds = time.perf_counter() - start
    return VariantRun(robot.name, task.robot, dict(task.values), results, seconds, _limits(todo))


def _limits(todo) -> dict[str, float]:
    """Each check's threshold that its `value` is judged against (see `margins.MARGINS`)."""
    from twin_cli.validate.checks import CHECKS

    out = {}
    for sc in todo:
        key = MARGINS.get(sc.check, ("", ""))[0]
        thresholds = {**CHECKS[sc.check].defaults, **sc.thresholds}
        if key in thresholds:
            out[sc.check] = float(thresholds[key])
    return out


def load_variant(path: str, values: Mapping[str, float], opts: Mapping):
    """The robot under test converted from `path` with the robot parameters of `values`.

    Reads the file into the neutral description, rewrites it (see `variants`), then runs the
    same stages as `converters.pipeline.convert_full` after the reader.
    """
    from converters.collision.plan import CollisionSettings
    from converters.mjcf.builder import ConvertOptions
    from converters.pipeline import build_description, read_description, read_robot
    from converters.report import Report
    from converters.resources.packages import PackageResolver
    from twin_cli.validate.robot import load_robot, robot_from_conversion
    from twin_cli.validate.variants import apply_to_description, foot_links

    repair = bool(opts.get("repair_inertia"))
    if Path(path).suffix.lower() == ".xml" or not ROBOT_PARAMETERS.intersection(values):
        return load_robot(
            path,
            args=opts.get("args"),
            package_paths=opts.get("package_paths"),
            repair_inertia=repair,
            collision=opts.get("collision"),
            as_written=bool(opts.get("as_written")),
        )
    collision = opts.get("collision")
    options = ConvertOptions(
        repair_inertia=True,
        collision=CollisionSettings(mode=collision) if collision else CollisionSettings(),
        as_written=bool(opts.get("as_written")),
    )
    file = Path(path)
    resolver = PackageResolver.create(file, opts.get("package_paths"))
    report = Report(source=str(file))
    text = read_description(file, dict(opts.get("args") or {}), resolver, report)
    nominal = read_robot(
        text, str(file), file.resolve().parent, resolver, report, as_written=options.as_written
    )
    feet = frozenset()
    if {"foot_mu", "foot_friction_scale"} & set(values):
        done = build_description(nominal, options, Report(source=str(file)))
        feet = foot_links(done.spec, done.provenance)
    described = apply_to_description(nominal, values, feet)
    done = build_description(described, options, report)
    return robot_from_conversion(done, file, repair_inertia=repair)


def _absolute(path: str) -> str:
    """`path` made absolute when it names an existing file (a bundled scenario name stays)."""
    return str(Path(path).resolve()) if Path(path).exists() else path


@dataclass(frozen=True)
class SweepRun:
    """Every robot × variant's results, in task order, and the sweep's wall time [s]."""

    axes: tuple[Axis, ...]
    runs: tuple[VariantRun, ...]
    seconds: float
    executor: str

    @property
    def passed(self) -> bool:
        return all(r.passed for r in self.runs)

    @property
    def exit_code(self) -> int:
        """The worst variant's exit code: 70 when a check crashed anywhere, else 1 or 0."""
        return max((r.exit_code for r in self.runs), default=0)

    def to_dict(self) -> dict:
        return {
            "axes": {a.name: list(a.values) for a in self.axes},
            "executor": self.executor,
            "passed": self.passed,
            "seconds": round(self.seconds, 3),
            "variants": [r.to_dict() for r in self.runs],
        }


def sweep(
    robots: list[str],
    axes: list[Axis],
    *,
    options: Mapping | None = None,
    jobs: int | None = None,
    ray: str | None = None,
    on_done: Callable[[VariantRun, int, int], None] | None = None,
) -> SweepRun:
    """Run the checklist on every robot × variant, on a process pool or a Ray cluster.

    Args:
        robots: robot files (URDF, xacro, SDF, MJCF).
        axes: the swept parameters (their grid is the variants).
        options: the single-robot run's inputs (args, package_paths, scenarios, only, skip,
            repair_inertia, collision, joints, as_written).
        jobs: worker processes (default: every core); ignored with `ray`.
        ray: "auto" or a Ray address; None runs the local pool.
        on_done: called with each finished run, how many are done and the total (progress).

    Raises:
        SweepError: bad axes, jobs < 1, or a Ray cluster that does not answer.
    """
    from twin_cli.validate.executors import open_executor
    from twin_cli.validate.runner import plan

    opts = dict(options or {})
    plan(opts.get("scenarios"), opts.get("only"), opts.get("skip"))  # bad names: before any work
    # Workers (Ray's above all) do not share our working directory: give them absolute paths.
    opts["scenarios"] = [_absolute(s) for s in opts.get("scenarios") or []] or None
    tasks = [Task(_absolute(str(r)), v, opts) for r in robots for v in grid(axes)]
    start = time.perf_counter()
    done: list[VariantRun | None] = [None] * len(tasks)
    with open_executor(jobs=jobs, ray=ray) as executor:
        for count, (index, run) in enumerate(executor.imap(run_task, tasks), start=1):
            done[index] = run
            if on_done:
                on_done(run, count, len(tasks))
        name = executor.name
    # every task has filled its slot: no None is left in `done`
    return SweepRun(tuple(axes), tuple(done), time.perf_counter() - start, name)  # pyright: ignore[reportArgumentType]
