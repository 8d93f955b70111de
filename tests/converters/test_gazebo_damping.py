"""Gazebo `dampingFactor` as joint damping: a body keeps (1 − f) of its velocity per 1 ms step.

Oracle: ODE's `dxStepBody` scales a damped body's linear and angular velocity by (1 − f) after
every 1 ms step, so after n steps it has (1 − f)^n of it (while faster than 0.01 m/s, 0.01
rad/s, which every horizon here stays above). Gravity is off and nothing touches the bodies.
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest
from models import block, write_urdf

from converters.mjcf.writer import write_model
from converters.pipeline import convert
from converters.report import Outcome
from twin_cli.world import Pose, World

FRACTIONS = (0.001, 0.01, 0.1)
STEPS = 30  # 1 ms steps: 0.9^30 = 0.042 keeps the fastest decay above ODE's 0.01 threshold
V0, W0 = 1.0, 1.0  # [m/s], [rad/s] initial speeds, over 100 times ODE's damping threshold
SAME = 1e-9  # relative: the implicit step reproduces (1 − f) per step to rounding
ROTATION_SAME = 0.01  # relative, what a rotation would have to meet (it does not: see below)
SCENE_SAME = 1e-12  # [m/s or rad/s] the exported scene against the World


def damped_box(fraction: float) -> str:
    """A free 1 kg cube of 0.1 m (I = 1/600 kg m²) with Gazebo `dampingFactor` on it."""
    tag = f'<gazebo reference="box"><dampingFactor>{fraction}</dampingFactor></gazebo>'
    return block(name="box").replace("</robot>", tag + "</robot>")


def damped_pendulum(fraction: float) -> str:
    """A 2 kg rod hinged to the world 0.3 m from its centre of mass, tagged `dampingFactor`."""
    return f"""<robot name="pendulum">
  <link name="world"/>
  <link name="rod">
    <inertial><origin xyz="0 0 -0.3"/><mass value="2"/>
      <inertia ixx="0.02" iyy="0.03" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0 0 -0.3"/><geometry><box size="0.05 0.05 0.6"/></geometry>
    </collision>
  </link>
  <joint name="hinge" type="continuous"><parent link="world"/><child link="rod"/>
    <origin xyz="0 0 1"/><axis xyz="0 1 0"/></joint>
  <gazebo reference="rod"><dampingFactor>{fraction}</dampingFactor></gazebo>
</robot>"""


def _world_with(tmp_path: Path, text: str) -> tuple[World, mujoco.MjSpec]:
    spec, _ = convert(write_urdf(tmp_path, text))
    world = World()
    world.set_gravity((0.0, 0.0, 0.0))
    world.spawn(spec.copy(), name="r", pose=Pose(z=1.0))
    return world, spec


@pytest.mark.parametrize("fraction", FRACTIONS)
def test_free_box_translation_keeps_one_minus_f_per_millisecond(tmp_path, fraction):
    world, _ = _world_with(tmp_path, damped_box(fraction))
    world.data.qvel[:3] = [V0, 0.0, 0.0]
    world.step(STEPS)
    expected = V0 * (1.0 - fraction) ** STEPS
    vx = float(world.data.qvel[0])
    assert vx == pytest.approx(expected, rel=SAME), f"vx after {STEPS} ms: {vx} m/s"


@pytest.mark.xfail(
    strict=True,
    reason="one joint damping serves a free joint's 6 dofs: with b = K·m the cube's rotation "
    "decays m/I = 600 times Gazebo's rate; after 30 ms ω keeps 7.4e-7 (f 0.001), 3.4e-26 "
    "(0.01), 1.2e-55 (0.1) of itself where Gazebo keeps 0.970, 0.740, 0.042",
)
@pytest.mark.parametrize("fraction", FRACTIONS)
def test_free_box_rotation_keeps_one_minus_f_per_millisecond(tmp_path, fraction):
    world, _ = _world_with(tmp_path, damped_box(fraction))
    world.data.qvel[3:6] = [0.0, 0.0, W0]
    world.step(STEPS)
    expected = W0 * (1.0 - fraction) ** STEPS
    wz = float(world.data.qvel[5])
    assert wz == pytest.approx(expected, rel=ROTATION_SAME), f"ωz after {STEPS} ms: {wz} rad/s"


@pytest.mark.parametrize("fraction", FRACTIONS)
def test_hinged_rod_keeps_one_minus_f_per_millisecond(tmp_path, fraction):
    # A rod alone on a fixed axis: scaling its linear and angular velocity by (1 − f), as ODE
    # does, scales the joint speed by (1 − f).
    world, _ = _world_with(tmp_path, damped_pendulum(fraction))
    dof = int(world.model.joint("r/hinge").dofadr[0])
    world.data.qvel[dof] = W0
    world.step(STEPS)
    expected = W0 * (1.0 - fraction) ** STEPS
    speed = float(world.data.qvel[dof])
    assert speed == pytest.approx(expected, rel=SAME), f"hinge speed after {STEPS} ms: {speed}"


@pytest.mark.parametrize("fraction", FRACTIONS)
def test_exported_scene_decays_as_the_world(tmp_path, fraction):
    world, spec = _world_with(tmp_path, damped_box(fraction))
    scene = write_model(spec, convert(write_urdf(tmp_path, damped_box(fraction)))[1], tmp_path)
    model = mujoco.MjModel.from_xml_path(str(scene.parent / "scene.xml"))
    model.opt.gravity[:] = 0.0
    data = mujoco.MjData(model)
    data.qpos[:7] = world.data.qpos[:7]  # 1 m up, clear of the scene's ground as of the world's
    start = np.array([V0, 0.3, 0.0, 0.2, 0.0, W0])
    data.qvel[:6] = start
    world.data.qvel[:6] = start
    mujoco.mj_step(model, data, STEPS)
    world.step(STEPS)
    gap = float(np.abs(data.qvel[:6] - world.data.qvel[:6]).max())
    assert gap <= SCENE_SAME, f"largest velocity difference scene vs world: {gap}"
    assert data.qvel[0] == pytest.approx(V0 * (1 - fraction) ** STEPS, rel=SAME), "scene vx"


def test_report_gives_the_rotation_ratio(tmp_path):
    _, report = convert(write_urdf(tmp_path, damped_box(0.01)))
    entries = [e for e in report.entries if e.tag == "dampingFactor"]
    assert len(entries) == 1, f"dampingFactor report entries: {entries}"
    assert entries[0].outcome is Outcome.APPROXIMATED, entries[0]
    assert "600/600/600 times" in entries[0].detail, entries[0].detail


def test_untagged_box_has_no_joint_damping(tmp_path):
    spec, _ = convert(write_urdf(tmp_path, block(name="box")))
    model = spec.compile()
    assert not model.dof_damping.any(), f"dof damping {model.dof_damping}"
