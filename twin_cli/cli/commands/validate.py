"""`twin validate`: run the physics validation checklist on a robot, in-process (no server)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer

from twin_cli.cli.commands.validate_sweep import (
    JobsOpt,
    RayOpt,
    SweepOpt,
    check_report_targets,
    run_sweep,
    write_report,
)
from twin_cli.cli.options import (
    ArgOpt,
    JointOpt,
    JsonOpt,
    PackageOpt,
    joint_positions,
    source_inputs,
)

ScenarioOpt = Annotated[
    list[str] | None,
    typer.Option(
        "--scenario",
        help="Bundled scenario name or scenario .toml file (repeatable; default: the checklist).",
    ),
]
OnlyOpt = Annotated[list[str] | None, typer.Option("--only", help="Run only this check.")]
SkipOpt = Annotated[list[str] | None, typer.Option("--skip", help="Leave this check out.")]
JunitOpt = Annotated[Path | None, typer.Option("--junit", help="Write JUnit XML to FILE.")]
MarkdownOpt = Annotated[
    Path | None, typer.Option("--markdown", help="Write a Markdown summary to FILE.")
]
PlotsOpt = Annotated[Path | None, typer.Option("--plots", help="Write PNG plots into DIR.")]
VideoOpt = Annotated[
    Path | None,
    typer.Option("--video", help="Write one MP4 per physics scenario into DIR (offscreen EGL)."),
]
RepairOpt = Annotated[
    bool,
    typer.Option(
        "--repair-inertia",
        help="Accept the converter's inertia repairs (report them as warnings, not failures).",
    ),
]

RecordOpt = Annotated[
    Path | None,
    typer.Option("--record", help="Keep one rosbag2 MCAP file per physics scenario in DIR."),
]
CollisionOpt = Annotated[
    str | None,
    typer.Option(
        "--collision",
        help="Collision meshes as the converter makes them: auto|coacd|hull|mesh (default auto).",
    ),
]


def validate(
    robots: Annotated[
        list[Path], typer.Argument(help="URDF, xacro, SDF or MJCF file(s) of the robot(s).")
    ],
    arg: ArgOpt = None,
    package: PackageOpt = None,
    scenario: ScenarioOpt = None,
    only: OnlyOpt = None,
    skip: SkipOpt = None,
    junit: JunitOpt = None,
    json: JsonOpt = False,
    markdown: MarkdownOpt = None,
    plots: PlotsOpt = None,
    video: VideoOpt = None,
    repair_inertia: RepairOpt = False,
    collision: CollisionOpt = None,
    joint: JointOpt = None,
    as_written: Annotated[
        bool,
        typer.Option(
            "--as-written", help="Apply what the URDF says where Gazebo's parser drops it."
        ),
    ] = False,
    sweep: SweepOpt = None,
    jobs: JobsOpt = None,
    ray: RayOpt = None,
    record: RecordOpt = None,
) -> None:
    """Validate a robot: model checks plus physics scenarios. Exit 0 pass, 1 fail, 2 bad input.

    A check that crashed (a bug, not the robot's fault) makes the exit code 70.

    Several robots, --sweep, --jobs or --ray run every robot × variant in worker processes.
    """
    from twin_cli.cli.output import Output
    from twin_cli.validate import report as render
    from twin_cli.validate import video as films
    from twin_cli.validate.runner import validate as run_validation

    check_report_targets(junit, markdown)
    if sweep or len(robots) > 1 or jobs is not None or ray is not None:
        if video or record:
            raise typer.BadParameter(
                "--video and --record film or record one robot's scenarios; run them without "
                "--sweep, --jobs, --ray and with one ROBOT"
            )
        options = {
            **source_inputs(arg, package),
            "scenarios": scenario,
            "only": only,
            "skip": skip,
            "repair_inertia": repair_inertia,
            "collision": collision,
            "joints": joint_positions(joint),
            "as_written": as_written,
        }
        run_sweep(
            robots,
            sweep or [],
            options,
            jobs=jobs,
            ray=ray,
            json=json,
            junit=junit,
            markdown=markdown,
            plots=plots,
        )
    robot = robots[0]
    with films.filming(video):
        run = run_validation(
            robot,
            **source_inputs(arg, package),
            scenarios=scenario,
            only=only,
            skip=skip,
            repair_inertia=repair_inertia,
            collision=collision,
            joints=joint_positions(joint),
            as_written=as_written,
            record=record,
        )
    out = Output(json)
    if json:
        out.data(run.to_dict())
    else:
        print_table(run, out)
    if junit:
        write_report(junit, render.junit_xml(run))
    if markdown:
        linked = None
        if plots:  # linked from where the Markdown file is, if the plots are below it
            base = markdown.resolve().parent
            target = plots.resolve()
            linked = str(target.relative_to(base)) if target.is_relative_to(base) else str(target)
        write_report(markdown, render.markdown(run, plots=linked))
    if plots:
        for path in render.write_plots(run, plots):
            out.line(f"plot: {path}")
    if record and not json:
        from twin_cli.validate.recording import written

        for path in written:
            out.line(f"recording: {path}")
    for path in films.written if video else []:
        out.line(f"video: {path}")
    raise typer.Exit(run.exit_code)  # 0 pass, 1 a check failed, 70 a check crashed


def register(app: typer.Typer) -> None:
    """Add `twin validate` to the app."""
    app.command("validate")(validate)


def print_table(run: Any, out: Any) -> None:
    """The human view: one row per check, then the hints of every failed or warned check."""
    from twin_cli.validate import report as render

    rows = [(render.label(r), r.measured, r.threshold, render.MARK[r.status]) for r in run.results]
    out.table(f"twin validate {run.robot}", ["check", "measured", "threshold", "result"], rows)
    for r in run.results:
        if r.status in render.TO_FIX:
            for hint in r.hints or r.details:
                out.line(f"{render.MARK[r.status]} {r.check}: {hint}")
    counts = run.counts()
    out.line(
        f"{run.robot}: {counts['pass']} passed, {counts['warn']} warned, {counts['fail']} failed,"
        f" {counts.get('error', 0)} crashed, {counts['skip']} not applicable in {run.seconds:.1f} s"
    )
