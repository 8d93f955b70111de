"""`twin command --mode` and `twin joints` as a user types them, against a real (paused) world
server holding a robot whose joints declare several command interfaces in both tag forms."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

import pytest
from cli_world import twin_in, twin_ok
from interface_models import SEVERAL_INTERFACES
from models import write_urdf

WORLD_NAME = "modes_cli"


def _twin(runtime: Path, *args: str) -> subprocess.CompletedProcess:
    return twin_in(runtime, WORLD_NAME, *args)


def _ok(runtime: Path, *args: str) -> str:
    return twin_ok(runtime, WORLD_NAME, *args)


def _joints(runtime: Path) -> dict[str, dict]:
    return {j["name"]: j for j in json.loads(_ok(runtime, "joints", "discs", "--json"))}


@pytest.fixture(scope="module")
def served(tmp_path_factory, serve_world):
    root = tmp_path_factory.mktemp("modes_cli")
    with serve_world(root, WORLD_NAME, "--paused"):
        _ok(root, "spawn", str(write_urdf(root, SEVERAL_INTERFACES)))
        yield root


def test_joints_shows_each_joints_active_mode_and_the_modes_it_offers(served: Path) -> None:
    joints = _joints(served)
    offered = {name: (j["mode"], j["modes"]) for name, j in joints.items()}
    assert offered == {  # each joint's own servo holds it from load, in its first mode
        "d0": ("position", ["position", "velocity", "effort"]),
        "d1": ("position", ["position"]),
        "d2": ("velocity", ["velocity", "effort"]),
    }, offered
    table = _ok(served, "joints", "discs").splitlines()  # piped: tab-separated
    assert table[0].split("\t")[:3] == ["joint", "mode", "offers"], table[0]
    assert table[1].split("\t")[:3] == ["d0", "position", "position,velocity,effort"], table[1]


def test_command_mode_switches_a_live_joint_and_the_new_mode_acts_at_once(served: Path) -> None:
    # The disc: 1 kg, I = 0.005 kg m² about its vertical axis, 5 N m, 4 rad/s.
    _ok(served, "command", "discs", "d0=0.5", "--mode", "position")
    _ok(served, "step", "2000")
    assert _joints(served)["d0"]["position"] == pytest.approx(0.5, abs=1e-3), "reached"
    _ok(served, "command", "discs", "d0=2", "--mode", "velocity")
    assert _joints(served)["d0"]["mode"] == "velocity"
    _ok(served, "step", "200")
    before = _joints(served)["d0"]["position"]
    _ok(served, "step", "100")
    d0 = _joints(served)["d0"]
    speed = (d0["position"] - before) / 0.1
    assert speed == pytest.approx(2.0, rel=0.01), f"{speed:.4f} rad/s after the switch"
    assert d0["velocity"] == pytest.approx(2.0, rel=0.01), d0
    reply = json.loads(_ok(served, "command", "discs", "d0=-1.5", "--mode", "effort", "--json"))
    assert reply["mode"] == "effort", reply
    _ok(served, "step", "1")
    d0 = _joints(served)["d0"]
    assert (d0["mode"], d0["target"]) == ("effort", -1.5), d0
    assert d0["effort"] == pytest.approx(-1.5, abs=1e-9), f"applied {d0['effort']} N m"


def test_a_mode_the_joint_does_not_offer_exits_2_with_the_offered_ones_and_a_fix(
    served: Path,
) -> None:
    before = _joints(served)["d1"]
    proc = _twin(served, "command", "discs", "d1=0.5", "--mode", "effort")
    assert proc.returncode == 2, (proc.returncode, proc.stderr)
    assert "Traceback" not in proc.stderr, proc.stderr
    for words in ("joint [d1] of [discs]", "offer only position", "use --mode position"):
        assert words in proc.stderr, f"{words!r} not in {proc.stderr!r}"
    assert "hardware_interface/EffortJointInterface" in proc.stderr, "the fix names the tag"
    assert _joints(served)["d1"]["mode"] == before["mode"], "nothing changed"
    _ok(served, "command", "discs", "d1=0.5", "--mode", "position")  # the fix given works
