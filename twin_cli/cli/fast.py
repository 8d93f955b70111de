"""The fast path: world commands parsed without Typer; anything unusual goes to the Typer app.

A world command is one small request, yet importing typer (with click: 56 ms, `-X importtime`)
and building the app with every command module cost more than the request and Python's start-up
together; `twin gravity --moon` takes 115 ms median wall on the fast path (339 ms before, with
httpx; `benchmarks/bench_server.py`).
This module reads the same options as `commands/world.py` declares, for the plain forms people
and scripts type (`--opt VALUE`, `--opt=VALUE`, flags, positionals in any order), and calls the
same `world_actions` function. It *declines* (returns None) whenever Typer would do anything
else: `--help`, an unknown or clustered option, a missing or extra argument, a value that does
not convert, so help, usage errors and exit code 2 all come from Typer itself.
`tests/test_cli_fast.py` checks this grammar against the Typer app's options and its parses.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

WORLD_ENV = "TWIN_WORLD"  # --world's environment variable (options.WorldOpt)


@dataclass(frozen=True)
class Opt:
    """An option: its flags, the keyword it fills, how a value converts (None: a bool flag)."""

    flags: tuple[str, ...]
    dest: str
    convert: Callable[[str], Any] | None = None
    default: Any = None
    nargs: int = 1
    multiple: bool = False


@dataclass(frozen=True)
class Arg:
    """A positional argument; `minimum` bounds an int (Typer's `min=`)."""

    dest: str
    convert: Callable[[str], Any]
    required: bool = True
    default: Any = None
    minimum: int | None = None


@dataclass(frozen=True)
class Grammar:
    """One command: the `world_actions` function it calls, its arguments and options."""

    action: str
    args: tuple[Arg, ...] = ()
    opts: tuple[Opt, ...] = ()


@dataclass(frozen=True)
class Call:
    """A parsed command line: the `world_actions` function name and its keyword arguments."""

    action: str
    kwargs: dict[str, Any]


def _flag(*flags: str, dest: str) -> Opt:
    return Opt(flags, dest, None, False)


WORLD = Opt(("--world",), "world", str)  # default: $TWIN_WORLD, else "default"
JSON = _flag("--json", dest="json")
NAME = Arg("name", str)
POSE = tuple(
    Opt((flag,), dest, float, 0.0)
    for flag, dest in zip(
        ("-x", "-y", "-z", "-R", "-P", "-Y"), ("x", "y", "z", "roll", "pitch", "yaw"), strict=True
    )
)

GRAMMARS: dict[str, Grammar] = {
    "stop": Grammar("stop", opts=(WORLD,)),
    "spawn": Grammar(
        "spawn",
        (Arg("file", Path, required=False),),
        (
            *POSE,
            Opt(("--name",), "name", str),
            Opt(("--arg",), "arg", str, multiple=True),
            Opt(("--package",), "package", str, multiple=True),
            _flag("--on-ground", dest="on_ground"),
            Opt(("-J", "--joint"), "joint", str, multiple=True),
            WORLD,
            JSON,
            Opt(("--xml",), "xml", str),
            Opt(("--quat",), "quat", float, nargs=4),
            Opt(("--at",), "at", str, multiple=True),
            Opt(("--names",), "names", str),
            _flag("--view", dest="view"),
            _flag("--repair-inertia", dest="repair_inertia"),
        ),
    ),
    "delete": Grammar("delete", (NAME,), (WORLD,)),
    "list": Grammar("list_", opts=(WORLD, JSON)),
    "pose": Grammar(
        "pose",
        (NAME,),
        (Opt(("--set",), "set_", float, nargs=6), WORLD, JSON, _flag("--quat", dest="quat")),
    ),
    "joints": Grammar("joints", (NAME,), (WORLD, JSON)),
    "push": Grammar(
        "push",
        (NAME,),
        (
            Opt(("--force",), "force", float, (0, 0, 0), nargs=3),
            Opt(("--torque",), "torque", float, (0, 0, 0), nargs=3),
            Opt(("--link",), "link", str),
            Opt(("--duration",), "duration", float, 0.1),
            WORLD,
            JSON,
        ),
    ),
    "gravity": Grammar(
        "gravity",
        opts=(
            *(_flag(f"--{p}", dest=p) for p in ("earth", "moon", "mars", "zero")),
            Opt(("--set",), "set_", float, nargs=3),
            WORLD,
            JSON,
        ),
    ),
    "physics": Grammar(
        "physics",
        opts=(
            Opt(("--step",), "step", float),
            Opt(("--rate",), "rate", float),
            Opt(("--iterations",), "iterations", int),
            Opt(("--threads",), "threads", int),
            _flag("--sleep", dest="sleep"),
            _flag("--no-sleep", dest="no_sleep"),
            Opt(("--sleep-tolerance",), "sleep_tolerance", float),
            WORLD,
            JSON,
        ),
    ),
    "pause": Grammar("pause", opts=(WORLD,)),
    "resume": Grammar("resume", opts=(WORLD,)),
    "step": Grammar("step", (Arg("n", int, False, 1, minimum=1),), (WORLD, JSON)),
    "reset": Grammar("reset", opts=(_flag("--time-only", dest="time_only"), WORLD)),
    "stats": Grammar(
        "stats",
        opts=(
            Opt(("-d", "--duration"), "duration", float),
            _flag("-p", "--plot", dest="plot"),
            WORLD,
            JSON,
        ),
    ),
    "save": Grammar("save", (Arg("file", Path),), (WORLD,)),
    "load": Grammar(
        "load", (Arg("file", Path, required=False),), (WORLD, _flag("--last", dest="last"))
    ),
    "logs": Grammar("logs", opts=(Opt(("-n", "--lines"), "lines", int), WORLD)),
}


class _Decline(Exception):
    """The command line is not one the fast path reads exactly as Typer would."""


def parse(argv: list[str]) -> Call | None:
    """The call `argv` (without the program name) asks for, or None to leave it to Typer."""
    if not argv or argv[0] not in GRAMMARS:
        return None
    grammar = GRAMMARS[argv[0]]
    try:
        values, positionals = _read_options(grammar, argv[1:])
        values.update(_read_args(grammar, positionals))
    except _Decline:
        return None
    if values.get("world") is None and any(o.dest == "world" for o in grammar.opts):
        values["world"] = os.environ.get(WORLD_ENV) or "default"
    return Call(grammar.action, values)


def _read_options(grammar: Grammar, tokens: list[str]) -> tuple[dict[str, Any], list[str]]:
    """Option values by keyword (defaults for those not given) and the positional tokens."""
    by_flag = {flag: opt for opt in grammar.opts for flag in opt.flags}
    values: dict[str, Any] = {opt.dest: opt.default for opt in grammar.opts}
    positionals: list[str] = []
    rest = list(tokens)
    while rest:
        token = rest.pop(0)
        if not token.startswith("-") or token == "-":
            positionals.append(token)
            continue
        flag, eq, inline = token.partition("=")
        opt = by_flag.get(flag if flag.startswith("--") else token)
        if opt is None or (eq and (opt.convert is None or opt.nargs != 1)):
            raise _Decline
        if opt.convert is None:
            values[opt.dest] = True
            continue
        raw = [inline] if eq else _take(rest, opt.nargs)
        value = _convert(opt.convert, raw, opt.nargs)
        values[opt.dest] = [*(values[opt.dest] or []), value] if opt.multiple else value
    return values, positionals


def _take(rest: list[str], count: int) -> list[str]:
    if len(rest) < count:
        raise _Decline
    taken = rest[:count]
    del rest[:count]
    return taken


def _convert(convert: Callable[[str], Any], raw: list[str], nargs: int) -> Any:
    try:
        values = tuple(convert(text) for text in raw)
    except ValueError:
        raise _Decline from None
    return values if nargs > 1 else values[0]


def _read_args(grammar: Grammar, tokens: list[str]) -> dict[str, Any]:
    if len(tokens) > len(grammar.args):
        raise _Decline
    values: dict[str, Any] = {}
    for i, arg in enumerate(grammar.args):
        if i >= len(tokens):
            if arg.required:
                raise _Decline
            values[arg.dest] = arg.default
            continue
        value = _convert(arg.convert, [tokens[i]], 1)
        if arg.minimum is not None and value < arg.minimum:
            raise _Decline
        values[arg.dest] = value
    return values


def run(argv: list[str]) -> bool:
    """Runs `argv` on the fast path; False when it is left to the Typer app.

    A value the action refuses (BadOption, raised before any request) is left to Typer too, which
    refuses it again and prints the usage message.
    """
    call = parse(argv)
    if call is None:
        return False
    from twin_cli.cli import pairs, world_actions

    try:
        getattr(world_actions, call.action)(**call.kwargs)
    except pairs.BadOption:
        return False
    return True
