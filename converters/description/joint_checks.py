"""Joint definitions no simulator can honour: a moving joint without a direction, and mimic
joints that follow each other in a circle (no joint leads, so no position is defined).

Both used to pass without a word: MuJoCo normalised the zero axis into NaNs at compile time, and
the mimic equalities of a circle fought each other. Each is refused with the joint named.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from converters.description.robot import RobotDescription

MOVING = ("revolute", "continuous", "prismatic")
MIN_AXIS_NORM = 1e-12


@dataclass(frozen=True)
class JointProblem:
    """One joint that cannot be simulated: where, what, and the fix."""

    subject: str
    problem: str
    fix: str


def joint_problems(robot: RobotDescription) -> list[JointProblem]:
    """Zero axes on moving joints, then mimic circles, in document order."""
    found = [
        JointProblem(
            f"joint '{joint.name}' <axis>",
            f"xyz {' '.join(f'{v:g}' for v in joint.axis)} has no direction",
            "give the axis of motion as a nonzero vector, e.g. xyz='0 0 1'",
        )
        for joint in robot.joints
        if joint.kind in MOVING and math.hypot(*joint.axis) < MIN_AXIS_NORM
    ]
    return found + [_circle_problem(circle) for circle in mimic_circles(robot)]


def mimic_circles(robot: RobotDescription) -> list[list[str]]:
    """Each set of joints whose `<mimic>` leaders lead back to themselves, in the chain's order."""
    leader = {j.name: j.mimic.joint for j in robot.joints if j.mimic is not None}
    circles: list[list[str]] = []
    seen: set[str] = set()
    for start in leader:
        chain: list[str] = []
        joint: str | None = start
        while joint in leader and joint not in chain and joint not in seen:
            chain.append(joint)
            joint = leader[joint]
        seen.update(chain)
        if joint in chain:
            circles.append(chain[chain.index(joint) :])
    return circles


def _circle_problem(circle: list[str]) -> JointProblem:
    path = " → ".join([*circle, circle[0]])
    return JointProblem(
        f"joint '{circle[0]}' <mimic>",
        f"the mimic joints follow each other in a circle ({path}), so none leads",
        f"remove the <mimic> of one of {', '.join(circle)}",
    )
