"""The conversion pipeline: file → xacro → URDF or SDF → description → MjSpec → Gazebo semantics.

The single entry of `converters`; each stage adds its findings to one report.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING

from converters.description import RobotDescription
from converters.errors import (
    DanglingReferenceError,
    InputFileError,
    MissingVisualMeshError,
    URDFStructureError,
    XacroError,
)
from converters.formats import format_of
from converters.isolated.budget import XacroBudget
from converters.isolated.stages import stage
from converters.mjcf.builder import ConvertOptions, build_spec
from converters.provenance import Provenance
from converters.report import Report
from converters.resources.packages import PackageResolver
from converters.urdf.reader import parse_urdf
from converters.urdf.xacro_expand import XacroResult, expand_xacro, needs_xacro, xacro_marker

if TYPE_CHECKING:
    import mujoco

    from converters.description.sensors import SensorSpec


@dataclass(frozen=True)
class Conversion:
    """Everything one conversion produced: the spec, the report, provenance, the description and
    the robot's sensors (typed `<sensor>` elements, each a site `sensor:<name>` in the spec)."""

    spec: mujoco.MjSpec
    report: Report
    provenance: Provenance
    description: RobotDescription
    sensors: tuple[SensorSpec, ...] = ()
    plugins: tuple = ()  # converters.gazebo.drive_records records (run by twin_cli.control)


def read_description(
    path: Path,
    args: Mapping[str, str],
    resolver: PackageResolver,
    report: Report,
    budget: XacroBudget | None = None,
) -> str:
    """The description text of `path`: xacro files are expanded, URDF and SDF read as they are.

    Raises:
        InputFileError: the file is missing or unreadable.
        XacroError, PackageNotFoundError: from xacro.
    """
    if not path.is_file():
        raise InputFileError(
            str(path), "no such file", "give the path of a .urdf, .xacro or .sdf file"
        )
    if not needs_xacro(path):
        stage(f"reading {path}")
        if args:
            report.ignored("--arg", f"{path.name} is not xacro; xacro arguments are not used")
        try:
            return path.read_text()
        except (OSError, UnicodeDecodeError) as exc:
            raise InputFileError(str(path), f"cannot be read ({exc})", "check the file") from exc
    stage(f"expanding xacro {path}")
    try:
        result = _expand(path, args, resolver, budget)
    except XacroError as exc:
        marker = xacro_marker(path)
        if marker is None or marker.startswith("."):
            raise
        why = f"read as xacro because its text has {marker!r}"
        raise XacroError(exc.path, f"{exc.detail} ({why})", exc.fix) from None
    for call in result.unexpanded:
        report.warn(
            f"xacro macro call {call}",
            "matches a macro name but has no 'xacro:' prefix, so xacro left it "
            "unexpanded and its content is missing; write it as <xacro:NAME …/>",
        )
    for line in result.warnings:
        report.warn("xacro", line)
    return result.text


def _expand(
    path: Path, args: Mapping[str, str], resolver: PackageResolver, budget: XacroBudget | None
) -> XacroResult:
    """xacro on `path`, here or (with a budget) in a bounded child."""
    if budget is None:
        return expand_xacro(path, args, resolver)
    from converters.urdf.xacro_worker import expand_bounded

    return expand_bounded(path, dict(args), resolver, budget)


def read_robot(
    text: str,
    source: str,
    base_dir: Path,
    resolver: PackageResolver,
    report: Report,
    *,
    as_written: bool = False,
) -> RobotDescription:
    """The robot description of a URDF or SDF text, chosen by its root element.

    Raises:
        InputFileError: the text is MJCF (nothing to convert) or of no known format.
        ConversionError: any subclass from the format's reader.
    """
    stage(f"parsing {source}")
    kind = format_of(text)
    if kind == "mjcf":
        raise InputFileError(
            source, "is MJCF, already MuJoCo's format", "spawn it directly; nothing to convert"
        )
    if kind == "sdf":
        from converters.sdf import read_sdf_model

        robot = read_sdf_model(text, source, base_dir, resolver, report)
    else:
        robot = parse_urdf(text, source, base_dir, resolver, as_written=as_written)
    return replace(robot, base_dir=str(base_dir))


def convert_full(
    path: str | Path,
    *,
    args: Mapping[str, str] | None = None,
    package_paths: Mapping[str, str | Path] | None = None,
    options: ConvertOptions | None = None,
    env: Mapping[str, str] | None = None,
) -> Conversion:
    """Convert a xacro, URDF or SDF model file into an MjSpec carrying Gazebo's semantics.

    Args:
        path: the `.urdf`, `.xacro` or `.sdf` file.
        args: xacro arguments (`NAME:=VALUE` pairs as a dict).
        package_paths: package name → directory (`--package`), searched first.
        options: keep_fixed, repair_inertia, collision settings.
        env: the package search variables (ROS_PACKAGE_PATH, ...) to use; None: this process's.

    Raises:
        ConversionError: any subclass, with file/link/joint and the fix in its message.
    """
    options = options or ConvertOptions()
    robot, report = read_file(
        path, args=args, package_paths=package_paths, options=options, env=env
    )
    return build_description(robot, options, report)


def read_file(
    path: str | Path,
    *,
    args: Mapping[str, str] | None = None,
    package_paths: Mapping[str, str | Path] | None = None,
    options: ConvertOptions | None = None,
    env: Mapping[str, str] | None = None,
) -> tuple[RobotDescription, Report]:
    """The robot description of a model file (xacro expanded, URDF or SDF parsed) and the report
    so far: `convert_full` up to the build, with the same arguments."""
    path = Path(path)
    resolver = PackageResolver.create(path, package_paths, env)
    report = Report(source=str(path))
    options = options or ConvertOptions()
    text = read_description(path, dict(args or {}), resolver, report, options.xacro_budget)
    robot = read_robot(
        text, str(path), path.resolve().parent, resolver, report, as_written=options.as_written
    )
    return robot, report


def convert_text(
    text: str,
    *,
    source: str = "<text>",
    base_dir: str | Path | None = None,
    package_paths: Mapping[str, str | Path] | None = None,
    options: ConvertOptions | None = None,
    env: Mapping[str, str] | None = None,
) -> Conversion:
    """Convert a description given as text (URDF, xacro output or SDF), as SpawnEntity's `xml`.

    Args:
        text: the description.
        source: a name for messages (`<stdin>`, `<xml>`, a request id).
        base_dir: where relative mesh paths start (default: the working directory).
        package_paths, options, env: as for `convert_full`.
    """
    options = options or ConvertOptions()
    robot, report = read_text(
        text,
        source=source,
        base_dir=base_dir,
        package_paths=package_paths,
        options=options,
        env=env,
    )
    return build_description(robot, options, report)


def read_text(
    text: str,
    *,
    source: str = "<text>",
    base_dir: str | Path | None = None,
    package_paths: Mapping[str, str | Path] | None = None,
    options: ConvertOptions | None = None,
    env: Mapping[str, str] | None = None,
) -> tuple[RobotDescription, Report]:
    """`convert_text` up to the build: the robot description and the report so far."""
    directory = Path(base_dir or Path.cwd()).resolve()
    resolver = PackageResolver.create(directory / "description", package_paths, env)
    report = Report(source=source)
    options = options or ConvertOptions()
    robot = read_robot(text, source, directory, resolver, report, as_written=options.as_written)
    return robot, report


def read_build_files(robot: RobotDescription, options: ConvertOptions | None = None) -> None:
    """Read every file `build_description` of `robot` reads (meshes, collision parts with their
    hulls and CoACD, height images, controller parameter files) and make no MjSpec: under
    `converters.isolated.replay.recording`, another process builds the spec from the log.

    Raises:
        ConversionError: what `build_description` raises before or while reading.
    """
    from converters.mjcf.builder import read_build_inputs

    options = options or ConvertOptions()
    scratch = Report(source=robot.source)  # the build says all of it again
    check_references(robot, options, scratch)
    check_joints(robot)
    read_build_inputs(robot, options, scratch)
    if declares_heightmap(robot):
        from converters.mjcf.heightfields import read_height_images

        read_height_images(robot, keep_fixed=options.keep_fixed, fixed_base=options.fixed_base)
    if robot.gazebo.plugins:
        from converters.gazebo.plugins import read_plugin_files

        base = Path(robot.base_dir) if robot.base_dir else None
        read_plugin_files(robot.gazebo.plugins, robot.source, base)


def build_description(
    robot: RobotDescription, options: ConvertOptions | None = None, report: Report | None = None
) -> Conversion:
    """Description → MjSpec, then Gazebo's semantics on it (the stages after any reader)."""
    from converters.gazebo.apply import apply_gazebo
    from converters.mjcf.passive_motors import add_passive_motors

    options = options or ConvertOptions()
    report = report or Report(source=robot.source)
    report.robot = robot.name
    stage(f"building the model of {robot.source}")
    check_references(robot, options, report)
    check_joints(robot)
    provenance = Provenance()
    spec = build_spec(robot, options=options, report=report, provenance=provenance)
    _add_height_fields(spec, robot, options, report)
    apply_gazebo(spec, robot.gazebo, provenance, report)
    sensors = _add_sensors(spec, robot, provenance, report)
    plugins = _add_plugins(spec, robot, report)
    add_passive_motors(spec, robot, report)
    return Conversion(spec, report, provenance, robot, sensors, plugins)


def declares_heightmap(robot: RobotDescription) -> bool:
    """Whether a collision of `robot` is a `<heightmap>` (SDF terrain)."""
    from converters.mjcf.geometry import HEIGHTMAP

    return any(
        c.geometry is not None and c.geometry.shape == HEIGHTMAP
        for link in robot.links
        for c in link.collisions
    )


def _add_height_fields(
    spec: mujoco.MjSpec, robot: RobotDescription, options: ConvertOptions, report: Report
) -> None:
    """SDF terrain as height fields; `heightfields` is imported only if the robot has one."""
    if not declares_heightmap(robot):
        return
    from converters.mjcf.heightfields import add_height_fields

    add_height_fields(
        spec, robot, report, keep_fixed=options.keep_fixed, fixed_base=options.fixed_base
    )


def _add_sensors(
    spec: mujoco.MjSpec, robot: RobotDescription, provenance: Provenance, report: Report
) -> tuple[SensorSpec, ...]:
    """The robot's sensors as sites; the sensor family is imported only if it declares one."""
    if not robot.gazebo.declares_sensors:
        return ()
    from converters.gazebo.sensor_sites import add_sensors

    return add_sensors(spec, robot, provenance, report)


def _add_plugins(spec: mujoco.MjSpec, robot: RobotDescription, report: Report) -> tuple:
    """The robot's drives, controllers and rotors with their motors (`gazebo.plugins`); the
    plugin families (drives, wheels, multicopter) are imported only if it declares a plugin."""
    if not robot.gazebo.plugins:
        return ()
    from converters.gazebo.plugins import add_drive_motors, read_plugins

    base = Path(robot.base_dir) if robot.base_dir else Path(robot.source).parent
    plugins = read_plugins(
        robot.gazebo.plugins, robot.source, spec, robot.name, robot.base_link, report, base
    )
    add_drive_motors(spec, plugins, report)
    return plugins


def check_joints(robot: RobotDescription) -> None:
    """Refuse joints no simulator can honour (no axis, mimic circles).

    Raises:
        URDFStructureError: the first such joint, named, with the fix.
    """
    from converters.description.joint_checks import joint_problems

    for found in joint_problems(robot)[:1]:
        raise URDFStructureError(robot.source, found.subject, found.problem, found.fix)


def check_references(robot: RobotDescription, options: ConvertOptions, report: Report) -> None:
    """Report each tag naming a missing link or joint, and each visual whose mesh is missing,
    as left out (Gazebo loads the robot without them); with `strict`, refuse them. A command
    interface on a joint that closes a loop is refused: the joint exists, but not as a joint.

    Raises:
        URDFStructureError: a control tag names a joint that closes a loop.
        DanglingReferenceError: with `strict`, the tags, each with what it carries, and the
            valid names.
        MissingVisualMeshError: with `strict`, the visuals, each with where the mesh was sought.
    """
    from converters.description.references import (
        dangling_references,
        missing_visuals,
        part_names,
    )

    dangling, visuals = dangling_references(robot), missing_visuals(robot)
    for loop in [d for d in dangling if d.closes_loop][:1]:  # there, not ignored: refused
        raise URDFStructureError(
            robot.source,
            loop.element,
            f"names joint '{loop.target}', which closes a loop: MuJoCo holds it by equality "
            "constraints, not as a joint a motor can drive",
            "command another joint of the loop",
        )
    if options.strict and dangling:
        problems = [d.describe() for d in dangling]
        raise DanglingReferenceError(robot.source, problems, part_names(robot))
    if options.strict and visuals:
        raise MissingVisualMeshError(robot.source, [v.problem for v in visuals])
    for found in (*dangling, *visuals):
        report.warn(
            found.element, f"{found.describe()}; left out, as Gazebo does (--strict refuses)"
        )


def convert(
    path: str | Path,
    *,
    args: Mapping[str, str] | None = None,
    package_paths: Mapping[str, str | Path] | None = None,
    options: ConvertOptions | None = None,
) -> tuple[object, Report]:
    """`convert_full` reduced to the public contract: `(MjSpec, Report)`."""
    done = convert_full(path, args=args, package_paths=package_paths, options=options)
    return done.spec, done.report
