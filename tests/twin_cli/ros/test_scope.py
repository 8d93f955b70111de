"""Where the ROS 2 participant may be seen: ROS's variables read as ROS reads them, loopback only
unless widened, and Cyclone's XML saying exactly that (pure functions, no DDS)."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import pytest

from twin_cli.errors import InvalidRequestError
from twin_cli.ros.scope import LOOPBACK, cyclone_config, scope_from


def _general(scope) -> tuple[ET.Element, ET.Element]:
    domain = ET.fromstring(cyclone_config(scope)).find("Domain")
    assert domain is not None
    return domain.find("General"), domain.find("Discovery")


def test_by_default_only_loopback_with_multicast_off_and_loopback_as_the_peer() -> None:
    scope = scope_from({})
    assert (scope.domain_id, scope.range, scope.local_only) == (0, "LOCALHOST", True)
    general, discovery = _general(scope)
    interface = general.find("Interfaces/NetworkInterface")
    assert interface is not None and interface.get("address") == LOOPBACK
    assert general.findtext("AllowMulticast") == "false"
    assert [p.get("address") for p in discovery.iter("Peer")] == [LOOPBACK]
    assert discovery.findtext("ParticipantIndex") == "auto"


@pytest.mark.parametrize(
    ("env", "interface", "local_only", "multicast"),
    [
        ({"ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"}, None, True, False),
        ({"ROS_LOCALHOST_ONLY": "1", "ROS_AUTOMATIC_DISCOVERY_RANGE": "SUBNET"}, None, True, False),
        ({"ROS_LOCALHOST_ONLY": "0"}, None, True, False),  # Humble's 0 does not widen alone
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
    assert general.findtext("AllowMulticast") == str(multicast).lower()


def test_off_has_no_peers_and_an_interface_is_named_as_given() -> None:
    _, discovery = _general(scope_from({"ROS_AUTOMATIC_DISCOVERY_RANGE": "OFF"}))
    assert list(discovery.iter("Peer")) == []
    general, _ = _general(scope_from({}, "eth0"))
    assert general.find("Interfaces/NetworkInterface").get("name") == "eth0"


def test_static_peers_join_loopback_by_unicast_only() -> None:
    scope = scope_from({"ROS_STATIC_PEERS": "10.0.0.7; 10.0.0.8"})
    assert scope.peers == (LOOPBACK, "10.0.0.7", "10.0.0.8") and not scope.local_only
    assert (scope.interface, scope.multicast) == (None, False), "loopback could not reach them"
    assert "unicast to 10.0.0.7, 10.0.0.8" in scope.describe()
    assert scope_from({"ROS_STATIC_PEERS": "127.0.0.2"}).local_only


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
        ({}, "<eth0>", ("--ros-interface", "eth0")),
    ],
)
def test_a_bad_setting_names_itself_and_the_fix(env, interface, names) -> None:
    with pytest.raises(InvalidRequestError) as caught:
        scope_from(env, interface)
    for name in names:
        assert name in str(caught.value), str(caught.value)


def test_the_description_says_where_the_participant_reaches() -> None:
    assert "nothing leaves this machine" in scope_from({}).describe()
    assert "interface eth0, multicast" in scope_from({}, "eth0").describe()
    wide = scope_from({"ROS_AUTOMATIC_DISCOVERY_RANGE": "SUBNET", "ROS_DOMAIN_ID": "3"})
    assert wide.describe() == "ROS 2 domain 3, SUBNET: Cyclone's interface choice, multicast"
