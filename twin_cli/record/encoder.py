"""The encoder process of a bag recording: raw records from the ring → ROS messages → MCAP.

Runs in its own interpreter (a fresh `python -m`, so the server's threads are not forked and
no script is re-imported), so computing link poses (`mj_kinematics` on its own MjData),
building messages, CDR-encoding them (rosbags) and writing chunks (foxglove-sdk's MCAP writer)
never hold the stepping loop's GIL. The parent sends each layout (compiled model, entity index,
what its frames are named from; MjModel pickles) over a pipe before the first record of that
layout, with an epoch and the ring position where its records start; then "stop" with its
figures (time the writer waited for room), after which the ring is drained and the file closed.
A parent that dies (even by SIGKILL, even while it waits for "done") closes the pipe, and the
encoder is re-parented: either way the file is finished with what the ring holds, and the
encoder exits. Idle or not, written messages reach the file within `FLUSH_PERIOD_S`.
"""

from __future__ import annotations

import os
from typing import Any

NICE = 10  # added niceness of the encoder process
IDLE_S = 0.05  # [s] wait when the ring is empty: fewer, longer runs of warm encoding
BATCH = 256  # records taken from the ring between looks at the pipe, encoded as one batch


def main(argv: list[str]) -> None:
    """`python -m twin_cli.record.encoder RING_FD PIPE_FD OUT.mcap` (started by BagRecording)."""
    from multiprocessing.connection import Connection

    from twin_cli.record import ring

    parent = os.getppid()
    signals()
    _warm_up()
    ring_fd, pipe_fd, path = int(argv[0]), int(argv[1]), argv[2]
    # Below the loop's priority: on a busy machine the loop keeps its CPU and the encoder works
    # in the gaps; the ring holds the backlog (the loop waits, measured, only when it is full).
    # Lowered only after the imports: niced on a busy machine, their second of CPU would get a
    # tenth of a core, and every sample of that time would wait in the ring, lost to a kill.
    os.nice(NICE)
    encode_main(ring.attach(ring_fd), Connection(pipe_fd), path, parent)


def encode_main(memory: Any, conn: Any, path: str, parent: int | None = None) -> None:
    """Encodes until told to stop, or until the parent (pid `parent`) is gone; then drains the
    ring and closes the file with its summary."""
    from twin_cli.record import ring
    from twin_cli.record.recorder import BagSink

    buf, head, times = ring.views(memory)
    encoder = Encoder(BagSink(path, overwrite=True), times, ring.RingReader(buf, head), parent)
    run_encoder(encoder, conn, head)


def run_encoder(encoder: Encoder, conn: Any, head: Any) -> None:
    """The encoder's loop: records from the ring and messages from the pipe to `encoder`'s
    sink until "stop" (or the parent's end), then the rest of the ring; "done" to the parent."""
    from twin_cli.record import ring

    error, stop = None, None
    try:
        conn.send(("ready", None))
    except OSError:
        pass  # let go before the imports ended: what it sent is still read, then its end

    try:
        while True:
            write = int(head[ring.WRITE])  # first: the layouts of these records are sent
            stop = encoder.poll(conn)  # layouts, sensor readings, stop
            runs = encoder.reader.read(write, BATCH)
            for epoch, records in runs:
                encoder.encode(epoch, records)
            head[ring.SAMPLES] = encoder.samples
            if runs or (stop is not None and int(head[ring.READ]) < int(head[ring.WRITE])):
                continue  # (records written after `write` was read, before "stop")
            if stop is not None:  # never wait on the pipe after "stop": a parent that dies
                break  # then leaves it readable (at its end) for ever
            encoder.idle()
            conn_pending(conn, encoder.idle_s)  # the ring fills meanwhile; a message wakes it
    except Exception as exc:  # disk full...: report it to the parent
        error = f"{type(exc).__name__}: {exc}"
    finally:
        try:
            encoder.close(stop if isinstance(stop, dict) else {})
        except Exception as exc:
            error = error or f"{type(exc).__name__}: {exc}"
        head[ring.DONE] = 1
        try:
            conn.send(("done", error))
        except OSError:
            pass


_TERMINATED: list[int] = []  # the signal that asked this process to end, once one did


def signals() -> None:
    """Ctrl-C reaches the whole foreground group: the server decides when the recording ends
    (it sends "stop"). SIGTERM (a group or a cgroup ended) finishes the file as a stop does."""
    import signal

    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, lambda signum, frame: _TERMINATED.append(signum))


def _warm_up() -> None:
    """Imports (and builds rosbags' message types) at the server's priority, before `NICE`."""
    import foxglove  # noqa: F401

    from twin_cli.record import layout, messages, recorder, sensor_messages  # noqa: F401

    messages.typestore()


class Encoder:
    """Turns records into messages with the layouts the parent sent, for `writer` (a sink)."""

    idle_s = IDLE_S  # [s] wait on the pipe when the ring is empty

    def __init__(self, writer: Any, times: Any, reader: Any, parent: int | None) -> None:
        from twin_cli.record.recorder import Publisher

        self.writer = writer
        self.times = times
        self.reader = reader
        self.samples = 0
        self._layouts: dict[int, Any] = {}
        self._epoch = -1
        self._publisher = Publisher()
        self._stop: dict | None = None
        self.parent_gone = False  # its pipe closed without "stop": finish with what is in the ring
        self._parent = parent  # its pid: re-parented means gone, even if the pipe stayed open

    def poll(self, conn: Any) -> dict | None:
        """Takes waiting control messages; the stop figures once the parent said stop."""
        try:
            while self._stop is None and conn.poll():
                self._take(conn.recv())
        except (EOFError, OSError):  # the parent is gone: finish the file
            self._parent_gone()
        if self._stop is None and self._parent is not None and os.getppid() != self._parent:
            self._parent_gone()
        if self._stop is None and _TERMINATED:
            self._stop = {"signal": str(_TERMINATED[0])}
        return self._stop

    def _parent_gone(self) -> None:
        self._stop = self._stop or {"parent": "gone"}
        self.parent_gone = True

    def _take(self, message: tuple) -> None:
        from twin_cli.record.layout import make_layout

        if message[0] == "layout":
            _, epoch, model, index, sources, start = message
            self._layouts[epoch] = make_layout(model, index, sources)
            self.reader.add_layout(start, epoch, model)
        elif message[0] == "readings":
            from twin_cli.record.sensor_messages import sensor_message

            for topic, reading in message[1]:
                self.writer.set_topics([topic])
                self.writer.write(sensor_message(topic, reading))
        elif message[0] == "stop":
            self._stop = message[1]

    def encode(self, epoch: int, records: Any) -> None:
        """Writes the messages of consecutive records (n × record length) of one layout."""
        samples = _samples(records, self._layouts[epoch])
        sent = self._publisher.publish(samples, self.writer, new_layout=epoch != self._epoch)
        if len(sent):
            self._epoch = epoch  # (a layout whose first records all diverged is not new yet)
            if self.samples == 0:
                self.times[0] = sent.times[0]
            self.times[1] = sent.times[-1]
            self.samples += len(sent)

    def idle(self) -> None:
        """The ring is empty: what is written reaches the file."""
        self.writer.writer.flush_if_due()

    def close(self, figures: dict) -> None:
        self.writer.writer.custom_data = {k: str(v) for k, v in figures.items()}
        self.writer.close()


def conn_pending(conn: Any, timeout: float = 0.0) -> bool:
    """Whether the parent sent something not yet taken, waiting up to `timeout` [s] for it
    (False once the pipe is closed). The encoder's idle wait is this: the parent's sends must
    not wait for it (a camera image is larger than the pipe's buffer, so its send blocks until
    it is read)."""
    try:
        return bool(conn.poll(timeout))
    except (EOFError, OSError):
        return False


def _samples(records: Any, layout: Any) -> Any:
    """The `Samples` that records hold (column views): MuJoCo's state vector (time, qpos, qvel,
    mocap_pos, mocap_quat, in `mjtState` order) and then qfrc_actuator."""
    from twin_cli.record.sampler import Samples

    m, n = layout.model, len(records)
    sizes = (m.nq, m.nv, 3 * m.nmocap, 4 * m.nmocap, m.nv)
    parts, at = [], 1
    for size in sizes:
        parts.append(records[:, at : at + size])
        at += size
    qpos, qvel, mpos, mquat, qfrc = parts
    return Samples(
        layout, records[:, 0], qpos, qvel, qfrc, mpos.reshape(n, -1, 3), mquat.reshape(n, -1, 4)
    )


if __name__ == "__main__":
    import sys

    main(sys.argv[1:])
