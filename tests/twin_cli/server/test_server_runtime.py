"""Runtime files of world servers: private directory, liveness by flock, stale-file cleanup."""

from __future__ import annotations

import os
import signal
import stat
import subprocess
import sys
import time

import pytest

from twin_cli.errors import WorldRunningError
from twin_cli.server import runtime

HOLDER = """
import sys, time
from twin_cli.server import runtime
paths = runtime.world_paths(sys.argv[1])
with runtime.hold_pid_file(paths):
    paths.socket.write_text("")
    print("held", flush=True)
    time.sleep(60)
"""


@pytest.fixture
def rtdir(tmp_path, monkeypatch):
    path = tmp_path / "rt"
    monkeypatch.setenv(runtime.RUNTIME_ENV, str(path))
    return path


def _hold(world: str) -> subprocess.Popen:
    proc = subprocess.Popen(
        [sys.executable, "-c", HOLDER, world], stdout=subprocess.PIPE, text=True
    )
    assert proc.stdout.readline().strip() == "held", "holder process did not take the pid lock"
    return proc


def test_runtime_dir_is_created_private(rtdir):
    path = runtime.runtime_dir()
    assert path == rtdir
    mode = stat.S_IMODE(path.stat().st_mode)
    assert mode == 0o700, f"runtime dir mode {oct(mode)}"


def test_world_name_must_be_a_safe_file_name(rtdir):
    with pytest.raises(runtime.WorldNameError, match="letters, digits"):
        runtime.world_paths("../etc")


def test_too_long_socket_path_is_refused_with_fix(tmp_path, monkeypatch):
    monkeypatch.setenv(runtime.RUNTIME_ENV, str(tmp_path / ("d" * 120)))
    with pytest.raises(runtime.RuntimeDirError, match="TWIN_RUNTIME_DIR"):
        runtime.world_paths("w")


def test_live_holder_is_alive_and_owns_the_world(rtdir):
    proc = _hold("w")
    try:
        paths = runtime.world_paths("w")
        assert runtime.server_alive(paths)
        assert runtime.read_pid(paths) == proc.pid
        assert runtime.clean_stale(paths) == [], "clean_stale removed files of a live server"
        with pytest.raises(WorldRunningError, match=f"pid {proc.pid}"):
            with runtime.hold_pid_file(paths):
                pass
    finally:
        proc.terminate()
        proc.wait()


def test_sigkilled_holder_leaves_stale_files_that_are_cleaned(rtdir):
    proc = _hold("w")
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait()
    paths = runtime.world_paths("w")
    assert paths.pid.exists() and paths.socket.exists(), "SIGKILL should leave the files behind"
    assert not runtime.server_alive(paths), "a dead holder must not count as alive"
    removed = set(runtime.clean_stale(paths))
    assert {paths.pid, paths.socket} <= removed, f"removed: {removed}"
    assert not paths.pid.exists() and not paths.socket.exists()


def test_start_lock_serialises_starters(rtdir):
    paths = runtime.world_paths("w")
    with runtime.start_lock(paths):
        t0 = time.monotonic()
        with pytest.raises(Exception, match="another start is stuck"):
            with runtime.start_lock(paths, timeout=0.2):
                pass
        assert time.monotonic() - t0 >= 0.2


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("8765", ("127.0.0.1", 8765)),
        ("localhost:1", ("127.0.0.1", 1)),
        ("[::1]:5", ("::1", 5)),
        ("0.0.0.0:9", ("0.0.0.0", 9)),
    ],
)
def test_tcp_address_defaults_to_loopback(text, expected):
    from twin_cli.server.process import parse_tcp

    assert parse_tcp(text) == expected


@pytest.mark.parametrize("text", ["nonsense", "example.com:80", "127.0.0.1:70000"])
def test_bad_tcp_address_is_refused_with_an_example(text):
    from twin_cli.errors import RequestError
    from twin_cli.server.process import parse_tcp

    with pytest.raises(RequestError, match="--tcp"):
        parse_tcp(text)


def test_a_world_file_serve_refuses_ends_in_order_not_as_a_death(rtdir, tmp_path):
    # The run record stayed behind, so every later command said the world had died by SIGKILL.
    def twin(*args: str) -> subprocess.CompletedProcess:
        return subprocess.run(
            [sys.executable, "-m", "twin_cli.cli.app", *args, "--world", "refused"],
            capture_output=True,
            text=True,
            timeout=120,
        )

    served = twin("serve", str(tmp_path / "missing.world"), "--no-autosave")
    assert served.returncode == 2, served.stderr
    assert "missing.world: no such file" in served.stderr and "Traceback" not in served.stderr
    listed = twin("list")
    assert listed.returncode == 2 and "not running" in listed.stderr, listed.stderr
    assert "died" not in listed.stderr and "SIGKILL" not in listed.stderr, listed.stderr
    logged = twin("logs")
    assert "not served: " in logged.stdout and "missing.world" in logged.stdout, logged.stdout
