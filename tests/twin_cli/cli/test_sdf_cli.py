"""SDF as a Gazebo user types it: `twin serve my.world`, spawning text and stdin, quaternions."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import pytest
from cli_world import twin_in, twin_ok
from sdf_models import LESSON_BOX, WORLD

WORLD_NAME = "sdf_cli"


def _twin(runtime: Path, *args: str, stdin: str | None = None) -> subprocess.CompletedProcess:
    return twin_in(runtime, WORLD_NAME, *args, stdin=stdin)


def _ok(runtime: Path, *args: str, stdin: str | None = None) -> str:
    return twin_ok(runtime, WORLD_NAME, *args, stdin=stdin)


@pytest.fixture(scope="module")
def served(tmp_path_factory, serve_world):
    """`twin serve moon_lab.world`, paused so that poses stay where the file puts them."""
    root = tmp_path_factory.mktemp("sdf_cli")
    world_file = root / "moon_lab.world"
    world_file.write_text(WORLD)
    with serve_world(root, WORLD_NAME, str(world_file), "--paused"):
        yield root


def test_serve_reports_what_the_world_file_says(served: Path) -> None:
    physics = json.loads(_ok(served, "physics", "--json"))
    assert (physics["timestep"], physics["rate"], physics["iterations"]) == (0.002, 500.0, 80)
    assert json.loads(_ok(served, "gravity", "--json"))["gravity"] == [0.0, 0.0, -1.62]
    names = [e["name"] for e in json.loads(_ok(served, "list", "--json"))]
    assert names[:3] == ["ground_plane", "crate", "table"], "one entity per model, in file order"
    crate = json.loads(_ok(served, "pose", "crate", "--json"))
    assert (crate["x"], crate["y"], crate["z"]) == (1.0, 0.0, 2.0), "the file's <pose> [m]"
    table = json.loads(_ok(served, "pose", "table", "--json"))
    assert (table["x"], table["y"], table["z"]) == (-1.0, 0.5, 0.0)
    assert table["yaw"] == pytest.approx(0.5, abs=1e-12), "yaw [rad]"


def test_lesson_box_spawns_inline_and_from_stdin(served: Path) -> None:
    inline = _ok(served, "spawn", "--xml", LESSON_BOX, "-x", "2", "-z", "0.25", "--name", "a")
    piped = _ok(
        served, "spawn", "-", "--name", "b", "-x", "2", "-y", "1", "-z", "0.25", stdin=LESSON_BOX
    )
    assert (inline.strip(), piped.strip()) == ("a", "b"), "spawn prints the entity's name"
    for name, y in (("a", 0.0), ("b", 1.0)):
        pose = json.loads(_ok(served, "pose", name, "--json"))
        assert (pose["x"], pose["y"], pose["z"]) == (2.0, y, 0.25), f"{name} [m]"
        assert json.loads(_ok(served, "joints", name, "--json")) == [], "static: no joints"


def test_quaternion_in_and_out(served: Path) -> None:
    half = math.sqrt(0.5)
    _ok(
        served,
        "spawn",
        "--xml",
        LESSON_BOX,
        "--name",
        "q",
        "-z",
        "0.25",
        "--quat",
        "0",
        "0",
        f"{half}",
        f"{half}",
    )
    assert json.loads(_ok(served, "pose", "q", "--json"))["yaw"] == pytest.approx(math.pi / 2)
    printed = [float(v) for v in _ok(served, "pose", "q", "--quat").split()]
    assert printed == pytest.approx([0.0, 0.0, 0.25, 0.0, 0.0, half, half], abs=1e-6)


@pytest.mark.parametrize(
    ("text", "needle"),
    [
        ('<sdf version="1.6"><model name="m"><link name="a"><pose>0 0 q 0 0 0</pose>', "malformed"),
        (
            '<sdf version="1.6"><model name="m"><link name="a"><pose>0 0 q 0 0 0</pose>'
            "</link></model></sdf>",
            "<xml>:1",
        ),
        ('<sdf version="9.9"><model name="m"/></sdf>', "'9.9'"),
    ],
)
def test_bad_sdf_text_is_one_message_and_exit_2(served: Path, text: str, needle: str) -> None:
    proc = _twin(served, "spawn", "-", stdin=text)
    assert proc.returncode == 2, proc.stderr
    assert needle in proc.stderr and "Traceback" not in proc.stderr, proc.stderr
    names = [e["name"] for e in json.loads(_ok(served, "list", "--json"))]
    assert "m" not in names, "a refused spawn leaves the world unchanged"


def test_convert_and_validate_take_an_sdf_model(tmp_path: Path) -> None:
    model = tmp_path / "box.sdf"
    model.write_text(LESSON_BOX.replace("<static>true</static>", ""))
    out = tmp_path / "out"

    def twin(*args: str) -> subprocess.CompletedProcess:
        command = [sys.executable, "-m", "twin_cli", *args]
        return subprocess.run(command, capture_output=True, text=True, timeout=120)

    converted = twin("convert", str(model), "-o", str(out))
    assert converted.returncode == 0, converted.stderr
    assert (out / "test_box.xml").is_file() and (out / "scene.xml").is_file()
    run = twin("validate", str(model), "--only", "gravity", "--json")
    assert run.returncode == 0, run.stderr
    checks = json.loads(run.stdout)["checks"]
    assert [(c["check"], c["status"]) for c in checks] == [("gravity", "pass")], checks
