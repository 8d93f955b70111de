"""Loop/raw throughput on identical work: raw mj_step's time for exactly the steps a loop ran.

A loop (in-process thread or server) and raw `mj_step` start from the same saved state, so they
step the same deterministic trajectory; but the cost of a step changes along it (a falling robot
is cheap, a robot on the ground is not). Timing the loop over a window and raw `mj_step` over
another window, as earlier benchmarks did, mixed that in: repeats ranged 0.83-1.21. Here raw
`mj_step` records its cumulative wall and CPU time every PROFILE_CHUNK steps, and a loop window
from step i0 to i1 is compared with raw's time for steps i0 to i1.
"""

from __future__ import annotations

import copy
import time
from dataclasses import dataclass

import mujoco
import numpy as np

PROFILE_CHUNK = 100  # steps per raw mj_step call (and resolution of the profile)


@dataclass(frozen=True)
class RawProfile:
    """Cumulative wall and CPU time [s] of raw mj_step after k·PROFILE_CHUNK steps (k = index)."""

    wall_s: np.ndarray
    cpu_s: np.ndarray

    @property
    def steps(self) -> int:
        return (len(self.wall_s) - 1) * PROFILE_CHUNK

    def between(self, first: int, last: int) -> tuple[float, float]:
        """Raw wall and CPU time [s] for steps first..last (counted from the saved state)."""
        if last > self.steps:
            raise ValueError(f"raw profile covers {self.steps} steps, the window ends at {last}")
        chunks = np.arange(len(self.wall_s)) * PROFILE_CHUNK
        wall = np.interp([first, last], chunks, self.wall_s)
        cpu = np.interp([first, last], chunks, self.cpu_s)
        return float(wall[1] - wall[0]), float(cpu[1] - cpu[0])


def raw_profile(model: mujoco.MjModel, data: mujoco.MjData, steps: int) -> RawProfile:
    """Steps a copy of `data` `steps` times (in PROFILE_CHUNK calls) and records the times."""
    work = copy.copy(data)
    walls, cpus = [0.0], [0.0]
    wall0, cpu0 = time.perf_counter(), time.thread_time()
    for _ in range(-(-steps // PROFILE_CHUNK)):
        mujoco.mj_step(model, work, nstep=PROFILE_CHUNK)
        walls.append(time.perf_counter() - wall0)
        cpus.append(time.thread_time() - cpu0)
    return RawProfile(np.array(walls), np.array(cpus))


@dataclass(frozen=True)
class Window:
    """Steps first..last (from the saved state) that a loop ran in `wall_s` and `cpu_s` [s]."""

    first: int
    last: int
    wall_s: float
    cpu_s: float

    def ratios(self, raws: list[RawProfile]) -> dict[str, float]:
        """Loop throughput over raw throughput on the same steps, by wall and by CPU time.

        Raw time is the fastest of several whole raw runs over these steps (background load only
        slows a run); not a minimum taken chunk by chunk, which would favour raw by picking each
        chunk's luckiest run.
        """
        raw_wall = min(raw.between(self.first, self.last)[0] for raw in raws)
        raw_cpu = min(raw.between(self.first, self.last)[1] for raw in raws)
        return {
            "steps": self.last - self.first,
            "loop_over_raw_wall": raw_wall / self.wall_s,
            "loop_over_raw_cpu": raw_cpu / self.cpu_s,
        }
