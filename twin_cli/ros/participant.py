"""The twin's DDS participant: writers of the world's topics, readers of the commands it takes.

One Cyclone DDS domain and participant per bridge, configured by `scope.cyclone_config` alone;
the participant announces one node, `/twin`, with its readers and writers (`node`), in the GID
form of the scope's distribution, and carries rmw's participant USER_DATA, `enclave=/;` (the
default enclave, as rmw_cyclonedds_cpp writes it: no terminating NUL), which ROS 2's graph
cache reads to list the participant's nodes.
Writers send the CDR bytes rosbags encoded (a recording's very bytes) through a topic typed by
`graph.idl_type`, so subscribers see the types rmw_cyclonedds_cpp announces; readers hand back
the cyclonedds objects of those same types.

As a recording sink (`set_topics`, `write`, `close`) it runs in the bridge's publisher process
(node `/twin`); the server's own participant holds the readers (node `/twin_commands`), polled
by the command thread. Cyclone's entities are thread safe.
"""

from __future__ import annotations

import logging
import threading
from functools import cache
from typing import Any

from twin_cli.errors import RequestError
from twin_cli.record.topics import Message, Topic
from twin_cli.ros import graph
from twin_cli.ros.graph import LATCHED_QOS, Qos, dds_qos, dds_topic, idl_type, qos_of
from twin_cli.ros.node import DISCOVERY_TOPIC, INFO, NODE_NAME, discovery_info, info_type
from twin_cli.ros.scope import Scope, cyclone_config
from twin_cli.ros.sockets import confine_to_loopback, open_sockets

log = logging.getLogger("twin.ros")
ENCLAVE = "/"  # the default enclave: SROS2's root, what a node without --enclave runs in
USER_DATA = f"enclave={ENCLAVE};".encode()  # rmw_cyclonedds_cpp's participant USER_DATA


@cache
def _encoded_type(name: str) -> type:
    """A sample class of message type `name` that carries its CDR bytes as they are: cyclonedds'
    writer asks a sample to `serialize` itself, and these hand back rosbags' encoding."""
    base = idl_type(name)

    def __init__(self: Any, cdr: bytes) -> None:
        self.cdr = cdr

    def serialize(self: Any, use_version_2: bool | None = None, **_: Any) -> bytes:
        return self.cdr

    return type(base.__name__ + "Cdr", (base,), {"__init__": __init__, "serialize": serialize})


class Participant:
    """A DDS participant in `scope`'s domain, with a writer per topic set by `set_topics`, and
    one node, `node`."""

    def __init__(self, scope: Scope, node: str = NODE_NAME) -> None:
        """Raises: RequestError: Cyclone DDS refused the configuration (e.g. no such
        interface) or is not installed."""
        try:
            from cyclonedds.domain import Domain, DomainParticipant
            from cyclonedds.qos import Policy, Qos
        except ImportError as exc:
            raise RequestError(
                "ROS 2 bridge", f"cyclonedds cannot be imported ({exc})",
                "install it: pip install cyclonedds==11.0.1",
            ) from exc  # fmt: skip
        self.scope = scope
        self.node = node
        self._lock = threading.Lock()
        before = open_sockets()
        try:
            self._domain = Domain(scope.domain_id, cyclone_config(scope))
            # before the participant announces itself: nothing is sent off the device
            self.on_loopback_device = scope.local_only and confine_to_loopback(before)
            self._participant = DomainParticipant(
                scope.domain_id, qos=Qos(Policy.Userdata(USER_DATA))
            )
        except Exception as exc:  # cyclonedds raises DDSException with Cyclone's return code
            raise RequestError(
                f"ROS 2 participant ({scope.describe()})",
                f"Cyclone DDS cannot start ({exc})",
                "check --ros-interface and the ROS_* variables; see the server log",
            ) from exc
        self._topics: dict[tuple[str, str], Any] = {}
        self._writers: dict[str, tuple[Any, type]] = {}
        self._readers: list[Any] = []
        self._service_writers: list[Any] = []
        self._closed = False
        with self._lock:
            self._info_writer = self._open_info_writer()

    # ------------------------------------------------------------ a recording sink
    def set_topics(self, topics: list[Topic]) -> None:
        """Opens a writer for each new topic and closes those of topics that are gone."""
        wanted = {t.name: t for t in topics}
        with self._lock:
            for name in [n for n in self._writers if n not in wanted]:
                _delete(self._writers.pop(name)[0])
            for name, topic in wanted.items():
                if name not in self._writers and not self._closed:
                    self._writers[name] = self._open_writer(topic)
            self._announce()

    def write(self, message: Message) -> None:
        """Publishes `message`'s CDR bytes (encoded now: its object is refilled after)."""
        entry = self._writers.get(message.topic)
        if entry is None:
            return
        writer, sample_type = entry
        data = message.cdr()
        writer.write(sample_type(data.ljust((len(data) + 3) & ~3, b"\0")))

    def close(self) -> None:
        """Deletes every writer, reader and topic, then the participant and its domain."""
        with self._lock:
            if self._closed:
                return
            self._closed = True
            entities = [w for w, _ in self._writers.values()] + self._readers
            entities += self._service_writers
            entities.append(self._info_writer)
            entities += [*self._topics.values(), self._participant, self._domain]
            self._writers.clear()
            self._readers.clear()
            self._service_writers.clear()
        for entity in entities:
            _delete(entity)

    # ------------------------------------------------------------ readers
    def reader(self, name: str, type_name: str, qos: Qos) -> Any:
        """A DataReader of ROS topic `name` with message type `type_name`; its `take` returns
        cyclonedds objects of `graph.idl_type(type_name)`."""
        from cyclonedds.sub import DataReader

        with self._lock:
            reader = DataReader(
                self._participant, self._topic(name, type_name), qos=dds_qos(qos, type_name)
            )
            self._readers.append(reader)
            self._announce()
        return reader

    def service(self, name: str, service_type: str) -> tuple[Any, Any]:
        """A reader of service `name`'s requests and a writer of its replies (`service_types`:
        DDS topics and types as rmw_cyclonedds_cpp maps them; QoS: services' default)."""
        from cyclonedds.pub import DataWriter
        from cyclonedds.sub import DataReader

        from twin_cli.ros import service_types as srv

        qos = dds_qos(graph.DEFAULT_QOS, None)
        with self._lock:
            request = self._dds_topic(
                srv.request_topic(name), srv.service_idl(service_type, srv.REQUEST)
            )
            reply = self._dds_topic(
                srv.reply_topic(name), srv.service_idl(service_type, srv.RESPONSE)
            )
            reader = DataReader(self._participant, request, qos=qos)
            writer = DataWriter(self._participant, reply, qos=qos)
            self._readers.append(reader)
            self._service_writers.append(writer)
            self._announce()
        return reader, writer

    def drop_reader(self, reader: Any) -> None:
        with self._lock:
            if reader in self._readers:
                self._readers.remove(reader)
                _delete(reader)
                self._announce()

    # ------------------------------------------------------------ inside (lock held)
    def _open_writer(self, topic: Topic) -> tuple[Any, type]:
        from cyclonedds.pub import DataWriter

        writer = DataWriter(
            self._participant,
            self._topic(topic.name, topic.type),
            qos=dds_qos(qos_of(topic), topic.type),
        )
        return writer, _encoded_type(topic.type)

    def _open_info_writer(self) -> Any:
        from cyclonedds.pub import DataWriter
        from cyclonedds.topic import Topic as DdsTopic

        topic = DdsTopic(self._participant, DISCOVERY_TOPIC, info_type(self.scope.distro))
        self._topics[(DISCOVERY_TOPIC, INFO)] = topic
        return DataWriter(self._participant, topic, qos=dds_qos(LATCHED_QOS, INFO))

    def _announce(self) -> None:
        """Publishes the node's readers and writers on `ros_discovery_info` (`ros2 node`)."""
        if self._closed:
            return
        writers = [w.get_guid().bytes for w, _ in self._writers.values()]
        writers += [w.get_guid().bytes for w in self._service_writers]
        readers = [r.get_guid().bytes for r in self._readers]
        guid = self._participant.get_guid().bytes
        self._info_writer.write(
            discovery_info(self.scope.distro, guid, readers, writers, self.node)
        )

    def _topic(self, name: str, type_name: str) -> Any:
        return self._dds_topic(dds_topic(name), idl_type(type_name))

    def _dds_topic(self, dds_name: str, idl: type) -> Any:
        from cyclonedds.topic import Topic as DdsTopic

        key = (dds_name, idl.__name__)
        if key not in self._topics:
            self._topics[key] = DdsTopic(self._participant, dds_name, idl)
        return self._topics[key]


def _delete(entity: Any) -> None:
    """Deletes a cyclonedds entity now: the binding keeps every entity in a class-wide table
    until its `__del__`, so dropping the reference alone would keep it on the network."""
    try:
        entity.__del__()
    except Exception:  # already gone with its parent
        log.debug("deleting %r failed", entity, exc_info=True)
