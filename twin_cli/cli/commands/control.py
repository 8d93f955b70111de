"""`twin command` and `twin trajectory`: drive an entity's joints, as ros2_control users do.

Client-side only (no mujoco or numpy): the server checks every value against the joint's command
interfaces and limits and refuses the whole request when one is off (exit 2, world unchanged).
`twin trajectory` sends a trajectory_msgs/JointTrajectory file (YAML or CSV), waits until it
ends in sim time and prints the tracking error.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Annotated

import typer

from twin_cli.cli.options import JsonOpt, WorldOpt
from twin_cli.cli.output import Output

POLL_S = 0.1  # [s] wall time between trajectory status requests
MODES = ("position", "velocity", "effort")


def parse_targets(pairs: list[str]) -> dict[str, float]:
    """`JOINT=VALUE` words → {joint: value}.

    Raises:
        InvalidRequestError: a word without `=`, or a value that is not a finite number.
    """
    from twin_cli.errors import InvalidRequestError

    out: dict[str, float] = {}
    for pair in pairs:
        joint, sep, raw = pair.partition("=")
        try:
            value = float(raw)
        except ValueError:
            value = float("nan")
        if not sep or not joint or value != value or value in (float("inf"), float("-inf")):
            raise InvalidRequestError(
                f"command target [{pair}]", "is not JOINT=VALUE", "write e.g. elbow_joint=0.5"
            )
        out[joint] = value
    return out


def command(
    entity: Annotated[str, typer.Argument(help="The entity whose joints to drive.")],
    targets: Annotated[list[str], typer.Argument(help="JOINT=VALUE pairs [rad, m, /s, N m, N].")],
    mode: Annotated[
        str,
        typer.Option(
            "--mode",
            "-m",
            help="position | velocity | effort: any mode the joint offers (twin joints); "
            "a joint in another mode switches at once.",
        ),
    ] = "position",
    world: WorldOpt = "default",
    json: JsonOpt = False,
) -> None:
    """Hold joint targets until changed (position, velocity or effort command interfaces)."""
    from twin_cli.errors import InvalidRequestError
    from twin_cli.server.connection import connect

    if mode not in MODES:
        raise InvalidRequestError(f"--mode [{mode}]", "unknown", f"use one of {', '.join(MODES)}")
    parsed = parse_targets(targets)
    with connect(world) as client:
        done = client.command_joints(entity, parsed, mode)
    out = Output(json)
    if json:
        out.data(done)
        return
    out.line(f"{entity}: {mode} " + " ".join(f"{j}={v:g}" for j, v in parsed.items()))
    for note in done.get("notes", []):
        out.line(note)


def trajectory(
    entity: Annotated[str, typer.Argument(help="The entity to move.")],
    file: Annotated[Path, typer.Argument(help="JointTrajectory as YAML or CSV.")],
    rate: Annotated[float, typer.Option("--rate", help="Controller update rate [Hz].")] = 100.0,
    wait: Annotated[bool, typer.Option("--wait/--no-wait", help="Wait for the end.")] = True,
    world: WorldOpt = "default",
    json: JsonOpt = False,
) -> None:
    """Follow a joint trajectory with joint_trajectory_controller's interpolation."""
    from twin_cli.control.trajectory import read_trajectory
    from twin_cli.errors import InvalidRequestError
    from twin_cli.server.connection import connect

    try:
        text = file.read_text(encoding="utf-8")
    except OSError as exc:
        raise InvalidRequestError(
            f"trajectory file {file}", f"cannot be read ({exc.strerror})", "give a YAML/CSV file"
        ) from exc
    parsed = read_trajectory(text, file.name)
    with connect(world) as client:
        report = client.trajectory(entity, parsed.to_dict(), rate)
        while wait and report["active"]:
            time.sleep(POLL_S)
            report = client.trajectory_status(entity)
    _print_report(report, Output(json))


def _print_report(report: dict, out: Output) -> None:
    if out.json_mode:
        out.data(report)
        return
    state = "running" if report["active"] else "done"
    out.table(
        f"trajectory of {report['entity']}: {state} at {report['elapsed']:.3f} / "
        f"{report['duration']:.3f} s",
        ["joint", "max error", "final error", "clamped onto limit"],
        [
            [
                j,
                report["max_error"].get(j),
                report["final_error"].get(j),
                report.get("clamped", {}).get(j),
            ]
            for j in report["joint_names"]
        ],
    )


def register(app: typer.Typer) -> None:
    """Add `twin command` and `twin trajectory` to the `twin` app."""
    app.command("command")(command)
    app.command("trajectory")(trajectory)
