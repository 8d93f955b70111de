"""Physics settings of a World: gravity, timestep, update rate, solver and integrator.

Functions of a world's state (`twin_cli.world.state`). Settings are written to both the
compiled model (effective on the next step) and the spec (so a recompile after spawn or delete
keeps them).
"""

from __future__ import annotations

from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np

from converters.mjcf.world_options import INTEGRATORS, SOLVERS
from twin_cli.world.contacts import cap_contact_stiffness, spec_solrefs
from twin_cli.world.engine_threads import set_engine, sleeping, threads_of
from twin_cli.world.pose import vec3
from twin_cli.world.scene import ODE_ONLY_FIELDS
from twin_cli.world.sensor_rings import align_sensor_ticks
from twin_cli.world.sleeping import wake_trees
from twin_cli.world.state import WorldState
from twin_cli.world.values import check_settings, finite_vector

if TYPE_CHECKING:
    from twin_cli.world.loop import SteppingLoop


def gravity(state: WorldState) -> tuple[float, float, float]:
    """The gravity vector [m/s²]."""
    with state.lock:
        return vec3(state.model.opt.gravity)


def set_gravity(state: WorldState, vector: tuple[float, float, float]) -> None:
    """Sets gravity [m/s²]; takes effect on the next step (see GRAVITY_PRESETS)."""
    g = finite_vector("gravity", vector, 3)
    with state.lock:
        state.model.opt.gravity[:] = g
        state.spec.option.gravity = np.array(g)
        state.settings = replace(state.settings, gravity=vec3(g))
        wake_trees(state.data, range(state.model.ntree))  # sleeping robots feel it too


def physics(state: WorldState) -> dict:
    """Timestep [s], rate [Hz], iterations, solver, integrator, gravity, target factor, and
    the ODE-only fields Gazebo carries that MuJoCo has no counterpart for."""
    with state.lock:
        s = state.settings
        return {
            "timestep": s.timestep,
            "rate": s.rate,
            "iterations": s.iterations,
            "solver": s.solver,
            "integrator": s.integrator,
            "gravity": list(s.gravity),
            "target_factor": s.timestep * s.rate if s.rate > 0 else None,
            "contact_max_correcting_vel": s.contact_max_correcting_vel,
            "not_applicable": list(ODE_ONLY_FIELDS),
            "threads": threads_of(state),
            "pool_threads": state.pool_threads,
            "sleep": sleeping(state.model),
            "sleep_tolerance": float(state.model.opt.sleep_tolerance),
        }


def set_physics(
    state: WorldState,
    loop: SteppingLoop,
    *,
    timestep: float | None = None,
    rate: float | None = None,
    iterations: int | None = None,
    solver: str | None = None,
    integrator: str | None = None,
    threads: int | None = None,
    sleep: bool | None = None,
    sleep_tolerance: float | None = None,
) -> dict:
    """Changes any of the physics settings (None keeps a value); returns `physics()`.

    `threads`: MuJoCo engine threads; `sleep`: island sleeping (see `engine_threads`).
    """
    given = dict(
        timestep=timestep,
        rate=rate,
        iterations=iterations,
        solver=solver,
        integrator=integrator,
    )
    changes = {k: v for k, v in given.items() if v is not None}
    with state.lock:
        new = replace(state.settings, **changes)
        check_settings(new)
        set_engine(state, threads=threads, sleep=sleep, sleep_tolerance=sleep_tolerance)
        state.settings = new
        for target in (state.model.opt, state.spec.option):
            target.timestep, target.iterations = new.timestep, new.iterations
            target.solver, target.integrator = SOLVERS[new.solver], INTEGRATORS[new.integrator]
        if "timestep" in changes:  # contacts resolvable at the old step may not be now
            cap_contact_stiffness(state.model, spec_solrefs(state.spec, state.model))
            align_sensor_ticks(state.model, state.data)  # the lead is half the new step
        loop.reanchor()
        wake_trees(state.data, range(state.model.ntree))  # new settings act on every robot
        return physics(state)
