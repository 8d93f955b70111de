"""Physics settings of a World: gravity, timestep, update rate, solver and integrator.

A mixin of `twin_cli.world.engine.World` (it uses the world's lock, settings, spec, model and loop).
Settings are written to both the compiled model (effective on the next step) and the spec (so a
recompile after spawn or delete keeps them).
"""

from __future__ import annotations

from dataclasses import replace

from converters.mjcf.world_options import INTEGRATORS, SOLVERS
from twin_cli.world import actuation as control
from twin_cli.world.contacts import cap_contact_stiffness, spec_solrefs
from twin_cli.world.entities import element_names
from twin_cli.world.scene import ODE_ONLY_FIELDS
from twin_cli.world.sensor_rings import align_sensor_ticks
from twin_cli.world.sleeping import wake_trees
from twin_cli.world.values import check_settings, finite_vector


class PhysicsSettings:
    """Reading and changing a World's gravity and physics settings (mixin)."""

    def gravity(self) -> tuple[float, float, float]:
        """The gravity vector [m/s²]."""
        with self.lock:
            return tuple(float(v) for v in self.model.opt.gravity)  # type: ignore[return-value]

    def set_gravity(self, vector: tuple[float, float, float]) -> None:
        """Sets gravity [m/s²]; takes effect on the next step (see GRAVITY_PRESETS)."""
        g = finite_vector("gravity", vector, 3)
        with self.lock:
            self.model.opt.gravity[:] = g
            self._spec.option.gravity = g
            self.settings = replace(self.settings, gravity=tuple(g))
            wake_trees(self.data, range(self.model.ntree))  # sleeping robots feel it too

    def physics(self) -> dict:
        """Timestep [s], rate [Hz], iterations, solver, integrator, gravity, target factor, and
        the ODE-only fields Gazebo carries that MuJoCo has no counterpart for."""
        with self.lock:
            s = self.settings
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
                "threads": self.threads,
                "pool_threads": self.pool_threads,
                "sleep": self.sleeping,
                "sleep_tolerance": float(self.model.opt.sleep_tolerance),
            }

    def set_physics(
        self,
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
        with self.lock:
            new = replace(self.settings, **changes)
            check_settings(new)
            self.set_engine(threads=threads, sleep=sleep, sleep_tolerance=sleep_tolerance)
            self.settings = new
            for target in (self.model.opt, self._spec.option):
                target.timestep, target.iterations = new.timestep, new.iterations
                target.solver, target.integrator = SOLVERS[new.solver], INTEGRATORS[new.integrator]
            if "timestep" in changes:  # contacts resolvable at the old step may not be now
                cap_contact_stiffness(self.model, spec_solrefs(self._spec, self.model))
                align_sensor_ticks(self.model, self.data)  # the lead is half the new step
            # dampingFactor's per-step keep fraction depends on the timestep.
            self._damping = control.damping_of(
                self.model, element_names(self.model, self.model.name_numericadr)
            )
            self._loop.reanchor()
            wake_trees(self.data, range(self.model.ntree))  # new settings act on every robot
            return self.physics()
