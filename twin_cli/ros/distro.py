"""Which ROS 2 distribution the twin's graph entities are shaped for: the size of a node's GIDs.

rmw's `rmw_gid_t` holds RMW_GID_STORAGE_SIZE bytes (rmw/types.h): 24 up to Humble, 16 from Iron
on; rmw_dds_common's `Gid` message on `ros_discovery_info` carries as many (`char[24] data` in
Humble, `char[16] data` in Jazzy), and a DDS reader of one size does not match a writer of the
other. A Cyclone DDS GUID fills the first 16 bytes; rmw_cyclonedds_cpp zeroes the rest.
The distribution is `--ros-distro`, else `ROS_DISTRO` (set by a sourced ROS 2 setup file), else
Jazzy.
"""

from __future__ import annotations

from collections.abc import Mapping

from twin_cli.errors import InvalidRequestError

GID_SIZES = {  # [bytes] RMW_GID_STORAGE_SIZE in each distribution's rmw/types.h
    "foxy": 24,
    "galactic": 24,
    "humble": 24,
    "iron": 16,
    "jazzy": 16,
    "kilted": 16,
    "rolling": 16,
}
DEFAULT_DISTRO = "jazzy"
GUID_SIZE = 16  # [bytes] a DDSI GUID: 12-byte prefix and 4-byte entity id


def distro_from(
    env: Mapping[str, str], option: str | None = None, flag: str = "--ros-distro"
) -> str:
    """The distribution `option` (the command's `flag`) or `env`'s ROS_DISTRO names, else Jazzy.

    Raises:
        InvalidRequestError: a name that is not a ROS 2 distribution twin knows.
    """
    where = flag if option else "ROS_DISTRO"
    name = (option or env.get("ROS_DISTRO", "")).strip().lower()
    if not name:
        return DEFAULT_DISTRO
    if name not in GID_SIZES:
        raise InvalidRequestError(
            f"{where} {name!r}",
            "is not a ROS 2 distribution twin knows",
            f"give one of {', '.join(GID_SIZES)} (the nodes' distribution)",
        )
    return name


def gid(guid: bytes, distro: str) -> bytes:
    """The rmw GID of the entity with DDS GUID `guid` in `distro`: the GUID, zero-padded."""
    return guid.ljust(GID_SIZES[distro], b"\0")
