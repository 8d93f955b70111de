"""Stock ROS 2 nodes find `twin serve --ros` started with the same ROS variables, and drive it.

Each test runs in a network namespace of its own (`netns`): only `lo`, with multicast on it, so
ROS's default discovery (SUBNET: SPDP multicast) is exercised without a packet leaving the
machine; or `lo` and a LAN-like veth card, `eth0`, as on a robot's computer. There, twin's
default range (LOCALHOST) must put nothing on the card.

The peers share no code with twin: `rmw_peer.py` configures Cyclone DDS as rmw_cyclonedds_cpp
does on Humble's and on Jazzy's code path, and `fastdds_peer.py` is a stock rclpy node on
rmw_fastrtps_cpp, run by the Python that TWIN_FASTDDS_PYTHON names (else `.venv-ros/bin/python`
in the repository: `pip install ros-jazzy-rclpy ros-jazzy-rmw-fastrtps-cpp
ros-jazzy-geometry-msgs ros-jazzy-rosgraph-msgs`); without one, only the Cyclone peers run. Each
peer counts /clock for SESSION_S while sending a Twist on /bot/cmd_vel, and the base must move.
"""

from __future__ import annotations

import json
import math
import os
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import drive_models as dm
import netns
import pytest

pytest.importorskip("cyclonedds", reason="cyclonedds is not installed (CI installs it)")
if (why := netns.available()) is not None:
    pytest.skip(why, allow_module_level=True)
pytestmark = pytest.mark.xdist_group("ros_discovery")

HERE = Path(__file__).parent
ROOT = HERE.parents[2]
WORLD = "discovery"
SESSION_S = 2.5  # [s] each peer listens and drives
VX = 0.3  # [m/s] the peer's Twist
MIN_CLOCK = 50  # /clock samples in SESSION_S: 100 Hz of sim time in real time sends ~250, and
# discovery takes < 1 s (measured: 170-300 received)
MIN_TRAVEL = 0.1  # [m] in SESSION_S at VX (measured: 0.3-0.6 m, the command outlives the peer)
DIFF = (
    '<plugin name="dd" filename="libgazebo_ros_diff_drive.so"><left_joint>wheel_left_joint'
    "</left_joint><right_joint>wheel_right_joint</right_joint><wheel_separation>0.3"
    "</wheel_separation><wheel_diameter>0.1</wheel_diameter></plugin>"
)
# rmw_fastrtps_shared_cpp's Humble participant.cpp with localhost_only: built-in transports off,
# UDPv4 whitelisting 127.0.0.1 and shared memory instead
HUMBLE_LOCALHOST_ONLY_PROFILE = """<?xml version="1.0" encoding="UTF-8"?>
<profiles xmlns="http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles">
  <transport_descriptors>
    <transport_descriptor><transport_id>udp_localhost</transport_id><type>UDPv4</type>
      <interfaceWhiteList><address>127.0.0.1</address></interfaceWhiteList>
    </transport_descriptor>
    <transport_descriptor><transport_id>shm</transport_id><type>SHM</type></transport_descriptor>
  </transport_descriptors>
  <participant profile_name="humble_localhost_only" is_default_profile="true"><rtps>
    <userTransports><transport_id>udp_localhost</transport_id><transport_id>shm</transport_id>
    </userTransports>
    <useBuiltinTransports>false</useBuiltinTransports>
  </rtps></participant>
</profiles>
"""
HUMBLE_PROFILE = "HUMBLE_PROFILE"  # stands for the profile's path in a peer's variables


def _fastdds_python() -> str | None:
    named = os.environ.get("TWIN_FASTDDS_PYTHON") or str(ROOT / ".venv-ros/bin/python")
    return named if Path(named).exists() else None


def _env(variables: dict[str, str], **extra: str) -> dict[str, str]:
    env = netns.clean_env()
    return {**env, **variables, **extra}


class Twin:
    """`twin` commands run inside the namespace against the world served there."""

    def __init__(self, ns: netns.Namespace, runtime: Path, variables: dict[str, str]) -> None:
        self.ns, self.env = ns, _env(variables, TWIN_RUNTIME_DIR=str(runtime))

    def __call__(self, *args: str) -> str:
        command = [sys.executable, "-m", "twin_cli.cli.app", *args, "--world", WORLD]
        done = self.ns.run(command, env=self.env, cwd=ROOT, timeout=120)
        assert done.returncode == 0, f"twin {' '.join(args)}: {done.stderr[-1500:]}"
        return done.stdout

    def position(self) -> tuple[float, float]:
        pose = json.loads(self("pose", "bot", "--json"))
        return pose["x"], pose["y"]


@contextmanager
def served(
    ns: netns.Namespace, root: Path, variables: dict[str, str], *serve_args: str
) -> Iterator[Twin]:
    """`twin serve --ros [serve_args]` in `ns` with ROS `variables`, a diff-drive base `bot` on
    the ground."""
    twin = Twin(ns, root / "runtime", variables)
    log = open(root / "serve.out", "wb")  # noqa: SIM115 (the server writes to it until the end)
    command = [sys.executable, "-m", "twin_cli.cli.app", "serve", "--world", WORLD, "--ros"]
    command += serve_args
    server = ns.popen(command, env=twin.env, cwd=ROOT, stdout=log, stderr=log)
    try:
        deadline = time.monotonic() + 60.0
        while ns.run(command[:3] + ["ros", "status", "--world", WORLD], env=twin.env).returncode:
            assert server.poll() is None, (root / "serve.out").read_text()[-1500:]
            assert time.monotonic() < deadline, "twin serve --ros did not start in 60 s"
            time.sleep(0.3)
        (root / "bot.urdf").write_text(dm.two_wheel_base(DIFF))
        twin("spawn", str(root / "bot.urdf"), "--name", "bot", "--on-ground")
        yield twin
    finally:
        server.terminate()
        server.wait(timeout=30)
        log.close()


def _session(twin: Twin, root: Path, peer: tuple[str, str, dict[str, str]]) -> dict:
    """One peer's session (`rmw_peer.py` / `fastdds_peer.py`), with the base's travel [m]."""
    kind, distro, variables = peer
    profile = root / "humble_localhost_only.xml"
    profile.write_text(HUMBLE_LOCALHOST_ONLY_PROFILE)
    variables = {k: str(profile) if v == HUMBLE_PROFILE else v for k, v in variables.items()}
    if kind == "cyclone":
        command = [sys.executable, str(HERE / "rmw_peer.py"), distro]
    else:
        command = [str(_fastdds_python()), str(HERE / "fastdds_peer.py")]
        variables = {**variables, "RMW_IMPLEMENTATION": "rmw_fastrtps_cpp"}
    start = twin.position()
    command += ["session", str(SESSION_S), "bot", str(VX)]
    done = twin.ns.run(command, env=_env(variables), cwd=HERE, timeout=120)
    assert done.returncode == 0, f"{kind} {distro} peer: {done.stderr[-1500:]}"
    end = twin.position()
    twin("drive", "bot", "--linear", "0", "--angular", "0")
    return {**json.loads(done.stdout), "travel": math.dist(start, end)}


def _meets(twin: Twin, root: Path, peers: dict[str, tuple[str, str, dict[str, str]]]) -> None:
    """Each peer (the Fast DDS ones only where a Python with rclpy is at hand) gets /clock,
    matches the base's cmd_vel reader and moves the base."""
    if _fastdds_python() is None:
        peers = {name: peer for name, peer in peers.items() if peer[0] != "fastdds"}
    results = {name: _session(twin, root, peer) for name, peer in peers.items()}
    for name, got in results.items():
        assert got["clock"] >= MIN_CLOCK, f"{name}: {got['clock']} /clock samples; {results}"
        assert got["matched"] >= 1, f"{name}: no cmd_vel reader matched; {results}"
        assert got["travel"] >= MIN_TRAVEL, f"{name}: the base went {got['travel']} m; {results}"
        if "nodes" in got:  # rclpy's graph: what `ros2 node list` shows
            assert {"/twin", "/twin_commands"} <= set(got["nodes"]), f"{name}: {got['nodes']}"


# Peers by (kind, code path, variables): Humble's rmw ignores the range and the static peers.
LOCALHOST = {"ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"}
ONLY = {"ROS_LOCALHOST_ONLY": "1"}
SETTINGS = {
    "default (SUBNET nodes)": ({}, {
        "cyclone humble": ("cyclone", "humble", {}),
        "cyclone jazzy": ("cyclone", "jazzy", {}),
        "fastdds jazzy": ("fastdds", "jazzy", {}),
    }),
    "ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST": (LOCALHOST, {
        "cyclone jazzy": ("cyclone", "jazzy", LOCALHOST),
        "fastdds jazzy": ("fastdds", "jazzy", LOCALHOST),
    }),
    "ROS_LOCALHOST_ONLY=1": (ONLY, {
        "cyclone humble": ("cyclone", "humble", ONLY),
        "cyclone jazzy": ("cyclone", "jazzy", ONLY),
        "fastdds humble": ("fastdds", "humble", {"FASTRTPS_DEFAULT_PROFILES_FILE": HUMBLE_PROFILE}),
        "fastdds jazzy": ("fastdds", "jazzy", ONLY),
    }),
}  # fmt: skip


@pytest.mark.parametrize("setting", list(SETTINGS))
def test_a_stock_node_with_the_same_variables_gets_clock_and_drives_the_base(
    setting: str, tmp_path: Path
) -> None:
    """Only `lo` (multicast on): every peer receives /clock and moves the base by cmd_vel."""
    variables, peers = SETTINGS[setting]
    with netns.Namespace() as ns, served(ns, tmp_path, variables) as twin:
        _meets(twin, tmp_path, peers)


def test_on_a_loopback_without_multicast_the_default_meets_every_kind_of_node(
    tmp_path: Path,
) -> None:
    """`lo` as most hosts have it (no MULTICAST flag, no multicast route): twin's default still
    meets default, LOCALHOST and localhost-only peers of both middlewares."""
    peers = {
        "cyclone humble": ("cyclone", "humble", {}),
        "cyclone humble LOCALHOST_ONLY": ("cyclone", "humble", ONLY),
        "cyclone jazzy LOCALHOST": ("cyclone", "jazzy", LOCALHOST),
        "fastdds jazzy": ("fastdds", "jazzy", {}),
        "fastdds humble LOCALHOST_ONLY": (
            "fastdds", "humble", {"FASTRTPS_DEFAULT_PROFILES_FILE": HUMBLE_PROFILE}
        ),
    }  # fmt: skip
    with netns.Namespace(lo_multicast=False) as ns, served(ns, tmp_path, {}) as twin:
        _meets(twin, tmp_path, peers)


LAN_PEER = {"ROS_STATIC_PEERS": netns.LAN_ADDRESS}  # the card's address: another host's place
LAN_SETTINGS = {
    "default: localhost-scoped nodes, nothing on the card": ({}, {
        "cyclone jazzy LOCALHOST": ("cyclone", "jazzy", LOCALHOST),
        "cyclone humble LOCALHOST_ONLY": ("cyclone", "humble", ONLY),
        "fastdds jazzy LOCALHOST": ("fastdds", "jazzy", LOCALHOST),
        "fastdds humble LOCALHOST_ONLY": (
            "fastdds", "humble", {"FASTRTPS_DEFAULT_PROFILES_FILE": HUMBLE_PROFILE}
        ),
    }),
    "ROS_AUTOMATIC_DISCOVERY_RANGE=SUBNET": ({"ROS_AUTOMATIC_DISCOVERY_RANGE": "SUBNET"}, {
        "cyclone humble": ("cyclone", "humble", {}),
        "cyclone jazzy": ("cyclone", "jazzy", {}),
        "fastdds jazzy": ("fastdds", "jazzy", {}),
    }),
    "ROS_STATIC_PEERS": (LAN_PEER, {
        "cyclone jazzy": ("cyclone", "jazzy", LAN_PEER),
        "fastdds jazzy": ("fastdds", "jazzy", LAN_PEER),
    }),
}  # fmt: skip


@pytest.mark.parametrize("setting", list(LAN_SETTINGS))
def test_with_a_network_card_the_same_variables_meet_and_localhost_stays_off_it(
    setting: str, tmp_path: Path
) -> None:
    """`lo` and `eth0`: every peer receives /clock and drives; in twin's default range, with
    localhost-scoped peers, not one packet is sent on eth0 (its kernel counter)."""
    variables, peers = LAN_SETTINGS[setting]
    with netns.Namespace(lan=True) as ns, served(ns, tmp_path, variables) as twin:
        before = ns.sent_on("eth0")
        _meets(twin, tmp_path, peers)
        if not variables:
            assert ns.sent_on("eth0") == before, "twin's LOCALHOST scope sent on the card"


@pytest.mark.parametrize(
    ("distro", "gid_size", "variables", "serve_args"),
    [
        ("humble", 24, {}, ("--ros-distro", "humble")),
        ("humble", 24, {"ROS_DISTRO": "humble"}, ()),
        ("jazzy", 16, {}, ()),
    ],
)
def test_the_nodes_are_listed_with_the_distributions_gids_and_the_enclave(
    distro: str, gid_size: int, variables: dict, serve_args: tuple, tmp_path: Path
) -> None:
    """`--ros-distro`, else ROS_DISTRO, else Jazzy shapes `ros_discovery_info` as that
    distribution's `ros2 node list` reads it (Gid of RMW_GID_STORAGE_SIZE bytes: 24 in Humble,
    16 in Jazzy), and each of twin's participants carries rmw's USER_DATA `enclave=/;`."""
    with netns.Namespace() as ns, served(ns, tmp_path, variables, *serve_args):
        command = [sys.executable, str(HERE / "rmw_peer.py"), distro, "graph", "3"]
        done = ns.run(command, env=_env({}), cwd=HERE, timeout=120)
        assert done.returncode == 0, done.stderr[-1500:]
        got = json.loads(done.stdout)
    nodes = {(namespace, name): sizes for namespace, name, sizes in got["nodes"]}
    for name in ("twin", "twin_commands"):
        assert nodes.get(("/", name)) == [gid_size], f"/{name}: GID sizes; {got}"
    assert got["user_data"] == ["enclave=/;"], f"USER_DATA of the participants: {got}"
