"""The fast path reads world commands exactly as the Typer app does, or leaves them to it.

Both are built from one registry (`twin_cli.cli.registry`); these tests hold the two builders to
the same grammar, parse for parse.
"""

from __future__ import annotations

import os
import random
import subprocess
import sys
from pathlib import Path
from typing import Any

import click
import pytest
import typer

from twin_cli.cli.app import app
from twin_cli.cli.fast import parse
from twin_cli.cli.registry import Command, world_commands

GROUP = typer.main.get_command(app)
TABLE = world_commands()
WORLD_GROUP_COMMANDS = [c.name for c in app.registered_commands if c.name in TABLE]
SAMPLE = {float: "-1.5", int: "7", str: "name_1", Path: "robot.urdf"}


def _click_kind(param: click.Parameter) -> tuple:
    """(convert, nargs, minimum) of a click parameter, in the fast grammar's terms."""
    kind = param.type
    if isinstance(kind, click.Tuple):
        return (_KINDS[type(kind.types[0])], param.nargs, None)
    if isinstance(kind, click.IntRange):
        return (int, 1, kind.min)
    if isinstance(kind, click.Path):
        return (Path, 1, None)
    if isinstance(param, click.Option) and param.is_flag:
        return (None, 1, None)
    return (_KINDS[type(kind)], 1, None)


_KINDS = {click.types.FloatParamType: float, click.types.IntParamType: int}
_KINDS[click.types.StringParamType] = str


def _typer_grammar(name: str) -> dict[str, tuple]:
    """dest → (kind, nargs, min, flags, default, multiple, required, envvar) as Typer declares."""
    out = {}
    for p in GROUP.commands[name].params:
        convert, nargs, minimum = _click_kind(p)
        flags = tuple(p.opts) if isinstance(p, click.Option) else ()
        default = None if p.multiple else p.default
        out[p.name] = (convert, nargs, minimum, flags, default, p.multiple, p.required, p.envvar)
    return out


def _fast_grammar(spec: Command) -> dict[str, tuple]:
    out = {}
    for a in spec.args:
        out[a.dest] = (a.convert, 1, a.minimum, (), a.default, False, a.required, None)
    for o in spec.opts:
        out[o.dest] = (o.convert, o.nargs, None, o.flags, o.default, o.multiple, False, o.envvar)
    return out


def test_the_typer_app_holds_every_registered_world_command_in_help_order() -> None:
    assert WORLD_GROUP_COMMANDS == list(TABLE), "`twin --help` order or a command is missing"


@pytest.mark.parametrize("name", sorted(TABLE))
def test_fast_grammar_declares_the_typer_commands_options(name: str) -> None:
    fast, declared = _fast_grammar(TABLE[name]), _typer_grammar(name)
    assert fast == declared, f"`twin {name}`: fast {fast} != Typer {declared}"


def _normal(value: Any) -> Any:
    """Typer hands lists where click has tuples, Paths where click has text; compare as text."""
    if isinstance(value, list | tuple):
        return tuple(_normal(v) for v in value) or None
    return str(value) if isinstance(value, Path) else value


def _typer_parse(argv: list[str]) -> dict[str, Any]:
    """What the Typer app's parser makes of `argv` (raises click.UsageError if it refuses it)."""
    command = GROUP.commands[argv[0]]
    with command.make_context(argv[0], list(argv[1:])) as ctx:
        return {k: _normal(v) for k, v in ctx.params.items()}


def _full_argv(name: str, rng: random.Random) -> list[str]:
    """`twin NAME` with every argument and option given, options in random order."""
    spec = TABLE[name]
    words = [SAMPLE[a.convert] for a in spec.args]
    for opt in spec.opts:
        flag = rng.choice(opt.flags)
        if opt.convert is None:
            words.append(flag)
            continue
        values = [SAMPLE[opt.convert]] * opt.nargs
        inline = opt.nargs == 1 and flag.startswith("--") and rng.random() < 0.3
        words.append(f"{flag}={values[0]}" if inline else [flag, *values])
    rng.shuffle(words)
    flat = [w for item in words for w in (item if isinstance(item, list) else [item])]
    return [name, *flat]


READ = [
    ["gravity", "--moon"],
    ["gravity", "--set", "0", "0", "-1.62", "--world", "w"],
    ["gravity", "--moon", "--earth"],  # both parse it; the command then refuses it (exit 2)
    ["stats", "-d", "0"],
    ["stats", "-p", "--duration=2", "--json"],
    ["list"],
    ["list", "--world=other", "--json"],
    ["spawn", "r.urdf", "-z", "-1", "-J", "a=1", "-J", "b=2", "--arg", "x:=1"],
    ["spawn", "-x", "1", "r.urdf", "--on-ground"],
    ["pose", "box", "--set", "1", "2", "3", "0", "0", "-1e-3"],
    ["step"],
    ["step", "20"],
    ["logs", "-n", "5"],
    ["push", "box", "--force", "1", "2", "3", "--force", "4", "5", "6"],  # the last one wins
]
# Left to Typer: help, clustered or attached short options, unknown options, bad values, wrong
# argument counts (Typer reads some of these, refuses the others with a usage error).
LEFT_TO_TYPER = [
    ["gravity", "--help"],
    ["stats", "-pd", "1"],
    ["stats", "-d1"],
    ["step", "0"],
    ["step", "-5"],
    ["step", "two"],
    ["pose"],
    ["pose", "a", "b"],
    ["pose", "box", "--set", "1", "2"],
    ["gravity", "--moon=yes"],
    ["list", "--", "x"],
    ["physics", "--iterations", "1.5"],
    ["delete", "box", "--nope"],
    ["version"],
    ["convert", "r.urdf"],
]


@pytest.mark.parametrize("argv", READ, ids=" ".join)
def test_fast_path_reads_a_command_line_as_typer_does(
    argv: list[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.delenv("TWIN_WORLD", raising=False)
    call = parse(argv)
    assert call is not None, f"fast path declined {argv}"
    assert {k: _normal(v) for k, v in call.kwargs.items()} == _typer_parse(argv), f"twin {argv}"


@pytest.mark.parametrize("argv", LEFT_TO_TYPER, ids=" ".join)
def test_fast_path_leaves_help_and_unusual_command_lines_to_typer(argv: list[str]) -> None:
    assert parse(argv) is None, f"fast path should leave {argv} to Typer"


@pytest.mark.parametrize("name", sorted(TABLE))
def test_fast_path_reads_every_option_of_every_command_as_typer_does(
    name: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("TWIN_WORLD", "from_env")
    rng = random.Random(name)
    for _ in range(20):
        argv = _full_argv(name, rng)
        call = parse(argv)
        assert call is not None, f"fast path declined {argv}"
        fast = {k: _normal(v) for k, v in call.kwargs.items()}
        assert fast == _typer_parse(argv), f"twin {argv}"
    bare = [name, *(SAMPLE[a.convert] for a in TABLE[name].args if a.required)]
    call = parse(bare)
    assert call is not None and _typer_parse(bare) == {
        k: _normal(v) for k, v in call.kwargs.items()
    }, f"defaults of `twin {name}` ($TWIN_WORLD={os.environ['TWIN_WORLD']})"


def _twin(*args: str, runtime_dir: Path) -> subprocess.CompletedProcess:
    env = {**os.environ, "TWIN_RUNTIME_DIR": str(runtime_dir)}
    return subprocess.run(
        [sys.executable, "-m", "twin_cli.cli.app", *args],
        env=env,
        capture_output=True,
        text=True,
        timeout=60,
    )


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["gravity", "--moon", "--earth"], "give one of --earth, --moon"),
        (["spawn", "robot.urdf", "-J", "lead"], "must look like NAME=VALUE"),
        (["spawn", "robot.urdf", "-J", "lead=half"], "is not a number"),
        (["step", "0"], "0 is not in the range"),
        (["physics", "--sleep", "--no-sleep"], "give --sleep or --no-sleep, not both"),
    ],
)
def test_a_value_the_command_refuses_is_a_usage_error_with_exit_code_2(
    args: list[str], message: str, tmp_path: Path
) -> None:
    proc = _twin(*args, runtime_dir=tmp_path)
    assert proc.returncode == 2, f"twin {args}: exit {proc.returncode}, {proc.stderr}"
    assert "Usage:" in proc.stderr and message in proc.stderr, proc.stderr
    assert not (tmp_path / "default.sock").exists(), "a usage error must not start a world"


def test_help_still_comes_from_typer(tmp_path: Path) -> None:
    for args in (["--help"], ["spawn", "--help"], ["gravity", "--help"]):
        proc = _twin(*args, runtime_dir=tmp_path)
        assert proc.returncode == 0 and "Usage:" in proc.stdout, f"twin {args}: {proc}"
    assert "-J" in _twin("spawn", "--help", runtime_dir=tmp_path).stdout, "spawn's options listed"
