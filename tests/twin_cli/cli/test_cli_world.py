"""The used-by flow as a new user types it: `twin spawn` with no server, stats, gravity, stop."""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys

import pytest
from models import block, mimic_pincer

import scenarios

GZ_LINE = re.compile(
    r"^Factor\[\d+\.\d\d\] SimTime\[\d+\.\d\d\] RealTime\[\d+\.\d\d\] Paused\[[TF]\]$"
)
NOT_RUNNING = (  # gz's readiness-probe line, then how to start a server
    "An instance of twin is not running. Start one with `twin serve` (in the foreground) or "
    "`twin spawn FILE` (in the background)."
)
MOON, EARTH = 1.62, 9.81  # [m/s^2], the presets
DT, STEPS = 0.001, 300  # [s], steps of free fall measured through `twin pose`
BOX_URDF = block(size=0.2, name="box")  # 1 kg, 0.2 m cube


class Twin:
    """Runs `twin ...` as a user would, in a private runtime dir; stops the world at the end."""

    def __init__(self, runtime_dir) -> None:
        self.env = {**os.environ, "TWIN_RUNTIME_DIR": str(runtime_dir)}
        self.env.pop("TWIN_WORLD", None)

    def __call__(self, *args: str, check: bool = True, timeout: float = 120):
        proc = subprocess.run(
            [sys.executable, "-m", "twin_cli.cli.app", *args],
            env=self.env,
            capture_output=True,
            text=True,
            timeout=timeout,
        )
        if check:
            assert proc.returncode == 0, f"twin {' '.join(args)}: {proc.returncode} {proc.stderr}"
        return proc


@pytest.fixture
def twin(tmp_path):
    t = Twin(tmp_path / "rt")
    (tmp_path / "box.urdf").write_text(BOX_URDF)
    t.box = str(tmp_path / "box.urdf")
    yield t
    t("stop", check=False, timeout=60)


def _drop(twin: Twin, name: str, z0: float) -> float:
    return z0 - json.loads(twin("pose", name, "--json").stdout)["z"]


def test_used_by_flow_on_the_bundled_humanoid(twin):
    spawned = twin("spawn", str(scenarios.HUMANOID), "-z", "1.2")
    assert spawned.stdout.strip() == "humanoid", f"spawn printed {spawned.stdout!r}"
    started = [line for line in spawned.stderr.splitlines() if "started world" in line]
    assert len(started) == 1, f"expected one 'started world' line, stderr: {spawned.stderr!r}"

    lines = twin("stats", "-d", "2").stdout.splitlines()
    assert 8 <= len(lines) <= 13, f"{len(lines)} stats lines in 2 s (about 5 a second)"
    bad = [line for line in lines if not GZ_LINE.match(line)]
    assert not bad, f"lines not in gz-stats format: {bad}"
    factor = float(re.search(r"Factor\[([\d.]+)\]", lines[-1]).group(1))
    assert factor == pytest.approx(1.0, abs=0.1), f"real-time factor {factor}"
    csv = twin("stats", "-d", "0.2", "-p").stdout.splitlines()
    assert csv[0].startswith("# real-time factor") and len(csv[1].split(", ")) == 4, csv
    sample = json.loads(twin("stats", "-d", "0", "--json").stdout)
    assert sample["sim_time"] > 2.0 and sample["paused"] is False, sample

    # Free fall of a new box, earth then moon, measured by stepping a paused world.
    twin("pause")
    twin("spawn", twin.box, "--name", "earthbox", "-x", "3", "-z", "10")
    twin("step", str(STEPS))
    earth = _drop(twin, "earthbox", 10.0)
    twin("gravity", "--moon")
    assert twin("gravity").stdout.split() == ["0", "0", "-1.62"]
    twin("spawn", twin.box, "--name", "moonbox", "-x", "-3", "-z", "10")
    twin("step", str(STEPS))
    moon = _drop(twin, "moonbox", 10.0)
    fall = 0.5 * DT**2 * STEPS * (STEPS + 1)  # semi-implicit Euler: sum of k*g*dt^2 [m per g]
    assert earth == pytest.approx(EARTH * fall, rel=0.01), f"earth drop {earth} m in 0.3 s"
    assert moon == pytest.approx(MOON * fall, rel=0.01), f"moon drop {moon} m in 0.3 s"
    assert moon / earth == pytest.approx(MOON / EARTH, rel=0.01), "moon/earth fall ratio"

    names = {e["name"] for e in json.loads(twin("list", "--json").stdout)}
    assert names == {"humanoid", "earthbox", "moonbox"}, f"list: {names}"
    assert len(twin("pose", "humanoid").stdout.split()) == 6, "pose is x y z roll pitch yaw"
    joints = json.loads(twin("joints", "humanoid", "--json").stdout)
    assert len(joints) == 11, f"the bundled humanoid has 11 joints, twin joints: {len(joints)}"
    twin("delete", "humanoid")
    names = {e["name"] for e in json.loads(twin("list", "--json").stdout)}
    assert "humanoid" not in names, f"humanoid still listed after delete: {names}"

    taken = twin("spawn", twin.box, "--name", "moonbox", check=False)
    assert taken.returncode == 2 and "Entity [moonbox] already exists" in taken.stderr, taken

    twin("stop")
    assert "stopped" in twin("logs", "-n", "3").stdout, "server log should end with the stop"
    probe = twin("stats", "-d", "0", check=False)
    assert probe.returncode == 2, f"stats with no world: exit {probe.returncode}"
    assert probe.stderr.strip() == NOT_RUNNING, probe.stderr


def test_sigkilled_server_is_replaced_on_next_spawn(twin, tmp_path):
    twin("spawn", twin.box, "--name", "first", "-z", "1")
    pid_file = tmp_path / "rt" / "default.pid"
    old_pid = int(pid_file.read_text())
    os.kill(old_pid, signal.SIGKILL)
    again = twin("spawn", twin.box, "--name", "second", "-z", "1")
    assert "started world" in again.stderr, f"no restart announced: {again.stderr!r}"
    new_pid = int(pid_file.read_text())
    assert new_pid != old_pid, "the killed server's pid is still recorded"
    names = {e["name"] for e in json.loads(twin("list", "--json").stdout)}
    assert names == {"second"}, f"a fresh world should hold only the new entity: {names}"
    twice = twin("serve", check=False, timeout=60)
    assert twice.returncode == 2 and f"pid {new_pid}" in twice.stderr, twice.stderr
    assert "already served" in twice.stderr and "twin stop" in twice.stderr, twice.stderr
    twin("stop")
    again = twin("stop", check=False)
    assert again.returncode == 2, f"stop with no world: exit {again.returncode}"
    assert again.stderr.strip() == NOT_RUNNING, again.stderr


def test_concurrent_first_commands_start_exactly_one_server(twin):
    cmd = [sys.executable, "-m", "twin_cli.cli.app", "spawn", twin.box, "--name"]
    procs = [
        subprocess.Popen(
            [*cmd, f"box{i}"],
            env=twin.env,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        for i in range(3)
    ]
    outs = [p.communicate(timeout=120) for p in procs]
    codes = [p.returncode for p in procs]
    assert codes == [0, 0, 0], f"exit codes {codes}: {[err for _, err in outs]}"
    started = sum("started world" in err for _, err in outs)
    assert started == 1, f"{started} servers announced by 3 simultaneous first commands"


def _joints(twin: Twin, name: str) -> dict[str, tuple[float, float]]:
    """name → (position [rad], velocity [rad/s]) as `twin joints --json` reports them."""
    rows = json.loads(twin("joints", name, "--json").stdout)
    return {r["name"]: (r["position"], r["velocity"]) for r in rows}


def test_spawn_J_starts_at_rest_in_that_posture_mimic_follows_and_reset_returns_there(
    twin, tmp_path
):
    # follow = 0.2 - lead (mimic); gravity swings both fingers once stepped.
    (tmp_path / "pincer.urdf").write_text(mimic_pincer(offset=0.2, multiplier=-1.0))
    twin("spawn", twin.box, "--name", "anchor", "-x", "5", "-z", "0.1")  # only spawn starts one
    twin("pause")
    twin("spawn", str(tmp_path / "pincer.urdf"), "-J", "lead=0.6")
    start = _joints(twin, "pincer")
    assert start["lead"] == (pytest.approx(0.6, abs=1e-12), 0.0), f"lead at spawn: {start}"
    assert start["follow"] == (pytest.approx(-0.4, abs=1e-12), 0.0), f"follow = 0.2 - lead {start}"
    twin("step", "300")
    moved = _joints(twin, "pincer")
    assert abs(moved["lead"][0] - 0.6) > 0.1, f"gravity should swing the lead finger: {moved}"
    residual = moved["follow"][0] - (0.2 - moved["lead"][0])
    assert abs(residual) < 5e-3, f"mimic residual {residual:.2e} rad while swinging (≤ 5 mrad)"
    twin("reset")
    assert _joints(twin, "pincer") == start, "reset returns to the -J posture, at rest"


def test_spawn_J_out_of_range_exits_2_naming_joint_and_range_and_world_is_unchanged(twin, tmp_path):
    (tmp_path / "pincer.urdf").write_text(mimic_pincer(offset=0.2, multiplier=-1.0))
    twin("spawn", twin.box, "--name", "anchor", "-x", "5", "-z", "0.1")  # only spawn starts one
    twin("pause")
    twin("spawn", str(tmp_path / "pincer.urdf"), "-J", "lead=0.5")
    before = _joints(twin, "pincer")
    cases = {
        "lead=1.5": ("[lead]", "1.5 rad", "[-1, 1] rad"),
        "lead=-1": ("[follow]", "1.2 rad", "[lead]"),  # the follower would leave its range
        "nope=0": ("[nope]", "follow", "lead"),  # unknown: lists the valid names
    }
    for value, expected in cases.items():
        proc = twin(
            "spawn", str(tmp_path / "pincer.urdf"), "--name", "p2", "-J", value, check=False
        )
        assert proc.returncode == 2, f"-J {value}: exit {proc.returncode}, {proc.stderr}"
        missing = [text for text in expected if text not in proc.stderr]
        assert not missing, f"-J {value}: message lacks {missing}: {proc.stderr}"
    names = sorted(e["name"] for e in json.loads(twin("list", "--json").stdout))
    assert names == ["anchor", "pincer"], f"entities after failed spawns: {names}"
    assert _joints(twin, "pincer") == before, "the existing entity is untouched"
