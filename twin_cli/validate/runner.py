"""Runs the validation checklist on one robot, in-process, and returns typed results.

A missing or non-physical inertial must still reach validation as a failed model check, so the
robot is always converted with `ConvertOptions(repair_inertia=True)`; the converter's
`repaired` report entries then become failures (or warnings when the user passed
`--repair-inertia`, i.e. accepted the repairs).
"""

from __future__ import annotations

import contextlib
import time
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from twin_cli.errors import ScenarioError, TwinError, UnknownCheckError
from twin_cli.validate import video
from twin_cli.validate.checks import CHECKS, MODEL_CHECKS
from twin_cli.validate.checks.base import CheckResult, DeclaredJoint, RobotUnderTest, Status, result
from twin_cli.validate.scenario import Scenario, load_builtin, resolve, with_joints

if TYPE_CHECKING:
    from converters.description import Joint


@dataclass(frozen=True)
class ValidationRun:
    """Every check's result for one robot, and the wall time of the whole run [s]."""

    robot: str
    source: str
    results: tuple[CheckResult, ...]
    seconds: float

    @property
    def passed(self) -> bool:
        return not any(r.failed for r in self.results)

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
            "counts": self.counts(),
            "seconds": round(self.seconds, 3),
            "checks": [r.to_dict() for r in self.results],
        }


def load_robot(
    path: str | Path,
    *,
    args: dict[str, str] | None = None,
    package_paths: dict[str, str] | None = None,
    repair_inertia: bool = False,
    collision: str | None = None,
    as_written: bool = False,
) -> RobotUnderTest:
    """Convert (URDF/xacro/SDF) or load (MJCF .xml) a robot and compile it alone.

    Raises:
        ConversionError: the description cannot be converted (exit 2 at the CLI).
    """
    import mujoco

    from converters.report import Report

    path = Path(path)
    if path.suffix.lower() == ".xml":
        spec = mujoco.MjSpec.from_file(str(path))
        return _robot(spec, Report(source=str(path)), path, repair_inertia, {})
    from converters.collision.plan import CollisionSettings
    from converters.mjcf.builder import ConvertOptions
    from converters.pipeline import convert_full

    settings = CollisionSettings(mode=collision) if collision else CollisionSettings()
    done = convert_full(
        path,
        args=args,
        package_paths=package_paths,
        options=ConvertOptions(repair_inertia=True, collision=settings, as_written=as_written),
    )
    return robot_from_conversion(done, path, repair_inertia=repair_inertia)


def robot_from_conversion(done, path: str | Path, *, repair_inertia: bool) -> RobotUnderTest:
    """The robot under test from a `converters.Conversion` (spec, report, provenance)."""
    body_links = {g.body: g.link for g in done.provenance.geoms if g.body == g.link}
    joints = tuple(_declared(j) for j in done.description.joints)
    from dataclasses import replace

    robot = _robot(done.spec, done.report, Path(path), repair_inertia, body_links, joints)
    return replace(robot, sensors=tuple(getattr(done, "sensors", ())))


def _declared(joint: Joint) -> DeclaredJoint:
    from converters.description import Limit

    limit = joint.limit or Limit()
    return DeclaredJoint(
        joint.name,
        joint.kind,
        limit.lower,
        limit.upper,
        limit.effort,
        limit.velocity,
        joint.mimic is not None,
    )


def _robot(spec, report, path: Path, repair_inertia: bool, body_links, joints=()) -> RobotUnderTest:
    model = spec.copy().compile()
    name = report.robot or spec.modelname or path.stem.split(".")[0]
    return RobotUnderTest(
        name, str(path), spec, model, report, repair_inertia, body_links, tuple(joints)
    )


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
    """Run one scenario's check; an unexpected error becomes a failed result naming it."""
    from twin_cli.validate.recording import finish

    check = CHECKS[sc.check]
    thresholds = {**check.defaults, **sc.thresholds}
    start = time.perf_counter()
    try:
        with video.scenario(sc.name) if check.kind == "physics" else contextlib.nullcontext():
            outcome = check.run(robot, sc, thresholds)
        finish()
    except Exception as exc:  # noqa: BLE001 - one broken check must not hide the others
        finish()
        if debug:
            raise
        outcome = result(
            sc.check,
            check.kind,
            Status.FAIL,
            "error",
            "runs",
            hints=[f"the check could not run: {type(exc).__name__}: {exc}"],
        )
    return _stamp(outcome, sc, time.perf_counter() - start)


def _stamp(outcome: CheckResult, sc: Scenario, seconds: float) -> CheckResult:
    from dataclasses import replace

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
        debug: re-raise errors inside checks instead of reporting them as failures.
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
        results = tuple(run_check(robot, sc, debug=debug) for sc in todo)
    return ValidationRun(robot.name, robot.source, results, time.perf_counter() - start)


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
