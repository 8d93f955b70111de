"""A fixed arm's exported position servos hold it under gravity and move it as a stiff servo does.

Oracles: the commanded posture (a held arm does not sag: MuJoCo's gravity compensation carries
the weight within the effort limit), the step's target (no overshoot, settled within the time a
move at the joint's speed limit needs), and a World spawning the robot's source (a World spawning
the file must behave the same). Model: a Panda-like arm (`arm_models.panda_like_arm`, the
Panda's masses and limits, ros2_control position interfaces).
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest
from arm_models import panda_like_arm
from interface_models import PANDA_JOINTS
from models import write_urdf

from converters.mjcf.builder import ConvertOptions
from converters.mjcf.writer import write_model
from converters.pipeline import convert_full
from twin_cli.spawn_request import SpawnRequest
from twin_cli.world import World

HOLD_RAD = 1e-3  # [rad] a held posture stays this close to its target for HOLD_S
HOLD_S = 5.0  # [s]
SETTLED_RAD = 0.01  # [rad] a step has settled once it stays this close to its target
OVERSHOOT_RAD = 1e-3  # [rad] a step passes its target by at most this
STEADY_RAD = 1e-4  # [rad] a settled step's error at the end of STEP_S
STEP_S = 2.0  # [s] simulated per step
# [s] a move of Δ at the speed limit v takes Δ/v; a servo that settles within 1.3·Δ/v + 0.3 s runs
# near it (measured: the old export's overdamped servos took 4.4 s for 1 rad on joint 1).
SLACK, LEAD_S = 1.3, 0.3
VELOCITY = np.array([2.175] * 4 + [2.61] * 3)  # [rad/s] the arm's limits (interface_models)
POSTURES = {
    "horizontal": (0.0, 1.5, 0.0, -0.1, 0.0, 1.6, 0.0),
    "forward": (0.0, 0.9, 0.0, -0.3, 0.0, 1.5, 0.0),
    "twisted": (0.5, 1.2, -0.5, -0.8, 0.5, 2.0, 0.3),
    "ready": (0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785),
}


def _scene(tmp_path: Path, fixed_base: bool = False, world_link: bool = True) -> mujoco.MjModel:
    done = convert_full(
        write_urdf(tmp_path, panda_like_arm(world_link), "arm.urdf"),
        options=ConvertOptions(fixed_base=fixed_base),
    )
    robot = write_model(done.spec, done.report, tmp_path / "out")
    return mujoco.MjModel.from_xml_path(str(robot.parent / "scene.xml"))


def _from_home(model: mujoco.MjModel, posture: np.ndarray) -> mujoco.MjData:
    """Data reset to the `home` keyframe, then placed and commanded at `posture`."""
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("home").id)
    data.qpos[:7] = posture
    data.ctrl[:7] = posture
    mujoco.mj_forward(model, data)
    return data


@pytest.mark.parametrize("posture", list(POSTURES))
def test_exported_fixed_arm_holds_postures_under_gravity(tmp_path: Path, posture: str) -> None:
    """Without compensation the servos sagged up to 70 mrad here (load/kp)."""
    model = _scene(tmp_path)
    target = np.array(POSTURES[posture])
    data = _from_home(model, target)
    drift = 0.0
    for _ in range(round(HOLD_S / model.opt.timestep)):
        mujoco.mj_step(model, data)
        drift = max(drift, float(np.abs(data.qpos[:7] - target).max()))
    assert drift < HOLD_RAD, f"{posture}: drifted {drift * 1e3:.3f} mrad"


@pytest.mark.parametrize(
    ("fixed_base", "world_link"), [(False, False), (True, False), (False, True)]
)
def test_only_a_fixed_base_gets_gravity_compensation(
    tmp_path: Path, fixed_base: bool, world_link: bool
) -> None:
    """A floating arm compensated would float away; a fixed one (a `world` link or
    `--fixed-base`) carries each body's weight through its servos, within ±effort."""
    model = _scene(tmp_path, fixed_base, world_link)
    fixed = fixed_base or world_link
    hinges = [j for j in range(model.njnt) if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE]
    arm = model.jnt_bodyid[hinges]  # the seven links the servos move
    expected = np.zeros(model.nbody)
    expected[arm] = 1.0 if fixed else 0.0
    assert np.array_equal(model.body_gravcomp, expected), model.body_gravcomp
    assert list(model.jnt_actgravcomp[hinges]) == [fixed] * len(PANDA_JOINTS)
    if fixed:
        effort = np.abs(model.actuator_forcerange[:, 1])
        assert np.array_equal(model.jnt_actfrcrange[hinges, 1], effort)


STEPS = [
    (posture, joint, size)
    for posture in ("forward", "twisted", "ready")
    for joint in (0, 2, 3, 5)
    for size in (0.1, -0.5, 1.0)
]


@pytest.mark.parametrize(("posture", "joint", "size"), STEPS)
def test_exported_joint_steps_settle_fast_without_overshoot(
    tmp_path: Path, posture: str, joint: int, size: float
) -> None:
    model = _scene(tmp_path)
    start = np.array(POSTURES[posture])
    data = _from_home(model, start)
    low, high = model.actuator_ctrlrange[joint]
    target = float(np.clip(start[joint] + size, low, high))
    data.ctrl[joint] = target
    direction, settled, overshoot = np.sign(target - start[joint]), 0.0, 0.0
    for _ in range(round(STEP_S / model.opt.timestep)):
        mujoco.mj_step(model, data)
        error = data.qpos[joint] - target
        overshoot = max(overshoot, float(direction * error))
        settled = data.time if abs(error) > SETTLED_RAD else settled
    assert data.ncon == 0, "the step must not end in a self-contact"
    bound = SLACK * abs(target - start[joint]) / VELOCITY[joint] + LEAD_S
    where = f"{posture} joint {joint + 1} {size:+} rad"
    assert settled <= bound, f"{where}: settled in {settled:.3f} s (bound {bound:.3f})"
    assert overshoot <= OVERSHOOT_RAD, f"{where}: overshot {overshoot * 1e3:.1f} mrad"
    assert abs(data.qpos[joint] - target) < STEADY_RAD, f"{where}: {data.qpos[joint] - target}"


def test_a_world_spawning_the_exported_fixed_arm_moves_as_its_source(tmp_path: Path) -> None:
    """The file's gravity compensation is for MuJoCo users; a World spawning the file switches
    its own, as for the source, so both Worlds move the same to the bit."""
    done = convert_full(write_urdf(tmp_path, panda_like_arm(), "arm.urdf"))
    robot_file = write_model(done.spec, done.report, tmp_path / "out")
    assert mujoco.MjModel.from_xml_path(str(robot_file)).body_gravcomp.max() == 1.0
    from_file, from_source = World(), World()
    from_file.spawn(robot_file, name="r")
    from_source.spawn(SpawnRequest(done.spec.copy()), name="r")
    assert np.array_equal(from_file.model.body_gravcomp, from_source.model.body_gravcomp)
    target = dict(zip(PANDA_JOINTS, POSTURES["forward"], strict=True))
    for world in (from_file, from_source):
        world.command_joints("r", target, mode="position")
        world.step(500)
        world.command_joints("r", {"panda_joint1": 0.5}, mode="position")
        world.step(500)
    a, b = (w.data.qpos.copy() for w in (from_file, from_source))
    assert np.array_equal(a, b), f"the commanded arms differ by {np.abs(a - b).max()}"
