"""The last-resort boundary: an unexpected exception is one line, a traceback file, exit 70."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

from twin_cli.cli.app import _internal_error


def test_an_unexpected_error_is_one_line_naming_its_traceback_file() -> None:
    try:
        {}["missing"]
    except KeyError as exc:
        line = _internal_error(exc)
    assert "\n" not in line and line.startswith("internal error: KeyError"), line
    path = Path(re.search(r"traceback is in (\S+) ", line).group(1))
    text = path.read_text()
    assert "Traceback" in text and "KeyError: 'missing'" in text, text
    assert path.stat().st_mode & 0o077 == 0, "private to the user"
    path.unlink()


def test_version_flag() -> None:
    proc = subprocess.run(
        [sys.executable, "-m", "twin_cli", "--version"], capture_output=True, text=True, timeout=60
    )
    assert proc.returncode == 0 and re.fullmatch(r"twin \d+\.\d+\.\d+\n", proc.stdout), proc
