"""Run control of a World: pause, step, reset, stats, the stepping thread and divergence recovery.

A mixin of `twin_cli.world.engine.World` (it uses the world's lock, spec, model, data, entities,
pushes and loop); split out so that each file holds one concept. Stepping methods whose names
start with "_" expect the caller to hold the lock (the loop thread and `step`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace
from time import perf_counter

import mujoco

from twin_cli.errors import InvalidRequestError
from twin_cli.world import actuation as control
from twin_cli.world.divergence import (
    Divergence,
    batch_healthy,
    find_divergent,
    warning_counts,
)
from twin_cli.world.entities import index_entities, write_state
from twin_cli.world.sensor_rings import align_sensor_ticks, shift_sensor_history
from twin_cli.world.values import Stats

STATE = mujoco.mjtState.mjSTATE_INTEGRATION
mj_step = mujoco.mj_step  # one global lookup per split instead of two


class RunControl:
    """Pausing, stepping, resetting and metering a World (mixin; see module docstring)."""

    @property
    def paused(self) -> bool:
        """Whether the real-time loop is paused (step() still works)."""
        return self._paused

    def pause(self) -> None:
        """Pauses the real-time loop."""
        with self.lock:
            self._paused = True

    def resume(self) -> None:
        """Resumes the real-time loop (the pacer re-anchors: no catch-up burst)."""
        with self.lock:
            self._paused = False
            self._loop.reanchor()

    def step(self, n: int = 1) -> None:
        """Steps `n` times now (paused or not)."""
        if not isinstance(n, int) or n < 0:
            raise InvalidRequestError(
                "step count", f"{n!r} is not a whole number >= 0", "give e.g. 100"
            )
        with self.lock:
            self._advance(n)

    def reset(self, *, time_only: bool = False) -> None:
        """Puts every entity back to its spawn state and time to 0 (or only time and iterations).

        A full reset also clears pushes and joint commands (motors back to zero effort).
        """
        with self.lock:
            if time_only:
                self._pushes = [
                    replace(p, end_step=p.end_step - self._iterations) for p in self._pushes
                ]
                shift_sensor_history(self.model, self.data, -float(self.data.time))
                self.data.time, self._iterations = 0.0, 0
                align_sensor_ticks(self.model, self.data)  # the grid of the new clock
                self._loop.reset_clock()
                return
            self._commands, self._pushes = {}, []
            self._perturbation = {}
            model = self._spec.compile()
            data = mujoco.MjData(model)
            index = index_entities(model, list(self._entities))
            for n, e in self._entities.items():
                write_state(data, index[n], e.spawn_state)
            self._iterations = 0
            self._commit(self._spec, model, data, index)
            self._loop.reset_clock()

    def stats(self) -> Stats:
        """`gz stats` figures (factor averaged over the last 20 samples of 0.2 s)."""
        with self.lock:
            fig = self._loop.figures()
            return Stats(
                fig.factor, float(self.data.time), fig.real_time, self._iterations, self._paused
            )

    @property
    def stepping_time(self) -> float:
        """Wall time [s] spent inside mj_step since the world was made.

        Over a window of the unthrottled loop, its share of the window's wall time is the loop's
        throughput against raw mj_step on the very same steps at the very same moment (what the
        loop adds: locks, checks, bookkeeping), free of the ±15 % that one raw run differs from
        the next on a shared machine. `benchmarks/bench_world.py` reports it.
        """
        return self._stepping_time

    def loop_figures(self):  # noqa: ANN201
        """The loop's own measurements (factor, real time, lateness, dropped steps)."""
        return self._loop.figures()

    def start(self) -> None:
        """Starts the real-time stepping thread."""
        self._loop.start()

    def stop(self) -> None:
        """Stops and joins the stepping thread."""
        self._loop.stop()

    @property
    def running(self) -> bool:
        """Whether the stepping thread runs."""
        return self._loop.running

    def add_observer(self, callback: Callable[[], None], rate: float) -> int:
        """Calls `callback()` every 1/`rate` [Hz] of sim time, between steps, lock held.

        For consumers of the world (recorder, live stream; design.md §7): the stepping splits its
        `mj_step(nstep)` calls where an observer is due, so there is no Python per physics step.
        The callback must only copy what it needs. Returns a handle for `remove_observer`.
        """
        with self.lock:
            return self._observers.add(
                callback, rate, float(self.data.time), self.model.opt.timestep
            )

    def remove_observer(self, handle: int) -> None:
        """Stops calling an observer (may be called from within its callback)."""
        with self.lock:
            self._observers.remove(handle)

    # ----------------------------------------------------------------- stepping (lock held)
    def _loop_view(self) -> tuple[float, bool, float, int]:
        return self.settings.rate, self._paused, float(self.data.time), self._iterations

    def _advance(self, n: int) -> None:
        """Steps n times, splitting at push expiries; caller holds the lock."""
        while n > 0:
            due = min((p.end_step for p in self._pushes), default=None)
            chunk = n if due is None else max(1, min(n, due - self._iterations))
            self._step_chunk(chunk)
            n -= chunk
            if due is not None and self._iterations >= due:
                self._expire_pushes()

    def _step_chunk(self, n: int) -> None:
        """Steps n times; on divergence, replays the batch step by step to catch its origin.

        NaNs spread to other entities through collisions within a few steps, so a divergence
        found after a batch is traced back: the batch-start state is restored and stepped one
        step at a time, and the entity that goes bad first is reset to its spawn state.
        """
        m, d = self.model, self.data
        if n > 1:
            mujoco.mj_getState(m, d, self._snapshot, STATE)
        before = warning_counts(d)
        # MuJoCo's default handler prints and appends to ./MUJOCO_LOG.TXT; keep its text instead
        # (set once per chunk, not per observer split: each set is a Python call).
        previous = mujoco.get_mju_user_warning()
        mujoco.set_mju_user_warning(self.mujoco_warnings.append)
        try:
            if self._observers:
                self._observers.run(n, self._mj_steps, d, m.opt.timestep)
            else:
                self._mj_steps(n)
        finally:
            mujoco.set_mju_user_warning(previous)
        self._iterations += n
        if batch_healthy(d, before):
            return
        bad = find_divergent(d, before, self._index)
        if bad and n == 1:
            self._recover(bad)
        elif bad:
            mujoco.mj_setState(m, d, self._snapshot, STATE)
            self._iterations -= n
            for _ in range(n):
                self._step_chunk(1)

    def _mj_steps(self, n: int) -> None:
        """n MuJoCo steps, with velocity decay (dampingFactor) after each when any is set.

        Called between observer calls with the interpreter's caches cold from the last step
        (design.md §7), so it makes as few lookups as it can: each costs ~0.5 µs there.
        """
        start = perf_counter()
        if self._damping is None:
            mj_step(self.model, self.data, n)
        else:
            m, d = self.model, self.data
            dofs, keep = self._damping.dofs, self._damping.keep
            for _ in range(n):
                mj_step(m, d)
                d.qvel[dofs] *= keep
        self._stepping_time += perf_counter() - start

    def _recover(self, bad: dict[str, str]) -> None:
        """Resets the offending entities to their spawn state; the others keep their state.

        MuJoCo's auto-reset (which would reset the whole world) is disabled in every world
        spec (scene.apply_physics), so within one step a diverging entity's NaNs stay its own.
        """
        for name, reason in bad.items():
            write_state(self.data, self._index[name], self._entities[name].spawn_state)
            self.divergences += 1
            self.divergence_log.append(Divergence(name, float(self.data.time), reason))

    def _expire_pushes(self) -> None:
        ended = {p.body for p in self._pushes if p.end_step <= self._iterations}
        self._pushes = [p for p in self._pushes if p.end_step > self._iterations]
        control.apply_pushes(self.model, self.data, self._pushes, ended, self._perturbation)
