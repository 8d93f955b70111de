"""`twin --version` and every command's `--help`, as a user at an 80-column terminal reads them.

Each case runs the real entry point (`python -m twin_cli`). The list of commands comes from the
Typer app, so a command added later is covered too. A help line is broken mid-sentence when the
next line's first word would have fitted at its end: rich wraps at the width, so only a line
break written into the help text leaves such a gap.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from importlib.metadata import version

import pytest
import typer

from twin_cli.cli.app import build_app
from twin_cli.cli.output import DISTRIBUTION

COLUMNS = 80  # the terminal width the help is rendered for
PROSE_WIDTH = COLUMNS - 2  # rich's help prose: one space of margin on each side
BOX = "│╭╰"  # a panel's first character: its rows are checked apart
HEAVY = ("mujoco", "numpy", "trimesh", "coacd", "fastapi", "uvicorn", "scipy")
FRAMEWORK = ("typer", "click", "rich", "httpx")


def _twin(*args: str, importtime: bool = False) -> subprocess.CompletedProcess:
    env = {**os.environ, "COLUMNS": str(COLUMNS), "TERM": "dumb"}
    flags = ["-X", "importtime"] if importtime else []
    return subprocess.run(
        [sys.executable, *flags, "-m", "twin_cli", *args],
        env=env,
        capture_output=True,
        text=True,
        timeout=60,
    )


def _command_paths() -> list[list[str]]:
    """Every command and group of the app, as the words that name it (the app itself: [])."""
    root = typer.main.get_command(build_app())
    paths: list[list[str]] = []

    def walk(command, path: list[str]) -> None:  # noqa: ANN001
        paths.append(path)
        for name, sub in sorted(getattr(command, "commands", {}).items()):
            walk(sub, [*path, name])

    walk(root, [])
    return paths


def test_version_flag_prints_the_installed_distributions_version_without_heavy_imports():
    proc = _twin("--version", importtime=True)
    assert proc.returncode == 0, proc.stderr[-500:]
    assert proc.stdout == f"twin {version(DISTRIBUTION)}\n"
    names = set(re.findall(r"^import time:\s+\d+ \|\s+\d+ \|\s*([\w.]+)", proc.stderr, re.M))
    top = {n.split(".")[0] for n in names}
    assert not top & set(HEAVY + FRAMEWORK), f"imported {sorted(top & set(HEAVY + FRAMEWORK))}"


def test_version_flag_is_listed_in_the_apps_help_and_read_by_typer_too():
    help_text = _twin("--help").stdout
    assert re.search(r"--version\s+Print twin's version and exit\.", help_text), help_text
    proc = _twin("--version", "--help")  # not the fast form: Typer reads it, eagerly
    assert proc.returncode == 0 and proc.stdout == f"twin {version(DISTRIBUTION)}\n", proc


def _prose_breaks(text: str) -> list[str]:
    """Pairs of prose lines (outside the boxes) where the second's first word fitted above."""
    lines = text.splitlines()
    found = []
    for above, below in zip(lines, lines[1:], strict=False):
        if not (above.strip() and below.strip()) or "Usage:" in above:
            continue
        if above.lstrip()[0] in BOX or below.lstrip()[0] in BOX:
            continue
        word = below.split()[0]
        if len(above.rstrip()) + 1 + len(word) <= PROSE_WIDTH:
            found.append(f"{above.rstrip()!r} / {below.strip()!r}")
    return found


def _command_list_breaks(text: str) -> list[str]:
    """The same in a Commands panel: a description continued below though its word fitted."""
    panel = re.search(r"╭─ Commands ─.*?╰", text, re.S)
    if panel is None:
        return []
    rows = [line[2:-2] for line in panel.group(0).splitlines()[1:-1]]  # inside "│ " and " │"
    found = []
    for above, below in zip(rows, rows[1:], strict=False):
        continuation = re.match(r"^(\s+)(\S+)", below)
        if continuation is None:
            continue
        width = len(above)
        if len(above.rstrip()) + 1 + len(continuation.group(2)) <= width:
            found.append(f"{above.strip()!r} / {below.strip()!r}")
    return found


@pytest.mark.parametrize("path", _command_paths(), ids=lambda p: " ".join(p) or "twin")
def test_help_is_not_broken_mid_sentence_at_80_columns(path):
    proc = _twin(*path, "--help")
    assert proc.returncode == 0, proc.stderr[-500:]
    breaks = _prose_breaks(proc.stdout) + _command_list_breaks(proc.stdout)
    assert not breaks, "line breaks written into the help text:\n" + "\n".join(breaks)
