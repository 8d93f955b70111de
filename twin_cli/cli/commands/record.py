"""`twin record` and `twin foxglove`: the server records or streams; this side only asks.

Client-side like the world commands: no mujoco, numpy, mcap, rosbags or foxglove here. The
server samples the world in its stepping thread, so no sample is lost to client polling.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path
from typing import Annotated, Any

import typer

from twin_cli.cli.options import JsonOpt, WorldOpt
from twin_cli.cli.output import Output

POLL_S = 0.2  # [s] how often `twin record` asks whether the recording ended


def record(
    out: Annotated[Path, typer.Argument(help="The rosbag2 MCAP file to write (OUT.mcap).")],
    duration: Annotated[
        float | None, typer.Option(help="Stop after this much sim time (s); default: Ctrl-C.")
    ] = None,
    rate: Annotated[float, typer.Option(help="Samples per second of sim time (Hz).")] = 100.0,
    entity: Annotated[
        list[str] | None, typer.Option(help="Record only this entity (repeat); default: all.")
    ] = None,
    world: WorldOpt = "default",
    json: Annotated[
        bool,
        typer.Option(
            "--json",
            help="Print the recording's summary as one JSON object when it ends (at --duration "
            "or Ctrl-C: without --duration it records until stopped).",
        ),
    ] = False,
) -> None:
    """Record /clock, /tf, /tf_static and each entity's joint_states, odom and
    robot_description into a rosbag2 MCAP file, until --duration or Ctrl-C."""
    from twin_cli.server.connection import connect

    body = {"path": str(out.expanduser().resolve()), "rate": rate, "entities": entity or []}
    if duration is not None:
        body["duration"] = duration
    with connect(world, start=False) as client:
        client.request("POST", "/record", body=body)
        sys.stderr.write(f"twin: recording to {body['path']}; Ctrl-C stops\n")
        try:
            _wait(client)
        except KeyboardInterrupt:
            pass
        status = client.request("DELETE", "/record")
    _report(status, json)


def _wait(client: Any) -> None:
    """Until the server's recording ends: its duration is over, or it stopped early (a full
    disk), which without a duration would otherwise go unnoticed until Ctrl-C."""
    while True:
        time.sleep(POLL_S)
        if not client.request("GET", "/record")["active"]:
            return


def _report(status: dict, json: bool) -> None:
    """The summary; a recording cut short (a full disk) also says why on stderr and exits 2,
    so a script does not take a partial bag for a whole one."""
    out = Output(json)
    if json:
        out.data(status)
    else:
        span = (
            ""
            if status["start"] is None
            else (f", sim time {status['start']:.3f}-{status['end']:.3f} s")
        )
        out.line(f"{status['path']}: {status['samples']} samples{span}")
    if status.get("error"):
        sys.stderr.write(f"twin: {status['path']}: recording stopped early: {status['error']}\n")
        raise typer.Exit(code=2)


def foxglove(
    port: Annotated[int, typer.Option(help="Port on 127.0.0.1 (Foxglove's default 8765).")] = 8765,
    rate: Annotated[float, typer.Option(help="Samples per second of sim time (Hz).")] = 30.0,
    stop: Annotated[bool, typer.Option("--stop", help="Stop the stream.")] = False,
    world: WorldOpt = "default",
    json: JsonOpt = False,
) -> None:
    """Stream the world's topics live to Foxglove (open ws://127.0.0.1:PORT in Foxglove)."""
    from twin_cli.server.connection import connect

    with connect(world, start=False) as client:
        if stop:
            reply = client.request("DELETE", "/foxglove")
        else:
            reply = client.request("POST", "/foxglove", body={"port": port, "rate": rate})
    out = Output(json)
    if json:
        out.data(reply)
    elif stop:
        out.line(f"stopped the Foxglove stream on port {reply['stopped']}")
    else:
        out.line(f"{reply['url']}  (Foxglove: Open connection → Foxglove WebSocket)")


def register(app: typer.Typer) -> None:
    """Add `twin record` and `twin foxglove` to the `twin` app."""
    app.command("record")(record)
    app.command("foxglove")(foxglove)
