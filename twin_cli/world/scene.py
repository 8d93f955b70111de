"""The world spec a World starts from: Gazebo's empty world (ground, sun, SDF physics defaults)."""

from __future__ import annotations

from dataclasses import dataclass

import mujoco

# MuJoCo's solver and integrator names, as users type them (lower case).
SOLVERS = {
    "newton": mujoco.mjtSolver.mjSOL_NEWTON,
    "cg": mujoco.mjtSolver.mjSOL_CG,
    "pgs": mujoco.mjtSolver.mjSOL_PGS,
}
INTEGRATORS = {
    "euler": mujoco.mjtIntegrator.mjINT_EULER,
    "rk4": mujoco.mjtIntegrator.mjINT_RK4,
    "implicit": mujoco.mjtIntegrator.mjINT_IMPLICIT,
    "implicitfast": mujoco.mjtIntegrator.mjINT_IMPLICITFAST,
}
# implicitfast integrates joint damping and the PD gains of joint commands implicitly, so they
# stay stable at the 1 ms step; Euler would need much smaller gains (MuJoCo doc "Numerical
# integration").
DEFAULT_INTEGRATOR = "implicitfast"
DEFAULT_SOLVER = "newton"

# The SDF/ODE physics fields MuJoCo has no counterpart for (sdf/1.11/physics.sdf, ode section).
ODE_ONLY_FIELDS = (
    "sor",
    "erp",
    "cfm",
    "precon_iters",
    "min_step_size",
    "contact_max_correcting_vel",
    "contact_surface_layer",
    "max_contacts",
    "friction_model",
    "island_threads",
)


@dataclass(frozen=True)
class SceneSettings:
    """Physics of a world spec: the subset of WorldSettings the compiled model carries.

    Attributes:
        timestep: [s]; gravity: [m/s²]; iterations: solver iterations; solver, integrator: names
        in SOLVERS / INTEGRATORS; ground: whether to add Gazebo's ground plane.
    """

    timestep: float
    gravity: tuple[float, float, float]
    iterations: int
    solver: str = DEFAULT_SOLVER
    integrator: str = DEFAULT_INTEGRATOR
    ground: bool = True


def build_world_spec(settings: SceneSettings) -> mujoco.MjSpec:
    """An empty world: Gazebo's ground (μ=100, μ2=50) if asked, a sun light, the physics."""
    from converters.gazebo.contact import add_gazebo_ground

    spec = mujoco.MjSpec()
    spec.modelname = "world"
    if settings.ground:
        add_gazebo_ground(spec)
    # Gazebo's empty.world sun: directional, from above, casting shadows.
    spec.worldbody.add_light(
        name="sun",
        pos=[0.0, 0.0, 10.0],
        dir=[-0.5, 0.1, -0.9],
        castshadow=True,
    )
    apply_physics(spec, settings)
    return spec


def apply_physics(spec: mujoco.MjSpec, settings: SceneSettings) -> None:
    """Writes timestep, gravity, iterations, solver and integrator into `spec.option`."""
    spec.option.timestep = settings.timestep
    spec.option.gravity = list(settings.gravity)
    spec.option.iterations = settings.iterations
    spec.option.solver = SOLVERS[settings.solver]
    spec.option.integrator = INTEGRATORS[settings.integrator]
    spec.option.tolerance = SOLVER_TOLERANCE
    # A diverging entity must not reset the whole world (twin resets only that entity).
    spec.option.disableflags |= mujoco.mjtDisableBit.mjDSBL_AUTORESET


# Solver convergence threshold, fixed in every world. MuJoCo 4 solves each constraint island on its
# own, but an island's stopping point still shifts with what else is in the model: measured on a
# falling humanoid while a second one spawns, MuJoCo's default 1e-8 lets the first robot's qpos
# move 1.4e-7 m (and scaling the tolerance by meaninertia·nv, as once done here, 6 mm); 1e-12
# keeps it within 1.3e-13 m for 0.3 % more solver iterations (1145 against 1142 in 700 steps).
SOLVER_TOLERANCE = 1e-12


_OPTION_FIELDS = (
    "timestep",
    "gravity",
    "integrator",
    "iterations",
    "solver",
    "cone",
    "jacobian",
    "impratio",
    "tolerance",
    "ls_iterations",
    "ls_tolerance",
    "noslip_iterations",
    "noslip_tolerance",
    "ccd_iterations",
    "ccd_tolerance",
    "density",
    "viscosity",
    "wind",
    "magnetic",
    "o_margin",
    "o_solref",
    "o_solimp",
    "o_friction",
    "disableflags",
    "enableflags",
    "disableactuator",
    "sdf_iterations",
    "sdf_initpoints",
    "sleep_tolerance",
)
_SIZE_FIELDS = ("memory", "nstack", "njmax", "nconmax", "nemax", "nuserdata")
_VISUAL_AUTHORED = (
    "visual_global",
    "visual_headlight",
    "visual_map",
    "visual_quality",
    "visual_rgba",
    "visual_scale",
)


def adopt_world_globals(child: mujoco.MjSpec, world: mujoco.MjSpec) -> None:
    """Gives `child` the world's global settings, so attaching it raises no conflict.

    A robot's own <option>, <size> and <visual> do not apply inside a world (Gazebo ignores a
    model's physics too); copying the world's values avoids MuJoCo's attach-conflict warnings,
    which would otherwise be printed and would, for unauthored world values, take the child's.
    """
    for name in _OPTION_FIELDS:
        setattr(child.option, name, getattr(world.option, name))
    for name in _SIZE_FIELDS:
        setattr(child, name, getattr(world, name))
    for name in _VISUAL_AUTHORED:
        setattr(child.authored, name, 0)
