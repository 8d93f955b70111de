"""A private network namespace for tests: only this machine's loopback, or a LAN-like pair.

`unshare -n` makes a namespace whose only device is `lo` (down); a `sleep` holds it while
`nsenter -n` runs commands inside. Multicast is switched on for `lo` and 224.0.0.0/4 routed to
it, so DDS's default discovery (SPDP multicast to 239.255.0.1) works there as on a LAN. With
`lan=True` a veth pair (`eth0` 10.77.0.1/24, its peer `eth1` up without an address, multicast on)
plays a network card: both ends are in the namespace, so nothing sent on it leaves the machine.
Needs root (CAP_SYS_ADMIN) and util-linux's `unshare` and `nsenter`.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import time
from collections.abc import Sequence

# What decides a ROS 2 participant's reach: a test's namespace starts without the runner's.
SCOPE_VARIABLES = (
    "ROS_DOMAIN_ID", "ROS_AUTOMATIC_DISCOVERY_RANGE", "ROS_STATIC_PEERS", "ROS_LOCALHOST_ONLY",
    "ROS_DISTRO", "CYCLONEDDS_URI", "FASTRTPS_DEFAULT_PROFILES_FILE", "RMW_IMPLEMENTATION",
    "TWIN_WORLD",
)  # fmt: skip


def clean_env() -> dict[str, str]:
    """This process's environment without SCOPE_VARIABLES."""
    return {k: v for k, v in os.environ.items() if k not in SCOPE_VARIABLES}


SETUP_TIMEOUT_S = 10.0  # [s] for `unshare` to leave this namespace
LAN_ADDRESS = "10.77.0.1"  # eth0's address: a private network no test machine is on
SETUP_LO = (
    ("ip", "link", "set", "lo", "up"),
    ("ip", "link", "set", "lo", "multicast", "on"),
    ("ip", "route", "add", "224.0.0.0/4", "dev", "lo"),
)
SETUP_LAN = (  # no IPv6 on it: the kernel's own router and listener messages would count as sent
    ("sysctl", "-q", "-w", "net.ipv6.conf.default.disable_ipv6=1"),
    ("ip", "link", "add", "eth0", "type", "veth", "peer", "name", "eth1"),
    ("ip", "addr", "add", f"{LAN_ADDRESS}/24", "dev", "eth0"),
    ("ip", "link", "set", "eth0", "multicast", "on", "up"),
    ("ip", "link", "set", "eth1", "multicast", "on", "up"),
    ("ip", "route", "replace", "224.0.0.0/4", "dev", "eth0"),  # multicast's default route
)


def available() -> str | None:
    """Why namespaces cannot be made here, or None when they can."""
    if os.geteuid() != 0:
        return "needs root to make a network namespace"
    missing = [t for t in ("unshare", "nsenter", "ip") if shutil.which(t) is None]
    return f"needs {', '.join(missing)}" if missing else None


class Namespace:
    """A network namespace held by a `sleep` process, set up as the module docstring says."""

    def __init__(self, lan: bool = False, lo_multicast: bool = True) -> None:
        """`lo_multicast=False`: `lo` as most hosts have it, up without multicast or its route."""
        self._holder = subprocess.Popen(["unshare", "-n", "sleep", "3600"])
        setup = SETUP_LO if lo_multicast else SETUP_LO[:1]
        try:
            self._wait_until_apart()
            for command in setup + (SETUP_LAN if lan else ()):
                self.run(command, check=True)
        except BaseException:
            self.close()
            raise

    def _wait_until_apart(self) -> None:
        """Waits until the holder has left this process's namespace (`unshare` runs first)."""
        own = os.readlink("/proc/self/ns/net")
        deadline = time.monotonic() + SETUP_TIMEOUT_S
        while os.readlink(f"/proc/{self._holder.pid}/ns/net") == own:
            if time.monotonic() > deadline or self._holder.poll() is not None:
                raise RuntimeError("unshare -n did not make a network namespace")
            time.sleep(0.01)

    def prefix(self) -> list[str]:
        """The command prefix that runs a program inside the namespace."""
        return ["nsenter", "-t", str(self._holder.pid), "-n"]

    def run(self, command: Sequence[str], **kwargs) -> subprocess.CompletedProcess:
        kwargs.setdefault("capture_output", True)
        kwargs.setdefault("text", True)
        return subprocess.run([*self.prefix(), *command], **kwargs)

    def popen(self, command: Sequence[str], **kwargs) -> subprocess.Popen:
        return subprocess.Popen([*self.prefix(), *command], **kwargs)

    def sent_on(self, device: str) -> int:
        """Packets sent on `device` since it was made (the kernel's counter)."""
        shown = self.run(["ip", "-s", "-j", "link", "show", device], check=True).stdout
        return int(json.loads(shown)[0]["stats64"]["tx"]["packets"])

    def close(self) -> None:
        self._holder.kill()
        self._holder.wait()

    def __enter__(self) -> Namespace:
        return self

    def __exit__(self, *_: object) -> None:
        self.close()
