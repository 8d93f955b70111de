"""The world commands' registry: each command is its function, declared where it is defined.

A world command (a verb on a running world, as `twin pause`) is a keyword-only function in a
module of `twin_cli.cli.world_commands`, decorated with `command(name, *params, help=...)`.
`world_commands()` imports every module of that package (no list to edit) and returns what
they registered, by reference: go-to-definition on a registered action lands on its code.
Plain Python (stdlib only), so the fast path (`fast.py`) reads the declarations without
importing Typer, and `commands/world.py` builds the Typer commands (help, usage errors) from
the same entries. Parameters are listed in `--help` order; `dest` is the keyword the function
takes.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import cache
from typing import Any, TypeVar

from twin_cli.lazy import import_modules

PACKAGE = "twin_cli.cli.world_commands"  # every module in it is imported by `world_commands`

Action = TypeVar("Action", bound=Callable[..., None])


@dataclass(frozen=True)
class Opt:
    """An option: its flags, the keyword it fills, how a value converts (None: a bool flag)."""

    flags: tuple[str, ...]
    dest: str
    help: str
    convert: type | None = None
    default: Any = None
    nargs: int = 1
    multiple: bool = False
    envvar: str | None = None  # read when the option is not given (Typer's `envvar=`)


@dataclass(frozen=True)
class Arg:
    """A positional argument; `minimum` bounds an int (Typer's `min=`)."""

    dest: str
    help: str
    convert: type
    required: bool = True
    default: Any = None
    minimum: int | None = None


def flag(*flags: str, dest: str, help: str) -> Opt:
    """A bool option, off unless given."""
    return Opt(flags, dest, help, None, False)


@dataclass(frozen=True)
class Command:
    """One world command: the function it runs, its help and its parameters."""

    name: str
    action: Callable[..., None]
    help: str
    params: tuple[Arg | Opt, ...] = ()

    @property
    def args(self) -> tuple[Arg, ...]:
        return tuple(p for p in self.params if isinstance(p, Arg))

    @property
    def opts(self) -> tuple[Opt, ...]:
        return tuple(p for p in self.params if isinstance(p, Opt))


_REGISTERED: dict[str, Command] = {}


class DuplicateCommandError(RuntimeError):
    """Two functions registered the same command name (a bug in twin, not bad input)."""

    def __init__(self, name: str, first: Callable[..., None], second: Callable[..., None]) -> None:
        super().__init__(
            f"`twin {name}` is registered twice: by {first.__module__}.{first.__qualname__} "
            f"and {second.__module__}.{second.__qualname__}; rename one"
        )


def command(name: str, *params: Arg | Opt, help: str) -> Callable[[Action], Action]:
    """Registers the decorated function as `twin NAME` with these parameters; returns it as is.

    Raises:
        DuplicateCommandError: another function already registered NAME.
    """

    def register(action: Action) -> Action:
        known = _REGISTERED.get(name)
        if known is not None and known.action is not action:
            raise DuplicateCommandError(name, known.action, action)
        _REGISTERED[name] = Command(name, action, help, params)
        return action

    return register


@cache
def world_commands() -> dict[str, Command]:
    """Every world command, by name, in the order of `twin --help`.

    That order is the package's `ORDER`; a command it does not name follows those it names,
    in the order they were registered (modules are imported alphabetically).
    """
    package = import_modules(PACKAGE)
    rank = {name: i for i, name in enumerate(package.ORDER)}
    return dict(sorted(_REGISTERED.items(), key=lambda item: rank.get(item[0], len(rank))))
