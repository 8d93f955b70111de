"""`twin convert` (description → MJCF directory + report) and `twin inspect` (inertial stats)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer

from twin_cli.cli.options import (
    ArgOpt,
    CoacdCpuLimitOpt,
    FixedBaseOpt,
    JsonOpt,
    PackageOpt,
    parse_pairs,
    source_inputs,
)

RobotArg = Annotated[
    Path, typer.Argument(help="Robot description: .urdf, .xacro or .sdf (SDF model) file.")
]
AsWrittenOpt = Annotated[
    bool,
    typer.Option(
        "--as-written",
        help="Apply what the URDF says where Gazebo's parser drops it (inline <surface>, "
        "link friction on named collisions) instead of simulating what Gazebo simulates.",
    ),
]
KeepFixedOpt = Annotated[
    bool, typer.Option("--keep-fixed", help="Keep fixed joints as welded bodies (no lumping).")
]
RepairOpt = Annotated[
    bool,
    typer.Option("--repair-inertia", help="Bound non-physical inertias instead of failing."),
]
StrictOpt = Annotated[
    bool,
    typer.Option(
        "--strict",
        help="Refuse tags naming a missing link or joint, and visuals whose mesh is missing, "
        "instead of leaving them out with a warning (as Gazebo does).",
    ),
]
DanglingOpt = Annotated[
    bool,
    typer.Option(
        "--drop-dangling",
        help="Leave those out with a warning: the default (kept for older scripts).",
    ),
]


def import_mujoco_without_gl() -> None:
    """Imports mujoco with its OpenGL backends off, when this process has not imported it yet.

    A conversion never renders, and `import mujoco` otherwise loads glfw (about 60 ms of a 0.5 s
    conversion, `-X importtime`). Only this import sees `MUJOCO_GL=disable`: the variable is put
    back at once, so processes started later (a world server) render as before. This process
    cannot render afterwards (mujoco has no GL context class then), and the variable changes for
    the whole process for the moment of the import: call it only from a command's own process
    before any thread starts, as `twin convert` and `twin inspect` do.
    """
    import os
    import sys

    if "mujoco" in sys.modules:
        return
    before = os.environ.get("MUJOCO_GL")
    os.environ["MUJOCO_GL"] = "disable"
    try:
        import mujoco  # noqa: F401
    finally:
        if before is None:
            del os.environ["MUJOCO_GL"]
        else:
            os.environ["MUJOCO_GL"] = before


def _options(
    keep_fixed: bool,
    repair: bool,
    collision: dict[str, Any] | None = None,
    as_written: bool = False,
    strict: bool = False,
    fixed_base: bool = False,
) -> Any:
    from converters.collision.plan import CollisionSettings
    from converters.mjcf.builder import ConvertOptions

    return ConvertOptions(
        keep_fixed,
        repair,
        CollisionSettings(**(collision or {})),
        as_written=as_written,
        strict=strict,
        fixed_base=fixed_base,
    )


def _collision_settings(
    mode: str,
    per_link: list[str] | None,
    preset: str,
    threshold: float | None,
    max_hulls: int | None,
    resolution: int | None,
    seed: int,
    jobs: int | None,
    no_cache: bool,
    cpu_limit: float | None = None,
    threshold_m: float | None = None,
) -> dict[str, Any]:
    extra = {"cpu_limit": cpu_limit} if cpu_limit is not None else {}
    return {
        **extra,
        "threshold_m": threshold_m,
        "progress": True,
        "mode": mode,
        "per_link": parse_pairs(per_link, "=", "--collision-link"),
        "preset": preset,
        "threshold": threshold,
        "max_hulls": max_hulls,
        "resolution": resolution,
        "seed": seed,
        "jobs": jobs,
        "use_cache": not no_cache,
    }


def convert_command(
    robot: RobotArg,
    out_dir: Annotated[
        Path | None, typer.Option("-o", "--out", help="Output directory (default ./<robot>_mjcf).")
    ] = None,
    arg: ArgOpt = None,
    package: PackageOpt = None,
    keep_fixed: KeepFixedOpt = False,
    repair_inertia: RepairOpt = False,
    strict: StrictOpt = False,
    drop_dangling: DanglingOpt = False,
    fixed_base: FixedBaseOpt = False,
    print_xml: Annotated[bool, typer.Option("--print", help="Write the MJCF to stdout.")] = False,
    json_mode: JsonOpt = False,
    collision: Annotated[
        str, typer.Option("--collision", help="Collision meshes: auto|coacd|hull|mesh.")
    ] = "auto",
    collision_link: Annotated[
        list[str] | None,
        typer.Option("--collision-link", help="Per-link collision mode LINK=MODE (repeatable)."),
    ] = None,
    coacd_preset: Annotated[
        str, typer.Option("--coacd-preset", help="CoACD preset: fast|balanced|fine.")
    ] = "balanced",
    coacd_threshold: Annotated[
        float | None, typer.Option("--coacd-threshold", help="CoACD concavity threshold.")
    ] = None,
    max_hulls: Annotated[
        int | None, typer.Option("--max-hulls", help="Most convex parts per mesh.")
    ] = None,
    coacd_resolution: Annotated[
        int | None, typer.Option("--coacd-resolution", help="CoACD sampling resolution.")
    ] = None,
    coacd_threshold_m: Annotated[
        float | None,
        typer.Option("--coacd-threshold-m", help="CoACD concavity threshold in metres."),
    ] = None,
    coacd_cpu_limit: CoacdCpuLimitOpt = None,
    seed: Annotated[int, typer.Option("--seed", help="CoACD random seed.")] = 0,
    jobs: Annotated[int | None, typer.Option("--jobs", help="Parallel CoACD workers.")] = None,
    no_cache: Annotated[
        bool, typer.Option("--no-cache", help="Ignore the decomposition cache.")
    ] = False,
    as_written: AsWrittenOpt = False,
) -> None:
    """Convert a xacro/URDF (with Gazebo tags) or SDF robot into a MuJoCo MJCF directory."""
    import_mujoco_without_gl()
    from converters.mjcf.writer import standalone_xml, write_model
    from converters.pipeline import convert_full
    from twin_cli.cli.conversion_progress import LocalProgress
    from twin_cli.cli.output import Output

    settings = _collision_settings(
        collision,
        collision_link,
        coacd_preset,
        coacd_threshold,
        max_hulls,
        coacd_resolution,
        seed,
        jobs,
        no_cache,
        coacd_cpu_limit,
        coacd_threshold_m,
    )
    with LocalProgress():
        done = convert_full(
            robot,
            **source_inputs(arg, package),
            options=_options(keep_fixed, repair_inertia, settings, as_written, strict, fixed_base),
        )
    if print_xml:
        typer.echo(standalone_xml(done.spec), nl=False)
        if out_dir is None:
            return
    target = out_dir or Path(f"{robot.name.split('.')[0]}_mjcf")
    written = write_model(done.spec, done.report, target)
    _show_report(Output(json_mode), done.report, written)


def _show_report(out: Any, report: Any, written: Path) -> None:
    """The report as tables (summary, each finding, meshes) or one JSON document."""
    if out.json_mode:
        out.data(
            {"model": str(written), "scene": str(written.parent / "scene.xml"), **report.to_dict()}
        )
        return
    rows = [(k, v) for k, v in report.summary.items()]
    out.table(f"{report.robot}: {report.source}", ["quantity", "value"], rows)
    findings = [(e.outcome.value, e.subject, e.detail) for e in report.entries]
    if findings:
        out.table("What the converter did", ["outcome", "subject", "detail"], findings)
    out.line(f"wrote {written} and {written.parent / 'scene.xml'}")


def inspect_command(
    robot: RobotArg,
    arg: ArgOpt = None,
    package: PackageOpt = None,
    keep_fixed: KeepFixedOpt = False,
    repair_inertia: RepairOpt = False,
    strict: StrictOpt = False,
    drop_dangling: DanglingOpt = False,
    fixed_base: FixedBaseOpt = False,
    json_mode: JsonOpt = False,
    as_written: AsWrittenOpt = False,
) -> None:
    """Link tree, total mass, centre of mass and inertia (like `gz sdf --inertial-stats`)."""
    import_mujoco_without_gl()
    from converters.inspect import inertial_stats
    from converters.pipeline import convert_full
    from twin_cli.cli.output import Output

    done = convert_full(
        robot,
        **source_inputs(arg, package),
        options=_options(
            keep_fixed, repair_inertia, {"mode": "mesh"}, as_written, strict, fixed_base
        ),
    )
    stats = inertial_stats(done.spec, done.description)
    out = Output(json_mode)
    if json_mode:
        out.data({"robot": done.report.robot, **stats.to_dict()})
        return
    tree = [
        ("  " * d + link, joint, kind, stats.link_masses.get(link, 0.0))
        for d, link, joint, kind in stats.tree
    ]
    out.table(f"{done.report.robot}: links", ["link", "joint", "type", "mass [kg]"], tree)
    out.line(f"Total mass [kg]: {stats.total_mass:.6g}")
    out.line("Centre of mass [m]: " + " ".join(f"{v:.6g}" for v in stats.com))
    out.line("Inertia about the centre of mass [kg m^2]:")
    for row in stats.inertia:
        out.line("  " + " ".join(f"{v:12.6g}" for v in row))


def register(app: typer.Typer) -> None:
    """Add `convert` and `inspect` to the app."""
    app.command("convert")(convert_command)
    app.command("inspect")(inspect_command)
