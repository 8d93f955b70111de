"""`twin sensors` and the sensor routes against a real server (no mocks)."""

from __future__ import annotations

import json
import math
import subprocess
from pathlib import Path

import pytest
from cli_world import twin_in
from models import write_urdf
from sensor_models import imu_box, lidar_post

WORLD_NAME = "sensors_cli"
WALL_SDF = """<sdf version="1.7"><model name="wall"><static>true</static>
<link name="l"><collision name="c"><geometry><box><size>0.1 4 2</size></box></geometry></collision>
</link></model></sdf>"""


def _twin(runtime: Path, *args: str) -> subprocess.CompletedProcess:
    return twin_in(runtime, WORLD_NAME, *args)


@pytest.fixture(scope="module")
def served(tmp_path_factory, serve_world):
    """A running world with a lidar post 2 m from an SDF wall (near face at x = 2) and a static
    IMU box."""
    root = tmp_path_factory.mktemp("sensors_cli")
    post = write_urdf(root, lidar_post(), "post.urdf")
    box = write_urdf(root, imu_box(rate=100.0).replace("</robot>", STATIC), "imu.urdf")
    (root / "wall.sdf").write_text(WALL_SDF)
    with serve_world(root, WORLD_NAME) as (client, _):
        client.spawn(str(post), name="post")
        client.spawn(str(box), name="imu", pose={"x": 5.0, "z": 0.1})
        client.spawn(str(root / "wall.sdf"), name="wall", pose={"x": 2.05, "z": 1.0})
        yield root, client


STATIC = "<gazebo><static>true</static></gazebo>\n</robot>"


def test_sensor_routes_list_and_read(served) -> None:
    _, client = served
    listing = client.request("GET", "/entities/post/sensors")["sensors"]
    assert [(s["name"], s["type"], s["update_rate"], s["topic"]) for s in listing] == [
        ("lidar", "ray", 10.0, "scan")
    ]
    scan = client.request("GET", "/entities/post/sensors/lidar")
    assert scan["ranges"][len(scan["ranges"]) // 2] == pytest.approx(2.0, abs=1e-9)
    assert scan["ranges"][0] is None, "+inf (no return) is null in JSON"


def test_twin_sensors_prints_readings_at_the_sensor_rate(served) -> None:
    root, _ = served
    proc = _twin(root, "sensors", "imu", "-d", "1.0", "--json")
    assert proc.returncode == 0, proc.stderr
    readings = [json.loads(line) for line in proc.stdout.splitlines()]
    assert len(readings) >= 3, f"readings over 1 s of wall time: {len(readings)}"
    stamps = [r["time"] for r in readings]
    assert stamps == sorted(set(stamps)), "each reading printed once, in order"
    periods = [math.floor(t * 100.0 + 1e-9) for t in stamps]  # 100 Hz: 10 ms periods
    assert len(set(periods)) == len(periods), "at most one reading per period of sim time"
    for r in readings:
        assert r["linear_acceleration"][2] == pytest.approx(9.8, abs=0.02), "at rest: +g"
    human = _twin(root, "sensors", "post", "lidar")
    assert human.returncode == 0, human.stderr
    assert "lidar [ray]" in human.stdout and "nearest 2.000 m" in human.stdout


def test_twin_sensors_with_a_bad_name_exits_2_listing_the_sensors(served) -> None:
    root, _ = served
    proc = _twin(root, "sensors", "post", "sonar")
    assert proc.returncode == 2, proc.stdout + proc.stderr
    assert "sonar" in proc.stderr and "lidar" in proc.stderr, proc.stderr
