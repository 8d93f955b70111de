"""No process outlives the test run: servers left by tests are ended, even if pytest is killed.

A pytest plugin (loaded by conftest.py) plus the watcher it starts. The controlling pytest puts
a run id in its environment, so every process a test starts (worlds that `twin spawn` detaches
into a session of their own, their supervisors and recorders) inherits it. At the end of the run
the controller ends every process that carries the id. A watcher in a session of its own polls
the controller's pid; when the controller dies any other way (Ctrl-C, SIGTERM, SIGKILL), the
watcher ends those processes instead. (It polls rather than waits for a pipe to close: a child a
test forks would hold the pipe open after pytest died.)
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
import uuid
from pathlib import Path

RUN_ENV = "TWIN_TEST_RUN"
GRACE_S = 5.0  # [s] SIGTERM first: a world finishes its recording and log, then SIGKILL
POLL_S = 0.2  # [s] how often the watcher looks at the controlling pytest


def processes_with(variable: str, value: str) -> list[int]:
    """Pids of the live processes (other than this one) started with `variable=value`."""
    marker = f"{variable}={value}".encode()
    found = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit() or int(entry.name) == os.getpid():
            continue
        try:
            environ = (entry / "environ").read_bytes()
        except OSError:  # gone meanwhile, or not ours
            continue
        if marker in environ.split(b"\0"):
            found.append(int(entry.name))
    return found


def processes_of(run_id: str) -> list[int]:
    """Pids of the live processes of the test run `run_id`."""
    return processes_with(RUN_ENV, run_id)


def _signal_all(pids: list[int], sig: int) -> None:
    for pid in pids:
        try:
            os.kill(pid, sig)
        except ProcessLookupError:
            pass


def reap(run_id: str) -> list[int]:
    """End every process of the run: SIGTERM, then SIGKILL after `GRACE_S`. Returns their pids."""
    pids = processes_of(run_id)
    _signal_all(pids, signal.SIGTERM)
    deadline = time.monotonic() + GRACE_S
    while time.monotonic() < deadline and processes_of(run_id):
        time.sleep(0.05)
    _signal_all(processes_of(run_id), signal.SIGKILL)
    return pids


def _is_worker(config) -> bool:
    return hasattr(config, "workerinput")  # an xdist worker: its controller owns the run


def pytest_configure(config) -> None:
    if _is_worker(config):
        return
    run_id = uuid.uuid4().hex
    config._twin_reaper_previous = os.environ.get(RUN_ENV)  # a nested run gets its own id
    os.environ[RUN_ENV] = config._twin_reaper_id = run_id
    watcher_env = {k: v for k, v in os.environ.items() if k != RUN_ENV}
    config._twin_reaper = subprocess.Popen(
        [sys.executable, __file__, run_id, str(os.getpid())],
        stdin=subprocess.DEVNULL,
        start_new_session=True,
        env=watcher_env,
    )


def pytest_unconfigure(config) -> None:
    watcher = getattr(config, "_twin_reaper", None)
    if watcher is None:
        return
    left = reap(config._twin_reaper_id)
    if left:
        print(f"\nreaper: ended {len(left)} process(es) that tests left running: {left}")
    watcher.terminate()  # nothing is left for it to do
    watcher.wait(timeout=GRACE_S + 5)
    previous = config._twin_reaper_previous
    if previous is None:
        os.environ.pop(RUN_ENV, None)
    else:
        os.environ[RUN_ENV] = previous


def _watch(run_id: str, controller: int) -> None:
    """Poll the controlling pytest; once it is gone, end the run's processes."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # a Ctrl-C meant for pytest must not stop us
    while _alive(controller):
        time.sleep(POLL_S)
    reap(run_id)


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    try:  # an ended process its parent has not reaped yet counts as gone
        stat = Path(f"/proc/{pid}/stat").read_text()
        return stat.rsplit(")", 1)[1].split()[0] != "Z"
    except (OSError, IndexError):
        return True


if __name__ == "__main__":
    _watch(sys.argv[1], int(sys.argv[2]))
