"""Where the ROS 2 participant may be seen: ROS's variables read as ROS reads them, loopback only
(multicast on it) unless widened, and Cyclone's XML saying exactly that (pure functions, no DDS);
`twin serve --ros` refuses a bad variable before it opens a socket."""

from __future__ import annotations

import os
import subprocess
import sys
import xml.etree.ElementTree as ET

import pytest

from twin_cli.errors import InvalidRequestError
from twin_cli.ros.scope import LOOPBACK, cyclone_config, scope_from

ENFORCED = {"ROS_SECURITY_ENABLE": "true", "ROS_SECURITY_STRATEGY": "Enforce"}


def _general(scope) -> tuple[ET.Element, ET.Element]:
    domain = ET.fromstring(cyclone_config(scope)).find("Domain")
    assert domain is not None
    return domain.find("General"), domain.find("Discovery")


def test_by_default_only_loopback_with_multicast_on_it_and_loopback_as_the_peer() -> None:
    """Multicast on loopback: how Humble's localhost-only nodes announce themselves."""
    scope = scope_from({})
    assert (scope.domain_id, scope.range, scope.local_only) == (0, "LOCALHOST", True)
    general, discovery = _general(scope)
    interface = general.find("Interfaces/NetworkInterface")
    assert interface is not None and interface.get("address") == LOOPBACK
    assert interface.get("multicast") == "true"
    assert general.findtext("AllowMulticast") == "true"
    assert [p.get("address") for p in discovery.iter("Peer")] == [LOOPBACK]
    assert discovery.findtext("ParticipantIndex") == "auto"
    assert discovery.findtext("MaxAutoParticipantIndex") == "32"


@pytest.mark.parametrize(
    ("env", "interface", "local_only", "multicast"),
    [
        ({"ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"}, None, True, True),
        ({"ROS_LOCALHOST_ONLY": "1", "ROS_AUTOMATIC_DISCOVERY_RANGE": "SUBNET"}, None, True, True),
        ({"ROS_LOCALHOST_ONLY": "0"}, None, True, True),  # Humble's 0 does not widen alone
        ({"ROS_AUTOMATIC_DISCOVERY_RANGE": "OFF"}, None, True, False),
        ({"ROS_AUTOMATIC_DISCOVERY_RANGE": "subnet"}, None, False, True),
        ({"ROS_AUTOMATIC_DISCOVERY_RANGE": "SYSTEM_DEFAULT"}, None, False, True),
        ({}, "192.168.1.20", False, True),
        ({}, "eth0", False, True),
    ],
)
def test_only_an_explicit_setting_widens_the_scope(env, interface, local_only, multicast) -> None:
    scope = scope_from(env, interface)
    assert scope.local_only is local_only, scope
    general, _ = _general(scope)
    allowed = general.findtext("AllowMulticast")  # absent: Cyclone's default, multicast on
    assert (allowed != "false") is multicast, allowed


def test_off_has_no_peers_and_an_interface_is_named_as_given() -> None:
    """OFF as rmw_cyclonedds_cpp: no participant index and a domain tag of this process's."""
    off = scope_from({"ROS_AUTOMATIC_DISCOVERY_RANGE": "OFF", "ROS_STATIC_PEERS": "10.0.0.7"})
    domain = ET.fromstring(cyclone_config(off, pid=4321)).find("Domain")
    discovery = domain.find("Discovery")
    assert list(discovery.iter("Peer")) == []
    assert discovery.findtext("ParticipantIndex") == "none"
    assert discovery.findtext("Tag") == "ros_discovery_off_4321"
    general, _ = _general(scope_from({}, "eth0"))
    assert general.find("Interfaces/NetworkInterface").get("name") == "eth0"


def test_static_peers_join_loopback_by_unicast_only() -> None:
    scope = scope_from({"ROS_STATIC_PEERS": "10.0.0.7; 10.0.0.8"})
    assert scope.peers == (LOOPBACK, "10.0.0.7", "10.0.0.8") and not scope.local_only
    assert (scope.interface, scope.multicast) == (None, False), "loopback could not reach them"
    assert "unicast to 10.0.0.7, 10.0.0.8" in scope.describe()
    assert scope_from({"ROS_STATIC_PEERS": "127.0.0.2"}).local_only


def test_localhost_only_drops_static_peers_and_system_default_ignores_them() -> None:
    """rcl: ROS_LOCALHOST_ONLY=1 is the LOCALHOST range without static peers; rmw_cyclonedds_cpp:
    SYSTEM_DEFAULT leaves Cyclone's defaults, peers and participant index alike."""
    only = scope_from({"ROS_LOCALHOST_ONLY": "1", "ROS_STATIC_PEERS": "10.0.0.7"})
    assert (only.range, only.peers, only.local_only) == ("LOCALHOST", (LOOPBACK,), True)
    system = scope_from(
        {"ROS_AUTOMATIC_DISCOVERY_RANGE": "SYSTEM_DEFAULT", "ROS_STATIC_PEERS": "10.0.0.7"}
    )
    general, discovery = _general(system)
    assert (list(general), list(discovery)) == ([], []), cyclone_config(system)


def test_subnet_keeps_multicast_takes_the_peers_and_a_participant_index() -> None:
    """As rmw_cyclonedds_cpp's SUBNET: the index with or without peers, so Jazzy's LOCALHOST
    nodes, which probe 127.0.0.1's participant ports, find the twin."""
    for peers, wanted in (("", []), ("10.0.0.7;10.0.0.8", ["10.0.0.7", "10.0.0.8"])):
        env = {"ROS_AUTOMATIC_DISCOVERY_RANGE": "SUBNET", "ROS_STATIC_PEERS": peers}
        general, discovery = _general(scope_from(env))
        assert general.find("Interfaces") is None and general.find("AllowMulticast") is None
        assert [p.get("address") for p in discovery.iter("Peer")] == wanted
        assert discovery.findtext("ParticipantIndex") == "auto"


@pytest.mark.parametrize(
    ("env", "distro", "wanted"),
    [({}, None, "jazzy"), ({"ROS_DISTRO": "humble"}, None, "humble"),
     ({"ROS_DISTRO": "humble"}, "jazzy", "jazzy"), ({"ROS_DISTRO": "Iron"}, None, "iron")],
)  # fmt: skip
def test_the_distribution_is_the_option_else_ros_distro_else_jazzy(env, distro, wanted) -> None:
    assert scope_from(env, distro=distro).distro == wanted


def test_domain_id_is_read_from_ros_domain_id() -> None:
    assert scope_from({"ROS_DOMAIN_ID": "42"}).domain_id == 42
    assert scope_from({"ROS_DOMAIN_ID": ""}).domain_id == 0


@pytest.mark.parametrize(
    ("env", "interface", "names"),
    [
        ({"ROS_DOMAIN_ID": "300"}, None, ("ROS_DOMAIN_ID=300", "0-232")),
        ({"ROS_DOMAIN_ID": "abc"}, None, ("ROS_DOMAIN_ID=abc", "unset it")),
        ({"ROS_AUTOMATIC_DISCOVERY_RANGE": "LAN"}, None, ("LAN", "LOCALHOST, SUBNET")),
        ({"ROS_STATIC_PEERS": "robot.local"}, None, ("robot.local", "192.168.1.20")),
        ({"ROS_LOCALHOST_ONLY": "2"}, None, ("ROS_LOCALHOST_ONLY=2", "set it to 1")),
        ({"ROS_LOCALHOST_ONLY": "true"}, None, ("ROS_LOCALHOST_ONLY=true", "or 0")),
        ({"ROS_DISTRO": "ardent2"}, None, ("ROS_DISTRO 'ardent2'", "humble")),
        ({}, "<eth0>", ("--ros-interface", "eth0")),
        (ENFORCED, None, ("ROS_SECURITY_STRATEGY=Enforce", "security plugins", "Permissive")),
    ],
)
def test_a_bad_setting_names_itself_and_the_fix(env, interface, names) -> None:
    with pytest.raises(InvalidRequestError) as caught:
        scope_from(env, interface)
    for name in names:
        assert name in str(caught.value), str(caught.value)


@pytest.mark.parametrize(
    ("env", "unsecured"),
    [({"ROS_SECURITY_ENABLE": "true"}, True),
     ({"ROS_SECURITY_ENABLE": "true", "ROS_SECURITY_STRATEGY": "Permissive"}, True),
     ({"ROS_SECURITY_ENABLE": "True"}, False),  # rcl enables security for "true" only
     ({"ROS_SECURITY_STRATEGY": "Enforce"}, False)],
)  # fmt: skip
def test_sros2_asked_permissively_runs_unsecured_and_says_so(env, unsecured) -> None:
    """rcl runs a node whose security files are missing unsecured unless the strategy is
    Enforce; twin, whose Cyclone DDS has no security plugins, is always that node."""
    scope = scope_from(env)
    assert scope.unsecured is unsecured
    assert ("unsecured: ROS_SECURITY_ENABLE is true" in scope.describe()) is unsecured


def test_the_description_says_where_the_participant_reaches() -> None:
    assert "nothing leaves this machine" in scope_from({}).describe()
    assert "interface eth0, multicast" in scope_from({}, "eth0").describe()
    wide = scope_from({"ROS_AUTOMATIC_DISCOVERY_RANGE": "SUBNET", "ROS_DOMAIN_ID": "3"})
    assert wide.describe() == "ROS 2 domain 3, SUBNET: Cyclone's interface choice, multicast"


@pytest.mark.parametrize(
    ("variable", "value", "fix"),
    [
        ("ROS_LOCALHOST_ONLY", "2", "set it to 1"),
        ("ROS_AUTOMATIC_DISCOVERY_RANGE", "LAN", "SUBNET"),
        ("ROS_SECURITY_ENABLE", "true", "Permissive"),
    ],
)
def test_twin_serve_ros_with_a_bad_variable_exits_2_with_one_message(
    variable: str, value: str, fix: str, tmp_path
) -> None:
    """Before any socket: exit 2, one line naming the variable, its value and the fix."""
    env = {**os.environ, **ENFORCED, "TWIN_RUNTIME_DIR": str(tmp_path), variable: value}
    done = subprocess.run(
        [sys.executable, "-m", "twin_cli", "serve", "--ros", "--world", "bad_scope"],
        env=env, capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert done.returncode == 2, done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and f"{variable}={value}" in lines[0] and fix in lines[0], lines
