"""Real-time check: the CPU the robot's physics needs per simulated second, against the target.

Capacity = simulated time / CPU time of the stepping thread (`time.thread_time`) inside the
world's steps, on a run nothing observes: no video frame, recording, plot or rendering is
counted (`--video` once turned a 6.7× robot into a 0.08× failure). With one engine thread (a
world's default) MuJoCo steps on the calling thread, so that CPU time is all of the physics.

Wall time and the machine's load (`os.getloadavg`) are measured beside it and reported, never
judged: a loaded machine deschedules the process (wall ≫ CPU, which CPU time ignores) and, when
it shares cores and caches, can inflate the CPU time of each step as well. Load only slows the
physics, so a capacity above the target passes however loaded the machine; one below it while
the process got under `min_cpu_share` of a core, or while the CPU time per step varied more than
`max_cpu_spread`× between slices, cannot be told apart from the load: the check then warns,
saying so, instead of failing.
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass

from twin_cli.validate.checks.base import CheckResult, RobotUnderTest, Series, Status, result
from twin_cli.validate.checks.model_collision import MESH
from twin_cli.validate.checks.model_inertia import collision_geoms
from twin_cli.validate.checks.sim import ScenarioRun
from twin_cli.validate.scenario import Scenario

WARMUP_S = 0.1  # [s] simulated before timing: first steps pay for caches and allocations
CHUNKS = 5  # the stepping is timed in this many equal slices (the plot; the spread rule)
TINY_S = 1e-9  # [s] floor of a measured time: a division by it never by zero


@dataclass(frozen=True)
class Timing:
    """Per slice of the timed stepping: simulated [s], thread CPU [s] and wall [s] time."""

    sim: tuple[float, ...]
    cpu: tuple[float, ...]
    wall: tuple[float, ...]
    ends: tuple[float, ...]  # [s] simulated time at the end of each slice

    @property
    def capacity(self) -> float:
        """Simulated seconds per CPU second of the physics."""
        return sum(self.sim) / max(sum(self.cpu), TINY_S)

    @property
    def wall_capacity(self) -> float:
        """Simulated seconds per wall second (what a loaded machine lowers)."""
        return sum(self.sim) / max(sum(self.wall), TINY_S)

    @property
    def cpu_share(self) -> float:
        """The share of the wall time the stepping thread was on a CPU."""
        return sum(self.cpu) / max(sum(self.wall), TINY_S)

    @property
    def spread(self) -> float:
        """Largest over smallest CPU time per simulated second among the slices."""
        per_sim = [c / max(s, TINY_S) for c, s in zip(self.cpu, self.sim, strict=True)]
        return max(per_sim) / max(min(per_sim), TINY_S)


def time_physics(run: ScenarioRun, duration: float) -> Timing:
    """Step `duration` [s] of the run in CHUNKS slices, timing each on the thread's CPU clock
    and the wall clock."""
    sim, cpu, wall, ends = [], [], [], []
    for _ in range(CHUNKS):
        start_sim, start_cpu, start_wall = run.time, time.thread_time(), time.perf_counter()
        run.run(duration / CHUNKS, None, every=100)
        cpu.append(time.thread_time() - start_cpu)
        wall.append(time.perf_counter() - start_wall)
        sim.append(run.time - start_sim)
        ends.append(run.time)
    return Timing(tuple(sim), tuple(cpu), tuple(wall), tuple(ends))


def machine_load() -> tuple[float, int]:
    """The 1-minute load average and the number of CPUs (load 0 where the OS has none)."""
    try:
        load = os.getloadavg()[0]
    except OSError:
        load = 0.0
    return load, os.cpu_count() or 1


def _keep_artifacts(robot: RobotUnderTest, scenario: Scenario) -> None:
    """With `--video` or `--record`, an observed run of the scenario makes the film and the
    bag, untimed: the timed run beside it has no observer."""
    from twin_cli.validate import recording, video

    if video.active() or recording.active():
        run = ScenarioRun(robot, scenario)
        run.run(scenario.duration, None, every=100)
        run.close()


def check_realtime(robot: RobotUnderTest, scenario: Scenario, th: dict[str, float]) -> CheckResult:
    """Capacity on CPU time of the physics alone (simulated s per CPU s) ≥ `min_factor` ×
    the world's target (rate × timestep); wall time and load are reported, never judged."""
    _keep_artifacts(robot, scenario)
    run = ScenarioRun(robot, scenario, observed=False)
    run.run(WARMUP_S, None, every=100)
    timing = time_physics(run, scenario.duration)
    w = scenario.world
    needed = th["min_factor"] * (w.rate * w.timestep if w.rate > 0 else 1.0)
    load, cores = machine_load()
    measured = (
        f"{timing.capacity:.3g}× real time on CPU; wall {timing.wall_capacity:.3g}×, "
        f"CPU share {timing.cpu_share:.0%}, load {load:.2f} on {cores} CPUs"
    )
    status, hints = _verdict(run, robot, timing, needed, th)
    return result(
        "realtime",
        "physics",
        status,
        measured,
        f"≥ {needed:g}× (CPU time of the physics)",
        hints=hints,
        details=_slices(timing),
        value=timing.capacity,
        series=[_series(timing, needed)],
    )


def _verdict(
    run: ScenarioRun, robot: RobotUnderTest, timing: Timing, needed: float, th: dict[str, float]
) -> tuple[Status, list[str]]:
    """PASS at or above the target; below it WARN when the machine could not let the
    measurement decide, else FAIL with the fixes that apply to this robot."""
    if timing.capacity >= needed:
        return Status.PASS, []
    undecided = []
    if timing.cpu_share < th["min_cpu_share"]:
        undecided.append(
            f"the stepping got {timing.cpu_share:.0%} of a CPU over its wall time "
            f"(< {th['min_cpu_share']:.0%})"
        )
    if timing.spread > th["max_cpu_spread"]:
        undecided.append(
            f"its CPU time per step varied {timing.spread:.2g}× between slices "
            f"(> {th['max_cpu_spread']:g}×)"
        )
    if undecided:
        return Status.WARN, [
            f"{timing.capacity:.3g}× real time is below {needed:g}×, but the machine was too "
            f"loaded to tell the robot from the load ({'; '.join(undecided)}): rerun on a "
            "quieter machine"
        ]
    return Status.FAIL, [_slow_hint(run, robot, timing, needed)]


def _slow_hint(run: ScenarioRun, robot: RobotUnderTest, timing: Timing, needed: float) -> str:
    """What makes this robot's physics cheaper: meshes only when it collides with meshes."""
    w = run.scenario.world
    fixes = []
    meshes = [g for g in collision_geoms(robot.model) if int(robot.model.geom_type[g]) == MESH]
    if meshes:
        faces = sum(int(robot.model.mesh_facenum[int(robot.model.geom_dataid[g])]) for g in meshes)
        fixes.append(
            f"simplify its {len(meshes)} collision mesh(es) ({faces} triangles: --collision "
            "hull, or primitive <collision> shapes)"
        )
    fixes.append(
        f"raise the timestep and lower the rate with it (e.g. {2 * w.timestep:g} s at "
        f"{w.rate / 2:g} Hz keeps the {w.rate * w.timestep:g}× target and halves the steps: "
        "[world] timestep and rate in a scenario, max_step_size and real_time_update_rate "
        "in a world file)"
    )
    return (
        f"the physics needs {1.0 / max(timing.capacity, TINY_S):.3g} s of CPU per simulated "
        f"second ({timing.capacity:.3g}× real time, below {needed:g}×): " + "; or ".join(fixes)
    )


def _slices(timing: Timing) -> list[str]:
    slices = zip(timing.sim, timing.cpu, timing.wall, strict=True)
    return [
        f"slice {i + 1}: {s:g} s simulated in {c * 1e3:.3g} ms CPU, {wl * 1e3:.3g} ms wall"
        for i, (s, c, wl) in enumerate(slices)
    ]


def _series(timing: Timing, needed: float) -> Series:
    """Capacity of each slice on CPU time (judged) and on wall time (the load's share)."""
    on_cpu = [s / max(c, TINY_S) for s, c in zip(timing.sim, timing.cpu, strict=True)]
    on_wall = [s / max(wl, TINY_S) for s, wl in zip(timing.sim, timing.wall, strict=True)]
    return Series(
        "capacity",
        "× real time",
        timing.ends,
        {"simulated s per CPU s": tuple(on_cpu), "simulated s per wall s": tuple(on_wall)},
        threshold=needed,
        log=True,
    )
