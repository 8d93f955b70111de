"""Options shared by several commands, defined once (Gazebo's names where Gazebo has them).

The world commands' parameters are plain declarations (`registry`, `params`: for the fast path);
`annotation` turns one of them into the `Annotated[type, typer.Option(...)]` Typer reads, so the
options other command modules share (--world, --json, --arg, --package, -J) come from `params`.
"""

from __future__ import annotations

import inspect
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Annotated, Any

import typer

from twin_cli.cli import pairs, params, registry


def _kind(param: registry.Arg | registry.Opt) -> Any:
    """The Python type Typer infers the click type from: bool, a tuple, a list, or Optional."""
    if isinstance(param, registry.Opt) and param.convert is None:
        return bool
    kind: Any = param.convert
    if isinstance(param, registry.Opt) and param.nargs > 1:
        kind = tuple[(kind,) * param.nargs]
    if isinstance(param, registry.Opt) and param.multiple:
        kind = list[kind]
    return kind | None if param.default is None else kind


def annotation(param: registry.Arg | registry.Opt) -> Any:
    """`Annotated[type, typer.Option(...)]` (or `typer.Argument`) for a table parameter."""
    if isinstance(param, registry.Arg):
        return Annotated[_kind(param), typer.Argument(help=param.help, min=param.minimum)]
    info = typer.Option(*param.flags, help=param.help, envvar=param.envvar)
    return Annotated[_kind(param), info]


def parameter(param: registry.Arg | registry.Opt) -> inspect.Parameter:
    """A keyword-only parameter of a command function's signature, as Typer reads it."""
    required = isinstance(param, registry.Arg) and param.required
    default = inspect.Parameter.empty if required else param.default
    kind = inspect.Parameter.KEYWORD_ONLY
    return inspect.Parameter(param.dest, kind, default=default, annotation=annotation(param))


JsonOpt = annotation(params.JSON)
WorldOpt = annotation(params.WORLD)
ArgOpt = annotation(params.ARG)
PackageOpt = annotation(params.PACKAGE)
JointOpt = annotation(params.JOINT)
FixedBaseOpt = annotation(params.FIXED_BASE)
CoacdCpuLimitOpt = annotation(params.COACD_CPU_LIMIT)


def parse_pairs(items: list[str] | None, sep: str, what: str) -> dict[str, str]:
    """`pairs.parse_pairs`, with a bad item reported as Typer's usage error (exit code 2)."""
    with usage_errors():
        return pairs.parse_pairs(items, sep, what)


def joint_positions(items: list[str] | None) -> dict[str, float]:
    """`pairs.joint_positions` (`-J NAME=POS`), a bad item reported as a usage error."""
    with usage_errors():
        return pairs.joint_positions(items)


def source_inputs(arg: list[str] | None, package: list[str] | None) -> dict[str, dict[str, str]]:
    """`pairs.source_inputs` (`--arg`, `--package`), a bad item reported as a usage error."""
    with usage_errors():
        return pairs.source_inputs(arg, package)


@contextmanager
def usage_errors() -> Iterator[None]:
    """Turns BadOption into typer.BadParameter (click's "Invalid value: ..." usage error).

    Only a wording: `app.main` prints a BadOption as a usage error (exit code 2) without it.
    """
    try:
        yield
    except pairs.BadOption as exc:
        raise typer.BadParameter(str(exc)) from None
