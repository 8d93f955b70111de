"""A gz-sim robot served with `twin serve --ros` is on the ROS graph under the names a ROS user
bridges gz-sim's with (ros_gz_bridge keeps gz-sim's topic names): its DiffDrive takes
geometry_msgs/Twist on `/model/vehicle_blue/cmd_vel` and publishes nav_msgs/Odometry on
`/model/vehicle_blue/odometry` and its transform on `/model/vehicle_blue/tf`, from
`vehicle_blue/odom` to `vehicle_blue/chassis`. `twin topics` lists them, the command topic
marked as one twin reads, and a static model lists nothing.

The server and the peer (`ros_peer.py`, sharing no code with twin) run in a network namespace
of this module's own (`netns`: only `lo`), so no other test's DDS traffic can meet them.
"""

from __future__ import annotations

import json
import math
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import drive_models as dm
import netns
import pytest

pytest.importorskip("cyclonedds", reason="cyclonedds is not installed (CI installs it)")
if (why := netns.available()) is not None:
    pytest.skip(why, allow_module_level=True)
pytestmark = pytest.mark.xdist_group("ros_gz_names")

HERE = Path(__file__).parent
ROOT = HERE.parents[2]

WORLD = "gz_names"
CMD_VEL, ODOMETRY, TF = (f"/model/vehicle_blue/{leaf}" for leaf in ("cmd_vel", "odometry", "tf"))
VX, WZ = 0.2, 0.5  # [m/s, rad/s] the peer's Twist
STEPS = 2000  # 2 s of sim time at the SDF default step, 1 ms
ARC_TOL = 0.1  # of the arc's radius: the unicycle's end point within it (test_ros_live's bound)


class Served:
    """`twin` commands and peer scripts run inside the namespace against its served world."""

    def __init__(self, ns: netns.Namespace, runtime: Path) -> None:
        env = netns.clean_env()
        self.ns, self.env = ns, {**env, "TWIN_RUNTIME_DIR": str(runtime)}

    def __call__(self, *args: str) -> str:
        command = [sys.executable, "-m", "twin_cli.cli.app", *args, "--world", WORLD]
        done = self.ns.run(command, env=self.env, cwd=ROOT, timeout=120)
        assert done.returncode == 0, f"twin {' '.join(args)}: {done.stderr[-1500:]}"
        return done.stdout

    def peer(self, *args: str) -> dict:
        done = self.ns.run(
            [sys.executable, str(HERE / "ros_peer.py"), *args], env=self.env, cwd=HERE, timeout=180
        )
        assert done.returncode == 0, f"ros_peer {' '.join(args)}: {done.stderr[-1500:]}"
        return json.loads(done.stdout)


@pytest.fixture(scope="module")
def served(tmp_path_factory) -> Iterator[Served]:
    """`twin serve --ros` in a namespace, `vehicle_blue` on the ground and a static ground."""
    root = tmp_path_factory.mktemp("gz_names")
    (root / "vehicle_blue.sdf").write_text(dm.gz_vehicle())
    (root / "ground.sdf").write_text(dm.STATIC_GROUND)
    with netns.Namespace() as ns:
        twin = Served(ns, root / "runtime")
        log = open(root / "serve.out", "wb")  # noqa: SIM115 (the server writes to it until the end)
        command = [sys.executable, "-m", "twin_cli.cli.app", "serve", "--world", WORLD, "--ros"]
        server = ns.popen(command, env=twin.env, cwd=ROOT, stdout=log, stderr=log)
        try:
            deadline = time.monotonic() + 60.0
            status = [*command[:3], "ros", "status", "--world", WORLD]
            while ns.run(status, env=twin.env).returncode:
                assert server.poll() is None, (root / "serve.out").read_text()[-1500:]
                assert time.monotonic() < deadline, "twin serve --ros did not start in 60 s"
                time.sleep(0.3)
            twin("spawn", str(root / "vehicle_blue.sdf"), "--on-ground")
            twin("spawn", str(root / "ground.sdf"), "--name", "ground_plane", "-x", "5")
            yield twin
        finally:
            server.terminate()
            server.wait(timeout=30)
            log.close()


def test_twin_topics_lists_the_systems_topics_and_its_command(served: Served) -> None:
    listed = {t["name"]: t for t in json.loads(served("topics", "--json"))}
    assert listed[CMD_VEL]["type"] == "geometry_msgs/msg/Twist" and listed[CMD_VEL]["command"]
    assert listed[ODOMETRY]["type"] == "nav_msgs/msg/Odometry" and not listed[ODOMETRY]["command"]
    assert listed[TF]["type"] == "tf2_msgs/msg/TFMessage"
    assert "/vehicle_blue/odom" not in listed and "/vehicle_blue/cmd_vel" not in listed
    assert not [t for t in listed.values() if t["entity"] == "ground_plane"], "a static model"
    table = served("topics")
    assert CMD_VEL in table and "command (in)" in table


def test_odometry_and_its_tf_carry_the_systems_frames(served: Served) -> None:
    got = served.peer("odometry", "1.5", ODOMETRY, TF)["messages"]
    assert got[ODOMETRY] and got[TF], "no odometry or drive tf received"
    odometry = got[ODOMETRY][-1]
    assert (odometry["header"]["frame_id"], odometry["child_frame_id"]) == (
        "vehicle_blue/odom",
        "vehicle_blue/chassis",
    )
    transforms = got[TF][-1]["transforms"]
    assert [(t["header"]["frame_id"], t["child_frame_id"]) for t in transforms] == [
        ("vehicle_blue/odom", "vehicle_blue/chassis")
    ]
    parents = {
        t["child_frame_id"]: t["header"]["frame_id"]
        for key in ("/tf_static", "/tf")
        for message in got[key]
        for t in message["transforms"]
    }
    assert parents["vehicle_blue/odom"] == "world"
    assert parents["vehicle_blue/chassis"] == "vehicle_blue/odom"
    assert not [f for f in parents if f.startswith("vehicle_blue/vehicle_blue/")], parents


def test_a_twist_on_the_systems_cmd_vel_drives_the_base(served: Served) -> None:
    """(0.2 m/s, 0.5 rad/s) over DDS, 2 s of sim time: the unicycle's arc (0.337, 0.184) m and
    1 rad, within 10 % of its radius and heading."""
    served("pause")
    try:
        start = json.loads(served("pose", "vehicle_blue", "--json"))
        sent = served.peer("drive", CMD_VEL, str(VX), str(WZ), "0.6")
        assert sent["matched"] == 1, "the twin's reader did not match /model/vehicle_blue/cmd_vel"
        assert CMD_VEL in json.loads(served("ros", "status", "--json"))["inputs"]
        served("step", str(STEPS))
        end = json.loads(served("pose", "vehicle_blue", "--json"))
    finally:
        served("drive", "vehicle_blue", "--linear", "0", "--angular", "0")
        served("resume")
    yaw = start["yaw"]
    dx, dy = end["x"] - start["x"], end["y"] - start["y"]
    x = math.cos(yaw) * dx + math.sin(yaw) * dy
    y = -math.sin(yaw) * dx + math.cos(yaw) * dy
    turned = math.remainder(end["yaw"] - yaw, math.tau)
    t, radius = STEPS * 1e-3, VX / WZ
    arc = (radius * math.sin(WZ * t), radius * (1 - math.cos(WZ * t)))
    assert turned == pytest.approx(WZ * t, rel=ARC_TOL), f"turned {turned} rad"
    assert math.hypot(x - arc[0], y - arc[1]) < ARC_TOL * radius, f"({x}, {y}) vs {arc}"
