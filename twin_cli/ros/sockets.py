"""Keeps the participant's UDP sockets on the loopback device in the loopback-only scope.

Cyclone DDS 11.0.1 binds its receive sockets (the domain's discovery and data ports) to the
wildcard address whatever its configuration says: its UDP transport binds every socket made to
receive, unicast or multicast, to INADDR_ANY and only its send socket to the configured
interface's address; its TCP transport binds to the wildcard as well, and no configuration
element (interfaces, external address, the internal options) changes that. Replacing a wildcard
socket with one bound to 127.0.0.1 on the same port is not safe either: Cyclone's receive threads
already wait on the sockets when the domain is made, one through epoll, which would go on
watching the replaced socket and never see the new one; and the sockets are bound without
SO_REUSEADDR, so the port would be free to any process between the close and the new bind.

So in the loopback-only scope twin binds each UDP socket the new domain opened to the loopback
device (SO_BINDTODEVICE), right after Cyclone made it: the kernel then delivers to it only
datagrams that arrived on loopback, which carries only this host's own traffic, and routes what it
sends only through loopback, so no other host can reach the twin's ports and none is reached from
them. Such a socket still shows its address as 0.0.0.0 wherever the device is not reported
(/proc/net/udp); the kernel's socket diagnostics (`ss`) show 0.0.0.0%lo. A socket bound to a
device needs no privilege while it has none yet (Linux 5.7 and later).

Cyclone's send socket, bound to the interface's address 127.0.0.1, is left as it is: the kernel
never routes a datagram from 127.0.0.1 off loopback, and bound to the device it could not reach
this host's other addresses, where a Jazzy LOCALHOST node on the host's network card (multicast
off, its locators on the card's address) waits for the twin's replies.
"""

from __future__ import annotations

import ipaddress
import logging
import os
import socket
from pathlib import Path

log = logging.getLogger("twin.ros")

LOOPBACK_DEVICE = "lo"  # Linux's name for the loopback interface
FD_DIR = Path("/proc/self/fd")


def open_sockets() -> dict[int, str]:
    """This process's socket descriptors, each with its kernel identity (`socket:[inode]`)."""
    found: dict[int, str] = {}
    try:
        names = os.listdir(FD_DIR)
    except OSError:  # no /proc: not Linux
        return found
    for name in names:
        try:
            target = os.readlink(FD_DIR / name)
        except OSError:  # closed meanwhile
            continue
        if target.startswith("socket:"):
            found[int(name)] = target
    return found


def confine_to_loopback(before: dict[int, str]) -> bool:
    """Binds every UDP socket opened since `before` (`open_sockets`) to the loopback device.

    Returns whether each was bound (False where the platform has no SO_BINDTODEVICE or no new
    UDP socket was found: the caller says the sockets are then on the wildcard address).
    """
    option = getattr(socket, "SO_BINDTODEVICE", None)
    if option is None:
        return False
    fresh = [fd for fd, ident in open_sockets().items() if before.get(fd) != ident]
    bound = 0
    for fd in fresh:
        try:
            sock = socket.socket(fileno=fd)  # borrowed: detached below, never closed here
        except OSError:  # closed meanwhile
            continue
        try:
            if sock.type == socket.SOCK_DGRAM and sock.family in (socket.AF_INET, socket.AF_INET6):
                if _on_loopback_address(sock):
                    bound += 1  # already confined, and free to reach this host's other addresses
                    continue
                sock.setsockopt(socket.SOL_SOCKET, option, LOOPBACK_DEVICE.encode())
                bound += 1
        except OSError as exc:
            log.warning("could not bind DDS socket %d to %s: %s", fd, LOOPBACK_DEVICE, exc)
            return False
        finally:
            sock.detach()
    return bound > 0


def _on_loopback_address(sock: socket.socket) -> bool:
    """Whether `sock` is bound to a loopback address (Cyclone's send socket on 127.0.0.1)."""
    return ipaddress.ip_address(sock.getsockname()[0]).is_loopback
