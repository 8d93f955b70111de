"""An MJCF scene (its own ground plane and lights) spawns its robot only, and says so."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

import scenarios
from converters.mjcf.writer import write_model
from converters.pipeline import convert
from twin_cli.world import Pose, World


def _planes(model: mujoco.MjModel) -> int:
    return int(np.sum(model.geom_type == mujoco.mjtGeom.mjGEOM_PLANE))


def _lights(model: mujoco.MjModel) -> int:
    return int(model.nlight)


@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    spec, report = convert(scenarios.HUMANOID)
    robot = write_model(spec, report, tmp_path_factory.mktemp("export") / "humanoid")
    return robot, robot.parent / "scene.xml"


def test_spawned_convert_scene_adds_no_second_ground_and_says_so(exported):
    robot, scene = exported
    scene_model = mujoco.MjModel.from_xml_path(str(scene))
    assert _planes(scene_model) >= 1, "the written scene.xml has no ground plane to test with"
    world = World()
    ground_planes, ground_lights = _planes(world.model), _lights(world.model)
    result = world.spawn(scene, name="humanoid", pose=Pose(z=1.2))
    assert _planes(world.model) == ground_planes, "the scene's ground was spawned as well"
    assert _lights(world.model) == ground_lights, "the scene's lights were spawned as well"
    assert any("is a scene" in w and "ground" in w for w in result.warnings), result.warnings
    # The robot itself is all there: the same bodies and mass as the robot file spawned alone.
    alone = World()
    alone.spawn(robot, name="humanoid", pose=Pose(z=1.2))
    assert world.model.nbody == alone.model.nbody, "bodies differ from the robot file's"
    mass = float(np.sum(world.model.body_mass))
    assert mass == pytest.approx(float(np.sum(alone.model.body_mass)), rel=1e-12), "mass"
    assert not any("is a scene" in w for w in alone.spawn(robot, name="h2").warnings)
