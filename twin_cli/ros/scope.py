"""Where the twin's ROS 2 participant may be seen: its DDS domain and Cyclone DDS configuration.

ROS 2 scopes discovery with environment variables; twin reads the same ones, but its default is
the narrowest: without an explicit widening, Cyclone DDS is configured to use only the loopback
interface (127.0.0.1) with multicast off and 127.0.0.1 as its one unicast peer, so no packet
leaves the machine. The configuration is always given to Cyclone as XML (never read from
CYCLONEDDS_URI), so what the twin opens is decided here alone.

- `ROS_DOMAIN_ID` (0-232; default 0): the domain, hence the UDP ports (7400 + 250·id + ...).
- `ROS_AUTOMATIC_DISCOVERY_RANGE` (Jazzy): LOCALHOST (twin's default), SUBNET (Cyclone's own
  interface choice and multicast, as a plain ROS 2 node), OFF (no peers: nothing discovered,
  nothing sent), SYSTEM_DEFAULT (same as SUBNET here).
- `ROS_STATIC_PEERS` (Jazzy, `;`-separated addresses): extra unicast peers, in any range but OFF;
  with LOCALHOST, discovery and data go to them by unicast only (no multicast), on the interface
  Cyclone chooses (a loopback interface could not reach them).
- `ROS_LOCALHOST_ONLY=1` (Humble): LOCALHOST; `0` does not widen on its own.
- `--ros-interface ADDRESS`: that interface instead of loopback, multicast as Cyclone's default.
"""

from __future__ import annotations

import ipaddress
import os
from collections.abc import Mapping
from dataclasses import dataclass
from xml.sax.saxutils import quoteattr

from twin_cli.errors import InvalidRequestError

LOOPBACK = "127.0.0.1"
MAX_DOMAIN_ID = 232  # Cyclone's port mapping (7400 + 250·id) stays below 65535 up to here
RANGES = ("LOCALHOST", "SUBNET", "OFF", "SYSTEM_DEFAULT")
MAX_PARTICIPANTS = 32  # unicast discovery probes this many participant ports per peer


@dataclass(frozen=True)
class Scope:
    """The participant's reach.

    Attributes:
        domain_id: the DDS domain (ROS_DOMAIN_ID).
        range: one of RANGES.
        interface: the network interface's address or name, or None (Cyclone chooses).
        multicast: whether Cyclone may use multicast.
        peers: unicast discovery peers.
    """

    domain_id: int
    range: str
    interface: str | None
    multicast: bool
    peers: tuple[str, ...]

    @property
    def local_only(self) -> bool:
        """Nothing leaves the machine: loopback only, no multicast, loopback peers only."""
        return (
            self.interface == LOOPBACK
            and not self.multicast
            and all(ipaddress.ip_address(p).is_loopback for p in self.peers)
        )

    def describe(self) -> str:
        """One line for the server's log and the start reply."""
        if self.local_only:
            where = "loopback only (nothing leaves this machine)"
        elif not self.multicast:
            where = f"loopback and unicast to {', '.join(self.peers[1:])}"
        elif self.interface is not None:
            where = f"interface {self.interface}" + (", multicast" if self.multicast else "")
        else:
            where = f"{self.range}: Cyclone's interface choice, multicast"
        return f"ROS 2 domain {self.domain_id}, {where}"


def scope_from(env: Mapping[str, str] | None = None, interface: str | None = None) -> Scope:
    """The scope ROS's variables in `env` (default: this process's) and `--ros-interface` ask.

    Raises:
        InvalidRequestError: a variable or the interface that cannot be read (the message names
            it and the values it takes).
    """
    env = os.environ if env is None else env
    domain = _domain_id(env.get("ROS_DOMAIN_ID", ""))
    wanted = env.get("ROS_AUTOMATIC_DISCOVERY_RANGE", "").strip().upper()
    if wanted and wanted not in RANGES:
        raise InvalidRequestError(
            f"ROS_AUTOMATIC_DISCOVERY_RANGE={wanted}",
            "is not a discovery range",
            f"set one of {', '.join(RANGES)} (or unset it: LOCALHOST)",
        )
    if env.get("ROS_LOCALHOST_ONLY", "").strip() == "1":
        wanted = "LOCALHOST"
    peers = tuple(_address(p, "ROS_STATIC_PEERS") for p in _split(env.get("ROS_STATIC_PEERS", "")))
    if interface is not None:
        return Scope(domain, wanted or "SUBNET", _interface(interface), True, peers)
    if wanted in ("SUBNET", "SYSTEM_DEFAULT"):
        return Scope(domain, wanted, None, True, peers)
    if wanted == "OFF":
        return Scope(domain, wanted, LOOPBACK, False, ())
    remote = [p for p in peers if not ipaddress.ip_address(p).is_loopback]
    if remote:  # asked for by name: unicast to them (Cyclone's interface choice), no multicast
        return Scope(domain, "LOCALHOST", None, False, (LOOPBACK, *peers))
    return Scope(domain, "LOCALHOST", LOOPBACK, False, (LOOPBACK, *peers))


def cyclone_config(scope: Scope) -> str:
    """Cyclone DDS's XML configuration for `scope` (the whole of it: nothing else is read).

    ParticipantIndex auto: without multicast, a participant finds others by sending to the
    discovery ports of participant indices 0..MAX_PARTICIPANTS at each peer.
    """
    general = [f"<AllowMulticast>{str(scope.multicast).lower()}</AllowMulticast>"]
    if scope.interface is not None:
        key = "address" if _is_address(scope.interface) else "name"
        general.insert(
            0, f"<Interfaces><NetworkInterface {key}={quoteattr(scope.interface)}/></Interfaces>"
        )
    peers = "".join(f"<Peer address={quoteattr(p)}/>" for p in scope.peers)
    discovery = (
        "<ParticipantIndex>auto</ParticipantIndex>"
        f"<MaxAutoParticipantIndex>{MAX_PARTICIPANTS}</MaxAutoParticipantIndex>"
        f"<Peers>{peers}</Peers>"
        if peers
        else ""
    )
    return (
        '<CycloneDDS><Domain Id="any">'
        f"<General>{''.join(general)}</General><Discovery>{discovery}</Discovery>"
        "</Domain></CycloneDDS>"
    )


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
