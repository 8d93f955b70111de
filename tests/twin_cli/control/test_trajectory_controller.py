"""gz-sim's JointTrajectoryController, in URDF `<gazebo>` and in SDF, read as gz-sim reads it and
run through twin's trajectory follower.

A fixed two-joint arm the test writes, both joints about the vertical (no gravity load), the
plugin's per-joint tags repeated in the joints' order. Oracle: gz-sim's documented parameters
(repeatable per-joint tags, defaults 0, topic `/model/<model>/joint_trajectory` and its
`_progress`), the commanded angles, and the servo gains the mapping states: kp = position_p_gain,
kv = position_d_gain + velocity_p_gain (chosen above critical damping on each joint's inertia,
which twin's position servos keep as their least damping).
"""

from __future__ import annotations

from pathlib import Path

import drive_models as dm
import pytest
from models import hinged_bar
from pid_law import gz_held_bar

from converters.pipeline import convert_full
from converters.report import Outcome
from twin_cli.control import Trajectory, TrajectoryPoint, follow_trajectory
from twin_cli.spawn_request import SpawnRequest
from twin_cli.world import World

JTC = (
    '<plugin filename="gz-sim-joint-trajectory-controller-system" '
    'name="gz::sim::systems::JointTrajectoryController">{joints}'
    "<initial_position>0.3</initial_position><initial_position>-0.5</initial_position>"
    "<position_p_gain>200</position_p_gain><position_p_gain>100</position_p_gain>"
    "<position_d_gain>10</position_d_gain><position_d_gain>3</position_d_gain>"
    "<velocity_p_gain>2</velocity_p_gain><velocity_p_gain>1</velocity_p_gain>"
    "<position_cmd_min>-50</position_cmd_min><position_cmd_max>50</position_cmd_max>"
    "<velocity_cmd_min>-10</velocity_cmd_min><velocity_cmd_max>10</velocity_cmd_max>"
    "<velocity_i_gain>0.5</velocity_i_gain>{topic}</plugin>"
)
NAMED = "<joint_name>shoulder</joint_name><joint_name>elbow</joint_name>"


def _record(tmp_path: Path, text: str, suffix: str):  # noqa: ANN202
    path = tmp_path / f"arm.{suffix}"
    path.write_text(text)
    done = convert_full(path)
    (record,) = done.plugins
    return record, done.report


@pytest.mark.parametrize(
    ("robot", "suffix", "joints", "topic"),
    [
        (dm.arm_urdf, "urdf", NAMED, ""),
        (dm.arm_sdf, "sdf", "", "<topic>/arm/trajectory</topic>"),  # every 1-axis joint, in order
    ],
)
def test_its_per_joint_tags_are_read_in_the_joints_order(
    tmp_path: Path, robot, suffix: str, joints: str, topic: str
) -> None:
    record, report = _record(tmp_path, robot(JTC.format(joints=joints, topic=topic)), suffix)
    assert record.joints == ("shoulder", "elbow")
    assert record.initial_positions == (0.3, -0.5)
    # kp = position p + the shoulder's unbounded velocity integral (a spring); kv = d + velocity p
    assert record.pids == ((200.5, 0.0, 12.0), (100.0, 0.0, 4.0)), record.pids
    # the first joint's output limits are given, the second's default to none (gz-sim's PID)
    assert record.force_ranges == ((-60.0, 60.0), (-float("inf"), float("inf")))
    expected = "/arm/trajectory" if topic else "/model/arm/joint_trajectory"
    assert (record.topic, record.progress_topic) == (expected, expected + "_progress")
    lines = [e.detail for e in report.entries if e.tag == "plugin"]
    assert any("twin trajectory ENTITY FILE" in line for line in lines), lines
    notes = [e.detail for e in report.of(Outcome.APPROXIMATED)]
    assert not any("<velocity_i_gain>: not used" in n for n in notes), notes
    assert any("kv = position_d_gain + velocity_p_gain" in n for n in notes), notes


def test_the_arm_starts_at_its_initial_positions_and_follows_a_trajectory(
    tmp_path: Path,
) -> None:
    path = tmp_path / "arm.urdf"
    path.write_text(dm.arm_urdf(JTC.format(joints=NAMED, topic="")))
    world = World()
    world.spawn(SpawnRequest(str(path)), name="arm")
    start = {s.name: s.position for s in world.joint_states("arm")}
    assert start == pytest.approx({"shoulder": 0.3, "elbow": -0.5}, abs=1e-9)
    points = (TrajectoryPoint(1.0, (0.8, -1.0)),)
    follow_trajectory(world, "arm", Trajectory(("shoulder", "elbow"), points))
    world.step(2000)
    end = {s.name: s.position for s in world.joint_states("arm")}
    assert end == pytest.approx({"shoulder": 0.8, "elbow": -1.0}, abs=1e-3), "angles [rad]"
    rows = world.joint_commands("arm")
    gains = {j: (rows[j]["kp"], rows[j]["kv"]) for j in ("shoulder", "elbow")}
    assert gains == {"shoulder": (200.5, 12.0), "elbow": (100.0, 4.0)}, "the plugin's gains"


@pytest.mark.parametrize(
    ("offsets", "shifts"),
    [
        ((4.0, -1.0, 0.0, 0.5), (3.0 / 200.5, 0.5 / 100.0)),
        ((-2.0, 0.0, 1.0, 1.0), (-2.0 / 200.5, 2.0 / 100.0)),
    ],
)
def test_its_cmd_offsets_shift_where_each_joint_settles_before_and_after_a_trajectory(
    tmp_path: Path, offsets: tuple[float, float, float, float], shifts: tuple[float, float]
) -> None:
    """gz-math adds each PID's `cmd_offset` to its output and the system sums both PIDs: on the
    unloaded arm the force offset − p·(q − q*) vanishes at q = q* + offset/p, per joint, with
    (shoulder position, shoulder velocity, elbow position, elbow velocity) offsets."""
    tags = "".join(  # repeatable tags in the joints' order
        f"<{pid}_cmd_offset>{offsets[2 * joint + k]}</{pid}_cmd_offset>"
        for k, pid in enumerate(("position", "velocity"))
        for joint in (0, 1)
    )
    path = tmp_path / "arm.urdf"
    path.write_text(dm.arm_urdf(JTC.format(joints=NAMED, topic=tags)))
    world = World()
    world.spawn(SpawnRequest(str(path)), name="arm")
    world.command_joints("arm", {"shoulder": 0.3, "elbow": -0.5}, mode="position")
    world.step(round(3.0 / world.model.opt.timestep))
    end = {s.name: s.position for s in world.joint_states("arm")}
    expected = {"shoulder": 0.3 + shifts[0], "elbow": -0.5 + shifts[1]}
    assert end == pytest.approx(expected, abs=2e-4), f"angles [rad]: {end}"
    points = (TrajectoryPoint(1.0, (0.8, -1.0)),)  # the offsets act along and after it too
    follow_trajectory(world, "arm", Trajectory(("shoulder", "elbow"), points))
    world.step(round(3.0 / world.model.opt.timestep))
    end = {s.name: s.position for s in world.joint_states("arm")}
    expected = {"shoulder": 0.8 + shifts[0], "elbow": -1.0 + shifts[1]}
    assert end == pytest.approx(expected, abs=2e-4), f"after a trajectory [rad]: {end}"


LIMP_BAR = hinged_bar(
    '<plugin filename="gz-sim-joint-trajectory-controller-system" '
    'name="gz::sim::systems::JointTrajectoryController"><joint_name>hinge</joint_name>'
    "<initial_position>0.4</initial_position></plugin>",
    effort=100.0,
)


def test_a_joint_without_gains_is_limp_as_in_gz_sim_and_takes_efforts(tmp_path: Path) -> None:
    """With every gain 0 gz-sim's PIDs push nothing: the joint gets only a trajectory's effort.
    The level bar (1 kg, 0.5 m out) stays where the model puts it, not at initial_position,
    falls as a free pendulum (gz-math's PID with gains 0, `gz_held_bar`), and an effort
    command of its weight's moment holds it level."""
    path = tmp_path / "bar.urdf"
    path.write_text(LIMP_BAR)
    world = World()
    world.spawn(SpawnRequest(str(path)), name="bar")
    assert world.joint_commands("bar")["hinge"]["modes"] == ["effort"], "a torque motor only"
    fall = gz_held_bar((0.0, 0.0, 0.0), None, 0.5, inertia=0.2501, load=4.905, every=0.1)
    angles = []
    for _ in fall:
        world.step(round(0.1 / world.model.opt.timestep))
        angles.append(world.joint_states("bar")[0].position)
    assert angles == pytest.approx(fall, abs=1e-5), f"limp fall {angles}, pendulum {fall}"
    world.reset()
    world.command_joints("bar", {"hinge": -4.905}, mode="effort")
    world.step(round(1.0 / world.model.opt.timestep))
    level = world.joint_states("bar")[0].position
    assert abs(level) < 1e-6, f"held by its weight's moment: {level:.2e} rad"


@pytest.mark.parametrize("offset", [-4.905, -3.0])
def test_a_limp_joints_cmd_offset_still_pushes_as_gz_maths_pid_does(
    tmp_path: Path, offset: float
) -> None:
    """gz-math's PID with every gain 0 still outputs its `cmd_offset`: the level bar is held by
    an offset of its weight's moment, and with less falls as the pendulum under the rest
    (`gz_held_bar` with that constant force), in the world and in the exported scene.xml."""
    import mujoco

    from converters.mjcf.writer import write_model

    path = tmp_path / "bar.urdf"
    tag = f"<position_cmd_offset>{offset}</position_cmd_offset>"
    path.write_text(LIMP_BAR.replace("<initial_position>0.4</initial_position>", tag))
    world = World()
    world.spawn(SpawnRequest(str(path)), name="bar")
    law = gz_held_bar((0, 0, 0), None, 0.5, inertia=0.2501, load=4.905, every=0.1, offset=offset)
    angles = []
    for _ in law:
        world.step(round(0.1 / world.model.opt.timestep))
        angles.append(world.joint_states("bar")[0].position)
    assert angles == pytest.approx(law, abs=1e-5), f"bar {angles}, gz-math {law}"
    done = convert_full(path)
    scene = write_model(done.spec, done.report, tmp_path / "out" / "bar").parent / "scene.xml"
    model = mujoco.MjModel.from_xml_path(str(scene))
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, 0)
    mujoco.mj_step(model, data, nstep=round(0.5 / model.opt.timestep))
    assert float(data.qpos[0]) == pytest.approx(law[-1], abs=1e-5), "scene.xml"


VELOCITY_BAR = LIMP_BAR.replace(
    "<initial_position>0.4</initial_position>", "<initial_position>0</initial_position>{gains}"
)


@pytest.mark.parametrize(
    ("gains", "law"),
    [
        ("<velocity_p_gain>2</velocity_p_gain><velocity_i_gain>200</velocity_i_gain>", (200, 2)),
        (
            "<position_p_gain>50</position_p_gain><velocity_p_gain>1</velocity_p_gain>"
            "<velocity_i_gain>100</velocity_i_gain>",
            (150, 1),
        ),
    ],
)
def test_a_velocity_integral_holds_a_loaded_joint_as_gz_maths_pids_do(
    tmp_path: Path, gains: str, law: tuple[float, float]
) -> None:
    """gz-sim's velocity PID integrates q̇ − q̇*, i.e. i·(q − q_start) with no trajectory: with
    the position PID's p it is one spring, kp = position p + velocity i, damped by the velocity
    p. The level bar sags under its weight as gz-math's PIDs integrated by hand, every 0.5 s
    (`gz_held_bar` with that spring and damping): within 3e-4 rad while it rings (MuJoCo takes
    a position servo's damping implicitly, the oracle explicitly: 0.8 % a step at kv·h/I), and
    at 1e-5 rad once it settles where kp·q = 4.905·cos q."""
    path = tmp_path / "bar.urdf"
    path.write_text(VELOCITY_BAR.format(gains=gains))
    world = World()
    world.spawn(SpawnRequest(str(path)), name="bar")
    world.command_joints("bar", {"hinge": 0.0}, mode="position")
    kp, kv = law
    sag = gz_held_bar((kp, 0.0, kv), None, 4.0, inertia=0.2501, load=4.905, every=0.5)
    angles = []
    for _ in sag:
        world.step(round(0.5 / world.model.opt.timestep))
        angles.append(world.joint_states("bar")[0].position)
    assert angles == pytest.approx(sag, abs=3e-4), f"bar {angles}, gz-math {sag}"
    assert angles[-1] == pytest.approx(sag[-1], abs=1e-5), f"settled {angles[-1]:.6f} rad"


def test_a_bounded_velocity_integral_is_reported_not_run(tmp_path: Path) -> None:
    """With velocity_i_min/max the integral saturates: no spring, so it is left out and said."""
    gains = (
        "<velocity_p_gain>2</velocity_p_gain><velocity_i_gain>200</velocity_i_gain>"
        "<velocity_i_min>-1</velocity_i_min><velocity_i_max>1</velocity_i_max>"
    )
    path = tmp_path / "bar.urdf"
    path.write_text(VELOCITY_BAR.format(gains=gains))
    done = convert_full(path)
    (record,) = done.plugins
    assert record.pids == ((0.0, 0.0, 2.0),), "the velocity p only"
    notes = [e.detail for e in done.report.of(Outcome.APPROXIMATED)]
    assert any("hinge: velocity_i_gain within" in n and "not run" in n for n in notes), notes


def test_a_joint_it_names_that_the_model_lacks_is_refused_naming_the_joints(
    tmp_path: Path,
) -> None:
    from converters.errors import PluginJointError

    plugin = JTC.format(joints="<joint_name>wrist</joint_name>", topic="")
    path = tmp_path / "arm.urdf"
    path.write_text(dm.arm_urdf(plugin))
    with pytest.raises(PluginJointError, match="wrist") as caught:
        convert_full(path)
    assert "shoulder" in str(caught.value), "the message lists the model's joints"


def test_a_gain_that_is_not_a_number_is_refused_naming_its_tag(tmp_path: Path) -> None:
    from converters.errors import GazeboTagError

    plugin = JTC.format(joints=NAMED, topic="").replace(
        "<position_p_gain>100</position_p_gain>", "<position_p_gain>stiff</position_p_gain>"
    )
    path = tmp_path / "arm.urdf"
    path.write_text(dm.arm_urdf(plugin))
    with pytest.raises(GazeboTagError, match="position_p_gain") as caught:
        convert_full(path)
    assert "'stiff'" in str(caught.value) and "a number" in str(caught.value)
