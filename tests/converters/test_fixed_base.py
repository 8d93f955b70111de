"""`--fixed-base`: the converter welds a floating root to the world (no free joint) and leaves a
robot that is already fixed as it was, saying which in the report."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import mujoco
import numpy as np
import pytest
from arm_models import floating_arm
from models import write_urdf

from converters.mjcf.builder import ConvertOptions
from converters.pipeline import convert_full

STEPS = 1000  # 1 s at the converter's 1 ms step
ROOT_TOL = 1e-12  # [m] a welded root does not move
MOVED = 0.05  # [rad] the least swing of the shoulder under gravity; 0.141-0.143 measured
# [m] the least motion of a floating root, standing on the floor from its `home` key, while its
# arm swings; 1.1e-5 m measured, 1e5 times the welded root's tolerance
SHAKEN = 1e-7
WELDED = "root 'base_link' welded to the world (--fixed-base)"


def _convert(urdf: Path, out: Path, *flags: str) -> dict:
    """`twin convert URDF -o OUT --json FLAGS`, which must exit 0; its JSON report."""
    proc = subprocess.run(
        [sys.executable, "-m", "twin_cli", "convert", str(urdf), "-o", str(out), "--json", *flags],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode == 0, f"twin convert {' '.join(flags)}: {proc.stderr}"
    return json.loads(proc.stdout)


def _run_scene(scene: str) -> tuple[float, float]:
    """The scene from its `home` keyframe for 1 s: the root's largest deviation per axis [m]
    from its start, and the shoulder's largest swing [rad]."""
    model = mujoco.MjModel.from_xml_path(scene)
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("home").id)
    mujoco.mj_forward(model, data)
    root = model.body("base_link").id
    shoulder = model.jnt_qposadr[model.joint("shoulder").id]
    start, q0 = data.xpos[root].copy(), float(data.qpos[shoulder])
    drift = swing = 0.0
    for _ in range(STEPS):
        mujoco.mj_step(model, data)
        drift = max(drift, float(np.max(np.abs(data.xpos[root] - start))))
        swing = max(swing, abs(float(data.qpos[shoulder]) - q0))
    return drift, swing


@pytest.mark.parametrize("link_mass", [0.2, 1.0, 5.0])
def test_fixed_base_scene_holds_the_root_while_the_arm_swings(
    tmp_path: Path, link_mass: float
) -> None:
    urdf = write_urdf(tmp_path, floating_arm(link_mass))
    report = _convert(urdf, tmp_path / "fixed", "--fixed-base")
    details = [e["detail"] for e in report["entries"]]
    assert WELDED in details, f"report entries: {details}"
    model = mujoco.MjModel.from_xml_path(report["model"])
    free = [model.joint(j).name for j in range(model.njnt) if model.jnt_type[j] == 0]
    assert free == [], f"free joints in the fixed-base model: {free}"
    assert model.body_parentid[model.body("base_link").id] == 0, "root is a child of the world"
    drift, swing = _run_scene(report["scene"])
    assert drift <= ROOT_TOL, f"welded root moved {drift:.3g} m in 1 s ({link_mass} kg link)"
    assert swing > MOVED, f"shoulder swung {swing:.3g} rad in 1 s ({link_mass} kg link)"


def test_without_fixed_base_the_same_arm_rocks_on_its_base(tmp_path: Path) -> None:
    """The control: the scene test above tells a floating root from a welded one."""
    report = _convert(write_urdf(tmp_path, floating_arm()), tmp_path / "loose")
    assert WELDED not in [e["detail"] for e in report["entries"]]
    drift, _ = _run_scene(report["scene"])
    assert drift > SHAKEN, f"the floating arm's root moved only {drift:.3g} m in 1 s"


SDF_STATIC = """<sdf version="1.9"><model name="post"><static>true</static>
  <link name="base"><collision name="c"><geometry><box><size>0.1 0.1 1</size></box></geometry>
  </collision></link></model></sdf>"""


@pytest.mark.parametrize(
    ("name", "text"),
    [("arm.urdf", floating_arm(world_link=True)), ("post.sdf", SDF_STATIC)],
    ids=["world link", "static sdf"],
)
def test_an_already_fixed_robot_is_unchanged_and_the_report_says_so(
    tmp_path: Path, name: str, text: str
) -> None:
    path = tmp_path / name
    path.write_text(text)
    plain = convert_full(path, options=ConvertOptions())
    fixed = convert_full(path, options=ConvertOptions(fixed_base=True))
    assert fixed.spec.to_xml() == plain.spec.to_xml(), "--fixed-base changed a fixed robot"
    said = [(e.subject, e.detail) for e in fixed.report.entries if "--fixed-base" in e.subject]
    assert said and "already fixed" in said[0][1], f"report: {said}"


SDF_TWO_ROOTS = """<sdf version="1.9"><model name="pair">
  <link name="a"><inertial><mass>1</mass></inertial></link>
  <link name="b"><pose>1 0 0 0 0 0</pose><inertial><mass>1</mass></inertial></link>
</model></sdf>"""


def test_every_floating_root_of_an_sdf_model_is_welded(tmp_path: Path) -> None:
    path = tmp_path / "pair.sdf"
    path.write_text(SDF_TWO_ROOTS)
    done = convert_full(path, options=ConvertOptions(fixed_base=True))
    model = done.spec.compile()
    assert model.njnt == 0, f"{model.njnt} joints left in a welded two-link model"
    said = sorted(e.detail for e in done.report.entries if e.detail.endswith("(--fixed-base)"))
    expected = [f"root '{n}' welded to the world (--fixed-base)" for n in ("a", "b")]
    assert said == expected, f"report: {said}"
    floating = convert_full(path).spec.compile()
    assert floating.njnt == 2, "without --fixed-base each root link floats on its own"
