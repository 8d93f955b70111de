"""rosbag2-compatible MCAP files (what `ros2 bag info/play`, Foxglove and PlotJuggler open).

The container is written by Foxglove's `mcap` library with the layout rosbag2's MCAP storage
plugin writes: profile `ros2`, one `ros2msg` schema per message type (rosbags' definitions),
`cdr` channels carrying rosbag2's `offered_qos_profiles` (transient local for latched topics, so
`ros2 bag play` re-offers `/tf_static` and `robot_description` to late subscribers) and
`topic_type_hash`, and a closing `rosbag2` metadata record (the bag's metadata.yaml). Messages
are in zstd chunks with CRCs; a chunk is closed at least every `FLUSH_PERIOD_S` of wall time and
handed to the OS, so a server killed with SIGKILL leaves a file readable up to its last chunk.
"""

from __future__ import annotations

import os
import time
from pathlib import Path
from typing import Any

import yaml

from twin_cli.errors import RequestError
from twin_cli.record import messages as ros
from twin_cli.record.topics import Message, Topic

CHUNK_SIZE = 1 << 20  # [B] mcap's default: a chunk closes when its content exceeds this
FLUSH_PERIOD_S = 1.0  # [s] wall time: at most this much data is lost to a SIGKILL
BAG_VERSION = 9  # rosbag2 metadata version of Jazzy (QoS written as names, not numbers)
_INFINITE = {"sec": 9223372036, "nsec": 854775807}  # rmw's "infinite" duration


def qos_profiles(latched: bool) -> list[dict[str, Any]]:
    """The offered QoS of a topic as rosbag2 v9 stores it (tf2's static broadcaster's for
    latched topics: reliable, transient local, depth 1)."""
    return [
        {
            "history": "keep_last",
            "depth": 1 if latched else 10,
            "reliability": "reliable",
            "durability": "transient_local" if latched else "volatile",
            "deadline": _INFINITE,
            "lifespan": _INFINITE,
            "liveliness": "automatic",
            "liveliness_lease_duration": _INFINITE,
            "avoid_ros_namespace_conventions": False,
        }
    ]


def open_output(path: str | os.PathLike, *, overwrite: bool = False) -> Any:
    """The output file, opened for writing; the error names the path and the fix.

    Raises:
        RequestError: the file exists (and not `overwrite`), or cannot be created.
    """
    target = Path(path).expanduser()
    if target.suffix.lower() != ".mcap":
        raise RequestError(f"recording {target}", "is not a .mcap file", "name it OUT.mcap")
    try:
        return target.open("wb" if overwrite else "xb")
    except FileExistsError as exc:
        raise RequestError(
            f"recording {target}", "already exists", "remove it or choose another name"
        ) from exc
    except OSError as exc:
        raise RequestError(
            f"recording {target}",
            f"cannot be written ({exc.strerror or exc})",
            "give a path in an existing, writable directory on the server's host",
        ) from exc


class BagWriter:
    """Writes messages to one rosbag2 MCAP file; `close` writes the index and metadata."""

    def __init__(self, path: str | os.PathLike, *, overwrite: bool = False) -> None:
        """Raises: RequestError: see `open_output`."""
        from mcap.writer import CompressionType, Writer

        self.path = Path(path).expanduser()
        self._file = open_output(self.path, overwrite=overwrite)
        self._writer = Writer(self._file, chunk_size=CHUNK_SIZE, compression=CompressionType.ZSTD)
        self._writer.start(profile="ros2", library=f"twin {_version()}")
        self._schemas: dict[str, int] = {}
        self._channels: dict[str, int] = {}
        self._topics: dict[str, Topic] = {}
        self._counts: dict[str, int] = {}
        self._span = [2**63 - 1, 0]  # first and last log time [ns]
        self._flushed = time.monotonic()
        self.custom_data: dict[str, str] = {}  # rosbag2 metadata's custom_data (figures)

    def add_topic(self, topic: Topic) -> None:
        """Registers a topic (its schema first) unless known."""
        if topic.name in self._channels:
            return
        if topic.type not in self._schemas:
            d = ros.definition(topic.type)
            self._schemas[topic.type] = self._writer.register_schema(
                d.name, "ros2msg", d.text.encode()
            )
        metadata = {
            "offered_qos_profiles": yaml.safe_dump(qos_profiles(topic.latched), sort_keys=False),
            "topic_type_hash": ros.definition(topic.type).rihs01,
        }
        self._channels[topic.name] = self._writer.register_channel(
            topic.name, "cdr", self._schemas[topic.type], metadata
        )
        self._topics[topic.name] = topic
        self._counts[topic.name] = 0

    def write(self, message: Message) -> None:
        """Encodes and writes one message (its topic must have been added)."""
        stamp = ros.nanoseconds(message.time)
        self._writer.add_message(
            channel_id=self._channels[message.topic],
            log_time=stamp,
            publish_time=stamp,
            sequence=self._counts[message.topic],
            data=ros.encode(message.message, message.type),
        )
        self._counts[message.topic] += 1
        self._span = [min(self._span[0], stamp), max(self._span[1], stamp)]
        if time.monotonic() - self._flushed > FLUSH_PERIOD_S:
            self.flush()

    def flush(self) -> None:
        """Closes the chunk in progress and hands everything written so far to the OS."""
        self._writer.flush()
        self._flushed = time.monotonic()

    @property
    def message_count(self) -> int:
        return sum(self._counts.values())

    def close(self) -> None:
        """Writes the rosbag2 metadata record, the summary and the footer; closes the file."""
        try:
            self._writer.add_metadata(
                "rosbag2", {"serialized_metadata": self._metadata(), "ROS_DISTRO": ros.DISTRO}
            )
            self._writer.finish()
        finally:
            self._file.close()

    def _metadata(self) -> str:
        """rosbag2's BagMetadata (what `ros2 bag info` prints) as YAML."""
        start = self._span[0] if self.message_count else 0
        duration = max(0, self._span[1] - start)
        info = {
            "version": BAG_VERSION,
            "storage_identifier": "mcap",
            "duration": {"nanoseconds": duration},
            "starting_time": {"nanoseconds_since_epoch": start},
            "message_count": self.message_count,
            "topics_with_message_count": [
                {
                    "topic_metadata": {
                        "name": t.name,
                        "type": t.type,
                        "serialization_format": "cdr",
                        "offered_qos_profiles": qos_profiles(t.latched),
                        "type_description_hash": ros.definition(t.type).rihs01,
                    },
                    "message_count": self._counts[t.name],
                }
                for t in self._topics.values()
            ],
            "compression_format": "",
            "compression_mode": "",
            "relative_file_paths": [self.path.name],
            "files": [
                {
                    "path": self.path.name,
                    "starting_time": {"nanoseconds_since_epoch": start},
                    "duration": {"nanoseconds": duration},
                    "message_count": self.message_count,
                }
            ],
            "custom_data": dict(self.custom_data),
            "ros_distro": ros.DISTRO,
        }
        return yaml.safe_dump(info, sort_keys=False)


def _version() -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("twin")
    except PackageNotFoundError:
        return "dev"
