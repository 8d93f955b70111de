"""gz-sim's JointController and JointPositionController run through twin's joint commands.

A fixed rig the test writes: two discs (I = 0.01 kg m²) on vertical joints with no control tags,
one named by a JointController (velocity), the other by a JointPositionController (p_gain 30,
d_gain 2). Oracle: the commanded speed and angle; the joints offer only the plugin's mode.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import pytest
from models import hinged_bar
from pid_law import gz_held_bar, gz_position_pid, pid_law

from converters.mjcf.velocity_motors import rotor_name
from twin_cli.errors import InvalidRequestError, ModeNotOfferedError
from twin_cli.spawn_request import SpawnRequest
from twin_cli.world import World

INERTIAL = (
    '<inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" '
    'iyz="0"/></inertial>'
)
RIG = f"""<robot name="rig"><link name="world"/><link name="base">{INERTIAL}</link>
  <link name="fan">{INERTIAL}</link><link name="dial">{INERTIAL}</link>
  <joint name="fix" type="fixed"><parent link="world"/><child link="base"/></joint>
  <joint name="fan_joint" type="continuous"><parent link="base"/><child link="fan"/>
    <axis xyz="0 0 1"/></joint>
  <joint name="dial_joint" type="continuous"><parent link="base"/><child link="dial"/>
    <axis xyz="0 0 1"/></joint>
  <gazebo>
    <plugin filename="gz-sim-joint-controller-system" name="gz::sim::systems::JointController">
      <joint_name>fan_joint</joint_name></plugin>
    <plugin filename="gz-sim-joint-position-controller-system"
      name="gz::sim::systems::JointPositionController"><joint_name>dial_joint</joint_name>
      <p_gain>30</p_gain><d_gain>2</d_gain></plugin>
  </gazebo></robot>"""


def _spawned(tmp_path: Path, text: str) -> World:
    path = tmp_path / "rig.urdf"
    path.write_text(text)
    world = World()
    world.spawn(SpawnRequest(str(path)), name="rig")
    return world


@pytest.fixture
def rig(tmp_path: Path) -> World:
    return _spawned(tmp_path, RIG)


def _state(world: World, joint: str):  # noqa: ANN202
    return {s.name: s for s in world.joint_states("rig")}[joint]


def test_joint_controller_spins_its_joint_at_the_commanded_speed(rig: World) -> None:
    rig.command_joints("rig", {"fan_joint": 3.0}, mode="velocity")
    rig.step(1000)
    speed = _state(rig, "fan_joint").velocity
    assert speed == pytest.approx(3.0, rel=1e-3), f"fan at {speed:.4f} rad/s (commanded 3)"


def test_joint_position_controller_reaches_its_angle_with_the_plugins_gains(rig: World) -> None:
    rig.command_joints("rig", {"dial_joint": 1.0}, mode="position")
    rig.step(3000)  # kp 30, kd 2 on 0.01 kg m²: overdamped, time constant kd/kp ≈ 0.07 s
    angle = _state(rig, "dial_joint").position
    assert angle == pytest.approx(1.0, abs=1e-3), f"dial at {angle:.4f} rad (commanded 1)"
    row = rig.joint_commands("rig")["dial_joint"]
    assert (row["kp"], row["kv"]) == (30.0, 2.0), "p_gain and d_gain as the servo's gains"


@pytest.mark.parametrize(
    ("joint", "mode", "offered"),
    [("fan_joint", "position", "velocity"), ("dial_joint", "velocity", "position")],
)
def test_a_joint_controllers_joint_offers_only_its_mode(
    rig: World, joint: str, mode: str, offered: str
) -> None:
    with pytest.raises(InvalidRequestError, match=f"offers only {offered}") as caught:
        rig.command_joints("rig", {joint: 1.0}, mode=mode)
    assert f"--mode {offered}" in str(caught.value), "the message names the fix"


def _force_rig(tmp_path: Path, p_gain: float = 0.5, i_gain: float = 0.0) -> World:
    """The rig with the fan's JointController on force commands: p_gain, i_gain, cmd_max 2 N m."""
    text = RIG.replace(
        "<joint_name>fan_joint</joint_name></plugin>",
        "<joint_name>fan_joint</joint_name><use_force_commands>true</use_force_commands>"
        f"<p_gain>{p_gain}</p_gain><i_gain>{i_gain}</i_gain><cmd_max>{CMD_MAX}</cmd_max></plugin>",
    )
    return _spawned(tmp_path, text)


CMD_MAX = 2.0  # [N m] the force rig's cmd_max


def test_a_force_commanded_joint_controller_gets_no_joint_motor(tmp_path: Path) -> None:
    """A velocity PID in the tags is a force law: the joint keeps it, not Gazebo's joint motor
    (which put the disc at 2 rad/s 10 ms after a 3 rad/s command, p_gain 0.5 or not)."""
    world = _force_rig(tmp_path)
    tendons = [world.model.tendon(t).name for t in range(world.model.ntendon)]
    assert rotor_name("rig/fan_joint") not in tendons, tendons


@pytest.mark.parametrize(("p_gain", "i_gain"), [(0.2, 0.0), (0.5, 0.0), (5.0, 0.0), (0.5, 0.1)])
def test_a_force_commanded_joint_controller_closes_its_pid_not_a_rigid_motor(
    tmp_path: Path, p_gain: float, i_gain: float
) -> None:
    """With `use_force_commands` gz-sim's JointController pushes p·(ω* − ω) + i·∫(ω* − ω)
    within cmd_max: the 0.01 kg m² disc spins up as that law says (at p 5 the clamp binds for
    13 ms), not at once as the joint motor of a plain velocity command would (2 N m: 3 rad/s in
    15 ms), nor through its integral alone (an intvelocity with kp = i, kv = p: 0.001 rad/s at
    10 ms and 0.54 at 1 s for p 0.5, i 0.1). twin runs p; an i_gain of 0.1 adds under 2 % here."""
    world = _force_rig(tmp_path, p_gain, i_gain)
    world.command_joints("rig", {"fan_joint": 3.0}, mode="velocity")
    h, elapsed = world.model.opt.timestep, 0.0
    for t in (0.005, 0.01, 0.02, 0.04, 0.1):
        world.step(round((t - elapsed) / h))
        elapsed = t
        expected = pid_law(3.0, p_gain, i_gain, t, cmd_max=CMD_MAX)
        speed = _state(world, "fan_joint").velocity
        assert speed == pytest.approx(expected, rel=0.05), f"{speed:.4f} rad/s at {t} s"


def _force_rig_within(tmp_path: Path, p_gain: float, bounds: str) -> World:
    """The force rig (i_gain 0) whose JointController's output limits are the tags `bounds`."""
    text = RIG.replace(
        "<joint_name>fan_joint</joint_name></plugin>",
        "<joint_name>fan_joint</joint_name><use_force_commands>true</use_force_commands>"
        f"<p_gain>{p_gain}</p_gain>{bounds}</plugin>",
    )
    return _spawned(tmp_path, text)


@pytest.mark.parametrize(
    ("bounds", "cmd_max", "cmd_min"),
    [
        ("<cmd_max>2</cmd_max>", 2.0, -1000.0),  # a lone cmd_max: cmd_min keeps gz-math's -1000
        ("<cmd_max>2</cmd_max><cmd_min>-0.5</cmd_min>", 2.0, -0.5),
        ("<cmd_max>0.8</cmd_max><cmd_min>-2</cmd_min>", 0.8, -2.0),
    ],
)
def test_a_force_commanded_joint_controller_pushes_within_cmd_min_and_cmd_max(
    tmp_path: Path, bounds: str, cmd_max: float, cmd_min: float
) -> None:
    """gz-math's PID clamps its output to [cmd_min, cmd_max], each defaulting on its own: the
    disc (p 1, time constant I/p = 10 steps) spins up to 3 rad/s within cmd_max and back to 0
    within cmd_min, as the clamped law says; with a lone cmd_max of 2 N m it brakes at p·e
    (3 N m), not at -2 N m (1.82 rad/s after 5 ms where ±cmd_max would leave 2.0)."""
    world = _force_rig_within(tmp_path, 1.0, bounds)
    world.command_joints("rig", {"fan_joint": 3.0}, mode="velocity")
    h = world.model.opt.timestep
    world.step(round(0.5 / h))
    spun = _state(world, "fan_joint").velocity
    assert spun == pytest.approx(3.0, rel=0.01), f"{spun:.4f} rad/s after 0.5 s at 3 rad/s"
    world.command_joints("rig", {"fan_joint": 0.0}, mode="velocity")
    elapsed = 0.0
    for t in (0.005, 0.01, 0.02, 0.05):
        world.step(round((t - elapsed) / h))
        elapsed = t
        law = pid_law(0.0, 1.0, 0.0, t, cmd_max=cmd_max, cmd_min=cmd_min, start=spun)
        speed = _state(world, "fan_joint").velocity
        assert speed == pytest.approx(law, abs=0.03 * spun), f"{speed:.4f} rad/s at {t} s"
    row = world.joint_commands("rig")["fan_joint"]
    assert row["effort_range"] == [cmd_min, cmd_max], "`twin joints` shows each side"


def _kicked(d_gain: float, overshoot: tuple[float, float], peak_ms: tuple[int, int]):  # noqa: ANN202
    """A ring case gz-sim's derivative kick (d·Δ/h for the step the target jumps) decides,
    with twin's and gz-sim's measured overshoot and peak time."""
    reason = (
        f"gz-math's derivative kick ({d_gain * 1e3:g} N m for 1 ms) is not run: overshoot "
        f"{overshoot[0]:.3f} against gz-sim's {overshoot[1]:.3f}, peak at {peak_ms[0]} ms "
        f"against {peak_ms[1]} ms"
    )
    return pytest.param(
        d_gain, id=f"d{d_gain}", marks=pytest.mark.xfail(strict=True, reason=reason)
    )


# d gains of the ring test (below critical damping, 1.1)
RING = [
    pytest.param(0.05, id="d0.05"),
    _kicked(0.2, (0.560, 0.602), (58, 51)),
    _kicked(0.5, (0.205, 0.329), (65, 44)),
]


@pytest.mark.parametrize("d_gain", RING)
def test_a_joint_position_controller_rings_as_gz_sims_pid_does(
    tmp_path: Path, d_gain: float
) -> None:
    """p_gain 30 (i_gain 0) on the 0.01 kg m² dial with a d_gain below critical damping
    (2√(p·I) = 1.1): gz-sim's PID adds no damping, so a 1 rad step overshoots. Oracle: gz-math's
    PID run once a step on a disc (`pid_law.gz_position_pid`); the first overshoot and its time
    within 5 %. Before, twin damped every tag PID critically: no overshoot at all."""
    text = RIG.replace("<d_gain>2</d_gain>", f"<d_gain>{d_gain}</d_gain><i_gain>0</i_gain>")
    world = _spawned(tmp_path, text)
    world.command_joints("rig", {"dial_joint": 1.0}, mode="position")
    h = world.model.opt.timestep
    angles = []
    for _ in range(round(0.2 / h)):
        world.step(1)
        angles.append(_state(world, "dial_joint").position)
    gz = gz_position_pid(1.0, (30.0, 0.0, d_gain), 0.2, step=h)
    peak, gz_peak = max(angles), max(gz)
    print(
        f"d {d_gain}: overshoot {peak - 1:.3f} at {angles.index(peak) + 1} steps; "
        f"gz-sim {gz_peak - 1:.3f} at {gz.index(gz_peak) + 1}"
    )
    assert peak - 1.0 == pytest.approx(gz_peak - 1.0, rel=0.05), "first overshoot"
    assert angles.index(peak) == pytest.approx(gz.index(gz_peak), rel=0.05), "its time"
    row = world.joint_commands("rig")["dial_joint"]
    assert (row["kp"], row["kv"]) == (30.0, d_gain), "p_gain and d_gain as the servo's gains"


def test_a_joint_controllers_force_stays_within_the_joints_effort_limit_too(
    tmp_path: Path,
) -> None:
    """The fan's joint with its own effort limit of 1.5 N m under a PID whose output range is
    [-0.5, 2]: gz-sim clamps the PID to its range and the physics engine the joint to its
    limit, so the disc (p 1) spins up at 1.5 N m and brakes at 0.5 N m."""
    limited = RIG.replace(
        '<joint name="fan_joint" type="continuous"><parent link="base"/><child link="fan"/>\n'
        '    <axis xyz="0 0 1"/></joint>',
        '<joint name="fan_joint" type="revolute"><parent link="base"/><child link="fan"/>'
        '<axis xyz="0 0 1"/><limit lower="-1000" upper="1000" effort="1.5" velocity="100"/>'
        "</joint>",
    )
    assert limited != RIG
    world = _spawned(
        tmp_path,
        limited.replace(
            "<joint_name>fan_joint</joint_name></plugin>",
            "<joint_name>fan_joint</joint_name><use_force_commands>true</use_force_commands>"
            "<p_gain>1</p_gain><cmd_max>2</cmd_max><cmd_min>-0.5</cmd_min></plugin>",
        ),
    )
    h = world.model.opt.timestep
    world.command_joints("rig", {"fan_joint": 3.0}, mode="velocity")
    elapsed = 0.0
    for t in (0.005, 0.01, 0.02):
        world.step(round((t - elapsed) / h))
        elapsed = t
        law = pid_law(3.0, 1.0, 0.0, t, cmd_max=1.5, cmd_min=-0.5)
        speed = _state(world, "fan_joint").velocity
        assert speed == pytest.approx(law, rel=0.03), f"spin-up: {speed:.4f} rad/s at {t} s"
    world.step(round(0.5 / h))
    spun = _state(world, "fan_joint").velocity
    world.command_joints("rig", {"fan_joint": 0.0}, mode="velocity")
    world.step(round(0.02 / h))
    law = pid_law(0.0, 1.0, 0.0, 0.02, cmd_max=1.5, cmd_min=-0.5, start=spun)
    speed = _state(world, "fan_joint").velocity
    assert speed == pytest.approx(law, abs=0.03 * spun), f"braking: {speed:.4f} rad/s after 20 ms"
    row = world.joint_commands("rig")["fan_joint"]
    assert row["effort_range"] == [-0.5, 1.5], "the PID's range within the joint's limit"


# A 1 kg bar 0.5 m out on a horizontal hinge fixed to the world: its weight turns the hinge by
# 4.905·cos q N m, which a JointPositionController (p 100, d 2, i 0) holding 0 answers alone, as
# in Gazebo (no gravity compensation helps a PID): it settles where p·q = 4.905·cos q if its
# output range reaches that force, and falls otherwise.
BAR = hinged_bar(
    '<plugin filename="gz-sim-joint-position-controller-system" '
    'name="gz::sim::systems::JointPositionController"><joint_name>hinge</joint_name>'
    "<p_gain>100</p_gain><d_gain>2</d_gain><i_gain>0</i_gain>{bounds}</plugin>"
)  # `.format(bounds=…)`: the PID's range and integral tags


@pytest.mark.parametrize(
    ("bounds", "holds"),
    [
        ("<cmd_max>2</cmd_max>", True),  # [-1000, 2]: the weight needs -4.9 N m
        ("<cmd_min>-2</cmd_min>", False),  # [-2, 1000]
        ("<cmd_min>-2</cmd_min><cmd_max>2</cmd_max>", False),
        ("<cmd_min>-10</cmd_min><cmd_max>0</cmd_max>", True),
    ],
)
def test_a_held_arm_gets_only_the_force_its_pids_range_allows(
    tmp_path: Path, bounds: str, holds: bool
) -> None:
    """The PID carries the weight alone, within its own range, each side for itself: the bar
    settles at the static balance p·q = m·g·r·cos q (0.049 rad) when the range reaches the
    4.9 N m it needs, and falls past 0.3 rad when it does not (it then swings about where
    4.905·cos q = 2 N m)."""
    path = tmp_path / "bar.urdf"
    path.write_text(BAR.format(bounds=bounds))
    world = World()
    world.spawn(SpawnRequest(str(path)), name="bar")
    world.command_joints("bar", {"hinge": 0.0}, mode="position")
    angles = []
    for _ in range(200):
        world.step(round(0.01 / world.model.opt.timestep))
        angles.append({s.name: s for s in world.joint_states("bar")}["hinge"].position)
    if holds:
        balance = 0.0
        for _ in range(50):  # p·q = m·g·r·cos q by fixed-point iteration
            balance = 1.0 * 9.81 * 0.5 * math.cos(balance) / 100.0
        assert angles[-1] == pytest.approx(balance, abs=1e-4), f"{bounds}: at {angles[-1]:.5f}"
    else:
        assert max(angles) > 0.3, f"{bounds}: the bar held within {max(angles):.4f} rad"


# (tags, the integral's bound, cmd_offset and output range the oracle applies): gz-math's
# defaults (i 0.1 within ±1), an integral that saturates below the 4.9 N m load, one that can
# carry it, one unbounded (i_max below i_min: gz-math then clamps nothing); then each with a
# cmd_offset: on the defaults, against an integral that carries it, and one whose sum with the
# PID is clamped by cmd_min (the bar then swings about where 4.905·cos q = 4)
WIDE = (-1000.0, 1000.0)
CARRIES = "<i_gain>20</i_gain><i_max>10</i_max><i_min>-10</i_min>"
INTEGRALS = [
    pytest.param("", 1.0, 0.0, WIDE, id="defaults"),
    pytest.param(
        "<i_gain>20</i_gain><i_max>2</i_max><i_min>-2</i_min>", 2.0, 0.0, WIDE, id="saturates"
    ),
    pytest.param(CARRIES, 10.0, 0.0, WIDE, id="carries"),
    pytest.param(
        "<i_gain>5</i_gain><i_max>-1</i_max><i_min>1</i_min>", None, 0.0, WIDE, id="unbounded"
    ),
    pytest.param("<cmd_offset>3</cmd_offset>", 1.0, 3.0, WIDE, id="offset"),
    pytest.param(f"{CARRIES}<cmd_offset>-2</cmd_offset>", 10.0, -2.0, WIDE, id="offset-carried"),
    pytest.param(
        "<cmd_offset>3</cmd_offset><cmd_min>-4</cmd_min>",
        1.0,
        3.0,
        (-4.0, 1000.0),
        id="offset-clamped",
    ),
]


@pytest.mark.parametrize(("tags", "bound", "offset", "output"), INTEGRALS)
def test_a_held_arms_pid_integral_takes_up_its_sag_as_gz_maths_does(
    tmp_path: Path, tags: str, bound: float | None, offset: float, output: tuple[float, float]
) -> None:
    """The bar's weight sags it to where p·q = 4.9·cos q; gz-math's integral then adds up to its
    bound: the bar rises to where p·q + bound = 4.9·cos q (0.029 rad for 2 N m), or all the way
    to 0 when the integral can carry the weight. A `cmd_offset` adds to the PID before its
    output is clamped. In the world and in the exported scene.xml, second by second, as
    gz-math's PID integrated by hand (`gz_held_bar`)."""
    import mujoco

    from converters.mjcf.writer import write_model
    from converters.pipeline import convert_full

    path = tmp_path / "bar.urdf"
    path.write_text(BAR.format(bounds=tags).replace("<i_gain>0</i_gain>", ""))
    i_gain = float(tags.split("<i_gain>")[1].split("<")[0]) if "<i_gain>" in tags else 0.1
    law = gz_held_bar(
        (100.0, i_gain, 2.0), bound, 8.0, inertia=0.2501, load=4.905, offset=offset, output=output
    )
    world = World()
    world.spawn(SpawnRequest(str(path)), name="bar")
    world.command_joints("bar", {"hinge": 0.0}, mode="position")
    angles = []
    for _ in law:
        world.step(round(1.0 / world.model.opt.timestep))
        angles.append({s.name: s for s in world.joint_states("bar")}["hinge"].position)
    assert angles == pytest.approx(law, abs=2e-5), f"world: {angles}"
    row = world.joint_commands("bar")["hinge"]
    assert (row["kp"], row["kv"]) == (100.0, 2.0), f"p_gain and d_gain: {row}"
    assert row["effort_range"] == list(output), "gz-math's output range, not the targets'"
    done = convert_full(path)
    scene = write_model(done.spec, done.report, tmp_path / "out" / "bar").parent / "scene.xml"
    model = mujoco.MjModel.from_xml_path(str(scene))
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, 0)
    exported = []
    for _ in law:
        mujoco.mj_step(model, data, nstep=round(1.0 / model.opt.timestep))
        exported.append(float(data.qpos[0]))
    assert exported == pytest.approx(law, abs=2e-5), f"scene.xml: {exported}"


def test_a_files_own_pid_actuator_is_a_position_servo_and_takes_no_other_mode(
    tmp_path: Path,
) -> None:
    """A hand-written MJCF's `mujoco.pid` actuator (here the exported bar's, its instance
    renamed) is run by ctrl as the file says, whatever its instance is called; an effort or a
    velocity command, which the plugin would read as a position target, is refused."""
    from converters.mjcf.writer import write_model
    from converters.pipeline import convert_full

    path = tmp_path / "bar.urdf"
    path.write_text(BAR.format(bounds="").replace("<i_gain>0</i_gain>", ""))
    done = convert_full(path)
    scene = write_model(done.spec, done.report, tmp_path / "out" / "bar").parent / "scene.xml"
    robot = scene.with_name("bar.xml")
    text = re.sub(r'<text name="control">.*?</text>', "", robot.read_text(), flags=re.S)
    robot.write_text(text.replace("hinge:pid", "hold"))  # no control record: a user's file
    world = World()
    world.spawn(SpawnRequest(str(robot)), name="bar")
    row = world.joint_commands("bar")["hinge"]
    assert (row["modes"], row["kp"], row["kv"]) == (["position"], 100.0, 2.0), row
    for mode in ("effort", "velocity"):
        with pytest.raises(ModeNotOfferedError, match="offers only position"):
            world.command_joints("bar", {"hinge": 0.0}, mode=mode)
    world.command_joints("bar", {"hinge": 0.0}, mode="position")
    world.step(round(4.0 / world.model.opt.timestep))
    law = gz_held_bar((100.0, 0.1, 2.0), 1.0, 4.0, inertia=0.2501, load=4.905)
    angle = {s.name: s for s in world.joint_states("bar")}["hinge"].position
    assert angle == pytest.approx(law[-1], abs=2e-5), f"{angle:.5f} rad, gz-math {law[-1]:.5f}"


FILTERED_PID = """<mujoco><extension><plugin plugin="mujoco.pid"><instance name="p">
  <config key="kp" value="10"/></instance></plugin></extension><worldbody>
  <body name="b" pos="0 0 1"><joint name="j" type="slide" axis="0 0 1"/><geom size="0.1"
  mass="1"/></body></worldbody><actuator><plugin name="j" joint="j" instance="p"
  dyntype="filter" dynprm="0.1" actdim="1"/></actuator></mujoco>"""


def test_a_plugin_actuator_twin_cannot_read_takes_no_command(tmp_path: Path) -> None:
    """A `mujoco.pid` whose ctrl is filtered first is no position target twin can write: its
    joint offers no mode, and a command is refused naming why, the world unchanged."""
    path = tmp_path / "filtered.xml"
    path.write_text(FILTERED_PID)
    world = World()
    world.spawn(SpawnRequest(str(path)), name="u")
    assert world.joint_commands("u")["j"]["modes"] == []
    before = world.data.ctrl.copy()
    with pytest.raises(ModeNotOfferedError, match="reads ctrl its own way"):
        world.command_joints("u", {"j": 0.1}, mode="position")
    assert (world.data.ctrl == before).all(), "a refused command leaves the world as it was"


def test_a_pid_integral_goes_on_while_island_sleeping_is_on(tmp_path: Path) -> None:
    """`twin physics --sleep` lets resting trees sleep; a bar at rest under gz-math's default
    integral (0.1, within ±1) still rises as its integral grows, as gz-sim's does: a sleeping
    tree would stay where it fell asleep while the integral winds on."""
    path = tmp_path / "bar.urdf"
    path.write_text(BAR.format(bounds="").replace("<i_gain>0</i_gain>", ""))
    law = gz_held_bar((100.0, 0.1, 2.0), 1.0, 30.0, inertia=0.2501, load=4.905)
    world = World()
    world.spawn(SpawnRequest(str(path)), name="bar")
    world.set_engine(sleep=True)
    world.command_joints("bar", {"hinge": 0.0}, mode="position")
    world.step(round(30.0 / world.model.opt.timestep))
    angle = {s.name: s for s in world.joint_states("bar")}["hinge"].position
    assert angle == pytest.approx(law[-1], abs=2e-5), f"{angle:.5f} rad, gz-math {law[-1]:.5f}"


def test_equal_cmd_min_and_cmd_max_are_refused_naming_the_tag(tmp_path: Path) -> None:
    """gz-math would push that one force whatever the error: not a controller twin can run."""
    from converters.errors import GazeboTagError
    from converters.pipeline import convert

    path = tmp_path / "rig.urdf"
    path.write_text(RIG.replace("<d_gain>2</d_gain>", "<cmd_min>2</cmd_min><cmd_max>2</cmd_max>"))
    with pytest.raises(GazeboTagError, match=r"<plugin/cmd_min>: value '2'") as caught:
        convert(path)
    assert "below cmd_max" in str(caught.value), "the message names the fix"


@pytest.mark.parametrize(("p_gain", "offset"), [(30.0, 3.0), (30.0, -1.5), (60.0, 3.0)])
def test_a_position_controllers_cmd_offset_shifts_where_it_settles(
    tmp_path: Path, p_gain: float, offset: float
) -> None:
    """gz-math adds `cmd_offset` to the PID's output: on the unloaded dial the force
    -p·(q − q*) + offset vanishes at q = q* + offset/p, where the dial settles."""
    text = RIG.replace(
        "<p_gain>30</p_gain><d_gain>2</d_gain>",
        f"<p_gain>{p_gain}</p_gain><d_gain>2</d_gain><cmd_offset>{offset}</cmd_offset>",
    )
    world = _spawned(tmp_path, text)
    world.command_joints("rig", {"dial_joint": 1.0}, mode="position")
    world.step(round(3.0 / world.model.opt.timestep))
    angle = _state(world, "dial_joint").position
    assert angle == pytest.approx(1.0 + offset / p_gain, abs=1e-3), f"dial at {angle:.4f} rad"


@pytest.mark.parametrize("offset", [0.5, -0.25])
def test_a_force_commanded_joint_controllers_cmd_offset_shifts_its_speed(
    tmp_path: Path, offset: float
) -> None:
    """With force commands the fan (p 0.5) settles where p·(ω* − ω) + offset = 0: at
    ω* + offset/p, 1 rad/s above or 0.5 below a 3 rad/s command."""
    world = _force_rig_within(tmp_path, 0.5, f"<cmd_offset>{offset}</cmd_offset>")
    world.command_joints("rig", {"fan_joint": 3.0}, mode="velocity")
    world.step(round(1.0 / world.model.opt.timestep))
    speed = _state(world, "fan_joint").velocity
    assert speed == pytest.approx(3.0 + offset / 0.5, rel=1e-3), f"fan at {speed:.4f} rad/s"
