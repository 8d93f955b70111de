"""What each world command does, without Typer: check the values, one client call, the output.

Each function is named by a `world_table` entry and called with the keywords its parameters
declare (their `dest`), by the Typer commands built from that table (`commands/world.py`) and by
the fast path (`fast.py`). Imports stay client-side: no mujoco, numpy, fastapi or typer.

Raises:
    BadOption: a value that does not parse (the error boundary, `app.main`, prints it as a usage
        error, exit 2).
    SystemExit(2): no world runs, for the commands that must not start one (gz's wording and
        how to start one).
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

from twin_cli.cli import pairs
from twin_cli.cli.output import Output, cell
from twin_cli.cli.spawn_action import POSE_KEYS, Vec3
from twin_cli.cli.spawn_action import spawn as spawn  # the table names it here
from twin_cli.cli.world_client import connect_world, not_running

GRAVITY_PRESETS = ("earth", "moon", "mars", "zero")


def quat_of(pose: dict) -> tuple[float, float, float, float]:
    """(x, y, z, w) of a reply's roll-pitch-yaw (R = Rz(yaw)·Ry(pitch)·Rx(roll))."""
    import math

    cr, sr = math.cos(pose["roll"] / 2), math.sin(pose["roll"] / 2)
    cp, sp = math.cos(pose["pitch"] / 2), math.sin(pose["pitch"] / 2)
    cy, sy = math.cos(pose["yaw"] / 2), math.sin(pose["yaw"] / 2)
    return (
        cy * cp * sr - sy * sp * cr,
        cy * sp * cr + sy * cp * sr,
        sy * cp * cr - cy * sp * sr,
        cy * cp * cr + sy * sp * sr,
    )


def _pose_text(pose: dict) -> str:
    """`x y z roll pitch yaw` as `gz model -p` prints it (rounding first: no `-0.000000`)."""
    return " ".join(f"{round(float(pose[k]), 6) + 0.0:.6f}" for k in POSE_KEYS)


def stop(*, world: str) -> None:
    from twin_cli.errors import NotRunningError
    from twin_cli.server import connection

    try:
        pid = connection.stop(world)
    except NotRunningError as exc:
        raise not_running(exc) from None
    sys.stderr.write(f"twin: stopped world [{world}] (pid {pid})\n")


def delete(*, name: str, world: str) -> None:
    with connect_world(world) as c:
        c.delete(name)


def list_(*, world: str, json: bool) -> None:
    with connect_world(world) as c:
        rows = c.entities()
    out = Output(json)
    if json:
        out.data(rows)
        return
    out.table(
        "entities",
        ["name", "x", "y", "z", "joints", "source", "hull stand-ins", "decomposition"],
        [
            [e["name"], *e["position"], e["n_joints"], e["source"], _stand_ins(e), _state(e)]
            for e in rows
        ],
    )
    for e in rows:
        for mesh in e.get("hull_stand_ins", []):
            out.line(f"{e['name']}: convex hull stands in for {mesh}")


def _stand_ins(entity: dict) -> str:
    """How many collision meshes of an entity are convex hulls standing in for their
    decomposition ("-" for none); an older server sends no such field."""
    count = len(entity.get("hull_stand_ins", []))
    return str(count) if count else "-"


DECOMPOSITION_STATES = {"pending": "pending", "done": "done", "failed": "failed (hull kept)"}


def _state(entity: dict) -> str:
    """Where the background decomposition of an entity's collision meshes is ("-": it had
    none, or an older server)."""
    return DECOMPOSITION_STATES.get(entity.get("decomposition") or "", "-")


def pose(
    *, name: str, set_: tuple[float, ...] | None, world: str, json: bool, quat: bool = False
) -> None:
    """Print (or set) an entity's pose; `quat` prints `x y z qx qy qz qw` (geometry_msgs order)."""
    with connect_world(world) as c:
        if set_ is None:
            result = c.pose(name)
        else:
            result = c.set_pose(name, dict(zip(POSE_KEYS, set_, strict=True)))
    out = Output(json)
    if quat:
        result = {**result, "quat": list(quat_of(result))}
    if json:
        out.data(result)
    elif quat:
        values = [result[k] for k in POSE_KEYS[:3]] + result["quat"]
        out.line(" ".join(f"{round(float(v), 6) + 0.0:.6f}" for v in values))
    else:
        out.line(_pose_text(result))


def joints(*, name: str, world: str, json: bool) -> None:
    with connect_world(world) as c:
        rows = c.joints(name)
        control = {j["name"]: j for j in c.joint_control(name)}
    # each actuated joint's active mode ("none": zero effort), target and offered modes
    for row in rows:
        extra = control.get(row["name"], {})
        row.update(mode=extra.get("mode"), target=extra.get("target"), modes=extra.get("modes"))
    out = Output(json)
    if json:
        out.data(rows)
        return
    out.table(
        f"joints of {name}",
        ["joint", "mode", "offers", "target", "position", "velocity", "effort"],
        [
            [j["name"], j["mode"] or "-", ",".join(j["modes"] or []) or "-", j["target"]]
            + [j["position"], j["velocity"], j["effort"]]
            for j in rows
        ],
    )


def push(
    *,
    name: str,
    force: Vec3,
    torque: Vec3,
    link: str | None,
    duration: float,
    world: str,
    json: bool = False,
) -> None:
    with connect_world(world) as c:
        result = c.push(name, force, torque, link=link, duration=duration)
    if json:
        Output(json).data(result)


def gravity_choice(
    *, earth: bool, moon: bool, mars: bool, zero: bool, set_: Vec3 | None
) -> str | None:
    """The one preset asked for (None: --set or nothing).

    Raises:
        BadOption: more than one of --earth, --moon, --mars, --zero and --set.
    """
    chosen = [p for p, on in zip(GRAVITY_PRESETS, (earth, moon, mars, zero), strict=True) if on]
    if len(chosen) + (set_ is not None) > 1:
        raise pairs.BadOption("give one of --earth, --moon, --mars, --zero or --set")
    return chosen[0] if chosen else None


def gravity(
    *,
    earth: bool,
    moon: bool,
    mars: bool,
    zero: bool,
    set_: Vec3 | None,
    world: str,
    json: bool,
) -> None:
    preset = gravity_choice(earth=earth, moon=moon, mars=mars, zero=zero, set_=set_)
    with connect_world(world) as c:
        if preset is not None:
            result = c.set_gravity(preset=preset)
        elif set_ is not None:
            result = c.set_gravity(vector=set_)
        else:
            result = c.gravity()
    out = Output(json)
    if json:
        out.data(result)
    else:
        out.line(" ".join(f"{v:g}" for v in result["gravity"]))


def physics(
    *,
    step: float | None,
    rate: float | None,
    iterations: int | None,
    world: str,
    json: bool,
    threads: int | None = None,
    sleep: bool = False,
    sleep_tolerance: float | None = None,
    no_sleep: bool = False,
) -> None:
    if sleep and no_sleep:
        raise pairs.BadOption("give --sleep or --no-sleep, not both")
    sleep = True if sleep else (False if no_sleep else None)
    given = (("timestep", step), ("rate", rate), ("iterations", iterations))
    given += (("threads", threads), ("sleep", sleep), ("sleep_tolerance", sleep_tolerance))
    changes = {k: v for k, v in given if v is not None}
    with connect_world(world) as c:
        result = c.set_physics(**changes) if changes else c.physics()
    out = Output(json)
    if json:
        out.data(result)
        return
    out.table("physics", ["setting", "value"], physics_rows(result))


def physics_rows(result: dict) -> list[list]:
    """`twin physics` for people: each setting once. A field the world file carries that MuJoCo
    has no counterpart for (listed in `not_applicable`) is not a setting in force: it shows
    only in that last row, with the file's value (`contact_max_correcting_vel=100`)."""
    unused = result.get("not_applicable") or []
    rows = [
        [key, " ".join(f"{v:g}" for v in value) if key == "gravity" else value]
        for key, value in result.items()
        if key != "not_applicable" and key not in unused
    ]
    shown = [f"{name}={cell(result[name])}" if name in result else name for name in unused]
    return [*rows, ["not_applicable", ", ".join(shown) or None]]


def pause(*, world: str) -> None:
    with connect_world(world) as c:
        c.pause()


def resume(*, world: str) -> None:
    with connect_world(world) as c:
        c.resume()


def step(*, n: int, world: str, json: bool) -> None:
    from twin_cli.cli.stats_format import stats_line

    with connect_world(world) as c:
        result = c.step(n)
    out = Output(json)
    if json:
        out.data(result)
    else:
        out.line(stats_line(result))


def reset(*, time_only: bool, world: str) -> None:
    with connect_world(world) as c:
        c.reset(time_only=time_only)


def stats(*, duration: float | None, plot: bool, world: str, json: bool) -> None:
    from twin_cli.cli import stats_format as fmt
    from twin_cli.errors import NotRunningError

    try:
        c = connect_world(world, start=False)
    except NotRunningError as exc:
        raise not_running(exc) from None
    render = fmt.stats_json if json else fmt.stats_csv_row if plot else fmt.stats_line
    try:
        with c:
            if plot and not json:
                print(fmt.CSV_HEADER, flush=True)
            for tick in fmt.sample_times(time.monotonic(), duration):
                time.sleep(max(0.0, tick - time.monotonic()))
                print(render(c.stats()), flush=True)
    except NotRunningError as exc:
        raise not_running(exc) from None
    except (KeyboardInterrupt, BrokenPipeError):
        return


def save(*, file: Path, world: str, force: bool = False) -> None:
    with connect_world(world) as c:
        c.save(file, force=force)


def load(*, file: Path | None, world: str, last: bool = False) -> None:
    """Load a saved world (or with `last`, the last autosave) into the world's server.

    With no server running, starts one that serves the file (the user named the world it must
    hold, so nothing appears silently); with one, replaces its world.

    Raises:
        BadOption: neither or both of FILE and --last.
    """
    if (file is None) == (not last):
        raise pairs.BadOption("give a FILE written by `twin save`, or --last, not both")
    if last:
        file = _last_autosave(world)
    path = str(Path(file).expanduser().absolute())
    started: list[str] = []

    def announce(line: str) -> None:
        started.append(line)
        sys.stderr.write(f"{line}\n")

    with connect_world(world, start=True, serve_args=(path,), announce=announce) as c:
        reply = None if any("started world" in line for line in started) else c.load(path)
    sys.stderr.write(f"twin: world [{world}] loaded from {path}\n")
    for consumer in ("recording", "foxglove", "ros"):  # they follow, or say they stopped
        if isinstance(reply, dict) and consumer in reply:
            sys.stderr.write(f"twin: {consumer} {reply[consumer]}\n")


def _last_autosave(world: str) -> Path:
    """The world's newest autosave; a dead server is reported (and retired) first."""
    from twin_cli.server import lifecycle, runtime

    paths = runtime.world_paths(world)
    with runtime.start_lock(paths):
        if not runtime.server_alive(paths):
            runtime.clean_stale(paths)
            died = lifecycle.retire(paths)
            if died:
                sys.stderr.write(f"twin: {died}\n")
    return lifecycle.last_autosave(paths)


def logs(*, lines: int | None, world: str) -> None:
    from twin_cli.server import runtime

    paths = runtime.world_paths(world)
    if not paths.log.exists():
        from twin_cli.errors import start_fix

        sys.stderr.write(
            f"twin: no log for world [{world}] in {paths.directory}: no server has run for it. "
            f"{start_fix(world)}\n"
        )
        raise SystemExit(2)
    sys.stdout.write(runtime.log_tail(paths, lines))
