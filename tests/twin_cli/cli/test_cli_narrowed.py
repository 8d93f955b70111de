"""`app.narrowed`: a run builds only the click command it runs, and that command is the same one
the whole app would build (its help page and usage errors), so nothing a user sees changes."""

from __future__ import annotations

import warnings
from typing import Any, cast

import pytest

with warnings.catch_warnings():  # typer's own import of click's deprecated names
    warnings.simplefilter("ignore", DeprecationWarning)
    import click
    import typer.main
    from typer.testing import CliRunner

from twin_cli.cli import app as cli_app
from twin_cli.cli.app import build_app, narrowed

WIDE = {"COLUMNS": "100", "TERM": "dumb"}  # one page width for both renderings


def _click(app: Any) -> click.Group:
    return cast(click.Group, typer.main.get_command(app))


def _names() -> list[str]:
    app = build_app()
    return [c.name for c in app.registered_commands if c.name] + [
        g.name for g in app.registered_groups if g.name
    ]


def _seen(app: Any, argv: list[str]) -> tuple[int, str]:
    """Exit code and output of `twin ARGV` on `app`, as a terminal 100 columns wide shows it."""
    result = CliRunner().invoke(app, argv, env=WIDE, prog_name="twin")
    return result.exit_code, result.output


@pytest.mark.parametrize("name", _names())
def test_a_narrowed_app_holds_one_command_that_reads_the_same_as_the_whole_apps(name: str) -> None:
    alone = narrowed(build_app(), [name, "--json"])
    assert list(_click(alone).commands) == [name]
    for argv in ([name, "--help"], [name, "--no-such-option"]):
        assert _seen(alone, argv) == _seen(build_app(), argv), argv


@pytest.mark.parametrize("argv", [[], ["--help"], ["no-such-command"]])
def test_help_and_unknown_names_keep_the_whole_app(argv: list[str]) -> None:
    assert set(_click(narrowed(build_app(), argv)).commands) == set(_click(build_app()).commands)


def test_a_run_builds_only_its_own_command(monkeypatch: pytest.MonkeyPatch, capsys) -> None:
    """Counts the click commands Typer builds while `twin cache info --json` runs in process."""
    built: list[str] = []
    build = typer.main.get_command_from_info

    def counted(command_info: Any, **kwargs: Any) -> Any:
        built.append(command_info.name or command_info.callback.__name__)
        return build(command_info, **kwargs)

    monkeypatch.setattr(typer.main, "get_command_from_info", counted)
    cli_app._run_app(["cache", "info", "--json"])
    assert '"entries"' in capsys.readouterr().out
    assert built == ["info", "clear"], built  # the cache group's two, of the app's 35
