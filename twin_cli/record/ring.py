"""A ring of raw state records in shared memory: the stepping thread writes, a process reads.

Recording at 100 Hz of sim time is thousands of samples per wall second when the loop runs
unthrottled; encoding them (rosbags CDR, MCAP chunks) in a thread of the server shares the GIL
with the loop and cost it 40 % of its throughput. So the stepping thread only copies the raw
state vectors into this ring (no Python object per sample) and an encoder process
(`encoder`) reads them. The memory is an unlinked file in /dev/shm whose descriptor the
process inherits (no named segment to leak).

A record is MuJoCo's state `[time, qpos, qvel, mocap_pos, mocap_quat]` (`mj_getState`, one C
call) followed by the joint efforts (`qfrc_actuator`, plus the tendon's force on a joint a
velocity motor drives, `twin_cli.world.velocity_motors`): two copies, because after `mj_step` every
Python operation meets caches that the step has emptied (~2-4 µs each). Records carry no header:
all records of one compiled model have its `record_length`, and the writer tells the reader
(over the pipe, before the first such record) the position from which they start
(`start_layout`). A record that does not fit before the end of the ring starts at 0; both sides
know the length, so both skip.
Positions are absolute counts of doubles (never wrapped), so `write - read` is what is in use.
The writer never overwrites unread data: when the ring is full it waits, and the recording
reports that time (`RecordingStatus.blocked_s`). x86-64 keeps stores in order, so the reader
that sees the new write position also sees the record.
"""

from __future__ import annotations

import collections
import mmap
import os
import tempfile
import time
from collections.abc import Callable

import mujoco
import numpy as np

from twin_cli.world.velocity_motors import effort_dofs

HEADER = 8  # int64 slots: write, read, samples, done, ...
WRITE, READ, SAMPLES, DONE = 0, 1, 2, 3
SPAN = 2  # doubles: first and last sample time [s]
WAIT_S = 0.0005  # [s] the writer's poll period while the ring is full
STATE = int(
    mujoco.mjtState.mjSTATE_TIME
    | mujoco.mjtState.mjSTATE_QPOS
    | mujoco.mjtState.mjSTATE_QVEL
    | mujoco.mjtState.mjSTATE_MOCAP_POS
    | mujoco.mjtState.mjSTATE_MOCAP_QUAT
)


def record_length(model: mujoco.MjModel) -> int:
    """Doubles in one record of `model`: its `STATE` and then `qfrc_actuator`."""
    return int(mujoco.mj_stateSize(model, STATE)) + int(model.nv)


def allocate(doubles: int) -> tuple[int, mmap.mmap]:
    """A ring of `doubles` float64 in an unnamed shared file: its descriptor (for the reader
    process) and the writable mapping. Nothing is left behind when both sides close it."""
    folder = "/dev/shm" if os.path.isdir("/dev/shm") else None
    size = 8 * (HEADER + SPAN + doubles)
    with tempfile.TemporaryFile(dir=folder) as handle:
        os.ftruncate(handle.fileno(), size)
        fd = os.dup(handle.fileno())
    # populated now: else the loop would take the page faults, one per 4 kB of records
    flags = mmap.MAP_SHARED | getattr(mmap, "MAP_POPULATE", 0)
    return fd, mmap.mmap(fd, size, flags=flags)


def attach(fd: int) -> mmap.mmap:
    """The mapping of a ring whose descriptor the writer handed down."""
    return mmap.mmap(fd, os.fstat(fd).st_size)


def views(memory: mmap.mmap) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """numpy views (no copies) of a ring's data, header (int64) and span (float64)."""
    header = np.frombuffer(memory, dtype=np.int64, count=HEADER)
    span = np.frombuffer(memory, dtype=np.float64, count=SPAN, offset=8 * HEADER)
    data = np.frombuffer(memory, dtype=np.float64, offset=8 * (HEADER + SPAN))
    return data, header, span


class RingWriter:
    """The stepping thread's side: copies one state into the next record (two C calls; the read
    position is re-read only when room runs short)."""

    def __init__(self, data: np.ndarray, header: np.ndarray, alive: Callable[[], bool]) -> None:
        """Args: data, header: ring views; alive: () -> bool, whether the reader still runs."""
        self._data, self._header, self._alive = data, header, alive
        self._capacity = data.size
        self._write = int(header[WRITE])  # only this side writes it: a Python mirror
        self._limit = int(header[READ]) + data.size  # write may grow to here without a look
        self._model: mujoco.MjModel | None = None
        self._d: mujoco.MjData | None = None  # the MjData whose qfrc_actuator view is cached
        self._forces: np.ndarray | None = None
        self._motors: tuple[np.ndarray, np.ndarray] = (np.zeros(0, int), np.zeros(0, int))
        self._constraint: np.ndarray | None = None  # the cached qfrc_constraint view
        self._state = self._length = 0
        self.blocked_s = 0.0  # [s] waited for room (the reader fell behind)
        self.waits = 0

    def start_layout(self, model: mujoco.MjModel) -> int:
        """Records from now on are of `model`; the position they start at, for the reader."""
        self._model, self._d = model, None
        self._motors = effort_dofs(model)
        self._state = int(mujoco.mj_stateSize(model, STATE))
        self._length = record_length(model)
        return self._write

    def put(self, d: mujoco.MjData) -> bool:
        """Writes MjData `d`'s state (of the model of the last `start_layout`) as a record;
        False if the reader is gone."""
        if d is not self._d:
            self._d, self._forces = d, d.qfrc_actuator  # each attribute access costs ~0.5 µs
            self._constraint = d.qfrc_constraint
        length, write = self._length, self._write
        pos = write % self._capacity
        if pos + length > self._capacity or write + length > self._limit:
            pos = self._make_room(length)
            if pos < 0:
                return False
        middle = pos + self._state
        mujoco.mj_getState(self._model, d, self._data[pos:middle], STATE)
        np.copyto(self._data[middle : pos + length], self._forces)
        joints, rotors = self._motors
        if len(joints):
            self._data[middle + joints] -= self._constraint[rotors]
        self._write = write = self._write + length
        self._header[WRITE] = write
        return True

    def _make_room(self, length: int) -> int:
        """Skips to the start of the ring when the record does not fit before the end (the
        reader skips the same way), then waits until the reader has freed `length` doubles;
        the record's position, or -1 (reader gone)."""
        capacity = self._capacity
        pos = self._write % capacity
        if pos + length > capacity:
            if not self._room(capacity - pos):
                return -1
            self._write += capacity - pos
            self._header[WRITE] = self._write  # so the reader can pass the unused end
            pos = 0
        return pos if self._room(length) else -1

    def _room(self, needed: int) -> bool:
        if self._write + needed <= self._limit:
            return True
        capacity = self._data.size
        self._limit = int(self._header[READ]) + capacity
        if self._write + needed <= self._limit:
            return True
        start = time.perf_counter()
        self.waits += 1
        try:
            while self._write + needed > self._limit:
                if not self._alive():
                    return False
                time.sleep(WAIT_S)
                self._limit = int(self._header[READ]) + capacity
        finally:
            self.blocked_s += time.perf_counter() - start
        return True


class RingReader:
    """The encoder's side: the records between the read and a write position, each with the
    layout (epoch) it was written in."""

    def __init__(self, data: np.ndarray, header: np.ndarray) -> None:
        self._data, self._header = data, header
        self._layouts: collections.deque[tuple[int, int, int]] = collections.deque()

    def add_layout(self, start: int, epoch: int, model: mujoco.MjModel) -> None:
        """Records from position `start` on are of `model`, tagged `epoch`."""
        self._layouts.append((start, epoch, record_length(model)))

    def read(self, write: int, limit: int) -> list[tuple[int, np.ndarray]]:
        """Up to `limit` unread records before position `write` (read before the layouts sent
        with them were taken), as runs of consecutive records of one layout: (epoch, a copy of
        n records × their length); marks them read."""
        data, layouts, capacity = self._data, self._layouts, self._data.size
        read = int(self._header[READ])
        out, taken = [], 0
        while read < write and taken < limit:
            while len(layouts) > 1 and layouts[1][0] <= read:
                layouts.popleft()
            _, epoch, length = layouts[0]
            pos = read % capacity
            if pos + length > capacity:  # the writer started this record over at 0
                read += capacity - pos
                continue
            end = write if len(layouts) == 1 else min(write, layouts[1][0])
            n = min((end - read) // length, (capacity - pos) // length, limit - taken)
            if n < 1:  # only if writer and reader disagree on a layout's start or length
                raise RuntimeError(f"ring: no whole record at {read} (layout {epoch})")
            out.append((epoch, data[pos : pos + n * length].reshape(n, length).copy()))
            read, taken = read + n * length, taken + n
        self._header[READ] = read
        return out
