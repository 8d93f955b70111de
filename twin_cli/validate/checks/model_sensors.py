"""Model check on sensor placement: every `<sensor>` sits on a link the robot has.

Gazebo's URDF parser moves a `<gazebo reference="X">` block onto link X; when no link is named X
it drops the block with a warning in a log nobody reads, and the robot spawns without the sensor
(a lidar on `lidar_linkk` publishes nothing). The description keeps the block (`unplaced_sensors`,
read by `robot.robot_from_conversion`): each fails here, with the link names to choose from.
"""

from __future__ import annotations

from converters.report import Outcome
from twin_cli.validate.checks.base import CheckResult, RobotUnderTest, judged, not_applicable
from twin_cli.validate.scenario import Scenario

SHOWN_LINKS = 30  # at most this many valid link names in one message


def _link_list(robot: RobotUnderTest) -> str:
    names = sorted(robot.link_names)
    more = f" (and {len(names) - SHOWN_LINKS} more)" if len(names) > SHOWN_LINKS else ""
    return ", ".join(names[:SHOWN_LINKS]) + more


def check_sensor_links(
    robot: RobotUnderTest, scenario: Scenario, th: dict[str, float]
) -> CheckResult:
    """Every sensor is attached to an existing link (Gazebo drops the others silently)."""
    if not robot.described:
        reason = "an MJCF robot has no Gazebo <sensor> tags to place"
        return not_applicable("sensor_links", "model", "MJCF input", reason)
    total = len(robot.sensors) + len(robot.unplaced_sensors)
    if not total:
        reason = "the robot declares no <sensor> (URDF <gazebo> or SDF link)"
        return not_applicable("sensor_links", "model", "no sensor", reason)
    hints = [
        f"sensor '{s.name}' ({s.kind}) is attached to link '{s.link}', which does not exist: "
        "Gazebo drops it and it measures nothing; set its <gazebo reference> to one of the "
        f"robot's links: {_link_list(robot)}"
        for s in robot.unplaced_sensors
    ]
    unplaced = {f"link '{s.link}' sensor '{s.name}'" for s in robot.unplaced_sensors}
    details = [  # the converter's other reasons to leave a sensor out (an unsimulated type...)
        f"{e.subject}: {e.detail}"
        for e in robot.report.of(Outcome.IGNORED)
        if e.tag == "sensor" and e.subject not in unplaced
    ]
    return judged(
        "sensor_links",
        "model",
        f"{len(robot.unplaced_sensors)} of {total} sensor(s) on a missing link",
        "0",
        hints,
        details=details,
        value=float(len(robot.unplaced_sensors)),
    )
