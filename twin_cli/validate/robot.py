"""Builds the robot under test: converted (or MJCF loaded), compiled, with what checks read.

A missing or non-physical inertial must still reach validation as a failed model check, so the
robot is always converted with `ConvertOptions(repair_inertia=True)`; the converter's
`repaired` report entries then become failures (or warnings when the user passed
`--repair-inertia`, i.e. accepted the repairs). Likewise a sensor on a link that does not exist
must reach the `sensor_links` check, not stop the conversion: it converts as spawn does, without
`strict` (Gazebo's own behaviour: the block is left out and reported), and the `ignored_parts`
check fails naming each part left out.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

from twin_cli.validate.checks.base import DeclaredJoint, RobotUnderTest, UnplacedSensor

if TYPE_CHECKING:
    import mujoco

    from converters.description import Joint, RobotDescription
    from converters.pipeline import Conversion
    from converters.report import Report


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

    from converters.report import Report

    path = Path(path)
    if path.suffix.lower() == ".xml":
        return _robot(_mjcf_spec(path), Report(source=str(path)), path, repair_inertia, {})
    from converters.collision.plan import CollisionSettings
    from converters.mjcf.builder import ConvertOptions
    from converters.pipeline import convert_full

    settings = CollisionSettings(mode=collision) if collision else CollisionSettings()
    options = ConvertOptions(repair_inertia=True, collision=settings, as_written=as_written)
    done = convert_full(path, args=args, package_paths=package_paths, options=options)
    return robot_from_conversion(done, path, repair_inertia=repair_inertia)


def _mjcf_spec(path: Path) -> mujoco.MjSpec:
    """An MJCF robot's spec; a missing or malformed file is the user's input error (exit 2).

    Raises:
        InputFileError: naming the file, and MuJoCo's parse message.
    """
    import mujoco

    from converters.errors import InputFileError

    if not path.is_file():
        raise InputFileError(
            str(path), "no such file", "give the path of an MJCF, URDF or SDF file"
        )
    try:
        return mujoco.MjSpec.from_file(str(path))
    except ValueError as exc:
        message = " ".join(str(exc).split())
        raise InputFileError(str(path), f"not valid MJCF ({message})", "fix the file") from exc


def robot_from_conversion(
    done: Conversion, path: str | Path, *, repair_inertia: bool
) -> RobotUnderTest:
    """The robot under test from a `converters.Conversion` (spec, report, provenance)."""
    body_links = {g.body: g.link for g in done.provenance.geoms if g.body == g.link}
    joints = tuple(_declared(j) for j in done.description.joints)
    robot = _robot(done.spec, done.report, Path(path), repair_inertia, body_links, joints)
    gazebo = done.description.gazebo
    return replace(
        robot,
        sensors=tuple(getattr(done, "sensors", ())),
        link_names=tuple(link.name for link in done.description.links),
        geom_links={g.geom: g.link for g in done.provenance.geoms if g.geom},
        unplaced_sensors=unplaced_sensors(done.description),
        ignored_parts=ignored_parts(done.description),
        self_collide_links=frozenset(n for n, e in gazebo.links.items() if e.self_collide),
        model_self_collide=bool(gazebo.self_collide),
    )


def unplaced_sensors(description: RobotDescription) -> tuple[UnplacedSensor, ...]:
    """Sensors whose `<gazebo reference>` names no link of the robot: Gazebo drops them with
    their tags, so they measure nothing (the converter reports each as ignored)."""
    links = {link.name for link in description.links}
    return tuple(
        UnplacedSensor(blob.name, blob.kind or "?", reference)
        for reference, ext in description.gazebo.links.items()
        if reference not in links
        for blob in ext.sensors
    )


def ignored_parts(description: RobotDescription) -> tuple[str, ...]:
    """What Gazebo loads the robot without, one line each naming the element and the fix."""
    from converters.description.references import Dangling, part_names
    from converters.description.references import ignored_parts as found

    names = ", ".join(part_names(description)[:30])
    return tuple(
        f"{part.describe()}; name one of its links or joints ({names}) or remove it"
        if isinstance(part, Dangling)
        else part.describe()
        for part in found(description)
    )


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


def _robot(
    spec: mujoco.MjSpec,
    report: Report,
    path: Path,
    repair_inertia: bool,
    body_links: dict[str, str],
    joints: tuple[DeclaredJoint, ...] = (),
) -> RobotUnderTest:
    model = spec.copy().compile()
    name = report.robot or spec.modelname or path.stem.split(".")[0]
    return RobotUnderTest(
        name, str(path), spec, model, report, repair_inertia, body_links, tuple(joints)
    )
