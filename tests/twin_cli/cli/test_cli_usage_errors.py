"""Every world command refuses a bad option or value as a usage error: exit 2, one message.

The cases come from the world command registry, so a command added there is covered here too. Each
runs the real entry point (`python -m twin_cli`) with a private runtime directory, and none may
start a world.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from twin_cli.cli.registry import Arg, Command, Opt, world_commands

TABLE = world_commands()

SAMPLE = {str: "box", Path: "world.twin", int: "3", float: "1.5"}
UNKNOWN = "--no-such-option"


def _required(spec: Command) -> list[str]:
    """Values for the command's required arguments, so that only the bad part is wrong."""
    return [SAMPLE[a.convert] for a in spec.args if a.required]


def _typed(spec: Command) -> Arg | Opt | None:
    """The command's first parameter whose value must be a number, if it has one."""
    return next((p for p in spec.params if p.convert in (int, float)), None)


def _bad_value(name: str, spec: Command, param: Arg | Opt) -> tuple[list[str], str]:
    """A command line giving `param` a word where a number belongs, and the name click shows."""
    if isinstance(param, Arg):  # the only positional number is optional and the last argument
        return [name, *_required(spec), "abc"], f"[{param.dest.upper()}]"
    return [name, *_required(spec), param.flags[-1], *["abc"] * param.nargs], param.flags[-1]


def _cases() -> list[tuple[list[str], str]]:
    """(argv, text the message must hold): per world command an unknown option and a bad value."""
    cases = []
    for name, spec in TABLE.items():
        cases.append(([name, *_required(spec), UNKNOWN], UNKNOWN))
        param = _typed(spec)
        if param is not None:
            cases.append(_bad_value(name, spec, param))
    return cases


# Values the action refuses (BadOption), on the fast path and, after `--`, on the Typer path.
REFUSED = [
    (["physics", "--sleep", "--no-sleep"], "give --sleep or --no-sleep, not both"),
    (["physics", "--sleep", "--no-sleep", "--"], "give --sleep or --no-sleep, not both"),
    (["gravity", "--moon", "--earth"], "give one of --earth, --moon"),
    (["gravity", "--moon", "--earth", "--"], "give one of --earth, --moon"),
    (["load"], "give a FILE written by `twin save`, or --last"),
    (["spawn", "robot.urdf", "-R", "1", "--quat", "0", "0", "0", "1"], "-R/-P/-Y or --quat"),
]


def _twin(args: list[str], runtime_dir: Path) -> subprocess.CompletedProcess:
    env = {**os.environ, "TWIN_RUNTIME_DIR": str(runtime_dir), "COLUMNS": "200"}
    env.pop("TWIN_WORLD", None)
    return subprocess.run(
        [sys.executable, "-m", "twin_cli", *args],
        env=env,
        capture_output=True,
        text=True,
        timeout=60,
    )


def _assert_usage_error(args: list[str], message: str, runtime_dir: Path) -> None:
    proc = _twin(args, runtime_dir)
    said = f"twin {' '.join(args)}: exit {proc.returncode}\n{proc.stderr}"
    assert proc.returncode == 2, said
    assert "Traceback" not in proc.stderr and "internal error" not in proc.stderr, said
    assert message in proc.stderr, f"the message should name {message!r}; {said}"
    assert f"Usage: twin {args[0]}" in proc.stderr, said
    started = sorted(p.name for p in runtime_dir.iterdir()) if runtime_dir.exists() else []
    assert not started, f"a usage error must not start a world: {started}"


CASES = _cases()


@pytest.mark.parametrize(("args", "message"), CASES, ids=[" ".join(a) for a, _ in CASES])
def test_a_bad_option_of_every_world_command_is_a_usage_error(
    args: list[str], message: str, tmp_path: Path
) -> None:
    _assert_usage_error(args, message, tmp_path / "runtime")


@pytest.mark.parametrize(("args", "message"), REFUSED, ids=[" ".join(a) for a, _ in REFUSED])
def test_a_value_the_action_refuses_is_a_usage_error_on_either_path(
    args: list[str], message: str, tmp_path: Path
) -> None:
    _assert_usage_error(args, message, tmp_path / "runtime")


def test_every_world_command_has_a_case() -> None:
    covered = {args[0] for args, _ in CASES}
    assert covered == set(TABLE), f"no usage-error case: {sorted(set(TABLE) - covered)}"
