"""Spawning into a live world: invariance of existing entities, rollback, placement checks."""

from __future__ import annotations

from dataclasses import replace

import mujoco
import numpy as np
import pytest
from models import block, mimic_pincer, mjcf_arm, mjcf_ball, mjcf_box, mjcf_with_home, write_urdf
from world_helpers import full_state, spec_of

from twin_cli.errors import (
    EntityExistsError,
    EntityNotFoundError,
    InvalidRequestError,
    PartNotFoundError,
    SpawnError,
)
from twin_cli.spawn_request import SpawnRequest
from twin_cli.world import Pose, World, WorldSettings, savefile


@pytest.fixture(scope="module")
def humanoid_spec() -> mujoco.MjSpec:
    from converters.pipeline import convert
    from scenarios import HUMANOID

    spec, _ = convert(HUMANOID)
    return spec


def falling_trajectory(humanoid_spec: mujoco.MjSpec, spawn_second: bool) -> np.ndarray:
    """qpos of a humanoid dropped from 2 m, pushed, 700 steps (it lands at about 0.45 s),
    optionally spawning a second humanoid standing on the ground at step 100."""
    world = World()
    world.spawn(humanoid_spec, name="first", pose=Pose(z=2.0))
    world.push("first", force=(0.0, 30.0, 0.0), torque=(0.0, 0.0, 5.0), duration=0.2)
    rows = []
    for k in range(700):
        if spawn_second and k == 100:
            world.spawn(humanoid_spec, name="second", pose=Pose(x=3.0, z=0.96))
        world.step(1)
        rows.append(world.data.qpos[world.index_of("first").qpos].copy())
    return np.array(rows)


def test_spawning_a_second_robot_leaves_the_falling_first_ones_trajectory_unchanged(humanoid_spec):
    alone = falling_trajectory(humanoid_spec, spawn_second=False)
    with_spawn = falling_trajectory(humanoid_spec, spawn_second=True)
    assert np.array_equal(alone[:100], with_spawn[:100]), "identical before the spawn"
    difference = np.max(np.abs(alone - with_spawn))
    # Not bitwise: island solves stop where the model decides (see SOLVER_TOLERANCE in
    # converters/mjcf/world_options.py); measured 1.6e-10 m on the elliptic friction cone.
    assert difference <= 1e-9, f"first robot's qpos changed by {difference:.3g} after the spawn"


def test_new_entity_starts_at_rest_at_its_pose_in_its_home_configuration():
    world = World()
    world.spawn(spec_of(mjcf_ball()), pose=Pose(z=3.0))
    world.step(50)
    world.spawn(spec_of(mjcf_with_home(hinge=0.7, z=0.5)), pose=Pose(x=1.0, z=1.0, yaw=0.5))
    pose = world.get_pose("homed")
    assert (pose.x, pose.z) == pytest.approx((1.0, 1.5)), "home key z composed with spawn pose"
    assert pose.yaw == pytest.approx(0.5), "spawn yaw"
    assert world.joint_states("homed")[0].position == pytest.approx(0.7), "home key hinge"
    assert not np.any(world.data.qvel[world.index_of("homed").dofs]), "new entity at rest"
    world.spawn(spec_of(mjcf_with_home()), name="homed_again", pose=Pose(x=-1.0, z=1.0))
    assert world.joint_states("homed_again")[0].position == pytest.approx(0.7), "second home"


def test_spawn_keeps_applied_forces_and_controls_of_existing_entities():
    world = World()
    world.set_gravity((0.0, 0.0, 0.0))
    world.spawn(spec_of(mjcf_ball()), pose=Pose(z=1.0))
    world.push("ball", force=(1.0, 0.0, 0.0), duration=0.1)
    world.step(50)
    world.spawn(spec_of(mjcf_box()), pose=Pose(x=5.0, z=1.0))
    world.step(100)
    vx = world.data.qvel[world.index_of("ball").dofs[0]]
    assert vx == pytest.approx(0.1, rel=1e-9), f"push impulse survived the spawn: vx = {vx}"


@pytest.mark.parametrize(
    "bad",
    ["taken name", "missing file", "compile error", "bad name", "joint out of range", "joint name"],
)
def test_failed_spawn_leaves_the_world_bit_identical(bad, tmp_path):
    world = World()
    world.spawn(spec_of(mjcf_ball()), pose=Pose(z=2.0))
    world.push("ball", force=(3.0, 0.0, 0.0), duration=1.0)
    world.step(20)
    before, xml_before = full_state(world), world._state.spec.to_xml()
    broken = tmp_path / "broken.xml"
    broken.write_text(
        '<mujoco><worldbody><body><geom type="mesh" mesh="nope"/></body></worldbody></mujoco>'
    )
    attempts = {
        "taken name": (lambda: world.spawn(spec_of(mjcf_box()), name="ball"), EntityExistsError),
        "missing file": (lambda: world.spawn(tmp_path / "none.urdf"), SpawnError),
        "compile error": (lambda: world.spawn(broken), SpawnError),
        "bad name": (lambda: world.spawn(spec_of(mjcf_box()), name="a/b"), InvalidRequestError),
        "joint out of range": (
            lambda: world.spawn(
                SpawnRequest(spec_of(mjcf_arm(-1.0, 1.0, 5.0)), joints={"shoulder": 1.2})
            ),
            InvalidRequestError,
        ),
        "joint name": (
            lambda: world.spawn(
                SpawnRequest(spec_of(mjcf_arm(-1.0, 1.0, 5.0)), joints={"elbow": 0.0})
            ),
            PartNotFoundError,
        ),
    }
    attempt, error = attempts[bad]
    with pytest.raises(error) as caught:
        attempt()
    assert np.array_equal(full_state(world), before), f"state changed by a failed spawn ({bad})"
    assert world._state.spec.to_xml() == xml_before, f"world spec changed by a failed spawn ({bad})"
    assert [e.name for e in world.entities()] == ["ball"], "entity list unchanged"
    assert "ball" in str(caught.value) or bad != "taken name", "message names the entity"
    reference = World()
    reference.spawn(spec_of(mjcf_ball()), pose=Pose(z=2.0))
    reference.push("ball", force=(3.0, 0.0, 0.0), duration=1.0)
    reference.step(20)
    world.step(100), reference.step(100)
    assert np.array_equal(full_state(world), full_state(reference)), "continues as if untried"


def test_spawn_inside_the_ground_warns_with_depth_and_clearing_height():
    world = World()
    result = world.spawn(spec_of(mjcf_box(half=(0.1, 0.1, 0.1))), pose=Pose(z=0.05))
    assert len(result.warnings) == 1, f"one overlap warning, got {result.warnings}"
    warning = result.warnings[0]
    assert "0.0500 m inside the ground" in warning, f"depth in the warning: {warning}"
    assert "z >= 0.1000 m" in warning and "--on-ground" in warning, f"the fix: {warning}"
    clear = world.spawn(spec_of(mjcf_box()), name="clear", pose=Pose(x=2.0, z=0.5))
    assert clear.warnings == [], "no warning when the entity starts clear"
    overlap = world.spawn(spec_of(mjcf_ball()), pose=Pose(x=2.0, z=0.65))
    assert any("entity [clear]" in w for w in overlap.warnings), "overlap with another entity"


def test_on_ground_puts_the_lowest_point_on_the_ground():
    world = World()
    world.spawn(
        SpawnRequest(spec_of(mjcf_box(half=(0.1, 0.2, 0.3))), on_ground=True),
        pose=Pose(z=5.0, roll=0.3),
    )
    scratch = mujoco.MjData(world.model)
    scratch.qpos[:] = world.data.qpos
    mujoco.mj_kinematics(world.model, scratch)
    corners = np.array(
        [[sx, sy, sz] for sx in (-0.1, 0.1) for sy in (-0.2, 0.2) for sz in (-0.3, 0.3)]
    )
    g = world.index_of("box").geoms[0]
    z_corners = scratch.geom_xpos[g][2] + corners @ scratch.geom_xmat[g].reshape(3, 3)[2]
    assert z_corners.min() == pytest.approx(0.0, abs=1e-12), "lowest corner on the ground"
    fixed = world.spawn(
        SpawnRequest(spec_of(mjcf_box(free=False)), on_ground=True),
        name="post",
        pose=Pose(x=2, z=3),
    )
    assert world.get_pose(fixed.name).z == pytest.approx(0.1), "fixed-base entity placed too"


def test_humanoid_on_ground_rests_its_soles_on_the_ground(humanoid_spec):
    world = World()
    result = world.spawn(SpawnRequest(humanoid_spec, on_ground=True), pose=Pose(z=3.0))
    assert result.warnings == [], f"no overlap at rest: {result.warnings}"
    assert world.get_pose("humanoid").z == pytest.approx(0.95, abs=1e-9), "soles 0.95 m below"


def test_delete_keeps_the_others_exact_and_frees_the_name():
    world, reference = World(), World()
    for w in (world, reference):
        w.spawn(spec_of(mjcf_ball()), pose=Pose(z=2.0))
        w.push("ball", force=(1.0, 0.0, 0.0), duration=0.5)
    world.spawn(spec_of(mjcf_box()), pose=Pose(x=1.0, z=1.0))
    world.step(10), reference.step(10)
    world.delete("box")
    world.step(200), reference.step(200)
    assert np.array_equal(full_state(world), full_state(reference)), "ball unaffected by delete"
    world.spawn(spec_of(mjcf_box()), pose=Pose(x=1.0, z=1.0))
    assert [e.name for e in world.entities()] == ["ball", "box"], "name reusable after delete"
    with pytest.raises(EntityNotFoundError, match=r"\[ghost\].*ball, box"):
        world.delete("ghost")


def test_default_names_are_made_unique():
    world = World()
    names = [world.spawn(spec_of(mjcf_ball()), pose=Pose(x=k, z=1.0)).name for k in range(3)]
    assert names == ["ball", "ball_1", "ball_2"], "robot name, then _1, _2"


def test_spawn_then_delete_restores_the_world_spec_exactly(humanoid_spec):
    world = World()
    world.spawn(spec_of(mjcf_ball()), pose=Pose(z=2.0))
    xml_before = world._state.spec.to_xml()
    world.spawn(humanoid_spec, name="h", pose=Pose(x=2.0, z=1.0))
    assert "h/main" in world._state.spec.to_xml(), "the humanoid's default classes were attached"
    world.delete("h")
    assert world._state.spec.to_xml() == xml_before, (
        "frame, elements and default classes all removed"
    )


@pytest.mark.parametrize("stage", ["attach", "compile"])
def test_failed_humanoid_spawn_leaves_the_spec_as_it_was(humanoid_spec, stage):
    """The spawn attaches to the live spec; a failure in attach or compile must undo it all."""
    world = World()
    world.spawn(humanoid_spec, name="h0", pose=Pose(z=1.0))
    xml_before, state_before = world._state.spec.to_xml(), full_state(world)
    broken = humanoid_spec.copy()
    bad = broken.worldbody.add_body(name="bad")
    if stage == "attach":  # MuJoCo resolves mesh names when attaching
        bad.add_geom(type=mujoco.mjtGeom.mjGEOM_MESH, meshname="missing")
    else:  # a reversed joint range is found only by the compiler (no home key to read first)
        for key in list(broken.keys):
            broken.delete(key)
        bad.add_geom(size=[0.1, 0.0, 0.0])
        bad.add_joint(range=[1.0, -1.0], limited=mujoco.mjtLimited.mjLIMITED_TRUE)
    message = {"attach": "cannot be attached", "compile": "does not compile"}[stage]
    with pytest.raises(SpawnError, match=rf"h1.*{message}"):
        world.spawn(broken, name="h1", pose=Pose(x=2.0, z=1.0))
    assert world._state.spec.to_xml() == xml_before, "attached elements and defaults removed again"
    assert np.array_equal(full_state(world), state_before), "state untouched"
    world.spawn(humanoid_spec, name="h1", pose=Pose(x=2.0, z=1.0))
    assert [e.name for e in world.entities()] == ["h0", "h1"], "the name is free after rollback"


def test_entity_index_matches_per_joint_addresses_after_spawns_and_deletes(humanoid_spec):
    """Oracle: every entity's qpos/dof/geom ids, looked up element by element by name."""
    world = World()
    for name in ("a", "b", "c"):
        world.spawn(humanoid_spec, name=name, pose=Pose(x=2.0 * len(name), z=1.0))
    world.spawn(spec_of(mjcf_ball()), pose=Pose(z=3.0))
    world.delete("b")
    m = world.model
    qpos_width, dof_width = {0: 7, 1: 4, 2: 1, 3: 1}, {0: 6, 1: 3, 2: 1, 3: 1}
    assert set(world.entity_names()) == {"a", "c", "ball"}, "deleted entity not indexed"
    for name, ix in ((n, world.index_of(n)) for n in world.entity_names()):
        joints = [j for j in range(m.njnt) if m.joint(j).name.startswith(f"{name}/")]
        kinds = [int(m.jnt_type[j]) for j in joints]
        qpos = [
            m.jnt_qposadr[j] + k
            for j, t in zip(joints, kinds, strict=True)
            for k in range(qpos_width[t])
        ]
        dofs = [
            m.jnt_dofadr[j] + k
            for j, t in zip(joints, kinds, strict=True)
            for k in range(dof_width[t])
        ]
        owner = [m.body(m.geom_bodyid[g]).name.partition("/")[0] for g in range(m.ngeom)]
        assert ix.qpos.tolist() == qpos, f"{name}: qpos addresses"
        assert ix.dofs.tolist() == dofs, f"{name}: dof addresses"
        assert ix.geoms.tolist() == [g for g, o in enumerate(owner) if o == name], f"{name}: geoms"
        assert m.jnt_type[joints[0]] != 0 or ix.free_qpos == m.jnt_qposadr[joints[0]], "free"


def test_spawn_joints_posture_survives_save_and_load_and_on_ground_placement(tmp_path):
    urdf = write_urdf(tmp_path, mimic_pincer(offset=0.2, multiplier=-1.0))
    world = World()
    world.spawn(
        SpawnRequest(urdf, joints={"lead": -0.5}, on_ground=True)
    )  # fixed base: the frame moves
    start = {j.name: j.position for j in world.joint_states("pincer")}
    assert start == pytest.approx({"lead": -0.5, "follow": 0.7}, abs=1e-12), "posture on ground"
    world.step(200)
    savefile.save(world, tmp_path / "w.json")
    loaded = savefile.load(tmp_path / "w.json")
    assert np.array_equal(full_state(loaded), full_state(world)), "loaded state bit for bit"
    loaded.reset()
    after = {j.name: j.position for j in loaded.joint_states("pincer")}
    assert after == pytest.approx(start, abs=1e-12), "a loaded world resets to the -J posture"


TWO_ROOTS = """<sdf version="1.8"><model name="M">
<link name="A"><collision name="c"><geometry><box><size>0.2 0.2 0.2</size></box></geometry>
</collision></link>
<link name="B"><pose>3 2 0 0 0 0</pose><collision name="c"><geometry><box><size>0.2 0.2 0.2</size>
</box></geometry></collision></link></model></sdf>"""


def test_a_model_of_unjoined_links_is_placed_and_posed_by_its_model_frame(tmp_path):
    # Both links float; the spawn frame moved only the first link's pose, and that twice.
    import math

    path = tmp_path / "two_roots.sdf"
    path.write_text(TWO_ROOTS)
    world = World(WorldSettings(gravity=(0.0, 0.0, 0.0)))
    world.spawn(path, name="M", pose=Pose(x=1.0, z=2.0, yaw=0.5))
    mujoco.mj_kinematics(world.model, world.data)
    c, s = math.cos(0.5), math.sin(0.5)
    where = {b: world.data.xpos[world.model.body(f"M/{b}").id] for b in "AB"}
    assert where["A"] == pytest.approx([1.0, 0.0, 2.0], abs=1e-9)
    assert where["B"] == pytest.approx([1.0 + 3 * c - 2 * s, 3 * s + 2 * c, 2.0], abs=1e-9)
    pose = world.get_pose("M")
    assert (pose.x, pose.y, pose.z, pose.yaw) == pytest.approx((1.0, 0.0, 2.0, 0.5), abs=1e-9)


def test_a_model_of_unjoined_links_moves_and_lands_as_one(tmp_path):
    # set_pose moved only the first link (to z 0) and --on-ground lowered only the first.
    import math

    path = tmp_path / "two_roots.sdf"
    path.write_text(TWO_ROOTS)
    world = World(WorldSettings(gravity=(0.0, 0.0, 0.0)))
    world.spawn(SpawnRequest(path, on_ground=True), name="M", pose=Pose(z=2.0, yaw=0.5))
    mujoco.mj_kinematics(world.model, world.data)
    heights = [world.data.xpos[world.model.body(f"M/{b}").id][2] for b in "AB"]
    assert heights == pytest.approx([0.1, 0.1], abs=1e-9), "both boxes rest on the ground"
    world.set_pose("M", Pose(x=-1.0, y=2.0, z=3.0, yaw=1.5))
    mujoco.mj_kinematics(world.model, world.data)
    c, s = math.cos(1.5), math.sin(1.5)
    where = {b: world.data.xpos[world.model.body(f"M/{b}").id] for b in "AB"}
    assert where["A"] == pytest.approx([-1.0, 2.0, 3.0], abs=1e-9)
    assert where["B"] == pytest.approx([-1.0 + 3 * c - 2 * s, 2.0 + 3 * s + 2 * c, 3.0], abs=1e-9)
    pose = world.get_pose("M")
    assert (pose.x, pose.y, pose.z, pose.yaw) == pytest.approx((-1.0, 2.0, 3.0, 1.5), abs=1e-9)


def _entity_fields(world: World, name: str) -> dict:
    """An entity's record with its spawn state's arrays as lists (comparable with ==)."""
    entity = world.entity(name)
    record = {f: getattr(entity, f) for f in entity.__dataclass_fields__ if f != "spawn_state"}
    state = entity.spawn_state
    return record | {f: getattr(state, f).tolist() for f in state.__dataclass_fields__}


@pytest.mark.parametrize("robot", ["floating", "fixed"])
def test_spawn_and_a_batch_of_one_give_identical_entities_and_worlds(tmp_path, robot):
    from twin_cli.world.respec import model_bytes

    if robot == "fixed":  # on-ground placement moves its attach frame: a second compile
        request = SpawnRequest(write_urdf(tmp_path, mimic_pincer()), joints={"lead": -0.5})
    else:
        request = SpawnRequest(write_urdf(tmp_path, block(name="crate")), joints={})
    request = replace(request, on_ground=True)
    pose = Pose(x=1.0, y=-0.5, z=0.7, yaw=0.4)
    one, batch = World(), World()
    for world in (one, batch):
        world.spawn(spec_of(mjcf_ball()), name="ball", pose=Pose(z=2.0))  # a neighbour
    one.spawn(request, name="r", pose=pose)
    batch.spawn_batch(request, poses=[pose], names=["r"])
    assert _entity_fields(one, "r") == _entity_fields(batch, "r"), "entity records"
    assert model_bytes(one.model) == model_bytes(batch.model), "compiled models"
    np.testing.assert_array_equal(full_state(one), full_state(batch), err_msg="world states")
    one.step(200)
    batch.step(200)
    np.testing.assert_array_equal(full_state(one), full_state(batch), err_msg="after 0.2 s")


def test_a_failed_fixed_base_move_leaves_the_entity_as_it_was(tmp_path):
    """Moving a fixed base recompiles the world; when that fails, the entity's record (its
    spawn pose) and the world's state stay as they were."""
    world = World()
    world.spawn(SpawnRequest(write_urdf(tmp_path, mimic_pincer())), name="p", pose=Pose(x=1.0))
    with pytest.raises(InvalidRequestError, match="not finite"):
        world.set_pose("p", Pose(x=float("nan")))
    before, state = world.entity("p"), full_state(world)
    bad = world._state.spec.worldbody.add_body(name="bad")  # the next compile of the spec fails
    bad.add_geom(size=[0.1, 0.0, 0.0])
    bad.add_joint(range=[1.0, -1.0], limited=mujoco.mjtLimited.mjLIMITED_TRUE)
    with pytest.raises(SpawnError, match="does not compile"):
        world.set_pose("p", Pose(x=2.0))
    assert world.entity("p") == before, "the entity's record after the failed move"
    np.testing.assert_array_equal(full_state(world), state, err_msg="world state")
    world._state.spec.delete(bad)
    world.set_pose("p", Pose(x=2.0))
    assert world.get_pose("p").x == pytest.approx(2.0) and world.entity("p").pose.x == 2.0


def _folded_arm() -> str:
    """base → (j1 about z) → upper, 0.3 m out → (j2 about z) → fore, folded back over the base:
    at zero posture fore's box sits 0.05 m deep in base's; j2 = 3 rad swings it clear."""

    def link(name: str, x: float) -> str:
        inertia = '<inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/>'
        box = f'<origin xyz="{x} 0 0"/><geometry><box size="0.2 0.2 0.2"/></geometry>'
        return (
            f'<link name="{name}"><inertial><mass value="0.5"/>{inertia}</inertial>'
            f"<collision>{box}</collision></link>"
            f'<gazebo reference="{name}"><selfCollide>true</selfCollide></gazebo>'
        )

    def joint(name: str, parent: str, child: str, x: float) -> str:
        return (
            f'<joint name="{name}" type="revolute"><parent link="{parent}"/><child link="{child}"/>'
            f'<origin xyz="{x} 0 0"/><axis xyz="0 0 1"/>'
            '<limit lower="-3.1" upper="3.1" effort="10" velocity="1"/></joint>'
        )

    parts = link("base", 0.0) + link("upper", 0.15) + link("fore", -0.15)
    joints = joint("j1", "base", "upper", 0.0) + joint("j2", "upper", "fore", 0.3)
    return f'<robot name="folded">{parts}{joints}</robot>'


def test_spawn_warns_of_links_that_start_inside_each_other_and_the_posture_that_clears_it(
    tmp_path,
):
    urdf = write_urdf(tmp_path, _folded_arm())
    world = World(WorldSettings(ground=False))
    folded = world.spawn(urdf, name="a", pose=Pose(z=1.0))
    said = [w for w in folded.warnings if "inside each other" in w]
    assert len(said) == 1 and "'base' and 'fore'" in said[0], folded.warnings
    depth = float(said[0].split(" start ")[1].split(" m ")[0])
    assert depth == pytest.approx(0.05, abs=1e-3), f"overlap depth [m] in {said[0]}"
    assert "-J" in said[0] and "self_collide" in said[0], said[0]
    clear = world.spawn(SpawnRequest(urdf, joints={"j2": 3.0}), name="b", pose=Pose(x=3, z=1.0))
    assert not [w for w in clear.warnings if "inside each other" in w], clear.warnings
