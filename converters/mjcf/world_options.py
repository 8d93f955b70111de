"""The physics options of a twin world (SDF defaults, Newton, implicit) written into an MjSpec.

One source for the world engine (`twin_cli.world.scene`) and the exported `scene.xml`
(`converters.mjcf.writer`), so a model opened in plain MuJoCo steps with the physics that
`twin validate` proved. Here rather than in `twin_cli`: converters never import twin_cli.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

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

# SDF world defaults (sdf/1.11/physics.sdf): 1 ms step at 1000 Hz; ODE quick solver 50 iterations.
TIMESTEP_S = 0.001  # [s]
UPDATE_RATE_HZ = 1000.0  # [Hz]
ITERATIONS = 50
# twin's --earth preset [m/s²] (standard gravity, rounded; Gazebo's empty.world has 9.8).
GRAVITY = (0.0, 0.0, -9.81)
# implicitfast integrates joint damping and the actuators' velocity gains implicitly, so the
# servos of joint commands stay stable at the 1 ms step, and leaves the Coriolis and centrifugal
# forces explicit (MuJoCo doc "Numerical integration"). `implicit` also treats those implicitly
# and costs 1.2-1.8 times the step (mean 1.34-1.39 over the corpus and the humanoid, measured by
# benchmarks/bench_integrator.py). Neither integrator lets a corpus robot diverge in the
# random-ctrl gates. At rest only limp robots whose heavy links swing a light one do worse: an
# IRB 2400 lying limp on its free base moved 1.04 mm and turned 4.2 mrad in 60 s on the pyramidal
# cone (implicit: 0.05 mm, 0.008 mrad); held by its motors both give the same. The server's
# PUT /physics takes {"integrator": "implicit"} for a world that needs the other.
INTEGRATOR = "implicitfast"
SOLVER = "newton"
# Solver convergence threshold, fixed in every world. MuJoCo 4 solves each constraint island on its
# own, but an island's stopping point still shifts with what else is in the model: measured on a
# falling humanoid while a second one spawns, MuJoCo's default 1e-8 lets the first robot's qpos
# move 1.4e-7 m (and scaling the tolerance by meaninertia·nv, as once done here, 6 mm); 1e-12
# keeps it within 1.3e-13 m (1.6e-10 m on the elliptic cone below) for 0.3 % more solver
# iterations (1145 against 1142 in 700 steps).
SOLVER_TOLERANCE = 1e-12
# MuJoCo's elliptic friction cone: a contact is one normal row and its friction rows, each with its
# own regulariser, so a contact's stiffness along the normal is the one its kp asks for at every
# μ (a ball rests at m·g/kp for μ 0-1.5 and kp 1e3-1e7), and its friction is the circle μ·f_n
# (or the ellipse of a pair's two μ) at every heading. The pyramidal cone shares one regulariser
# among its 2·(condim − 1) edges, μ²·(1 + μ²)/2 times the normal's at condim 3: a ball rested at
# 0.005 of m·g/kp at μ 0.1 and 3.7 times it at μ 1.5, and a skid steer's turn swung 30 % with
# its heading (docs/contacts.md).
CONE = mujoco.mjtCone.mjCONE_ELLIPTIC


@dataclass(frozen=True)
class WorldOptions:
    """The MuJoCo options of a world.

    Attributes:
        timestep: [s]; gravity: [m/s²]; iterations: solver iterations; solver, integrator: names
        in SOLVERS / INTEGRATORS.
    """

    timestep: float = TIMESTEP_S
    gravity: tuple[float, float, float] = GRAVITY
    iterations: int = ITERATIONS
    solver: str = SOLVER
    integrator: str = INTEGRATOR


def apply_world_options(spec: mujoco.MjSpec, options: WorldOptions = WorldOptions()) -> None:
    """Writes timestep, gravity, iterations, solver, integrator, tolerance and the friction cone
    into `spec.option`."""
    spec.option.timestep = options.timestep
    spec.option.gravity = np.array(options.gravity)
    spec.option.iterations = options.iterations
    spec.option.solver = SOLVERS[options.solver]
    spec.option.integrator = INTEGRATORS[options.integrator]
    spec.option.tolerance = SOLVER_TOLERANCE
    spec.option.cone = CONE
