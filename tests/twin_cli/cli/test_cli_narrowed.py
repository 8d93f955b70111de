"""`app.narrowed`: a run builds only the click command it runs, and that command is the same one
the whole app would build (its parameters, help and usage), so nothing a user sees changes."""

from __future__ import annotations

import warnings

import pytest

with warnings.catch_warnings():  # typer's own import of click's deprecated names
    warnings.simplefilter("ignore", DeprecationWarning)
    import typer.main

from twin_cli.cli.app import build_app, narrowed


def _click(app):
    return typer.main.get_command(app)


def _described(command) -> list:
    """What a user meets of a click command: its help and every parameter's form."""
    params = [
        (p.name, tuple(p.opts), p.required, repr(p.default), getattr(p, "help", None))
        for p in command.params
    ]
    subcommands = getattr(command, "commands", {})
    return [command.help, params, {n: _described(c) for n, c in sorted(subcommands.items())}]


def _names() -> list[str]:
    app = build_app()
    return [c.name for c in app.registered_commands if c.name] + [
        g.name for g in app.registered_groups if g.name
    ]


@pytest.mark.parametrize("name", _names())
def test_a_narrowed_app_holds_one_command_the_same_as_the_whole_app(name: str) -> None:
    whole = _click(build_app())
    alone = _click(narrowed(build_app(), [name, "--json"]))
    assert list(alone.commands) == [name]
    assert _described(alone.commands[name]) == _described(whole.commands[name])


@pytest.mark.parametrize("argv", [[], ["--help"], ["no-such-command"], ["version"]])
def test_help_and_unknown_names_keep_the_whole_app(argv: list[str]) -> None:
    assert set(_click(narrowed(build_app(), argv)).commands) == set(_click(build_app()).commands)
