"""Consumers of a running world (recorder, live stream, viewers) called between batches.

An observer asks for a rate in *simulated* time; the stepping code splits each `mj_step(nstep)`
call at the steps where an observer is due and calls it there, with the world's lock held, so a
100 Hz recording of a 1 ms world gets a sample every 10 steps exactly, at any real-time factor,
with no Python per physics step. Callbacks must only copy what they need (a few microseconds)
and do their encoding and I/O elsewhere, or they would slow the loop. The rules (`steps_until_due`,
`is_due`, `next_due`) are pure functions, testable without threads; `Observers.run` inlines
the first two on its hot path (tests drive `run` itself too).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import mujoco

    from twin_cli.world.engine import World
    from twin_cli.world.entities import EntityIndex

DUE_TOLERANCE = 1e-6  # fraction of a step: sim time accumulates rounding (0.01 != 10 * 0.001)


def steps_until_due(time: float, due: float, timestep: float) -> int:
    """Steps from `time` [s] until the sim time reaches `due` [s]; at least 1."""
    return max(1, math.ceil((due - time) / timestep - DUE_TOLERANCE))


def next_due(time: float, origin: float, period: float, timestep: float) -> float:
    """The first time `origin + k·period` [s] strictly after `time` (within a step's rounding).

    Computed from the origin, not by adding periods, so rounding never accumulates.
    """
    k = math.floor((time - origin) / period + DUE_TOLERANCE * timestep / period)
    return origin + (k + 1) * period


def is_due(time: float, due: float, timestep: float) -> bool:
    """Whether sim `time` [s] has reached `due` [s] (to a millionth of a step)."""
    return time >= due - DUE_TOLERANCE * timestep


@dataclass
class _Entry:
    callback: Callable[[], None]
    period: float  # [s] of simulated time
    origin: float  # [s] sim time the observer was added (or the clock was reset) at
    due: float  # [s] next sim time to call at


class Observers:
    """The observers of one world, by handle; empty costs one attribute test per batch.

    The earliest due time is kept up to date on every change, so a split costs a
    few comparisons besides the callbacks (measured: ~20 µs of Python per split before, with
    the interpreter's caches cold after each `mj_step`).
    """

    def __init__(self) -> None:
        self._entries: dict[int, _Entry] = {}
        self._handles = itertools.count(1)
        self._due = math.inf  # [s] the earliest entry's due time
        self._time = -math.inf  # [s] at the end of the last split: later time before it, a reset
        self._version = 0  # changes with the set of entries or their grid (ends a stride run)

    def __bool__(self) -> bool:
        return bool(self._entries)

    def add(
        self,
        callback: Callable[[], None],
        rate: float,
        time: float,
        timestep: float,
        *,
        aligned: bool = False,
    ) -> int:
        """Registers `callback` every 1/`rate` [Hz] of sim time after `time` [s]; a handle.

        `aligned`: on the clock's own k/`rate` grid instead of a grid from `time`, so that an
        observer registered again (a sensor's, after a spawn changed the model or a live view
        changed its stride) keeps the stamps it had, as a Gazebo sensor keeps its update grid.
        """
        period = 1.0 / rate
        origin = time
        if aligned:
            origin = math.floor(time / period + DUE_TOLERANCE * timestep / period) * period
        handle = next(self._handles)
        self._entries[handle] = _Entry(
            callback, period, origin, next_due(time, origin, period, timestep)
        )
        self._summarize()
        return handle

    def remove(self, handle: int) -> None:
        """Forgets an observer (unknown handles are ignored: removal may race with a reset)."""
        if self._entries.pop(handle, None) is not None:
            self._summarize()

    def run(
        self, n: int, step: Callable[[int], None], data: mujoco.MjData, timestep: float
    ) -> None:
        """Steps `n` times through `step(k)`, calling each observer when it is due.

        A clock that went back (reset) re-anchors the observers at the new time. This runs
        after every split with the interpreter's caches cold from `mj_step`, so the rules of
        `steps_until_due` and `is_due` are inlined here (each call or lookup costs ~1 µs).
        """
        late = DUE_TOLERANCE * timestep  # [s] is_due's slack
        while n > 0:
            now = data.time
            if now < self._time:
                self._reanchor(now)
            due = self._due
            k = math.ceil((due - now) / timestep - DUE_TOLERANCE)  # steps_until_due
            k = 1 if k < 1 else n if k > n else k
            step(k)
            n -= k
            now = self._time = data.time
            if now >= due - late:  # is_due
                self._notify(now, timestep)
                n = self._stride(n, step, data, timestep)
                if not self._entries:
                    if n:
                        step(n)
                    return

    def _stride(
        self, n: int, step: Callable[[int], None], data: mujoco.MjData, timestep: float
    ) -> int:
        """Right after a call: while a lone observer, called just now, has a period of a whole
        number K of steps, steps K and calls it, with no sim-time arithmetic in between (it
        cost a 100 Hz recording of an unthrottled humanoid about 1 % of the loop). A callback
        that adds or removes observers ends the run; the due times are brought up to date
        once, at the end. Returns the steps left."""
        if len(self._entries) != 1:
            return n
        (entry,) = self._entries.values()
        ratio = entry.period / timestep
        stride = round(ratio)
        now = data.time
        called_now = abs(entry.due - entry.period - now) <= DUE_TOLERANCE * timestep
        if not called_now or stride < 1 or abs(ratio - stride) > DUE_TOLERANCE or n < stride:
            return n  # (a survivor of a removal may be off this step's grid)
        callback, version = entry.callback, self._version
        while n >= stride and self._version == version:
            step(stride)
            n -= stride
            callback()
        now = self._time = data.time
        if any(e is entry for e in self._entries.values()):
            entry.due = next_due(now, entry.origin, entry.period, timestep)
        self._summarize()
        return n

    def _summarize(self) -> None:
        self._version += 1
        entries = self._entries.values()
        self._due = min((e.due for e in entries), default=math.inf)

    def replaying(self, time: float) -> None:
        """The state of sim `time` [s] was restored to step a batch again (the divergence
        watchdog's replay). Not a reset: each observer keeps its origin and next due time, so
        its calls stay on its k·period grid and the span already observed is not observed
        twice (its sim time would go back)."""
        self._time = time

    def _reanchor(self, time: float) -> None:
        """The clock went back (reset, load): every observer starts over from `time`."""
        for entry in self._entries.values():
            entry.origin, entry.due = time, time + entry.period
        self._summarize()

    def _notify(self, time: float, timestep: float) -> None:
        entries = self._entries
        if len(entries) == 1:  # the common case (one recording): no copies, no min()
            (entry,) = entries.values()
            entry.due = next_due(time, entry.origin, entry.period, timestep)
            self._due = entry.due
            entry.callback()
            return
        for entry in list(entries.values()):
            if is_due(time, entry.due, timestep):
                entry.due = next_due(time, entry.origin, entry.period, timestep)
                entry.callback()
        self._summarize()


@dataclass(frozen=True)
class WorldView:
    """What an observer may read of a world, under its lock (references, no copies).

    Attributes:
        model, data: the compiled model and its live data (read only).
        index: entity name → `twin_cli.world.entities.EntityIndex` in `model`.
        descriptions: entity name → its URDF text after xacro (None: not a URDF source).
    """

    model: mujoco.MjModel
    data: mujoco.MjData
    index: dict[str, EntityIndex]
    descriptions: dict[str, str | None]


def world_view(world: World) -> WorldView:
    """The world's model, data and entity index; call with `world.lock` held."""
    names = world.entity_names()
    return WorldView(
        world.model,
        world.data,
        {n: world.index_of(n) for n in names},
        {n: world.entity(n).description for n in names},
    )
