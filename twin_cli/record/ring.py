"""A ring of raw state records in shared memory: the stepping thread writes, a process reads.

Recording at 100 Hz of sim time is thousands of samples per wall second when the loop runs
unthrottled; encoding them (rosbags CDR, MCAP chunks) in a thread of the server shares the GIL
with the loop and cost it 40 % of its throughput. So the stepping thread only copies the raw
state vectors into this ring (no Python object per sample) and an encoder process
(`encoder`) reads them. The memory is an unlinked file in /dev/shm whose descriptor the
process inherits (no named segment to leak).

A record is a run of doubles `[length, epoch, time, qpos, qvel, qfrc_actuator, mocap_pos,
mocap_quat]`; a record that does not fit before the end leaves a -1 marker and starts at 0.
Positions are absolute counts of doubles (never wrapped), so `write - read` is what is in use.
The writer never overwrites unread data: when the ring is full it waits, and the recording
reports that time (`RecordingStatus.blocked_s`). x86-64 keeps stores in order, so the reader
that sees the new write position also sees the record.
"""

from __future__ import annotations

import mmap
import os
import tempfile
import time
from typing import Any

import numpy as np

WRAP = -1.0
HEADER = 8  # int64 slots: write, read, samples, done, ...
WRITE, READ, SAMPLES, DONE = 0, 1, 2, 3
SPAN = 2  # doubles: first and last sample time [s]
WAIT_S = 0.0005  # [s] the writer's poll period while the ring is full


def allocate(doubles: int) -> tuple[int, Any]:
    """A ring of `doubles` float64 in an unnamed shared file: its descriptor (for the reader
    process) and the writable mapping. Nothing is left behind when both sides close it."""
    folder = "/dev/shm" if os.path.isdir("/dev/shm") else None
    size = 8 * (HEADER + SPAN + doubles)
    with tempfile.TemporaryFile(dir=folder) as handle:
        os.ftruncate(handle.fileno(), size)
        fd = os.dup(handle.fileno())
    return fd, mmap.mmap(fd, size)


def attach(fd: int) -> Any:
    """The mapping of a ring whose descriptor the writer handed down."""
    return mmap.mmap(fd, os.fstat(fd).st_size)


def views(memory: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """numpy views (no copies) of a ring's data, header (int64) and span (float64)."""
    header = np.frombuffer(memory, dtype=np.int64, count=HEADER)
    span = np.frombuffer(memory, dtype=np.float64, count=SPAN, offset=8 * HEADER)
    data = np.frombuffer(memory, dtype=np.float64, offset=8 * (HEADER + SPAN))
    return data, header, span


class RingWriter:
    """The stepping thread's side: copies one state into the next record (~2 µs: one
    `np.concatenate` into the ring; the read position is re-read only when room runs short)."""

    def __init__(self, data: np.ndarray, header: np.ndarray, alive: Any) -> None:
        """Args: data, header: ring views; alive: () -> bool, whether the reader still runs."""
        self._data, self._header, self._alive = data, header, alive
        self._capacity = data.size
        self._write = int(header[WRITE])  # only this side writes it: a Python mirror
        self._limit = int(header[READ]) + data.size  # write may grow to here without a look
        self._d: Any = None  # the MjData whose views are cached
        self._head = np.zeros(3)  # [length, epoch, time] of the record being written
        self._views: tuple = ()
        self._length = 0
        self.blocked_s = 0.0  # [s] waited for room (the reader fell behind)
        self.waits = 0

    def put(self, epoch: int, d: Any) -> bool:
        """Writes MjData `d`'s state as a record of `epoch`; False if the reader is gone."""
        if d is not self._d:
            self._bind(d)
        length, write = self._length, self._write
        pos = write % self._capacity
        if pos + length > self._capacity or write + length > self._limit:
            pos = self._make_room(length)
            if pos < 0:
                return False
        head = self._head
        head[1], head[2] = epoch, d.time
        np.concatenate(self._views, out=self._data[pos : pos + length])
        self._write += length
        self._header[WRITE] = self._write
        return True

    def _bind(self, d: Any) -> None:
        """numpy views of `d`, made once: each attribute access costs ~0.5 µs."""
        self._d = d
        self._views = (
            self._head,
            d.qpos,
            d.qvel,
            d.qfrc_actuator,
            d.mocap_pos.ravel(),
            d.mocap_quat.ravel(),
        )
        nq, nv, nmocap = d.qpos.size, d.qvel.size, d.mocap_pos.size
        self._length = 3 + nq + 2 * nv + nmocap * 7 // 3
        self._head[0] = self._length

    def _make_room(self, length: int) -> int:
        """Wraps to the start when the record does not fit before the end, then waits until
        the reader has freed `length` doubles; the record's position, or -1 (reader gone)."""
        capacity = self._capacity
        pos = self._write % capacity
        if pos + length > capacity:
            if not self._room(capacity - pos):
                return -1
            self._data[pos] = WRAP
            self._write += capacity - pos
            self._header[WRITE] = self._write
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


def read_records(data: np.ndarray, header: np.ndarray, limit: int) -> list[np.ndarray]:
    """Up to `limit` unread records (copies), and marks them read."""
    capacity = data.size
    read, write = int(header[READ]), int(header[WRITE])
    out = []
    while read < write and len(out) < limit:
        pos = read % capacity
        length = data[pos]
        if length == WRAP:
            read += capacity - pos
            continue
        n = int(length)
        out.append(data[pos : pos + n].copy())
        read += n
    header[READ] = read
    return out
