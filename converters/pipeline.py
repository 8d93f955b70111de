"""The conversion pipeline: file → xacro → URDF → description → MjSpec → Gazebo semantics.

The single entry of `converters`; each stage adds its findings to one report.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

from converters.description import RobotDescription
from converters.errors import InputFileError
from converters.mjcf.builder import ConvertOptions, build_spec
from converters.provenance import Provenance
from converters.report import Report
from converters.resources.packages import PackageResolver
from converters.urdf.reader import parse_urdf
from converters.urdf.xacro_expand import expand_xacro, needs_xacro


@dataclass(frozen=True)
class Conversion:
    """Everything one conversion produced: the spec, the report, provenance and the description."""

    spec: object
    report: Report
    provenance: Provenance
    description: RobotDescription


def read_description(
    path: Path, args: Mapping[str, str], resolver: PackageResolver, report: Report
) -> str:
    """URDF text of `path`: xacro files are expanded, plain URDF files read as they are.

    Raises:
        InputFileError: the file is missing or unreadable.
        XacroError, PackageNotFoundError: from xacro.
    """
    if not path.is_file():
        raise InputFileError(str(path), "no such file", "give the path of a .urdf or .xacro file")
    if not needs_xacro(path):
        if args:
            report.ignored("--arg", f"{path.name} is plain URDF; xacro arguments are not used")
        try:
            return path.read_text()
        except (OSError, UnicodeDecodeError) as exc:
            raise InputFileError(str(path), f"cannot be read ({exc})", "check the file") from exc
    result = expand_xacro(path, args, resolver)
    for call in result.unexpanded:
        report.warn(
            f"xacro macro call {call}",
            "matches a macro name but has no 'xacro:' prefix, so xacro left it "
            "unexpanded and its content is missing; write it as <xacro:NAME …/>",
        )
    for line in result.warnings:
        report.warn("xacro", line)
    return result.text


def convert_full(
    path: str | Path,
    *,
    args: Mapping[str, str] | None = None,
    package_paths: Mapping[str, str | Path] | None = None,
    options: ConvertOptions | None = None,
) -> Conversion:
    """Convert a xacro/URDF file into an MjSpec carrying Gazebo's semantics.

    Args:
        path: the `.urdf` or `.xacro` file.
        args: xacro arguments (`NAME:=VALUE` pairs as a dict).
        package_paths: package name → directory (`--package`), searched first.
        options: keep_fixed, repair_inertia, collision settings.

    Raises:
        ConversionError: any subclass, with file/link/joint and the fix in its message.
    """
    from converters.gazebo.apply import apply_gazebo

    path = Path(path)
    options = options or ConvertOptions()
    resolver = PackageResolver.create(path, package_paths)
    report = Report(source=str(path))
    text = read_description(path, dict(args or {}), resolver, report)
    robot = parse_urdf(text, str(path), path.resolve().parent, resolver)
    report.robot = robot.name
    provenance = Provenance()
    spec = build_spec(robot, options=options, report=report, provenance=provenance)
    apply_gazebo(spec, robot.gazebo, provenance, report)
    return Conversion(spec, report, provenance, robot)


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
