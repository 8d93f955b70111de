"""rosbag2-compatible MCAP files (what `ros2 bag info/play`, Foxglove and PlotJuggler open).

The container is written by foxglove-sdk's MCAP writer, in Rust: a message costs the encoder
process ~1 µs there against ~6 µs in the pure-Python `mcap` writer (the tests read the files
back with that library, an independent reader). The layout is the one rosbag2's MCAP storage
plugin writes: profile `ros2`, one `ros2msg` schema per message type (rosbags' definitions),
`cdr` channels carrying rosbag2's `offered_qos_profiles` (the live writers' QoS, `qos`:
transient local for latched topics, so `ros2 bag play` re-offers `/tf_static` and
`robot_description` to late subscribers; best effort, depth 5 for sensor topics) and
`topic_type_hash`, and a closing `rosbag2` metadata record (the bag's metadata.yaml, version 9,
read by Jazzy and later only). The QoS on the channels are numbers (Humble's form, which Jazzy
also reads), those in the metadata record names (Jazzy's form for version 9). Messages
are in zstd chunks with CRCs; a chunk is closed and handed to the OS once `FLUSH_PERIOD_S` of wall
time or of sim time (the messages' stamps) has passed since the last, and by `flush_if_due` when
no message comes (an idle encoder), so a server killed with SIGKILL leaves a file that a
streaming reader reads up to its last chunk: at most about a second of sim time is lost.
"""

from __future__ import annotations

import contextlib
import os
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import yaml

from twin_cli.errors import RequestError
from twin_cli.files.output_files import PRIVATE
from twin_cli.record import messages as ros
from twin_cli.record.qos import Qos, qos_of
from twin_cli.record.topics import Message, Topic

CHUNK_SIZE = 1 << 20  # [B] a chunk closes when its content exceeds this
FLUSH_PERIOD_S = 1.0  # [s] of wall or sim time: at most this much data is lost to a SIGKILL
FLUSH_MIN_S = 0.25  # [s] wall: an unthrottled world's chunks still hold several sim seconds
_FLUSH_NS = int(FLUSH_PERIOD_S * 1e9)
BAG_VERSION = 9  # rosbag2 metadata version of Jazzy (QoS written as names, not numbers)
_INFINITE = {"sec": 9223372036, "nsec": 854775807}  # rmw's "infinite" duration
# QoS policies as rmw's enum values (what rosbag2 before Jazzy reads and writes) and names
# (Jazzy's metadata version 9): keep_last, reliable / best_effort, transient_local / volatile,
# automatic (rmw/types.h: RMW_QOS_POLICY_*).
_NUMBERS = {
    "keep_last": 1,
    "reliable": 1,
    "best_effort": 2,
    "transient_local": 1,
    "volatile": 2,
    "automatic": 1,
}


def qos_profiles(qos: Qos, *, numbers: bool = False) -> list[dict[str, Any]]:
    """A topic's offered QoS `qos` as rosbag2 stores it: policies by name (metadata version 9),
    or by number (`numbers`: the form every rosbag2 reads, see `channel_qos`)."""
    names = {
        "history": "keep_last",
        "reliability": "reliable" if qos.reliable else "best_effort",
        "durability": "transient_local" if qos.transient_local else "volatile",
        "liveliness": "automatic",
    }
    policies = {k: _NUMBERS[v] for k, v in names.items()} if numbers else names
    return [
        {
            "history": policies["history"],
            "depth": qos.depth,
            "reliability": policies["reliability"],
            "durability": policies["durability"],
            "deadline": _INFINITE,
            "lifespan": _INFINITE,
            "liveliness": policies["liveliness"],
            "liveliness_lease_duration": _INFINITE,
            "avoid_ros_namespace_conventions": False,
        }
    ]


def channel_qos(qos: Qos) -> str:
    """A channel's `offered_qos_profiles`: YAML with the policies as numbers. Humble's MCAP
    storage reads only this (not the `rosbag2` metadata record) and its player converts each
    policy with `as<int>`, so names would stop `ros2 bag play`; Jazzy reads it with the bag's
    version but first tries numbers (a history that parses as an integer means numbers)."""
    return yaml.safe_dump(qos_profiles(qos, numbers=True), sort_keys=False)


def open_output(path: str | os.PathLike, *, overwrite: bool = False) -> Any:
    """The output file, opened for writing; the error names the path and the fix.

    Raises:
        RequestError: the file exists (and not `overwrite`), or cannot be created.
    """
    target = Path(path).expanduser()
    if target.suffix.lower() != ".mcap":
        raise RequestError(f"recording {target}", "is not a .mcap file", "name it OUT.mcap")
    # 0600 like a save: a recording holds the world's whole course. O_NONBLOCK: a FIFO with
    # no reader is refused at once instead of blocking the server (regular files ignore it).
    flags = os.O_WRONLY | os.O_CREAT | os.O_NONBLOCK | (os.O_TRUNC if overwrite else os.O_EXCL)
    try:
        return os.fdopen(os.open(target, flags, PRIVATE), "wb")
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
        import foxglove
        from foxglove.mcap import MCAPCompression, MCAPWriteOptions

        self.path = Path(path).expanduser()
        self._file = _CheckedFile(open_output(self.path, overwrite=overwrite), self.path)
        self._context = foxglove.Context()  # this file's channels only (not a live server's)
        options = MCAPWriteOptions(
            compression=MCAPCompression.Zstd,
            profile="ros2",
            chunk_size=CHUNK_SIZE,
            compression_threads=0,  # compress in this thread: the encoder stays one core
        )
        with self._file.checked():
            self._writer = foxglove.open_mcap(
                self._file, context=self._context, writer_options=options
            )
        self._channels: dict[str, Any] = {}
        self._topics: dict[str, Topic] = {}
        self._counts: dict[str, int] = {}
        self._span = [2**63 - 1, 0]  # first and last log time [ns]
        self._flushed = time.monotonic()  # wall time of the last flush
        self._flushed_stamp = 0  # [ns] the stamp of the last message before it
        self._dirty = False  # messages written since the last flush
        self.custom_data: dict[str, str] = {}  # rosbag2 metadata's custom_data (figures)

    def add_topic(self, topic: Topic) -> None:
        """Registers a topic (with its schema) unless known."""
        if topic.name in self._channels:
            return
        from twin_cli.record.foxglove import ros2_channel

        metadata = {
            "offered_qos_profiles": channel_qos(qos_of(topic)),
            "topic_type_hash": ros.definition(topic.type).rihs01,
        }
        self._channels[topic.name] = ros2_channel(topic, self._context, metadata)
        self._topics[topic.name] = topic
        self._counts[topic.name] = 0

    def write(self, message: Message) -> None:
        """Encodes and writes one message (its topic must have been added)."""
        stamp = ros.nanoseconds(message.time)
        data = message.cdr()
        self._channels[message.topic].log(data, log_time=stamp)
        self._file.check()
        self._counts[message.topic] += 1
        span = self._span
        if stamp < span[0]:
            span[0] = stamp
        if stamp > span[1]:
            span[1] = stamp
        self._dirty = True
        wall = time.monotonic() - self._flushed
        if wall > FLUSH_PERIOD_S or (
            abs(stamp - self._flushed_stamp) > _FLUSH_NS and wall > FLUSH_MIN_S
        ):
            self._flushed_stamp = stamp
            self.flush()

    def flush_if_due(self) -> None:
        """Flushes messages written more than `FLUSH_PERIOD_S` ago (for a writer that idles)."""
        if self._dirty and time.monotonic() - self._flushed > FLUSH_PERIOD_S:
            self.flush()

    def flush(self) -> None:
        """Closes the chunk in progress and hands everything written so far to the OS."""
        with self._file.checked():
            self._writer.flush()
        self._flushed, self._dirty = time.monotonic(), False

    @property
    def message_count(self) -> int:
        return sum(self._counts.values())

    def close(self) -> None:
        """Writes the rosbag2 metadata record, the summary and the footer; closes the file."""
        try:
            with self._file.checked():
                self._writer.write_metadata(
                    "rosbag2", {"serialized_metadata": self._metadata(), "ROS_DISTRO": ros.DISTRO}
                )
        finally:
            try:
                with self._file.checked():
                    self._writer.close()
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
                        "offered_qos_profiles": qos_profiles(qos_of(t)),
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


class _CheckedFile:
    """The output file as foxglove's writer sees it. That writer only logs a failed write (a
    full disk) and goes on, so this keeps the first error, and `check` raises it: the recording
    then stops and reports it instead of ending with a silently cut file."""

    def __init__(self, raw: Any, path: Path) -> None:
        self._raw, self._path = raw, path
        self.error: OSError | None = None

    def write(self, data: bytes) -> int:
        return self._keep(self._raw.write, data)

    def flush(self) -> None:
        self._keep(self._raw.flush)

    def seek(self, offset: int, whence: int = 0) -> int:
        return self._keep(self._raw.seek, offset, whence)  # (a buffered file flushes first)

    def tell(self) -> int:
        return self._keep(self._raw.tell)

    def _keep(self, method: Any, *args: Any) -> Any:
        try:
            return method(*args)
        except OSError as exc:
            self.error = self.error or exc
            raise

    def close(self) -> None:
        self._raw.close()

    @contextlib.contextmanager
    def checked(self) -> Iterator[None]:
        """Around a call into the writer: raises the file's own error, if one happened, in
        place of the SDK's RuntimeError ("a write method failed") or its silence."""
        try:
            yield
        except RuntimeError:
            self.check()
            raise
        self.check()

    def check(self) -> None:
        """Raises the first write error, if any (OSError: names the file and the cause)."""
        if self.error is not None:
            raise OSError(self.error.errno, self.error.strerror, str(self._path))
