"""The kernel's own account of a process's internet sockets (Linux sock_diag over netlink).

/proc/net/udp shows a socket's addresses but not the device it is bound to; the kernel's
socket-diagnostics answer (what `ss` prints as `0.0.0.0%lo:7410`) has both. Independent of
twin: it asks the kernel, not the code under test.
"""

from __future__ import annotations

import ipaddress
import os
import re
import socket
import struct
from dataclasses import dataclass
from pathlib import Path

NETLINK_SOCK_DIAG = 4
SOCK_DIAG_BY_FAMILY = 20
NLM_F_REQUEST, NLM_F_DUMP = 0x1, 0x300
NLMSG_ERROR, NLMSG_DONE = 2, 3
ALL_STATES = 0xFFFFFFFF
HEADER = struct.Struct("=IHHII")  # nlmsghdr
REQUEST = struct.Struct("=BBBxI48x")  # inet_diag_req_v2, any socket id
MESSAGE = struct.Struct("=BBBB2s2s16s16sI8sIIIII")  # inet_diag_msg


@dataclass(frozen=True)
class InetSocket:
    """One internet socket: protocol, local and remote address and port, bound device index
    (0: none), and its inode (as /proc/<pid>/fd links name it)."""

    protocol: str
    local: tuple[str, int]
    remote: tuple[str, int]
    device: int
    inode: int


def sockets_of(pid: int) -> list[InetSocket]:
    """Every TCP and UDP socket (IPv4 and IPv6) that process `pid` holds."""
    inodes = set()
    for fd in Path(f"/proc/{pid}/fd").iterdir():
        try:
            if m := re.match(r"socket:\[(\d+)\]", os.readlink(fd)):
                inodes.add(int(m.group(1)))
        except OSError:
            continue
    found = []
    for family in (socket.AF_INET, socket.AF_INET6):
        for protocol, number in (("udp", socket.IPPROTO_UDP), ("tcp", socket.IPPROTO_TCP)):
            found += [s for s in _dump(family, protocol, number) if s.inode in inodes]
    return found


def _dump(family: int, protocol: str, number: int) -> list[InetSocket]:
    request = REQUEST.pack(family, number, 0, ALL_STATES)
    header = HEADER.pack(HEADER.size + len(request), SOCK_DIAG_BY_FAMILY,
                         NLM_F_REQUEST | NLM_F_DUMP, 1, 0)  # fmt: skip
    with socket.socket(socket.AF_NETLINK, socket.SOCK_DGRAM, NETLINK_SOCK_DIAG) as nl:
        nl.sendall(header + request)
        found: list[InetSocket] = []
        while True:
            data = nl.recv(1 << 16)
            offset = 0
            while offset < len(data):
                length, kind, *_ = HEADER.unpack_from(data, offset)
                if kind == NLMSG_DONE:
                    return found
                assert kind != NLMSG_ERROR, f"sock_diag refused the {protocol} dump"
                found.append(_parse(data[offset + HEADER.size : offset + length], family, protocol))
                offset += (length + 3) & ~3


def _parse(body: bytes, family: int, protocol: str) -> InetSocket:
    fields = MESSAGE.unpack_from(body)
    sport, dport, src, dst, device, inode = *fields[4:8], fields[8], fields[14]
    size = 4 if family == socket.AF_INET else 16
    return InetSocket(
        protocol=protocol + ("6" if family == socket.AF_INET6 else ""),
        local=(str(ipaddress.ip_address(src[:size])), int.from_bytes(sport, "big")),
        remote=(str(ipaddress.ip_address(dst[:size])), int.from_bytes(dport, "big")),
        device=device,
        inode=inode,
    )
