"""The error of a sweep input that cannot run, raised by both the sweep and its executors."""

from __future__ import annotations

from twin_cli.errors import TwinError


class SweepError(TwinError):
    """A `--sweep`, `--jobs` or `--ray` value that cannot run; the message names the fix."""

    def __init__(self, given: str, problem: str, fix: str) -> None:
        super().__init__(f"{given}: {problem}; {fix}")
        self.given = given
