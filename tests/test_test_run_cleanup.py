"""Interrupting the test run (Ctrl-C, SIGTERM) leaves no world server behind (tests/reaper.py)."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from corpus_registry import REPO_ROOT
from reaper import processes_with
from signal_state import signal_state

READY_TIMEOUT_S = 90.0  # [s] the inner run starts pytest, then a world (imports mujoco)
GONE_TIMEOUT_S = 20.0  # [s] the reaper's SIGTERM grace is 5 s
# A test run that starts a world in the background, as `twin spawn` does, then waits forever.
INNER_TEST = """
import subprocess, sys, time
from pathlib import Path

BALL = ('<sdf version="1.6"><model name="b"><link name="l"><collision name="c"><geometry>'
        '<sphere><radius>0.1</radius></sphere></geometry></collision></link></model></sdf>')

def test_starts_a_world_and_hangs():
    subprocess.run([sys.executable, "-m", "twin_cli", "spawn", "--xml", BALL], check=True)
    Path("ready").write_text("ready")
    time.sleep(600)
"""


def _inner_run(tmp_path: Path) -> tuple[subprocess.Popen, Path]:
    runtime = tmp_path / "rt"
    runtime.mkdir(mode=0o700)
    (tmp_path / "test_inner.py").write_text(INNER_TEST)
    env = {
        **os.environ,
        "TWIN_RUNTIME_DIR": str(runtime),
        "TWIN_WORLD": "interrupted",
        "PYTHONPATH": os.pathsep.join([str(REPO_ROOT), str(REPO_ROOT / "tests")]),
    }
    inner = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "pytest",
            "-q",
            "-p",
            "reaper",
            "-p",
            "no:cacheprovider",
            "--rootdir",
            str(tmp_path),
            "test_inner.py",
        ],
        cwd=tmp_path,
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        start_new_session=True,  # its own process group, as a terminal's foreground job
    )
    deadline = time.monotonic() + READY_TIMEOUT_S
    while not (tmp_path / "ready").exists():
        assert inner.poll() is None, f"the inner run ended early (exit {inner.returncode})"
        assert time.monotonic() < deadline, "the inner run never started its world"
        time.sleep(0.1)
    return inner, runtime


@pytest.mark.parametrize(
    "how", ["ctrl-c", "sigterm"], ids=["ctrl-c to the process group", "sigterm to pytest"]
)
def test_an_interrupted_run_leaves_no_twin_process(tmp_path: Path, how: str) -> None:
    inner, runtime = _inner_run(tmp_path)
    marker = ("TWIN_RUNTIME_DIR", str(runtime))
    assert processes_with(*marker), "the inner run's world runs before the interrupt"
    if how == "ctrl-c":
        os.killpg(inner.pid, signal.SIGINT)  # what a terminal sends its foreground job
    else:
        inner.send_signal(signal.SIGTERM)  # what make sends the command it runs
    try:
        inner.wait(timeout=60)
    except subprocess.TimeoutExpired:
        state = signal_state(inner.pid)  # what it was doing, before the kill below ends it
        os.killpg(inner.pid, signal.SIGKILL)
        inner.wait()
        pytest.fail(f"{how}: the inner run still running 60 s after the signal: {state}")
    deadline = time.monotonic() + GONE_TIMEOUT_S
    while processes_with(*marker) and time.monotonic() < deadline:
        time.sleep(0.1)
    left = processes_with(*marker)
    for pid in left:  # do not leave them to the outer run either
        os.kill(pid, signal.SIGKILL)
    assert not left, f"{how}: processes of the interrupted run still alive: {left}"
