"""The scene.xml `twin convert` writes steps in plain MuJoCo exactly as a twin World steps it."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest

import scenarios
from converters.mjcf.writer import write_model
from converters.pipeline import convert
from twin_cli.world import Pose, World

FALL_S = 1.0  # [s] of falling and landing (feet touch down after about 0.2 s)
DROP_Z = 1.2  # [m] spawn height of the root
# [m] root position, scene.xml against a world spawning the same robot file, at every step.
# Measured 7.8e-13; with MuJoCo's default options (Euler, 100 iterations, tolerance 1e-8) 1.8e-7.
SAME_FILE_M = 1e-9
# [m] the same, the world spawning the xacro source. MjSpec.to_xml (MuJoCo 4.0) writes 6
# significant digits (inertia 0.208333, solref 1.11803: 3.6e-8 m); the writer restores full
# precision (converters/mjcf/precision.py), so the file is the spec.
XML_ROUNDING_M = 1e-9
OPTION_FIELDS = ("timestep", "gravity", "integrator", "iterations", "solver", "tolerance")


@pytest.fixture(scope="module")
def exported_robot(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The bundled humanoid converted and written with `write_model`; its robot file."""
    spec, report = convert(scenarios.HUMANOID)
    return write_model(spec, report, tmp_path_factory.mktemp("export") / "humanoid")


def _world_at_drop(source: Path) -> World:
    world = World()
    world.spawn(source, name="humanoid", pose=Pose(z=DROP_Z))
    return world


def _copy_state(world: World, model: mujoco.MjModel, data: mujoco.MjData) -> None:
    """The world's spawn state (pose, home posture, at rest) into `data`, joint by joint name."""
    for j in range(model.njnt):
        source = world.model.joint(f"humanoid/{model.joint(j).name}")
        width = {0: 7, 1: 4}.get(int(model.jnt_type[j]), 1)
        dofs = {0: 6, 1: 3}.get(int(model.jnt_type[j]), 1)
        qpos, src_qpos = model.jnt_qposadr[j], source.qposadr[0]
        dof, src_dof = model.jnt_dofadr[j], source.dofadr[0]
        data.qpos[qpos : qpos + width] = world.data.qpos[src_qpos : src_qpos + width]
        data.qvel[dof : dof + dofs] = world.data.qvel[src_dof : src_dof + dofs]
    mujoco.mj_forward(model, data)


def _root_gaps(world: World, scene: Path) -> tuple[list[float], float]:
    """Steps the world and the loaded scene side by side for FALL_S.

    Returns:
        The largest root position difference [m] at each step, and how far the scene's root fell.
    """
    model = mujoco.MjModel.from_xml_path(str(scene))
    data = mujoco.MjData(model)
    _copy_state(world, model, data)
    root, world_root = model.body("torso").id, world.model.body("humanoid/torso").id
    start_z = data.xpos[root][2]
    gaps = []
    for _ in range(round(FALL_S / model.opt.timestep)):
        world.step(1)
        mujoco.mj_step(model, data)
        gaps.append(float(np.max(np.abs(world.data.xpos[world_root] - data.xpos[root]))))
    return gaps, float(start_z - data.xpos[root][2])


def test_exported_scene_carries_the_world_physics_options(exported_robot: Path) -> None:
    exported = mujoco.MjModel.from_xml_path(str(exported_robot.parent / "scene.xml"))
    world = _world_at_drop(scenarios.HUMANOID)
    for field in OPTION_FIELDS:
        ours, theirs = getattr(exported.opt, field), getattr(world.model.opt, field)
        assert np.array_equal(ours, theirs), f"option {field}: scene.xml {ours}, world {theirs}"


@pytest.mark.parametrize(
    ("spawned", "tolerance"), [("exported", SAME_FILE_M), ("xacro", XML_ROUNDING_M)]
)
def test_exported_scene_drops_the_humanoid_along_the_world_trajectory(
    exported_robot: Path, spawned: str, tolerance: float
) -> None:
    source = exported_robot if spawned == "exported" else scenarios.HUMANOID
    gaps, fall = _root_gaps(_world_at_drop(source), exported_robot.parent / "scene.xml")
    assert fall > 0.2, f"the humanoid should fall 0.25 m onto its feet, fell {fall:.3f} m"
    worst = int(np.argmax(gaps))
    assert gaps[worst] <= tolerance, (
        f"root body position [m] differs by {gaps[worst]:.3g} at step {worst + 1} "
        f"(world spawning the {spawned} file)"
    )
