"""Runs the validation checklist on one robot, in-process, and returns typed results.

The robot is built by `robot` (converted, compiled, with the facts checks read). A check that
raises is an ERROR naming the exception, never a FAIL: a crash says nothing about the robot,
and a CI must tell "twin broke" (exit 70) from "the robot is broken" (exit 1).
"""

from __future__ import annotations

import contextlib
import time
import traceback
from dataclasses import dataclass, replace
from pathlib import Path

from twin_cli.errors import ScenarioError, TwinError, UnknownCheckError
from twin_cli.validate import video
from twin_cli.validate.checks import CHECKS, MODEL_CHECKS, Check
from twin_cli.validate.checks.base import (
    EXIT_CODES,
    CannotApply,
    CheckResult,
    RobotUnderTest,
    Status,
    not_applicable,
    result,
)
from twin_cli.validate.robot import load_robot
from twin_cli.validate.scenario import Scenario, load_builtin, resolve, with_joints

TRACEBACK_FRAMES = 4  # innermost frames of a crashed check kept in its report (JUnit <error>)


@dataclass(frozen=True)
class ValidationRun:
    """Every check's result for one robot, and the wall time of the whole run [s]."""

    robot: str
    source: str
    results: tuple[CheckResult, ...]
    seconds: float

    @property
    def passed(self) -> bool:
        """No check failed and none crashed."""
        return not any(r.failed or r.errored for r in self.results)

    @property
    def exit_code(self) -> int:
        """0 when passed, 1 when a check failed, 70 when a check crashed (a twin bug: it wins,
        so a crash is never read as a verdict on the robot)."""
        return max((EXIT_CODES.get(r.status, 0) for r in self.results), default=0)

    def counts(self) -> dict[str, int]:
        """How many checks ended in each status."""
        out = {s.value: 0 for s in Status}
        for r in self.results:
            out[r.status.value] += 1
        return out

    def to_dict(self) -> dict:
        return {
            "robot": self.robot,
            "source": self.source,
            "passed": self.passed,
            "exit_code": self.exit_code,
            "counts": self.counts(),
            "seconds": round(self.seconds, 3),
            "checks": [r.to_dict() for r in self.results],
        }


def _model_scenario(check: str) -> Scenario:
    return Scenario(name=check, check=check, source="built-in")


def plan(
    scenarios: list[str] | None = None,
    only: list[str] | None = None,
    skip: list[str] | None = None,
) -> list[Scenario]:
    """The scenarios to run: every model check plus the built-in (or the given) scenarios.

    Raises:
        UnknownCheckError: --only/--skip names a check that does not exist.
        ScenarioError: a scenario file is malformed or names an unknown check or threshold.
    """
    for name in (only or []) + (skip or []):
        if name not in CHECKS:
            raise UnknownCheckError(name, list(CHECKS))
    chosen = [resolve(s) for s in scenarios] if scenarios else load_builtin()
    for sc in chosen:
        _validate_scenario(sc)
    given = {sc.check for sc in chosen}
    todo = [_model_scenario(c) for c in MODEL_CHECKS if c not in given] + chosen
    return [sc for sc in todo if (not only or sc.check in only) and sc.check not in (skip or [])]


def _validate_scenario(sc: Scenario) -> None:
    check = CHECKS.get(sc.check)
    if check is None:
        raise ScenarioError(
            sc.source, "check", f"unknown check {sc.check!r}", f"use one of {', '.join(CHECKS)}"
        )
    for key in sc.thresholds:
        if key not in check.defaults:
            valid = ", ".join(check.defaults) or "none"
            raise ScenarioError(
                sc.source,
                f"thresholds.{key}",
                f"check {sc.check!r} has no threshold {key!r}",
                f"use one of: {valid}",
            )


def run_check(robot: RobotUnderTest, sc: Scenario, *, debug: bool = False) -> CheckResult:
    """Run one scenario's check; an unexpected error becomes an ERROR result naming it."""
    return run_registered(CHECKS[sc.check], robot, sc, debug=debug)


def run_registered(
    check: Check, robot: RobotUnderTest, sc: Scenario, *, debug: bool = False
) -> CheckResult:
    """Run `check` on the robot in the scenario with the scenario's thresholds over its
    defaults; `debug` re-raises an exception from inside the check instead of reporting it."""
    from twin_cli.validate.recording import finish

    thresholds = {**check.defaults, **sc.thresholds}
    start = time.perf_counter()
    try:
        with video.scenario(sc.name) if check.kind == "physics" else contextlib.nullcontext():
            outcome = check.run(robot, sc, thresholds)
        finish()
    except CannotApply as exc:
        finish()
        outcome = not_applicable(check.name, check.kind, "cannot apply", exc.reason)
    except Exception as exc:  # one broken check must not hide the others
        finish()
        if debug:
            raise
        outcome = crashed(check, exc)
    return _stamp(outcome, sc, time.perf_counter() - start)


def crashed(check: Check, exc: Exception) -> CheckResult:
    """The ERROR result of a check that raised: the exception in the table, its innermost
    frames in the details (JUnit <error> text)."""
    frames = traceback.format_tb(exc.__traceback__)[-TRACEBACK_FRAMES:]
    return result(
        check.name,
        check.kind,
        Status.ERROR,
        f"crashed: {type(exc).__name__}: {exc}",
        "runs",
        hints=[
            f"the check crashed ({type(exc).__name__}: {exc}): a bug in twin, not a verdict on "
            "the robot; report it with this robot and the traceback below"
        ],
        details=[line.rstrip() for line in frames],
    )


def _stamp(outcome: CheckResult, sc: Scenario, seconds: float) -> CheckResult:
    scenario = None if sc.source == "built-in" else sc.name
    return replace(outcome, scenario=scenario, seconds=seconds)


def validate(
    robot_path: str | Path,
    *,
    args: dict[str, str] | None = None,
    package_paths: dict[str, str] | None = None,
    scenarios: list[str] | None = None,
    only: list[str] | None = None,
    skip: list[str] | None = None,
    repair_inertia: bool = False,
    collision: str | None = None,
    joints: dict[str, float] | None = None,
    debug: bool = False,
    as_written: bool = False,
    record: Path | None = None,
) -> ValidationRun:
    """Validate one robot: convert it, run the planned checks, return every result.

    Args:
        robot_path: URDF, xacro, SDF or MJCF file.
        args: xacro arguments NAME → VALUE.
        package_paths: package NAME → directory.
        scenarios: bundled scenario names or .toml paths (default: the built-in checklist).
        only, skip: check names to keep or leave out.
        repair_inertia: accept the converter's inertia repairs (warnings instead of failures).
        collision: the converter's collision-mesh mode (auto|coacd|hull|mesh); None = auto.
        joints: start posture, joint name → [rad] or [m] (`-J`), over each scenario's
            `[robot] joints`; what a scenario's `[hold]` holds.
        debug: re-raise errors inside checks instead of reporting them as ERROR results.
        as_written: apply what a URDF says where Gazebo's parser drops it.
        record: a folder for one rosbag2 MCAP file per physics scenario run (None: none).
    """
    from twin_cli.validate.recording import recording_into

    start = time.perf_counter()
    todo = [with_joints(sc, joints or {}) for sc in plan(scenarios, only, skip)]
    robot = load_robot(
        robot_path,
        args=args,
        package_paths=package_paths,
        repair_inertia=repair_inertia,
        collision=collision,
        as_written=as_written,
    )
    check_start_postures(robot, todo, joints or {})
    with recording_into(record):
        results = run_all(robot, todo, debug=debug)
    return ValidationRun(robot.name, robot.source, results, time.perf_counter() - start)


STARTS_FROM_POSTURE = frozenset(
    {
        "stability",
        "zero_gravity",
        "tracking",
        "joint_limits",
        "friction_standing",
        "friction_incline",
        "ground_contact",
        "collision",
        "sensor_contact",
        "sensor_imu",
        "sensor_lidar",
    }
)
"""Physics checks that measure the robot at rest or moving part against part: from a start
posture whose links overlap or whose joints are outside their ranges they would measure the
push apart. (Free fall, the Moon preset and the inertia check read the whole robot's motion,
which internal pushes do not change; the real-time check its cost.)"""


def run_all(
    robot: RobotUnderTest, todo: list[Scenario], *, debug: bool = False
) -> tuple[CheckResult, ...]:
    """Each scenario's result in order (`run_from_start`), each told whether a failed
    `initial_overlap` is already in the run (model checks come first)."""
    results: list[CheckResult] = []
    for sc in todo:
        reported = any(r.check == "initial_overlap" and r.failed for r in results)
        results.append(run_from_start(robot, sc, debug=debug, reported=reported))
    return tuple(results)


def run_from_start(
    robot: RobotUnderTest, sc: Scenario, *, debug: bool = False, reported: bool = False
) -> CheckResult:
    """`run_check`, unless the scenario's start posture is one `initial_overlap` fails: then
    the check is not run, and says why (a verdict on the posture, not on twin). Not run is a
    skip when the run's failed `initial_overlap` already fails it (`reported`), and a failure
    otherwise (`--only`, `--skip initial_overlap`), so a run never passes on checks it held."""
    from twin_cli.validate.checks.model_collision import start_posture_problems

    if sc.check not in STARTS_FROM_POSTURE:
        return run_check(robot, sc, debug=debug)
    tolerance = CHECKS["initial_overlap"].defaults["tolerance_m"]
    problems = start_posture_problems(robot, sc, tolerance)
    if not problems:
        return run_check(robot, sc, debug=debug)
    check = CHECKS[sc.check]
    reason = (
        f"not run because of initial_overlap: in this scenario's start posture "
        f"{'; '.join(problems)}, so the check would measure the robot pushing itself apart; "
        "start it in a valid posture (-J, or the scenario's [robot] joints) or fix the model"
    )
    if not reported:
        held = result(check.name, check.kind, Status.FAIL, "not run: start posture", "runs",
                      hints=[reason])  # fmt: skip
        return _stamp(held, sc, 0.0)
    return _stamp(not_applicable(check.name, check.kind, "not run: start posture", reason), sc, 0.0)


def check_start_postures(
    robot: RobotUnderTest, todo: list[Scenario], joints: dict[str, float]
) -> None:
    """Checks every scenario's start joints against the robot before anything runs.

    A wrong name or an out-of-range value is bad input (exit 2), not a failed check.

    Raises:
        PartNotFoundError, InvalidRequestError: a `-J` joint is unknown or out of range.
        ScenarioError: a scenario file's `[robot] joints` is (names the file and key).
    """
    import numpy as np

    from twin_cli.world.posture import joint_targets

    all_joints = np.arange(robot.model.njnt)
    joint_targets(robot.model, all_joints, "", joints, robot.name)
    for sc in todo:
        try:
            joint_targets(robot.model, all_joints, "", dict(sc.robot.joints), robot.name)
        except TwinError as exc:
            raise ScenarioError(
                sc.source, "robot.joints", str(exc), "fix the joint name or position"
            ) from exc
