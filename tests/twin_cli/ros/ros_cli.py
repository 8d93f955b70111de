"""What the served-world ROS tests share: `twin` commands and peer scripts run as their own
processes, in the test module's runtime folder and DDS domain, with the discovery variables of
the shell that started the tests removed (so a developer's ROS setup cannot change a result)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

SCOPE = ("TWIN_WORLD", "ROS_AUTOMATIC_DISCOVERY_RANGE", "ROS_STATIC_PEERS")


def ros_env(runtime: Path, domain: str) -> dict[str, str]:
    """This process's environment for a command against the world in `runtime`, in `domain`."""
    env = {**os.environ, "TWIN_RUNTIME_DIR": str(runtime), "ROS_DOMAIN_ID": domain}
    for name in SCOPE:
        env.pop(name, None)
    return env


def twin_ok(runtime: Path, domain: str, world: str, *args: str) -> str:
    """`twin ARGS --world WORLD`'s stdout; fails the test on a non-zero exit."""
    proc = subprocess.run(
        [sys.executable, "-m", "twin_cli", *args, "--world", world],
        env=ros_env(runtime, domain), capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert proc.returncode == 0, f"twin {' '.join(args)}: {proc.returncode} {proc.stderr}"
    return proc.stdout


def script_json(script: Path, runtime: Path, domain: str, *args: str) -> dict:
    """A peer script's JSON document on stdout; fails the test on a non-zero exit."""
    proc = subprocess.run(
        [sys.executable, str(script), *args],
        env=ros_env(runtime, domain), capture_output=True, text=True, timeout=180,
    )  # fmt: skip
    assert proc.returncode == 0, f"{script.name} {' '.join(args)}: {proc.stderr[-2000:]}"
    return json.loads(proc.stdout)
