"""Where the twin's ROS 2 participant may be seen: its DDS domain and Cyclone DDS configuration.

ROS 2 scopes discovery with environment variables; twin reads the same ones and configures its
participant as rmw_cyclonedds_cpp configures a node's (`check_create_domain` in rmw_node.cpp),
so a stock node with the same variables finds it, but its default is the narrowest range,
LOCALHOST. The configuration is always given to Cyclone as XML (never read from
CYCLONEDDS_URI), so what the twin opens is decided here alone.

- `ROS_DOMAIN_ID` (0-232; default 0): the domain, hence the UDP ports (7400 + 250·id + ...).
- `ROS_AUTOMATIC_DISCOVERY_RANGE` (Jazzy): LOCALHOST (twin's default; ROS's is SUBNET),
  SUBNET (Cyclone's own interface choice and multicast, as a plain ROS 2 node), OFF (no peers:
  nothing discovered, nothing sent), SYSTEM_DEFAULT (Cyclone's defaults, static peers ignored).
- LOCALHOST: the loopback interface only, with multicast on it, and 127.0.0.1 as a unicast peer
  probed at participant indices 0-32 (ParticipantIndex auto). Multicast on loopback never
  leaves the machine, and it is how Humble's `ROS_LOCALHOST_ONLY=1` nodes (rmw_cyclonedds_cpp
  on interface 127.0.0.1, rmw_fastrtps_cpp whitelisting 127.0.0.1) announce themselves;
  Jazzy's LOCALHOST nodes of both middlewares probe 127.0.0.1's participant ports instead, and
  find the twin at its index. rmw_cyclonedds_cpp's own LOCALHOST keeps Cyclone's interface
  and turns multicast off, which Humble's localhost-only nodes never hear.
- `ROS_STATIC_PEERS` (Jazzy, `;`-separated addresses): extra unicast peers in SUBNET and
  LOCALHOST; with LOCALHOST and a peer off this machine, twin is configured exactly as
  rmw_cyclonedds_cpp is (Cyclone's interface, multicast off, 127.0.0.1 and the peers), since
  a loopback interface could not reach them.
- `ROS_LOCALHOST_ONLY` (Humble; deprecated in Jazzy): 1 is LOCALHOST without static peers (as
  rcl does), 0 or unset leaves the range to the variable above; other values are refused.
- `--ros-interface ADDRESS`: that interface instead of loopback, multicast as Cyclone's default.
- `ROS_DISTRO` / `--ros-distro`: the distribution the node's GIDs are shaped for (`distro`).
- `ROS_SECURITY_ENABLE=true` (SROS2): the cyclonedds wheel carries no DDS Security plugins
  (authentication, access control, cryptography), so twin cannot be secured. As rcl does for a
  node without its security files: `ROS_SECURITY_STRATEGY=Enforce` refuses to start, any other
  strategy (Permissive, rcl's default) runs unsecured and says so.
"""

from __future__ import annotations

import ipaddress
import os
from collections.abc import Mapping
from dataclasses import dataclass, replace
from xml.sax.saxutils import quoteattr

from twin_cli.errors import InvalidRequestError
from twin_cli.ros.distro import DEFAULT_DISTRO, distro_from

LOOPBACK = "127.0.0.1"
MAX_DOMAIN_ID = 232  # Cyclone's port mapping (7400 + 250·id) stays below 65535 up to here
RANGES = ("LOCALHOST", "SUBNET", "OFF", "SYSTEM_DEFAULT")
MAX_PARTICIPANTS = 32  # rmw_cyclonedds_cpp's MaxAutoParticipantIndex: ports probed per peer
LOCALHOST_ONLY_VALUES = ("0", "1")


@dataclass(frozen=True)
class Scope:
    """The participant's reach.

    Attributes:
        domain_id: the DDS domain (ROS_DOMAIN_ID).
        range: one of RANGES.
        interface: the network interface's address or name, or None (Cyclone chooses).
        multicast: whether Cyclone may use multicast (on the loopback interface in LOCALHOST).
        peers: unicast discovery peers.
        distro: the ROS 2 distribution whose GIDs the node announces (`distro.GID_SIZES`).
    """

    domain_id: int
    range: str
    interface: str | None
    multicast: bool
    peers: tuple[str, ...]
    distro: str = DEFAULT_DISTRO
    unsecured: bool = False  # ROS_SECURITY_ENABLE asked for SROS2, Permissive: run without it

    @property
    def local_only(self) -> bool:
        """Nothing leaves the machine: the LOCALHOST or OFF range on the loopback interface
        (multicast there stays on it) with loopback peers only. `--ros-interface 127.0.0.1` is a
        widened setting on loopback: Cyclone's sockets are left as it binds them."""
        return (
            self.range in ("LOCALHOST", "OFF")
            and self.interface == LOOPBACK
            and all(ipaddress.ip_address(p).is_loopback for p in self.peers)
        )

    def describe(self) -> str:
        """One line for the server's log and the start reply."""
        if self.range == "OFF":
            where = "discovery off (nothing leaves this machine)"
        elif self.local_only:
            where = "loopback only, multicast on it (nothing leaves this machine)"
        elif not self.multicast:
            where = f"loopback and unicast to {', '.join(self.peers[1:])}"
        elif self.interface is not None:
            where = f"interface {self.interface}" + (", multicast" if self.multicast else "")
        else:
            where = f"{self.range}: Cyclone's interface choice, multicast"
        if self.unsecured:
            where += UNSECURED_NOTE
        return f"ROS 2 domain {self.domain_id}, {where}"


def scope_from(
    env: Mapping[str, str] | None = None, interface: str | None = None, distro: str | None = None
) -> Scope:
    """The scope ROS's variables in `env` (default: this process's), `--ros-interface` and
    `--ros-distro` ask.

    Raises:
        InvalidRequestError: a variable or the interface that cannot be read (the message names
            it and the values it takes).
    """
    env = os.environ if env is None else env
    return replace(_scope(env, interface, distro), unsecured=_security_asked(env))


def _scope(env: Mapping[str, str], interface: str | None, distro: str | None) -> Scope:
    domain = _domain_id(env.get("ROS_DOMAIN_ID", ""))
    ros_distro = distro_from(env, distro)
    wanted = _range(env)
    peers = tuple(_address(p, "ROS_STATIC_PEERS") for p in _split(env.get("ROS_STATIC_PEERS", "")))
    if _localhost_only(env):  # rcl: the LOCALHOST range, static peers ignored
        wanted, peers = "LOCALHOST", ()
    if interface is not None:
        return Scope(domain, wanted or "SUBNET", _interface(interface), True, peers, ros_distro)
    if wanted in ("SUBNET", "SYSTEM_DEFAULT"):
        kept = peers if wanted == "SUBNET" else ()  # SYSTEM_DEFAULT: rmw ignores the peers
        return Scope(domain, wanted, None, True, kept, ros_distro)
    if wanted == "OFF":
        return Scope(domain, wanted, LOOPBACK, False, (), ros_distro)
    remote = [p for p in peers if not ipaddress.ip_address(p).is_loopback]
    if remote:  # rmw_cyclonedds_cpp's LOCALHOST: Cyclone's interface, unicast, no multicast
        return Scope(domain, "LOCALHOST", None, False, (LOOPBACK, *peers), ros_distro)
    return Scope(domain, "LOCALHOST", LOOPBACK, True, (LOOPBACK, *peers), ros_distro)


def cyclone_config(scope: Scope, pid: int | None = None) -> str:
    """Cyclone DDS's XML configuration for `scope` (the whole of it: nothing else is read).

    ParticipantIndex auto in every range but OFF and SYSTEM_DEFAULT, as rmw_cyclonedds_cpp
    sets it: a participant finds others by sending to the discovery ports of participant
    indices 0..MAX_PARTICIPANTS at each peer, and is found at its own, so Jazzy's LOCALHOST
    nodes (which probe 127.0.0.1 so) find a SUBNET twin too. OFF is rmw_cyclonedds_cpp's: no
    multicast, no index, and a domain tag of this process's (`pid`, default this one) that no
    other participant has.
    """
    general = []
    if scope.interface is not None:
        key = "address" if _is_address(scope.interface) else "name"
        on_loopback = ' multicast="true"' if scope.local_only and scope.multicast else ""
        general.append(
            f"<Interfaces><NetworkInterface {key}={quoteattr(scope.interface)}{on_loopback}/>"
            "</Interfaces>"
        )
    if not scope.multicast or scope.local_only:
        general.append(f"<AllowMulticast>{str(scope.multicast).lower()}</AllowMulticast>")
    if scope.range == "OFF":
        tag = f"ros_discovery_off_{os.getpid() if pid is None else pid}"
        discovery = f"<ParticipantIndex>none</ParticipantIndex><Tag>{tag}</Tag>"
    elif scope.range == "SYSTEM_DEFAULT":
        discovery = ""
    else:
        peers = "".join(f"<Peer address={quoteattr(p)}/>" for p in scope.peers)
        discovery = (
            "<ParticipantIndex>auto</ParticipantIndex>"
            f"<MaxAutoParticipantIndex>{MAX_PARTICIPANTS}</MaxAutoParticipantIndex>"
            + (f"<Peers>{peers}</Peers>" if peers else "")
        )
    return (
        '<CycloneDDS><Domain Id="any">'
        f"<General>{''.join(general)}</General><Discovery>{discovery}</Discovery>"
        "</Domain></CycloneDDS>"
    )


UNSECURED_NOTE = (
    "; unsecured: ROS_SECURITY_ENABLE is true, but twin's Cyclone DDS has no security plugins"
    " (Permissive, as rcl runs a node without its keys)"
)


def _security_asked(env: Mapping[str, str]) -> bool:
    """Whether SROS2 was asked for (rcl enables it for `true` only), in a strategy that lets a
    node run without it.

    Raises:
        InvalidRequestError: asked with the Enforce strategy, which twin cannot honour.
    """
    if env.get("ROS_SECURITY_ENABLE", "") != "true":
        return False
    if env.get("ROS_SECURITY_STRATEGY", "") == "Enforce":
        raise InvalidRequestError(
            "ROS_SECURITY_ENABLE=true with ROS_SECURITY_STRATEGY=Enforce",
            "asks for DDS Security, and twin's Cyclone DDS (the cyclonedds wheel) has no "
            "security plugins",
            "unset ROS_SECURITY_ENABLE for twin, or set ROS_SECURITY_STRATEGY=Permissive to "
            "run it unsecured",
        )
    return True


def _range(env: Mapping[str, str]) -> str:
    wanted = env.get("ROS_AUTOMATIC_DISCOVERY_RANGE", "").strip().upper()
    if wanted and wanted not in RANGES:
        raise InvalidRequestError(
            f"ROS_AUTOMATIC_DISCOVERY_RANGE={wanted}",
            "is not a discovery range",
            f"set one of {', '.join(RANGES)} (or unset it: LOCALHOST)",
        )
    return wanted


def _localhost_only(env: Mapping[str, str]) -> bool:
    value = env.get("ROS_LOCALHOST_ONLY", "").strip()
    if value and value not in LOCALHOST_ONLY_VALUES:
        raise InvalidRequestError(
            f"ROS_LOCALHOST_ONLY={value}",
            "is neither 0 nor 1",
            "set it to 1 (this machine only) or 0, or unset it",
        )
    return value == "1"


def _domain_id(text: str) -> int:
    if not text.strip():
        return 0
    try:
        value = int(text)
    except ValueError:
        value = -1
    if not 0 <= value <= MAX_DOMAIN_ID:
        raise InvalidRequestError(
            f"ROS_DOMAIN_ID={text}",
            f"is not a domain id in 0-{MAX_DOMAIN_ID}",
            "set it to the ROS_DOMAIN_ID of the ROS 2 nodes to meet (or unset it: 0)",
        )
    return value


def _split(text: str) -> list[str]:
    return [p.strip() for p in text.replace(",", ";").split(";") if p.strip()]


def _address(text: str, what: str) -> str:
    if not _is_address(text):
        raise InvalidRequestError(
            f"{what} {text}", "is not an IP address", "give addresses such as 192.168.1.20"
        )
    return text


def _interface(text: str) -> str:
    text = text.strip()
    if not text or any(c in text for c in "<>\"'&"):
        raise InvalidRequestError(
            f"--ros-interface {text!r}",
            "is not an interface address or name",
            "give e.g. --ros-interface 192.168.1.20 or --ros-interface eth0",
        )
    return text


def _is_address(text: str) -> bool:
    try:
        ipaddress.ip_address(text)
    except ValueError:
        return False
    return True
