"""Model check on what Gazebo loads the robot without: tags naming a missing part, lost visuals.

Gazebo's parser drops a `<gazebo reference>` block (sensors, plugins, surface tags) that names
no link or joint, ignores a `<transmission>`/`<ros2_control>` joint that does not exist, and
draws nothing for a visual whose mesh file or package is missing; each only in a log. twin
spawns such a robot the same way, with a warning; this check fails naming each, so that CI
catches a camera that is not there or a mesh package that was never installed.
"""

from __future__ import annotations

from twin_cli.validate.checks.base import CheckResult, RobotUnderTest, judged, not_applicable
from twin_cli.validate.scenario import Scenario


def check_ignored_parts(
    robot: RobotUnderTest, scenario: Scenario, th: dict[str, float]
) -> CheckResult:
    """Every Gazebo and control tag names a part, and every visual mesh exists."""
    if not robot.described:
        reason = "an MJCF robot has no Gazebo tags or package meshes to check"
        return not_applicable("ignored_parts", "model", "MJCF input", reason)
    hints = [f"{found}; Gazebo and twin load the robot without it" for found in robot.ignored_parts]
    return judged(
        "ignored_parts",
        "model",
        f"{len(hints)} part(s) left out",
        "0",
        hints,
        value=float(len(hints)),
    )
