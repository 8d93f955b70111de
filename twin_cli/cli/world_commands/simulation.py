"""`twin gravity`, `physics`, `pause`, `resume`, `step`, `reset`, `stats`: the world's clock
and settings."""

from __future__ import annotations

import time

from twin_cli.cli import pairs
from twin_cli.cli.output import Output, cell
from twin_cli.cli.params import JSON, WORLD, Vec3
from twin_cli.cli.registry import Arg, Opt, command, flag
from twin_cli.cli.world_client import connect_world, not_running

GRAVITY_PRESETS = ("earth", "moon", "mars", "zero")


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


@command(
    "gravity",
    flag("--earth", dest="earth", help="(0, 0, -9.81)"),
    flag("--moon", dest="moon", help="(0, 0, -1.62)"),
    flag("--mars", dest="mars", help="(0, 0, -3.71)"),
    flag("--zero", dest="zero", help="(0, 0, 0)"),
    Opt(("--set",), "set_", "X Y Z (m/s^2).", float, nargs=3),
    WORLD,
    JSON,
    help="Print the gravity vector, or set it from a preset or --set X Y Z.",
)
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


@command(
    "physics",
    Opt(("--step",), "step", "Physics step (s).", float),
    Opt(("--rate",), "rate", "Real-time update rate (Hz); 0 = max.", float),
    Opt(("--iterations",), "iterations", "Solver iterations.", int),
    WORLD,
    JSON,
    Opt(("--threads",), "threads", "MuJoCo engine threads, 1-64 (default 1: no pool).", int),
    flag("--sleep", dest="sleep", help="Let resting robots sleep (off by default)."),
    flag("--no-sleep", dest="no_sleep", help="Keep every robot awake."),
    Opt(
        ("--sleep-tolerance",),
        "sleep_tolerance",
        "Speed (m/s) under which a robot may sleep.",
        float,
    ),
    help="Print the physics settings, or change step, rate, iterations, threads or sleeping.",
)
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
    asleep = True if sleep else (False if no_sleep else None)
    given = (("timestep", step), ("rate", rate), ("iterations", iterations))
    given += (("threads", threads), ("sleep", asleep), ("sleep_tolerance", sleep_tolerance))
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


@command("pause", WORLD, help="Pause the simulation.")
def pause(*, world: str) -> None:
    with connect_world(world) as c:
        c.pause()


@command("resume", WORLD, help="Resume the simulation.")
def resume(*, world: str) -> None:
    with connect_world(world) as c:
        c.resume()


@command(
    "step",
    Arg("n", "Number of steps.", int, False, 1, minimum=1),
    WORLD,
    JSON,
    help="Advance the simulation N steps (also while paused).",
)
def step(*, n: int, world: str, json: bool) -> None:
    from twin_cli.cli.stats_format import stats_line

    with connect_world(world) as c:
        result = c.step(n)
    out = Output(json)
    if json:
        out.data(result)
    else:
        out.line(stats_line(result))


@command(
    "reset",
    flag("--time-only", dest="time_only", help="Only reset time."),
    WORLD,
    help="Reset the world (entities to their spawn poses, time to 0), or only its time.",
)
def reset(*, time_only: bool, world: str) -> None:
    with connect_world(world) as c:
        c.reset(time_only=time_only)


@command(
    "stats",
    Opt(("-d", "--duration"), "duration", "Seconds to run (default: forever).", float),
    flag("-p", "--plot", dest="plot", help="Comma-separated values."),
    WORLD,
    flag(
        "--json",
        dest="json",
        help="Print one JSON object a line, about five a second, streamed until --duration "
        "ends or Ctrl-C (without -d it never ends).",
    ),
    help="Print `Factor[..] SimTime[..] RealTime[..] Paused[..]` about five times a second, "
    "until --duration ends or Ctrl-C.",
)
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
