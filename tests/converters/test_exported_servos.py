"""The exported scene is a model a MuJoCo user can drive: random `ctrl` within `ctrlrange` for
10 s on the ground never diverges (Menagerie's gate), tagged position joints hold their home
posture from the `home` keyframe, and a World that spawns the file commands the motors the
robot's source has."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest
from corpus_registry import corpus_ids, corpus_ids_expecting

from converters.mjcf.servo_gains import BRAKE_RAD, DAMPING_RATIO, OMEGA_STEP
from converters.mjcf.velocity_motors import rotor_name
from converters.mjcf.writer import write_model
from twin_cli.spawn_request import SpawnRequest
from twin_cli.world import World

GATE_S = 10.0  # [s] of random control per robot, on the ground
HOLD_STEPS = 50  # 50 ms per random ctrl at the 1 ms step
# solo12's URDF tags none of its joints and gives them 1000 N m on legs of 7-150 g (its real
# motors: about 2.7 N m). Untagged joints stay torque motors in the file (Gazebo leaves them
# passive, and the world keeps them limp until commanded, which the file must match); its random
# torques are drawn within 1 N m. Measured over seeds 0-7 of `default_rng`: at its real motors'
# 2.7 N m (which spin its legs to 700-1400 rad/s) some seeds diverge under either integrator
# (implicitfast 6 of 8, implicit 4 of 8), at 1 N m none does.
CTRL_SCALE = {"solo12": 0.001}
DIVERGES: dict[str, str] = {}
# [rad] a tagged arm joint's drift from home after 1 s in the scene. Measured: at most 0.011
# (wrist 3: kp 5.3 N m/rad on 1.3e-4 kg m², and a floating base gets no gravity compensation);
# limp, the same arm folds 0.2-5.6 rad.
HOME_HELD_RAD = 0.05


def _scene(tmp_path: Path, converted_corpus, robot_id: str) -> Path:
    done = converted_corpus(robot_id)
    return write_model(done.spec, done.report, tmp_path / robot_id).parent / "scene.xml"


@pytest.mark.parametrize(
    "robot_id",
    corpus_ids_expecting(DIVERGES),
)
def test_exported_scene_takes_random_ctrl_for_ten_seconds_on_the_ground(
    tmp_path: Path, converted_corpus, robot_id: str
) -> None:
    model = mujoco.MjModel.from_xml_path(str(_scene(tmp_path, converted_corpus, robot_id)))
    data = mujoco.MjData(model)
    if model.nkey:
        mujoco.mj_resetDataKeyframe(model, data, 0)
    low, high = (model.actuator_ctrlrange * CTRL_SCALE.get(robot_id, 1.0)).T
    rng = np.random.default_rng(0)
    for _ in range(round(GATE_S / model.opt.timestep) // HOLD_STEPS):
        data.ctrl[:] = rng.uniform(low, high)
        mujoco.mj_step(model, data, nstep=HOLD_STEPS)
    warnings = {i: w.number for i, w in enumerate(data.warning) if w.number}
    assert warnings == {}, f"{robot_id}: MuJoCo warnings (index: count) {warnings}"
    assert np.isfinite(data.qpos).all() and np.isfinite(data.qvel).all(), robot_id
    assert data.time == pytest.approx(GATE_S), f"{robot_id}: sim time {data.time}"


@pytest.mark.parametrize("robot_id", ["ur5e", "turtlebot3_burger"])
def test_tagged_joints_are_servos_bounded_by_their_effort(
    tmp_path: Path, converted_corpus, robot_id: str
) -> None:
    if robot_id not in corpus_ids():
        pytest.skip(f"corpus: no {robot_id}")
    done = converted_corpus(robot_id)
    source = done.spec.compile()
    model = mujoco.MjModel.from_xml_path(str(_scene(tmp_path, converted_corpus, robot_id)))
    for a in range(source.nu):
        name = source.actuator(a).name
        effort = source.actuator(name).ctrlrange
        if mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_TENDON, rotor_name(name)) >= 0:
            _assert_velocity_motor(model, name, effort)
            continue
        a = model.actuator(name).id
        assert model.actuator_biastype[a] == mujoco.mjtBias.mjBIAS_AFFINE, f"{name}: a servo"
        assert model.actuator_biasprm[a, 2] < 0, f"{name}: damped"
        assert list(model.actuator_forcerange[a]) == list(effort), f"{name}: ±effort"


def _assert_velocity_motor(model: mujoco.MjModel, name: str, effort: np.ndarray) -> None:
    """A joint whose tags offer velocity: its torque motor within ±effort, a damped velocity
    actuator on its rotor, and the tendon's friction bound = the effort."""
    a, rotor = model.actuator(name).id, model.actuator(rotor_name(name)).id
    assert model.actuator_biastype[a] == mujoco.mjtBias.mjBIAS_NONE, f"{name}: a torque motor"
    assert list(model.actuator_ctrlrange[a]) == list(effort), f"{name}: ±effort"
    assert model.actuator_biasprm[rotor, 2] < 0, f"{name}: the rotor's actuator damped"
    bound = model.tendon_frictionloss[model.tendon(rotor_name(name)).id]
    assert bound == max(abs(effort)), f"{name}: the tendon's bound {bound} is the effort"


def test_exported_arm_holds_its_home_posture_from_the_keyframe(
    tmp_path: Path, converted_corpus
) -> None:
    """ur5e lies on its free base: from `home`, its position servos keep every joint there."""
    if "ur5e" not in corpus_ids():
        pytest.skip("corpus: no ur5e")
    model = mujoco.MjModel.from_xml_path(str(_scene(tmp_path, converted_corpus, "ur5e")))
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("home").id)
    joints = [int(model.actuator_trnid[a, 0]) for a in range(model.nu)]
    home = np.array([data.qpos[model.jnt_qposadr[j]] for j in joints])
    assert np.array_equal(data.ctrl, home), "the keyframe's ctrl is the home posture"
    mujoco.mj_step(model, data, nstep=1000)
    now = np.array([data.qpos[model.jnt_qposadr[j]] for j in joints])
    assert np.abs(now - home).max() < HOME_HELD_RAD, f"drifted {now - home} rad"


@pytest.mark.parametrize("robot_id", ["ur5e", "turtlebot3_burger"])
def test_a_world_spawning_the_exported_file_has_the_sources_motors(
    tmp_path: Path, converted_corpus, robot_id: str
) -> None:
    if robot_id not in corpus_ids():
        pytest.skip(f"corpus: no {robot_id}")
    done = converted_corpus(robot_id)
    robot_file = write_model(done.spec, done.report, tmp_path / robot_id)
    from_file, from_source = World(), World()
    from_file.spawn(robot_file, name="r")  # the file's `home` key stands it on the ground
    from_source.spawn(SpawnRequest(done.spec.copy(), on_ground=True), name="r")
    fields = ("actuator_gainprm", "actuator_biasprm", "actuator_ctrlrange", "actuator_forcerange")
    for field in ("actuator_dyntype", "actuator_gaintype", "actuator_biastype"):
        ours, theirs = getattr(from_file.model, field), getattr(from_source.model, field)
        assert np.array_equal(ours, theirs), f"{robot_id}: {field} {ours} vs {theirs}"
    for field in fields:  # the file's inertias, read back, may round the gains' last bit
        ours, theirs = getattr(from_file.model, field), getattr(from_source.model, field)
        np.testing.assert_allclose(ours, theirs, rtol=1e-12, err_msg=f"{robot_id}: {field}")
    target = {"position": 0.3, "velocity": 2.0}
    joint = from_file.model.joint(int(from_file.model.actuator_trnid[0, 0])).name.split("/")[-1]
    mode = "velocity" if robot_id == "turtlebot3_burger" else "position"
    for world in (from_file, from_source):
        world.command_joints("r", {joint: target[mode]}, mode=mode)
        world.step(500)
    a, b = (w.data.qpos.copy() for w in (from_file, from_source))
    assert np.abs(a - b).max() < 1e-9, (
        f"{robot_id}: the commanded robots differ by {np.abs(a - b).max()}"
    )


# Two 1 kg discs on vertical hinges fixed to the world (no gravity load), commanded by position
# through ros2_control: d0 with no effort limit (effort 0) and a 1 rad/s velocity limit, d1 with
# its own PID gains (pos_kp 120, pos_kd 4) and a 5 N m effort limit.
TWO_DISCS = """<robot name="discs"><link name="world"/>
  <joint name="fix" type="fixed"><parent link="world"/><child link="base"/></joint>
  <link name="base"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01"
    ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="disc0"><inertial><mass value="1"/><inertia ixx="0.003" iyy="0.003" izz="0.005"
    ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="disc1"><inertial><mass value="1"/><inertia ixx="0.003" iyy="0.003" izz="0.005"
    ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="d0" type="revolute"><parent link="base"/><child link="disc0"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="0" velocity="1"/></joint>
  <joint name="d1" type="revolute"><origin xyz="0.3 0 0"/><parent link="base"/>
    <child link="disc1"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="5" velocity="4"/>
  </joint>
  <ros2_control name="discs" type="system"><hardware><plugin>x</plugin></hardware>
    <joint name="d0"><command_interface name="position"/></joint>
    <joint name="d1"><param name="pos_kp">120</param><param name="pos_kd">4</param>
      <command_interface name="position_pid"/></joint>
  </ros2_control>
  <gazebo><plugin name="control" filename="libgazebo_ros2_control.so"/></gazebo></robot>"""


def test_servo_gains_follow_the_effort_bound_and_the_tags_pid(tmp_path: Path) -> None:
    from converters.pipeline import convert

    source = tmp_path / "discs.urdf"
    source.write_text(TWO_DISCS)
    spec, report = convert(source)
    model = mujoco.MjModel.from_xml_path(str(write_model(spec, report, tmp_path / "out")))
    inertia, h = 0.005, 0.001  # [kg m²] each disc about its hinge, [s] the world's step
    d0, d1 = model.actuator("d0"), model.actuator("d1")
    # No effort limit: no force bound; kp = I·ω² with ω·h = OMEGA_STEP, and kv = kp·τ where τ
    # is the longer of critical damping's 2ζ/ω and BRAKE_RAD at the 1 rad/s velocity limit.
    omega, speed = OMEGA_STEP / h, 1.0
    tau = max(2 * DAMPING_RATIO / omega, BRAKE_RAD / speed)
    assert not model.actuator_forcelimited[d0.id]
    assert d0.gainprm[0] == pytest.approx(inertia * omega**2)
    assert d0.biasprm[2] == pytest.approx(-d0.gainprm[0] * tau)
    # The tags' PID: kp = pos_kp, kv = pos_kd as written, within I/h (an effort limit).
    assert d1.gainprm[0] == pytest.approx(120.0)
    assert -d1.biasprm[2] == pytest.approx(min(4.0, inertia / h))
    assert list(d1.forcerange) == [-5.0, 5.0]


def test_a_position_step_without_an_effort_limit_settles_and_slows_to_its_limit(
    tmp_path: Path,
) -> None:
    """d0 (no effort limit, 1 rad/s velocity limit) stepped 1 rad from home in the exported
    scene: it settles within 0.01 rad by 1.3·Δ/v + 0.3 s, passes its target by at most 1 mrad,
    and within BRAKE_RAD of the target it asks no more than its velocity limit (5 % slack)."""
    from converters.pipeline import convert

    source = tmp_path / "discs.urdf"
    source.write_text(TWO_DISCS)
    spec, report = convert(source)
    robot = write_model(spec, report, tmp_path / "out")
    model = mujoco.MjModel.from_xml_path(str(robot.parent / "scene.xml"))
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("home").id)
    a, j = model.actuator("d0").id, model.joint("d0")
    q0, step, speed = float(data.qpos[j.qposadr[0]]), 1.0, 1.0
    data.ctrl[a] = q0 + step
    times, errors, speeds = [], [], []
    while data.time < 2.0:
        mujoco.mj_step(model, data)
        times.append(data.time)
        errors.append(q0 + step - float(data.qpos[j.qposadr[0]]))
        speeds.append(float(data.qvel[j.dofadr[0]]))
    errors, speeds = np.array(errors), np.array(speeds)
    far = np.flatnonzero(np.abs(errors) > 0.01)
    settled = times[far[-1] + 1] if far.size else times[0]
    assert settled <= 1.3 * step / speed + 0.3, f"settled at {settled:.3f} s"
    assert errors.min() >= -1e-3, f"passed its target by {-errors.min():.4f} rad"
    near = np.abs(errors) <= BRAKE_RAD
    assert np.abs(speeds[near]).max() <= 1.05 * speed, "faster than its limit near the target"


@pytest.mark.parametrize("slope_deg", [3.0, 5.0, 8.0])
def test_an_exported_base_parked_on_a_slope_holds_where_it_stands(
    tmp_path: Path, slope_deg: float
) -> None:
    """A two-wheel base whose drive plugin commands its wheels by velocity, exported and reset to
    `home` with ctrl 0 on a slope (gravity tilted along its wheels' rolling direction): its
    wheels' `intvelocity` servos hold it as Gazebo's joint motors do (a velocity constraint at
    speed 0 within their effort), under 1 mm in 10 s; it does not roll off (a damper let a
    turtlebot3 roll 227 mm down 5°)."""
    import drive_models as dm

    from converters.pipeline import convert

    plugin = (
        '<plugin name="dd" filename="libgazebo_ros_diff_drive.so"><left_joint>wheel_left_joint'
        "</left_joint><right_joint>wheel_right_joint</right_joint><wheel_separation>0.3"
        "</wheel_separation><wheel_diameter>0.1</wheel_diameter><max_wheel_torque>5"
        "</max_wheel_torque></plugin>"
    )
    source = tmp_path / "base.urdf"
    source.write_text(dm.two_wheel_base(plugin))
    spec, report = convert(source)
    robot = write_model(spec, report, tmp_path / "out")
    model = mujoco.MjModel.from_xml_path(str(robot.parent / "scene.xml"))
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("home").id)
    theta = np.radians(slope_deg)
    model.opt.gravity[:] = (9.81 * np.sin(theta), 0.0, -9.81 * np.cos(theta))
    mujoco.mj_step(model, data, 1000)  # settle on the tilted ground
    start = data.qpos[:3].copy()
    mujoco.mj_step(model, data, 10000)
    moved = float(np.linalg.norm(data.qpos[:3] - start))
    assert moved < 1e-3, f"rolled {moved * 1e3:.3f} mm down {slope_deg}° in 10 s"


def test_an_exported_velocity_servo_driven_into_its_limit_leaves_it_at_once(
    tmp_path: Path,
) -> None:
    """A velocity-commanded hinge (±3 rad, 2 N m) driven at 1 rad/s into its limit for 3 s, then
    back at -1 rad/s: it leaves the limit within 0.2 s, as Gazebo's joint motor (which stores
    nothing) does. Its velocity motor's rotor winds on past the range, but the tendon only
    couples speeds (an integral reference wound on past the range would hold it there for about
    3 s more)."""
    from converters.pipeline import convert

    source = tmp_path / "hinge.urdf"
    source.write_text(
        TWO_DISCS.replace('effort="0" velocity="1"', 'effort="2" velocity="1"').replace(
            '<joint name="d0"><command_interface name="position"/>',
            '<joint name="d0"><command_interface name="velocity"/>',
        )
    )
    spec, report = convert(source)
    model = mujoco.MjModel.from_xml_path(str(write_model(spec, report, tmp_path / "out")))
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("home").id)
    a, q = model.actuator(rotor_name("d0")).id, model.joint("d0").qposadr[0]
    data.ctrl[a] = 1.0
    mujoco.mj_step(model, data, 6000)  # 3 s to the limit at 3 rad, 3 s against it
    assert data.qpos[q] == pytest.approx(3.0, abs=0.01), "at its limit"
    data.ctrl[a] = -1.0
    start = data.time
    while data.qpos[q] > 2.9 and data.time - start < 5.0:
        mujoco.mj_step(model, data)
    assert data.time - start < 0.2, f"left its limit after {data.time - start:.2f} s"
