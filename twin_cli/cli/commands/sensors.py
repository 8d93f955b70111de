"""`twin sensors ENTITY [NAME]`: print a robot's sensor readings, like `gz topic -e`.

Client-side (no mujoco or numpy): the server computes readings at each sensor's update rate in
sim time; this side asks at the fastest rate among the printed sensors (at most `MAX_POLL_HZ`
of wall time) and prints each reading once, when its stamp is new. `--json` prints one JSON
object per reading and line; an infinite lidar range is null there.
"""

from __future__ import annotations

import json
import time
from typing import Annotated, Any

import typer

from twin_cli.cli.options import WorldOpt
from twin_cli.cli.output import Output

MAX_POLL_HZ = 50.0  # [Hz] of wall time: a human reads; a recording samples in the server
ONCE_HZ = 10.0  # [Hz] poll rate when no sensor states a rate
HEADER = ("sensor", "type", "time", "frame_id")  # what every reading has (`Reading`)


def sensors(
    entity: Annotated[str, typer.Argument(help="The entity whose sensors to read.")],
    name: Annotated[str | None, typer.Argument(help="One sensor (default: all).")] = None,
    duration: Annotated[
        float | None,
        typer.Option("-d", "--duration", help="Print readings for this many seconds (wall)."),
    ] = None,
    world: WorldOpt = "default",
    json: Annotated[
        bool,
        typer.Option(
            "--json",
            help="Print one JSON object a line per reading, streamed until --duration ends "
            "(once without -d).",
        ),
    ] = False,
) -> None:
    """Print the readings of an entity's sensors (IMU, lidar, contact, force/torque, camera)."""
    from twin_cli.server.connection import connect
    from twin_cli.server.transport import path_segment

    out = Output(json)
    base = f"/entities/{path_segment(entity)}/sensors"
    with connect(world, start=False) as client:
        listing = client.request("GET", base)["sensors"]
        if name is not None:
            client.request("GET", f"{base}/{path_segment(name)}")  # a bad name: exit 2, listed
        chosen = [s for s in listing if name is None or s["name"] == name]
        if not chosen:
            out.line(f"entity [{entity}] has no sensors")
            return
        paths = {s["name"]: f"{base}/{path_segment(s['name'])}" for s in chosen}
        _print_loop(client, paths, _poll_period(chosen), duration, out)


def _poll_period(chosen: list[dict[str, Any]]) -> float:
    rates = [s["update_rate"] for s in chosen if s["update_rate"] > 0]
    fastest = max(rates) if len(rates) == len(chosen) else MAX_POLL_HZ
    return 1.0 / min(MAX_POLL_HZ, fastest or ONCE_HZ)


def _print_loop(
    client: Any, paths: dict[str, str], period: float, duration: float | None, out: Output
) -> None:
    """Print each new reading until `duration` [s] of wall time (once without one)."""
    seen: dict[str, float] = {}
    end = time.monotonic() + (duration or 0.0)
    while True:
        for sensor, path in paths.items():
            reading = client.request("GET", path)
            if seen.get(sensor) != reading["time"]:
                seen[sensor] = reading["time"]
                _print(reading, out)
        if duration is None or time.monotonic() >= end:
            return
        time.sleep(period)


def _print(reading: dict[str, Any], out: Output) -> None:
    if out.json_mode:  # one compact object per line, as a stream of messages
        out.stream.write(json.dumps(reading) + "\n")
        out.stream.flush()
        return
    head = f"{reading['sensor']} [{reading['type']}] t={reading['time']:.3f} s"
    out.line(f"{head}: {summary(reading)}")


def summary(reading: dict[str, Any]) -> str:
    """One line of a reading's values (the JSON form keeps all of them)."""
    if "linear_acceleration" in reading:
        return (
            f"orientation (x y z w) {_vec(reading['orientation'])}  angular_velocity "
            f"{_vec(reading['angular_velocity'])} rad/s  linear_acceleration "
            f"{_vec(reading['linear_acceleration'])} m/s²"
        )
    if "ranges" in reading:
        hits = [r for r in reading["ranges"] if r is not None]
        nearest = f"nearest {min(hits):.3f} m" if hits else "no returns"
        return f"{len(reading['ranges'])} ranges, {len(hits)} returns, {nearest}"
    if "states" in reading:
        return f"{len(reading['states'])} contacts, total force {_vec(reading['total_force'])} N"
    if "torque" in reading:
        return f"force {_vec(reading['force'])} N  torque {_vec(reading['torque'])} N m"
    if "encoding" in reading:
        return f"{reading['width']}×{reading['height']} {reading['encoding']} image"
    values = {k: v for k, v in reading.items() if k not in HEADER}
    return "  ".join(f"{k} {_value(v)}" for k, v in values.items())


def _value(value: Any) -> str:
    """A value of a reading of another kind: numbers to 4 significant digits."""
    if isinstance(value, list):
        return "(" + " ".join(_value(v) for v in value) + ")"
    return f"{value:.4g}" if isinstance(value, float) else str(value)


def _vec(values: list[float]) -> str:
    return "(" + " ".join(f"{v:.4g}" for v in values) + ")"


def register(app: typer.Typer) -> None:
    """Add `twin sensors` to the `twin` app."""
    app.command("sensors")(sensors)
