"""The bridge's publisher process: samples from the ring → ROS messages → DDS writers.

Runs in its own interpreter (`python -m twin_cli.ros.publisher`, started by `RosRecording`),
as a bag recording's encoder does, so computing link poses, building messages, CDR-encoding
them (rosbags) and writing them to DDS never hold the stepping loop's GIL. It is the encoder's
loop (`record.encoder.run_encoder`) with a DDS participant as its sink, and it publishes at
most `max_wall_rate` samples a wall second: a world faster than that is thinned (the newest are
taken each time), as a ROS node could not take more anyway; a slower one loses none. The
process holds its own participant (node `/twin`, the world's writers) in the server's scope;
`/tf` goes through `tf_repeats`, so a paused world's beats send no transform tf2 already has.
"""

from __future__ import annotations

import json
import os
import time
from dataclasses import asdict
from typing import Any

from twin_cli.record.encoder import Encoder, conn_pending, run_encoder, signals
from twin_cli.record.topics import Message, Topic
from twin_cli.ros.participant import Participant
from twin_cli.ros.scope import Scope
from twin_cli.ros.tf_repeats import RepeatFilter

NICE = 10  # added niceness of the publisher process (the bag encoder's)
BURST_S = 1.0  # [s]: a publisher stalled this long still sends every record of a world running
# up to max_wall_rate's speed (tokens build up only while records wait in the ring)


def command(fds: tuple[int, int], scope: Scope, max_wall_rate: float) -> list[str]:
    """The publisher's arguments after `python -m twin_cli.ros.publisher`."""
    return [*map(str, fds), json.dumps(asdict(scope)), repr(max_wall_rate)]


def main(argv: list[str]) -> None:
    """`python -m twin_cli.ros.publisher RING_FD PIPE_FD SCOPE_JSON MAX_WALL_RATE`."""
    from multiprocessing.connection import Connection

    from twin_cli.record import layout, messages, recorder, ring, sensor_messages  # noqa: F401

    parent = os.getppid()
    signals()
    messages.typestore()  # rosbags' types (and the imports above) before the first sample
    fields = json.loads(argv[2])
    scope = Scope(**{**fields, "peers": tuple(fields["peers"])})
    conn = Connection(int(argv[1]))
    try:
        participant = Participant(scope)
    except Exception as exc:  # Cyclone refused the scope: the parent reads why
        conn.send(("done", str(exc)))
        return
    # Below the loop's priority, as a bag's encoder (after the imports and the participant: their
    # second of CPU would otherwise wait for the gaps). On two busy vCPUs (load 8-10) the
    # unthrottled loop kept 0.85-0.94 of its throughput beside an un-niced publisher and
    # 1.01-1.08 beside this one; a real-time world lost no more samples (95-99 % of them sent
    # either way at that load): they wait in the ring, and the token bucket's saved-up second
    # sends them when the publisher gets the CPU.
    os.nice(NICE)
    buf, head, times = ring.views(ring.attach(int(argv[0])))
    reader = ring.RingReader(buf, head)
    encoder = LatestEncoder(DdsSink(participant), times, reader, parent, float(argv[3]))
    run_encoder(encoder, conn, head)


class DdsSink:
    """The participant as a recording sink: a layout's topics replace the last layout's, sensor
    topics stay once seen (a reading names only its own)."""

    def __init__(self, participant: Participant) -> None:
        self.participant = participant
        self._repeats = RepeatFilter()  # /tf: a frame once per stamp (a paused world's beats)
        self._layout: list[Topic] = []
        self._sensors: dict[str, Topic] = {}

    def set_topics(self, topics: list[Topic]) -> None:
        self._layout = topics
        self._announce()

    def add_sensor_topics(self, topics: list[Topic]) -> None:
        new = {t.name: t for t in topics if t.name not in self._sensors}
        if new:
            self._sensors.update(new)
            self._announce()

    def write(self, message: Message) -> None:
        fresh = self._repeats.filter(message)
        if fresh is not None:
            self.participant.write(fresh)

    def close(self) -> None:
        self.participant.close()

    def _announce(self) -> None:
        names = {t.name for t in self._layout}
        extra = [t for name, t in self._sensors.items() if name not in names]
        self.participant.set_topics(self._layout + extra)


class LatestEncoder(Encoder):
    """Publishes the records as they come, at most `max_wall_rate` per wall second (a token
    bucket holding up to BURST_S of them while records wait, one while the ring is empty):
    beyond that rate the newest are taken and the others skipped, and a record that finds no
    token waits, replaced by any newer one."""

    def __init__(
        self, writer: DdsSink, times: Any, reader: Any, parent: int | None, max_wall_rate: float
    ) -> None:
        super().__init__(writer, times, reader, parent)
        self.rate = max_wall_rate  # [1/s] wall
        self.idle_s = 1.0 / max_wall_rate
        self._burst = max(1.0, BURST_S * max_wall_rate)
        self._tokens, self._filled = self._burst, time.monotonic()
        self._pending: tuple[int, Any] | None = None

    def encode(self, epoch: int, records: Any) -> None:
        self._refill()
        count = min(len(records), int(self._tokens))
        if count:
            self._pending = None
            self._tokens -= count
            super().encode(epoch, records[-count:])
        else:  # copied: the ring reuses its memory
            self._pending = (epoch, records[-1:].copy())

    def idle(self) -> None:
        """The ring is empty: the waiting record goes if due, and no burst is saved up (only a
        publisher that fell behind, its records waiting in the ring, spends one)."""
        self._refill()
        if self._pending is not None and self._tokens >= 1.0:
            self._tokens -= 1.0
            pending, self._pending = self._pending, None
            super().encode(*pending)
        self._tokens = min(self._tokens, 1.0)

    def poll(self, conn: Any) -> dict | None:
        """As the encoder's, after waiting for a token when none is left (a busy world's
        records pile up in the ring meanwhile; only the newest are built)."""
        self._refill()
        if self._tokens < 1.0:
            conn_pending(conn, (1.0 - self._tokens) / self.rate)
        return super().poll(conn)

    def close(self, figures: dict) -> None:
        if self._pending is not None:
            super().encode(*self._pending)
        self.writer.close()

    def _take(self, message: tuple) -> None:
        if message[0] != "readings":
            super()._take(message)
            return
        from twin_cli.record.sensor_messages import sensor_message

        self.writer.add_sensor_topics([topic for topic, _ in message[1]])
        for topic, reading in message[1]:
            self.writer.write(sensor_message(topic, reading))

    def _refill(self) -> None:
        now = time.monotonic()
        self._tokens = min(self._burst, self._tokens + (now - self._filled) * self.rate)
        self._filled = now


if __name__ == "__main__":
    import sys

    main(sys.argv[1:])
