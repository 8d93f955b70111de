"""The exported scene's `home` keyframe starts a robot as a twin World spawned `--on-ground` does.

A MuJoCo user starts the exported model with `mj_resetDataKeyframe(model, data, home)` on
`scene.xml`. From there a floating robot stands with its lowest collision point on the floor,
its orientation and joints as converted, the keyframe's ctrl holding its position servos at
their posture; random ctrl near that start then never diverges. A fixed-base robot keeps its
pose. The lowest point is measured by MuJoCo's own distance query to the ground plane, not by
the converter's geometry.
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest
from corpus_registry import corpus_ids, corpus_ids_expecting

import scenarios
from converters.gazebo.drive_records import held_from_load
from converters.mjcf.velocity_motors import is_rotor
from converters.mjcf.writer import write_model
from converters.pipeline import convert
from twin_cli.spawn_request import SpawnRequest
from twin_cli.world import World

FLOOR_M = 1e-3  # [m] the lowest collision point's distance from the floor at `home`
GATE_S = 10.0  # [s] of random ctrl from `home`
RESAMPLE_S = 0.5  # [s] each random ctrl is held
CTRL_SHARE = 0.1  # random ctrl spans this share of each range, about the keyframe's ctrl
# [m] how far the root may rise above its home height under the gate's ctrl. Measured: at most
# 0.073 m (ur5e, an arm on a free base that its own swings tip), 0.0125 m (abb_irb2400), below
# 1 mm for the legged robots; from a buried keyframe the ground threw roots 6.8-28 m up in 0.5 s.
LAUNCH_M = 0.25
DIVERGES = {
    "solo12": "untagged joints keep torque motors of their URDF's 1000 N m; 10 % of that, "
    "100 N m, spins its 7-150 g legs to NaN within 0.03 s of `home`",
}
SCENE = "scene.xml"
IDENTITY = (1.0, 0.0, 0.0, 0.0)  # w-x-y-z: every robot here is converted upright
HOLDS_FROM_LOAD = ("turtlebot3_burger",)  # a diff drive: its wheels held at 0 rad/s

# A two-link robot whose knee's range [0.6, 1.2] rad sets its home at 0.6 rad: the box at the
# end of its 0.3 m shin then hangs lowest. FREE_BASE floats; FIXED_BASE welds it to `world`.
_LINKS = """
  <link name="base"><inertial><mass value="2"/><inertia ixx="0.02" iyy="0.02" izz="0.02"
    ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.2 0.2 0.1"/></geometry></collision></link>
  <link name="shin"><inertial><origin xyz="0 0 -0.15"/><mass value="1"/><inertia ixx="0.01"
    iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0 0 -0.3"/><geometry><box size="0.1 0.1 0.1"/></geometry>
    </collision></link>
  <joint name="knee" type="revolute"><origin xyz="0 0 -0.05"/><parent link="base"/>
    <child link="shin"/><axis xyz="0 1 0"/>
    <limit lower="0.6" upper="1.2" effort="20" velocity="2"/></joint>"""
FREE_BASE = f'<robot name="leg">{_LINKS}</robot>'
FIXED_BASE = f"""<robot name="leg"><link name="world"/>
  <joint name="weld" type="fixed"><origin xyz="0 0 0.1"/><parent link="world"/>
    <child link="base"/></joint>{_LINKS}</robot>"""
KNEE_HOME_RAD = 0.6
# The box's lowest corner below the base origin: knee 0.05 m down, shin rotated by the knee
# angle about y, the box's centre 0.3 m along it, half-extent 0.05 m on each axis.
LEG_DEPTH_M = (
    0.05 + 0.3 * np.cos(KNEE_HOME_RAD) + 0.05 * (np.cos(KNEE_HOME_RAD) + np.sin(KNEE_HOME_RAD))
)


def _scene(spec: mujoco.MjSpec, report, out: Path) -> Path:
    return write_model(spec, report, out).parent / SCENE


def _at_home(scene: Path) -> tuple[mujoco.MjModel, mujoco.MjData]:
    """The scene as plain MuJoCo loads it, reset to `home`, kinematics computed."""
    model = mujoco.MjModel.from_xml_path(str(scene))
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("home").id)
    mujoco.mj_forward(model, data)
    return model, data


def _floor_gap(model: mujoco.MjModel, data: mujoco.MjData) -> float:
    """The smallest signed distance [m] of the robot's collision geoms to the ground plane."""
    ground = model.geom("ground").id
    robot = [
        g
        for g in range(model.ngeom)
        if model.geom_bodyid[g] != 0 and (model.geom_contype[g] or model.geom_conaffinity[g])
    ]
    return min(mujoco.mj_geomDistance(model, data, g, ground, 10.0, None) for g in robot)


def _free_adr(model: mujoco.MjModel) -> list[int]:
    return [int(model.jnt_qposadr[j]) for j in np.flatnonzero(model.jnt_type == 0)]


def _source_home(spec: mujoco.MjSpec) -> np.ndarray:
    model = spec.copy().compile()
    return model.key("home").qpos.copy()


def _own_qpos(model: mujoco.MjModel) -> np.ndarray:
    """qpos addresses of the robot's own joints: the file adds a rotor per velocity motor
    (`converters.mjcf.velocity_motors`), after the robot's joints it sits beside."""
    widths = (7, 4, 1, 1)
    return np.array(
        [
            int(model.jnt_qposadr[j]) + k
            for j in range(model.njnt)
            if not is_rotor(model.joint(j).name)
            for k in range(widths[int(model.jnt_type[j])])
        ],
        dtype=int,
    )


def _assert_placed(scene: Path, spec: mujoco.MjSpec, label: str) -> None:
    """Floating: on the floor, upright, joints and orientation as converted; fixed: the key
    unchanged."""
    model, data = _at_home(scene)
    source = _source_home(spec)
    own = _own_qpos(model)
    free = _free_adr(model)
    if not free:
        key = model.key("home").qpos[own]
        assert np.array_equal(key, source), f"{label}: fixed base moved"
        return
    gap = _floor_gap(model, data)
    assert abs(gap) <= FLOOR_M, f"{label}: lowest collision point {gap:.4f} m from the floor"
    assert np.array_equal(data.qpos[free[0] + 3 : free[0] + 7], IDENTITY), f"{label}: upright"
    moved = np.zeros(model.nq, dtype=bool)
    moved[[a + 2 for a in free]] = True
    moved = moved[own]
    qpos = data.qpos[own]
    assert np.array_equal(qpos[~moved], source[~moved]), f"{label}: only root z changes"


def _gate(scene: Path) -> str | None:
    """Random ctrl within CTRL_SHARE of each range about the keyframe's ctrl, resampled every
    RESAMPLE_S for GATE_S (seed 0). Returns what went wrong, or None."""
    model, data = _at_home(scene)
    home_ctrl, free = model.key("home").ctrl.copy(), _free_adr(model)
    home_z = [float(data.qpos[a + 2]) for a in free]
    low, high = model.actuator_ctrlrange.T
    limited = model.actuator_ctrllimited.astype(bool)
    rng = np.random.default_rng(0)
    for _ in range(round(GATE_S / RESAMPLE_S)):
        drawn = home_ctrl + CTRL_SHARE * (rng.uniform(low, high) - home_ctrl)
        data.ctrl[:] = np.where(limited, drawn, home_ctrl)
        mujoco.mj_step(model, data, nstep=round(RESAMPLE_S / model.opt.timestep))
        warnings = {i: w.number for i, w in enumerate(data.warning) if w.number}
        if warnings or not (np.isfinite(data.qpos).all() and np.isfinite(data.qvel).all()):
            return f"at {data.time:.2f} s: warnings (index: count) {warnings}, or not finite"
        rise = max((data.qpos[a + 2] - z for a, z in zip(free, home_z, strict=True)), default=0)
        if rise > LAUNCH_M:
            return f"at {data.time:.2f} s: the root rose {rise:.2f} m above its home height"
    return None


@pytest.fixture(scope="module")
def humanoid_scene(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, mujoco.MjSpec]:
    spec, report = convert(scenarios.HUMANOID)
    return _scene(spec, report, tmp_path_factory.mktemp("home") / "humanoid"), spec


def _leg(tmp_path: Path, text: str) -> tuple[Path, mujoco.MjSpec]:
    path = tmp_path / "leg.urdf"
    path.write_text(text)
    spec, report = convert(path)
    return _scene(spec, report, tmp_path / "leg"), spec


def test_humanoid_home_stands_on_the_floor(humanoid_scene) -> None:
    _assert_placed(*humanoid_scene, "humanoid")


def test_humanoid_home_is_the_worlds_on_ground_spawn(humanoid_scene) -> None:
    """The keyframe's qpos and ctrl are those of a World spawning the source `--on-ground`."""
    scene, _ = humanoid_scene
    model, data = _at_home(scene)
    world = World()
    world.spawn(SpawnRequest(scenarios.HUMANOID, on_ground=True), name="h")
    ours = world.data.qpos[world.index_of("h").qpos]
    assert np.array_equal(data.qpos, ours), f"key qpos - world's: {data.qpos - ours}"
    assert np.array_equal(data.ctrl, world.data.ctrl), "the world's initial ctrl"


def test_floating_leg_home_is_raised_by_its_depth(tmp_path: Path) -> None:
    """The knee's home (0.6 rad, its lower limit) decides how far the key raises the base."""
    scene, spec = _leg(tmp_path, FREE_BASE)
    _assert_placed(scene, spec, "floating leg")
    model, data = _at_home(scene)
    assert data.qpos[model.joint("knee").qposadr[0]] == pytest.approx(KNEE_HOME_RAD)
    assert data.qpos[2] == pytest.approx(LEG_DEPTH_M, abs=1e-12), "base height [m]"


def test_fixed_leg_keeps_its_pose(tmp_path: Path) -> None:
    """Welded 0.1 m up, its shin's box stays below the floor: the key does not move a weld."""
    scene, spec = _leg(tmp_path, FIXED_BASE)
    _assert_placed(scene, spec, "fixed leg")
    model, data = _at_home(scene)
    assert _floor_gap(model, data) == pytest.approx(0.1 - LEG_DEPTH_M, abs=1e-9)


def test_humanoid_takes_random_ctrl_from_home(humanoid_scene) -> None:
    failure = _gate(humanoid_scene[0])
    assert failure is None, f"humanoid: {failure}"


def _corpus_scene(tmp_path: Path, converted_corpus, robot_id: str) -> tuple[Path, mujoco.MjSpec]:
    done = converted_corpus(robot_id)
    return _scene(done.spec, done.report, tmp_path / robot_id), done.spec


@pytest.mark.parametrize("robot_id", corpus_ids())
def test_corpus_home_stands_floating_robots_on_the_floor(
    tmp_path: Path, converted_corpus, robot_id: str
) -> None:
    _assert_placed(*_corpus_scene(tmp_path, converted_corpus, robot_id), robot_id)


@pytest.mark.parametrize("robot_id", corpus_ids())
def test_corpus_home_is_the_worlds_on_ground_spawn(
    tmp_path: Path, converted_corpus, robot_id: str
) -> None:
    """qpos as a World's `--on-ground` spawn at the origin (a fixed base: its joints; the world
    moves its weld instead); ctrl as the world's: position servos at home, others 0, and every
    joint a drive plugin holds from load (`held_from_load`, the world's rule) at its target."""
    done = converted_corpus(robot_id)
    scene = _scene(done.spec, done.report, tmp_path / robot_id)
    model, data = _at_home(scene)
    world = World()
    world.spawn(SpawnRequest(done.spec.copy(), on_ground=True), name="r")
    theirs = world.data.qpos[world.index_of("r").qpos]
    gap = np.abs(data.qpos - theirs).max()
    assert np.array_equal(data.qpos, theirs), (
        f"{robot_id}: key qpos differs from the world's by {gap}"
    )
    joints = [model.joint(int(model.actuator_trnid[a, 0])).name for a in range(model.nu)]
    expected = {j: _home_ctrl(model, data, a) for a, j in enumerate(joints)}
    held = {j: target for j, (_, target) in held_from_load(done.plugins).items() if j in expected}
    assert held or robot_id not in HOLDS_FROM_LOAD, f"{robot_id}: its drive holds its wheels"
    expected.update(held)
    assert dict(zip(joints, data.ctrl, strict=True)) == expected, f"{robot_id}: keyframe ctrl"


def _home_ctrl(model: mujoco.MjModel, data: mujoco.MjData, a: int) -> float:
    """A position servo's (MuJoCo bias -kp·q) target is its joint at home; any other ctrl 0."""
    servo = model.actuator_biastype[a] == mujoco.mjtBias.mjBIAS_AFFINE
    if not (servo and model.actuator_biasprm[a, 1] < 0):
        return 0.0
    return float(data.qpos[model.jnt_qposadr[int(model.actuator_trnid[a, 0])]])


@pytest.mark.parametrize(
    "robot_id",
    corpus_ids_expecting(DIVERGES),
)
def test_corpus_takes_random_ctrl_from_home(
    tmp_path: Path, converted_corpus, robot_id: str
) -> None:
    failure = _gate(_corpus_scene(tmp_path, converted_corpus, robot_id)[0])
    assert failure is None, f"{robot_id}: {failure}"
