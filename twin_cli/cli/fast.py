"""The fast path: world commands parsed without Typer; anything unusual goes to the Typer app.

A world command is one small request, yet importing typer (with click: 56 ms, `-X importtime`)
and building the app with every command module cost more than the request and Python's start-up
together; `twin gravity --moon` takes 115 ms median wall on the fast path (339 ms before, with
httpx; `benchmarks/bench_server.py`).
This module reads the options each command declares in the registry (`registry.world_commands`,
from which the Typer commands are built too), for the plain forms people and scripts type
(`--opt VALUE`, `--opt=VALUE`, flags, positionals in any order), and calls the command's
function. It *declines*
(returns None) whenever Typer would do anything else: `--help`, an unknown or clustered option, a
missing or extra argument, a value that does not convert, so help and click's usage errors come
from Typer itself. A value the action refuses (BadOption) reaches `app.main`'s error boundary.
`tests/twin_cli/cli/test_cli_fast.py` checks this grammar against the Typer app's parses.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from twin_cli.cli.registry import Command, Opt, world_commands


@dataclass(frozen=True)
class Call:
    """A parsed command line: the command's function and its keyword arguments."""

    action: Callable[..., None]
    kwargs: dict[str, Any]


class _Decline(Exception):
    """The command line is not one the fast path reads exactly as Typer would."""


def parse(argv: list[str]) -> Call | None:
    """The call `argv` (without the program name) asks for, or None to leave it to Typer."""
    commands = world_commands()
    if not argv or argv[0] not in commands:
        return None
    command = commands[argv[0]]
    try:
        values, positionals = _read_options(command, argv[1:])
        values.update(_read_args(command, positionals))
    except _Decline:
        return None
    return Call(command.action, values)


def _initial(opt: Opt) -> Any:
    """An option's value when it is not given: its environment variable (if set), else default.

    An empty variable counts as unset, as click reads it.
    """
    return (opt.envvar and os.environ.get(opt.envvar)) or opt.default


def _read_options(command: Command, tokens: list[str]) -> tuple[dict[str, Any], list[str]]:
    """Option values by keyword (defaults for those not given) and the positional tokens."""
    by_flag = {flag: opt for opt in command.opts for flag in opt.flags}
    values: dict[str, Any] = {opt.dest: _initial(opt) for opt in command.opts}
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


def _read_args(command: Command, tokens: list[str]) -> dict[str, Any]:
    if len(tokens) > len(command.args):
        raise _Decline
    values: dict[str, Any] = {}
    for i, arg in enumerate(command.args):
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

    A value the action refuses (BadOption, raised before any request) propagates to the error
    boundary in `app.main`, which prints it as a usage error (exit code 2).
    """
    call = parse(argv)
    if call is None:
        return False
    call.action(**call.kwargs)
    return True
