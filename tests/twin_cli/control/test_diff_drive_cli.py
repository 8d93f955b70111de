"""`twin drive` and `twin odom` as a user types them, against a real (paused) world server."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

import pytest
from cli_world import twin_in, twin_ok
from corpus_registry import CORPUS, PACKAGES_ROOT, needs_corpus

WORLD_NAME = "drive_cli"
ROBOT = CORPUS.get("turtlebot3_burger")
BOX = '<sdf version="1.6"><model name="box"><link name="l"><collision name="c"><geometry><box>'
BOX += "<size>0.2 0.2 0.2</size></box></geometry></collision></link></model></sdf>"

pytestmark = needs_corpus


def _twin(runtime: Path, *args: str) -> subprocess.CompletedProcess:
    return twin_in(runtime, WORLD_NAME, *args)


def _ok(runtime: Path, *args: str) -> str:
    return twin_ok(runtime, WORLD_NAME, *args)


@pytest.fixture(scope="module")
def served(tmp_path_factory, serve_world):
    """A paused world with turtlebot3 on the ground and a box without a drive plugin."""
    root = tmp_path_factory.mktemp("drive_cli")
    with serve_world(root, WORLD_NAME, "--paused"):
        package = f"turtlebot3_description={PACKAGES_ROOT / 'turtlebot3_description'}"
        entry = str(PACKAGES_ROOT / ROBOT["entry"])
        _ok(root, "spawn", entry, "--name", "tb3", "--package", package, "--on-ground")
        _ok(root, "spawn", "--xml", BOX, "-x", "1", "-z", "0.1")
        _ok(root, "step", "300")
        yield root


def test_drive_moves_the_robot_and_odom_reports_the_world_pose(served: Path) -> None:
    before = json.loads(_ok(served, "odom", "tb3", "--json"))
    reply = json.loads(
        _ok(served, "drive", "tb3", "--linear", "0.2", "--angular", "0", "-d", "1", "--json")
    )
    assert (reply["linear"], reply["angular"], reply["duration"]) == (0.2, 0.0, 1.0)
    _ok(served, "step", "1500")  # 1 s of driving and 0.5 s to stop [ms]
    odom = json.loads(_ok(served, "odom", "tb3", "--json"))
    pose = json.loads(_ok(served, "pose", "tb3", "--json"))
    assert odom["pose"]["position"][:2] == pytest.approx([pose["x"], pose["y"]], abs=1e-9)
    moved = odom["pose"]["position"][0] - before["pose"]["position"][0]
    # 1 s at 0.2 m/s, less the 0.2 s ramp up at 1 m/s² (0.02 m), plus the ramp down (0.02 m);
    # 10 %: the wheels (μ = 0.1) slip while accelerating at 1 m/s² ≈ μ·g (measured 0.186-0.193)
    assert moved == pytest.approx(0.2, rel=0.10), f"moved {moved:.4f} m forward"
    rows = {r.split("\t")[0]: r.split("\t")[1:] for r in _ok(served, "odom", "tb3").splitlines()}
    x = odom["pose"]["position"][0]
    assert float(rows["position [m]"][0]) == pytest.approx(x, abs=1e-4), "piped: tab-separated"


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (("drive", "ghost", "--linear", "0.2"), "ghost"),
        (("drive", "box", "--linear", "0.2"), "no drive plugin"),
        (("drive", "tb3", "--linear", "nan"), "not finite"),
        (("drive", "tb3", "--angular", "inf"), "not finite"),
        (("odom", "box"), "no drive plugin"),
    ],
)
def test_bad_drive_input_is_one_message_and_exit_2(served: Path, args: tuple, needle: str) -> None:
    before = _ok(served, "pose", "tb3", "--json")
    proc = _twin(served, *args)
    assert proc.returncode == 2, proc.stderr
    assert needle in proc.stderr and "Traceback" not in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1, proc.stderr
    assert _ok(served, "pose", "tb3", "--json") == before, "the world is unchanged"
