"""`twin` as a user runs it against a served world: a subprocess with the world's runtime folder
and `--world NAME`, the shell's own TWIN_WORLD left out."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path


def twin_in(
    runtime: Path, world: str, *args: str, stdin: str | None = None
) -> subprocess.CompletedProcess:
    """`twin ARGS --world WORLD` with TWIN_RUNTIME_DIR=runtime; its completed process."""
    env = {**os.environ, "TWIN_RUNTIME_DIR": str(runtime)}
    env.pop("TWIN_WORLD", None)
    return subprocess.run(
        [sys.executable, "-m", "twin_cli", *args, "--world", world],
        env=env,
        input=stdin,
        capture_output=True,
        text=True,
        timeout=120,
    )


def twin_ok(runtime: Path, world: str, *args: str, stdin: str | None = None) -> str:
    """`twin_in`, which must exit 0; its stdout."""
    proc = twin_in(runtime, world, *args, stdin=stdin)
    assert proc.returncode == 0, f"twin {' '.join(args)}: {proc.returncode} {proc.stderr}"
    return proc.stdout
