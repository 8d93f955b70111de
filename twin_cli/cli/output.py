"""One output sink per command: rich tables for people, JSON with --json, plain text when piped."""

from __future__ import annotations

import json
import sys
from collections.abc import Sequence
from typing import Any


def _default(obj: Any) -> Any:
    """JSON fallback for numpy scalars/arrays, paths and enums."""
    if hasattr(obj, "tolist"):
        return obj.tolist()
    if hasattr(obj, "value"):
        return obj.value
    return str(obj)


class Output:
    """Chosen once per command: `Output(json_mode)`; every printing call goes through it.

    Human mode on a terminal uses rich; human mode into a pipe prints tab-separated plain text,
    so `twin list | cut -f1` works. Either prints a missing value (None) as `-`. JSON mode
    prints exactly one JSON document per `data` call.
    """

    def __init__(self, json_mode: bool = False, stream: Any = None) -> None:
        self.json_mode = json_mode
        self.stream = stream or sys.stdout
        self.is_tty = bool(getattr(self.stream, "isatty", lambda: False)())

    def data(self, obj: Any) -> None:
        """Print a JSON document (JSON mode) — callers in human mode use table/line instead."""
        self.stream.write(json.dumps(obj, indent=2, default=_default, sort_keys=False) + "\n")
        self.stream.flush()

    def line(self, text: str) -> None:
        """One line of plain text (suppressed in JSON mode)."""
        if not self.json_mode:
            self.stream.write(text + "\n")
            self.stream.flush()

    def table(self, title: str, columns: Sequence[str], rows: Sequence[Sequence[Any]]) -> None:
        """A table: rich on a terminal, tab-separated lines (with a header) when piped."""
        if self.json_mode:
            return
        if self.is_tty:
            from rich.console import Console
            from rich.table import Table

            table = Table(title=title)
            for col in columns:
                table.add_column(str(col))
            for row in rows:
                table.add_row(*(cell(v) for v in row))
            Console(file=self.stream).print(table)
        else:
            self.stream.write("\t".join(str(c) for c in columns) + "\n")
            for row in rows:
                self.stream.write("\t".join(cell(v) for v in row) + "\n")
            self.stream.flush()


MISSING = "-"  # a cell without a value, as `gz` and `ros2` tables print one (JSON keeps null)


def cell(value: Any) -> str:
    """A table cell: floats to 6 significant digits, a missing value (None) as MISSING."""
    if value is None:
        return MISSING
    if isinstance(value, float):
        return f"{value:.6g}"
    return str(value)


DISTRIBUTION = "twin"  # pyproject.toml's [project] name, the one importlib.metadata knows


def print_version() -> None:
    """Print `twin VERSION`: the installed distribution's version (`twin --version`)."""
    from importlib.metadata import version

    sys.stdout.write(f"twin {version(DISTRIBUTION)}\n")


def error(message: str) -> None:
    """Print one error message to stderr (the CLI boundary's only printer of errors)."""
    sys.stderr.write(f"Error: {message}\n")
    sys.stderr.flush()
