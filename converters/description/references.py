"""What Gazebo loads a robot without: a `<gazebo reference>` (with its sensors and plugins) on a
missing link, a `<ros2_control>`/`<transmission>` joint that does not exist, a visual whose mesh
file or package is missing.

Gazebo's own parser drops such a block with a warning in a log nobody reads, and loads the robot
without it: a camera on a link that was commented out is simply not there; a visual whose
package is not installed is not drawn. twin does the same and reports each where the user
looks (the conversion report, `twin spawn`'s warnings, a failed `twin validate` check); with
`--strict` it refuses the description instead, naming each and the fix.
"""

from __future__ import annotations

from dataclasses import dataclass

from converters.description.robot import RobotDescription


@dataclass(frozen=True)
class Dangling:
    """One reference to a part that does not exist.

    Attributes:
        element: where it is written, e.g. `<gazebo reference='camera_link'>`.
        target: the link or joint it names.
        kind: "link or joint" or "joint" (what the name should be).
        carries: what is lost with it, e.g. ("sensor 'cam'", "tags mu1, material").
    """

    element: str
    target: str
    kind: str
    carries: tuple[str, ...] = ()
    closes_loop: bool = False  # the joint exists, as a loop's closing equalities (refused)

    def describe(self) -> str:
        lost = f" ({', '.join(self.carries)})" if self.carries else ""
        return f"{self.element}{lost} names {self.kind} '{self.target}', which does not exist"


def dangling_references(robot: RobotDescription) -> list[Dangling]:
    """Every reference of the robot's Gazebo and control tags that names no link or joint."""
    found = [_gazebo_reference(robot, name) for name in robot.gazebo.unresolved]
    joints = {joint.name for joint in robot.joints}
    loops = {joint.name for joint in robot.loop_joints}
    for control in robot.controls:
        if control.joint not in joints:
            element = f"{control.where} joint"
            found.append(
                Dangling(
                    element,
                    control.joint,
                    "joint",
                    ("command interfaces",),
                    closes_loop=control.joint in loops,
                )  # fmt: skip
            )
    return found


def _gazebo_reference(robot: RobotDescription, name: str) -> Dangling:
    ext = robot.gazebo.links.get(name)
    carries: list[str] = []
    if ext is not None:
        carries += [f"sensor '{blob.name}'" for blob in ext.sensors]
        carries += [f"<{blob.tag}> '{blob.name or blob.kind}'" for blob in ext.blobs]
        kept_whole = {blob.tag for blob in (*ext.sensors, *ext.blobs)}
        tags = sorted({source.tag for source in ext.sources} - kept_whole)
        if tags:
            carries.append("tags " + ", ".join(tags))
    return Dangling(f"<gazebo reference='{name}'>", name, "link or joint", tuple(carries))


@dataclass(frozen=True)
class MissingVisual:
    """A `<visual>` whose mesh file or package was not found, left out as Gazebo does.

    Attributes:
        element: where it is written, e.g. `link 'base' <visual name='shell'>`.
        problem: the resolver's message: what was looked for, where, and the fix.
    """

    element: str
    problem: str

    def describe(self) -> str:
        """One line: the reason, the places tried and the fix."""
        head, *rest = self.problem.splitlines()
        places = [line.strip() for line in rest if line.startswith(" ")]
        if places:
            head = f"{head} {', '.join(places)}"
        return "; ".join([head, *(line for line in rest if not line.startswith(" "))])


Ignored = Dangling | MissingVisual


def missing_visuals(robot: RobotDescription) -> list[MissingVisual]:
    """Every visual of the robot whose mesh was not found, in link order."""
    return [
        MissingVisual(_visual_element(link.name, visual.name, index), visual.missing)
        for link in robot.links
        for index, visual in enumerate(link.visuals)
        if visual.missing is not None
    ]


def ignored_parts(robot: RobotDescription) -> list[Ignored]:
    """Everything Gazebo would load the robot without: dangling references, missing visuals."""
    return [*dangling_references(robot), *missing_visuals(robot)]


def _visual_element(link: str, name: str | None, index: int) -> str:
    return f"link '{link}' <visual name='{name}'>" if name else f"link '{link}' <visual> {index}"


def part_names(robot: RobotDescription) -> list[str]:
    """The robot's links and joints, for the message that lists the valid names."""
    return [link.name for link in robot.links] + [joint.name for joint in robot.joints]
