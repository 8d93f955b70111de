"""Worlds never appear or vanish silently: only spawn/load start one; a dead server is reported."""

from __future__ import annotations

import contextlib
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from models import block

NOT_RUNNING = "An instance of twin is not running."  # gz's readiness-probe line
GZ_LINE = (  # ... then how to start a server
    "An instance of twin is not running. Start one with `twin serve` (in the foreground) or "
    "`twin spawn FILE` (in the background)."
)
AUTOSAVE_S = 0.3  # [s] the interval the tests ask for (TWIN_AUTOSAVE)


class Twin:
    """`twin ...` in a private runtime directory, as a user types it."""

    def __init__(self, runtime_dir: Path) -> None:
        self.dir = runtime_dir
        self.env = {**os.environ, "TWIN_RUNTIME_DIR": str(runtime_dir)}
        self.env.pop("TWIN_WORLD", None)
        self.env["TWIN_AUTOSAVE"] = str(AUTOSAVE_S)

    def __call__(self, *args: str, check: bool = True) -> subprocess.CompletedProcess:
        proc = subprocess.run(
            [sys.executable, "-m", "twin_cli.cli.app", *args],
            env=self.env,
            capture_output=True,
            text=True,
            timeout=120,
        )
        if check:
            assert proc.returncode == 0, f"twin {' '.join(args)}: {proc.returncode} {proc.stderr}"
        return proc


@pytest.fixture
def twin(tmp_path):
    t = Twin(tmp_path / "rt")
    (tmp_path / "box.urdf").write_text(block(size=0.2, name="box"))
    t.box = str(tmp_path / "box.urdf")
    yield t
    t("stop", check=False)


def _wait_for_autosave_after(path: Path, moment: float) -> None:
    deadline = time.time() + 30
    while not (path.is_file() and path.stat().st_mtime > moment + 0.05):
        assert time.time() < deadline, f"no autosave written to {path} within 30 s"
        time.sleep(0.05)


def test_commands_other_than_spawn_never_start_a_world(twin):
    commands = (
        ["list"],
        ["gravity", "--moon"],
        ["pause"],
        ["pose", "x"],
        ["physics"],
        ["view"],
        ["view", "--stop"],
        ["snapshot", str(twin.dir.parent / "shot.png")],
        ["command", "x", "j=0.1"],
        ["drive", "x", "--linear", "0.1"],
        ["odom", "x"],
        ["sensors", "x"],
    )
    for args in commands:
        probe = twin(*args, check=False)
        assert probe.returncode == 2, f"twin {args}: exit {probe.returncode} {probe.stderr}"
        assert probe.stderr.splitlines()[0] == GZ_LINE, f"twin {args}: {probe.stderr!r}"
    assert not (twin.dir / "default.pid").exists(), "a command other than spawn started a world"


def test_typo_in_world_names_the_worlds_that_run(twin):
    twin("spawn", twin.box, "--name", "b", "-z", "1")
    probe = twin("gravity", "--world", "typo", check=False)
    first = probe.stderr.splitlines()[0]
    fix = "`twin serve --world typo` (in the foreground) or `twin spawn FILE --world typo`"
    assert probe.returncode == 2 and first.startswith(NOT_RUNNING) and fix in first, first
    assert "running worlds: default" in probe.stderr, probe.stderr
    assert not (twin.dir / "typo.pid").exists(), "--world typo started a world"


def test_sigkilled_server_is_reported_and_load_last_restores_entities_and_poses(twin):
    twin("spawn", twin.box, "--name", "b1", "-z", "1")
    twin("spawn", twin.box, "--name", "b2", "-x", "2", "-z", "1")
    twin("pause")  # a paused world's autosave holds exactly the poses set below
    twin("pose", "b1", "--set", "1", "2", "3", "0.1", "0.2", "0.3")
    moved = time.time()
    poses = {n: json.loads(twin("pose", n, "--json").stdout) for n in ("b1", "b2")}
    _wait_for_autosave_after(twin.dir / "default.autosave.json", moved)
    pid = int((twin.dir / "default.pid").read_text())
    os.kill(pid, signal.SIGKILL)
    time.sleep(0.5)  # the supervisor reaps the server and writes its exit record

    probe = twin("list", check=False)
    assert probe.returncode == 2, f"list after SIGKILL: exit {probe.returncode}"
    first, *detail = probe.stderr.splitlines()
    assert first == GZ_LINE, probe.stderr
    text = "\n".join(detail)
    for fact in ("world [default]", f"pid {pid}", "signal 9 (SIGKILL)", "default.log", "--last"):
        assert fact in text, f"the death report lacks {fact!r}: {text}"

    loaded = twin("load", "--last")
    assert "started world" in loaded.stderr, loaded.stderr
    names = {e["name"] for e in json.loads(twin("list", "--json").stdout)}
    assert names == {"b1", "b2"}, f"entities after load --last: {names}"
    for name, before in poses.items():
        after = json.loads(twin("pose", name, "--json").stdout)
        for key in ("x", "y", "z", "roll", "pitch", "yaw"):
            assert after[key] == pytest.approx(before[key], abs=1e-9), f"{name}.{key}"
    # The death was reported once, when the new server took the world; none is left to report.
    twin("stop")
    again = twin("list", check=False)
    assert again.stderr.strip() == GZ_LINE, f"a clean stop is reported as a death: {again.stderr}"


def test_server_that_exits_with_an_error_is_reported_with_its_code(twin):
    twin("spawn", twin.box, "--name", "b", "-z", "1")
    pid = int((twin.dir / "default.pid").read_text())
    os.kill(pid, signal.SIGUSR1)  # default action: the process ends by that signal
    time.sleep(0.5)
    probe = twin("stats", "-d", "0", check=False)
    assert probe.returncode == 2 and f"pid {pid}" in probe.stderr, probe.stderr
    assert "SIGUSR1" in probe.stderr, probe.stderr
    stop = twin("stop", check=False)  # acknowledges the death: reported, then forgotten
    assert stop.returncode == 2 and "SIGUSR1" in stop.stderr, stop.stderr
    assert twin("list", check=False).stderr.strip() == GZ_LINE


def _busy_world(twin: Twin, seconds: float) -> subprocess.Popen:
    """`twin step N` in the background, N chosen to hold the world's lock about `seconds`."""
    from twin_cli.server.client import Client

    os.environ["TWIN_RUNTIME_DIR"] = str(twin.dir)
    try:
        with Client("default") as client:
            start = time.monotonic()
            client.step(20000)
            rate = 20000 / max(time.monotonic() - start, 1e-3)  # [steps/s], no start-up in it
    finally:
        del os.environ["TWIN_RUNTIME_DIR"]
    steps = str(int(rate * seconds) + 1)
    return subprocess.Popen(
        [sys.executable, "-m", "twin_cli.cli.app", "step", steps],
        env=twin.env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


def _started(env: dict, *args: str) -> subprocess.Popen:
    """`twin ARGS` started in the background, its output captured."""
    return subprocess.Popen(
        [sys.executable, "-m", "twin_cli.cli.app", *args],
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


def test_delete_and_spawn_that_outlive_the_clients_patience_are_unknown_and_repeats_are_safe(
    twin,
):
    twin("spawn", twin.box, "--name", "box", "-z", "1")
    twin("pause")
    busy = _busy_world(twin, 8.0)
    time.sleep(0.5)  # the step request holds the world's lock now
    impatient = {**twin.env, "TWIN_TIMEOUT": "1"}
    runs = [  # both at once, so both give up while the step still holds the world
        _started(impatient, *args)
        for args in (["delete", "box"], ["spawn", twin.box, "--name", "b2", "-x", "2", "-z", "1"])
    ]
    for proc in runs:
        _, err = proc.communicate(timeout=60)
        assert proc.returncode == 75, f"exit {proc.returncode}: {err}"
        assert "outcome is unknown" in err and "repeat" in err, err
    assert busy.poll() is None, "the busy step ended before the impatient clients gave up"
    assert busy.wait(timeout=120) == 0, busy.stderr.read()

    again = twin("delete", "box")  # the first delete happened; the repeat gets its outcome
    assert again.returncode == 0, again.stderr
    spawned = twin("spawn", twin.box, "--name", "b2", "-x", "2", "-z", "1")
    assert spawned.stdout.strip() == "b2", spawned
    names = sorted(e["name"] for e in json.loads(twin("list", "--json").stdout))
    assert names == ["b2"], f"after the repeats: {names}"
    third = twin("delete", "box", check=False)  # no outcome pending: an ordinary missing entity
    assert third.returncode == 2 and "Entity [box] does not exist" in third.stderr, third.stderr


def test_a_different_spawn_after_an_unknown_outcome_happens_and_a_repeat_is_replayed(twin):
    """The kept key belongs to the exact request: another pose of the same file is a new spawn,
    the same command line again gets the first one's outcome; a stopped world keeps no keys."""
    twin("spawn", twin.box, "--name", "box", "-z", "1")
    twin("pause")
    busy = _busy_world(twin, 6.0)
    time.sleep(0.5)  # the step request holds the world's lock now
    impatient = {**twin.env, "TWIN_TIMEOUT": "1"}
    first = subprocess.run(
        [sys.executable, "-m", "twin_cli.cli.app", "spawn", twin.box, "-x", "2", "-z", "1"],
        env=impatient,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert first.returncode == 75, f"exit {first.returncode}: {first.stderr}"
    assert busy.wait(timeout=120) == 0, busy.stderr.read()
    other = twin("spawn", twin.box, "-x", "3", "-z", "1")  # same file, another pose
    repeat = twin("spawn", twin.box, "-x", "2", "-z", "1")  # the unknown one, typed again
    assert (other.stdout.strip(), repeat.stdout.strip()) == ("box_2", "box_1"), (other, repeat)
    listed = {e["name"]: e["position"][0] for e in json.loads(twin("list", "--json").stdout)}
    assert listed == pytest.approx({"box": 0.0, "box_1": 2.0, "box_2": 3.0}, abs=1e-6), listed
    twin("spawn", twin.box, "-x", "4", "-z", "1", check=True)  # a spawn after the repeat: new
    assert len(json.loads(twin("list", "--json").stdout)) == 4
    twin("stop")
    assert not list(twin.dir.glob("*.pending-*")), "idempotency keys left after the world ended"


def test_a_snapshot_that_outlives_the_clients_patience_is_unknown_not_bad_input(twin, tmp_path):
    twin("spawn", twin.box, "--name", "box", "-z", "1")
    twin("pause")
    busy = _busy_world(twin, 5.0)
    time.sleep(0.5)  # the step request holds the world's lock now
    shot = subprocess.run(
        [sys.executable, "-m", "twin_cli.cli.app", "snapshot", str(tmp_path / "s.png")],
        env={**twin.env, "TWIN_TIMEOUT": "1"},
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert shot.returncode == 75, f"exit {shot.returncode}: {shot.stderr}"
    assert "outcome is unknown" in shot.stderr and "Traceback" not in shot.stderr, shot.stderr
    assert busy.wait(timeout=120) == 0, busy.stderr.read()


STALL_S = 5.0  # [s] the server is held stopped (SIGSTOP): a busy machine, made certain


@pytest.mark.parametrize("command", [("list", "--json"), ("gravity", "--moon")])
def test_a_client_waits_for_a_server_that_answers_late_and_succeeds(twin, command):
    """A live server that answers late is waited for, not given up on after a fixed 2 s (exit 75
    with 'GET /health no reply within 2 s' before); with TWIN_TIMEOUT set, the user's limit
    decides (exit 75, the outcome unknown)."""
    twin("spawn", twin.box, "--name", "box", "-z", "1")
    pid = int((twin.dir / "default.pid").read_text().strip())
    runs = {}
    os.kill(pid, signal.SIGSTOP)
    try:
        for limit in (None, "1"):
            env = twin.env if limit is None else {**twin.env, "TWIN_TIMEOUT": limit}
            runs[limit] = (time.monotonic(), _started(env, *command))
        time.sleep(STALL_S)
    finally:
        os.kill(pid, signal.SIGCONT)
    start, patient = runs[None]
    out, err = patient.communicate(timeout=60)
    assert patient.returncode == 0, f"exit {patient.returncode}: {err}"
    assert time.monotonic() - start >= STALL_S - 0.5, "answered while the server was stopped"
    if command[0] == "list":
        assert [e["name"] for e in json.loads(out)] == ["box"]
    _, impatient = runs["1"]
    _, err = impatient.communicate(timeout=60)
    assert impatient.returncode == 75, f"exit {impatient.returncode}: {err}"
    assert "no reply within 1 s" in err and "Traceback" not in err, err


def test_twin_stop_ends_a_server_that_does_not_answer(twin):
    """A stopped (SIGSTOP) server gets the shutdown request, no reply, then the signals: `twin
    stop` ends it and returns, instead of waiting on the request for ever."""
    twin("spawn", twin.box, "--name", "box", "-z", "1")
    pid = int((twin.dir / "default.pid").read_text().strip())
    os.kill(pid, signal.SIGSTOP)
    try:
        stopped = twin("stop", check=False)
    finally:
        with contextlib.suppress(ProcessLookupError):
            os.kill(pid, signal.SIGCONT)
    assert stopped.returncode == 0, stopped.stderr
    with pytest.raises(ProcessLookupError):
        os.kill(pid, 0)
