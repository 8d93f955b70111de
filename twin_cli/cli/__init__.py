"""The `twin` command line: the Typer app, one module per command group, and one output sink.

Commands are thin: they declare options, call one function of `server`, `validate` or
`converters`, and hand the result to `output`. Nothing heavy is imported at module top.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from twin_cli.lazy import lazy_getattr

if TYPE_CHECKING:
    from twin_cli.cli.app import app, main

__all__ = ["app", "main"]

__getattr__ = lazy_getattr("twin_cli.cli", {"app": "twin_cli.cli.app", "main": "twin_cli.cli.app"})
