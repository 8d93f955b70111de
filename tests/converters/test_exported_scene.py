"""The scene.xml `twin convert` writes steps in plain MuJoCo exactly as a twin World steps it."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest

import scenarios
from converters.mjcf.world_rules import POSE_FREE_FIELDS
from converters.mjcf.writer import write_model
from converters.pipeline import convert
from twin_cli.spawn_request import SpawnRequest
from twin_cli.world import Pose, World

FALL_S = 1.0  # [s] of falling and landing (feet touch down after about 0.2 s)
# Spawn poses of the root. At z = 1.5 m the world's contact regularisers, derived at the spawn
# pose, differed from the file's in the last bits (6e-13) and the roots by 4.5e-8 m after the
# landing, until every compiled model took them at the origin (world_rules.pose_free_constants).
POSES = {"upright": Pose(z=1.2), "high and turned": Pose(x=0.3, y=-0.2, z=1.5, yaw=0.7)}
PUSH_N = (60.0, -25.0, 0.0)  # [N] on the root, world frame
PUSH_S = 0.2  # [s]
# [m] root position, scene.xml against a world spawning the same robot file, at every step.
# Measured 0 (bit-equal) for both poses and the push; 4.5e-8 at z = 1.5 m before.
SAME_FILE_M = 1e-9
# [m] the same, the world spawning the xacro source. MjSpec.to_xml (MuJoCo 4.0) writes 6
# significant digits (inertia 0.208333, solref 1.11803: 3.6e-8 m); the writer restores full
# precision (converters/mjcf/precision.py), so the file is the spec. Measured 0.
XML_ROUNDING_M = 1e-9
# Geom fields that decide a contact: who wins the friction (priority), its softness, its shape.
CONTACT_FIELDS = ("priority", "solref", "solimp", "friction", "condim", "margin", "gap", "solmix")


@pytest.fixture(scope="module")
def exported_robot(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The bundled humanoid converted and written with `write_model`; its robot file."""
    spec, report = convert(scenarios.HUMANOID)
    return write_model(spec, report, tmp_path_factory.mktemp("export") / "humanoid")


def _world_at(source: Path, pose: Pose) -> World:
    world = World()
    world.spawn(source, name="humanoid", pose=pose)
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


def _root_gaps(world: World, scene: Path, push: bool = False) -> tuple[list[float], np.ndarray]:
    """Steps the world and the loaded scene side by side for FALL_S, the root pushed by PUSH_N
    for PUSH_S in both if asked (`World.push`; `xfrc_applied` in the scene).

    Returns:
        The largest root position difference [m] at each step, and the scene root's travel [m].
    """
    model = mujoco.MjModel.from_xml_path(str(scene))
    data = mujoco.MjData(model)
    _copy_state(world, model, data)
    root, world_root = model.body("torso").id, world.model.body("humanoid/torso").id
    start = data.xpos[root].copy()
    push_steps = round(PUSH_S / model.opt.timestep) if push else 0
    if push:
        world.push("humanoid", force=PUSH_N, duration=PUSH_S)
        data.xfrc_applied[root, :3] = PUSH_N
    gaps = []
    for step in range(round(FALL_S / model.opt.timestep)):
        if step == push_steps:
            data.xfrc_applied[root] = 0.0
        world.step(1)
        mujoco.mj_step(model, data)
        gaps.append(float(np.max(np.abs(world.data.xpos[world_root] - data.xpos[root]))))
    return gaps, data.xpos[root] - start


def _assert_within(gaps: list[float], tolerance: float, what: str) -> None:
    worst = int(np.argmax(gaps))
    assert gaps[worst] <= tolerance, (
        f"root body position [m] differs by {gaps[worst]:.3g} at step {worst + 1} ({what})"
    )


def test_exported_scene_carries_every_world_option_and_flag(exported_robot: Path) -> None:
    exported = mujoco.MjModel.from_xml_path(str(exported_robot.parent / "scene.xml"))
    world = _world_at(scenarios.HUMANOID, POSES["high and turned"])
    fields = [f for f in dir(exported.opt) if not f.startswith("_")]
    assert {"disableflags", "enableflags", "sleep_tolerance", "tolerance"} <= set(fields)
    for field in fields:
        ours, theirs = getattr(exported.opt, field), getattr(world.model.opt, field)
        assert np.array_equal(ours, theirs), f"option {field}: scene.xml {ours}, world {theirs}"


def test_exported_scene_has_the_world_contacts_and_constants(exported_robot: Path) -> None:
    """Every geom (ground included) decides its contacts as in the world, and the qpos0
    constants behind the contact regularisers are the world's to the bit."""
    exported = mujoco.MjModel.from_xml_path(str(exported_robot.parent / "scene.xml"))
    world = _world_at(scenarios.HUMANOID, POSES["high and turned"]).model
    assert exported.ngeom == world.ngeom
    for g in range(exported.ngeom):
        name = exported.geom(g).name
        theirs = world.geom(name if name == "ground" else f"humanoid/{name}")
        for field in CONTACT_FIELDS:
            ours, other = getattr(exported.geom(g), field), getattr(theirs, field)
            assert np.array_equal(ours, other), f"geom {name} {field}: file {ours}, world {other}"
    assert (exported.geom_priority > 0).all(), "every geom carries its min-μ priority"
    for field in POSE_FREE_FIELDS:
        assert np.array_equal(getattr(exported, field), getattr(world, field)), field
    assert np.array_equal(exported.light_dir, world.light_dir), "the world's sun"


@pytest.mark.parametrize("pose", POSES, ids=list(POSES))
@pytest.mark.parametrize(
    ("spawned", "tolerance"), [("exported", SAME_FILE_M), ("xacro", XML_ROUNDING_M)]
)
def test_exported_scene_drops_the_humanoid_along_the_world_trajectory(
    exported_robot: Path, spawned: str, tolerance: float, pose: str
) -> None:
    source = exported_robot if spawned == "exported" else scenarios.HUMANOID
    world = _world_at(source, POSES[pose])
    gaps, travel = _root_gaps(world, exported_robot.parent / "scene.xml")
    assert -travel[2] > 0.2, f"the humanoid should fall onto its feet, fell {-travel[2]:.3f} m"
    assert world.data.ncon > 0, "the robot ends on the ground"
    _assert_within(gaps, tolerance, f"world spawning the {spawned} file, {pose}")


def test_exported_scene_follows_the_world_through_a_push(exported_robot: Path) -> None:
    world = _world_at(scenarios.HUMANOID, POSES["high and turned"])
    gaps, travel = _root_gaps(world, exported_robot.parent / "scene.xml", push=True)
    assert np.hypot(travel[0], travel[1]) > 0.05, f"the push should move the root, {travel}"
    _assert_within(gaps, SAME_FILE_M, "pushed for 0.2 s")


def test_exported_scene_from_home_steps_as_the_world_spawned_on_ground(
    exported_robot: Path,
) -> None:
    """A MuJoCo user's start (`scene.xml` reset to its `home` keyframe, ctrl from the key) is a
    World's `--on-ground` spawn of the source: the same state, and the same steps after it."""
    model = mujoco.MjModel.from_xml_path(str(exported_robot.parent / "scene.xml"))
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("home").id)
    world = World()
    world.spawn(SpawnRequest(scenarios.HUMANOID, on_ground=True), name="humanoid")
    assert np.array_equal(data.ctrl, world.data.ctrl), "the keyframe's ctrl is the world's"
    assert np.array_equal(data.qpos, world.data.qpos), "the keyframe's qpos is the world's"
    root, world_root = model.body("torso").id, world.model.body("humanoid/torso").id
    gaps = []
    for _ in range(round(FALL_S / model.opt.timestep)):
        world.step(1)
        mujoco.mj_step(model, data)
        gaps.append(float(np.max(np.abs(world.data.xpos[world_root] - data.xpos[root]))))
    _assert_within(gaps, SAME_FILE_M, "scene from home, world spawned on the ground")
