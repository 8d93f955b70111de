"""A drive wheel's collision cylinder touches the ground on its mid-plane, once.

Oracle: the wheel's own geometry. Measured on the world after it settles: each wheel of a drive
has one ground contact, in its mid-plane (within 0.1 mm) and at its radius below the axle; a
cylinder that is not a rolling wheel of a drive keeps touching at its rims.
"""

from __future__ import annotations

from pathlib import Path

import drive_models as dm
import mujoco
import numpy as np

from converters.pipeline import convert_full
from converters.report import Outcome
from twin_cli.spawn_request import SpawnRequest
from twin_cli.world import World

DIFF = (
    '<plugin name="dd" filename="libgazebo_ros_diff_drive.so"><left_joint>wheel_left_joint'
    "</left_joint><right_joint>wheel_right_joint</right_joint><wheel_separation>0.3"
    "</wheel_separation><wheel_diameter>0.1</wheel_diameter></plugin>"
)
WIDTH = 0.03  # [m]
MID_PLANE = 1e-4  # [m] contact off the wheel's mid-plane


def _ground_contacts(world: World, body: str) -> list[np.ndarray]:
    """Contact points [m] of `body` with the ground, in the body's frame."""
    m, d = world.model, world.data
    b = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, f"base/{body}")
    points = []
    for c in d.contact[: d.ncon]:
        if b in (m.geom_bodyid[c.geom1], m.geom_bodyid[c.geom2]) and 0 in (
            m.geom_bodyid[c.geom1],
            m.geom_bodyid[c.geom2],
        ):
            points.append(d.xmat[b].reshape(3, 3).T @ (c.pos - d.xpos[b]))
    return points


def _settled(tmp_path: Path, plugin: str) -> World:
    path = tmp_path / "base.urdf"
    path.write_text(dm.two_wheel_base(plugin, width=WIDTH))
    world = World()
    world.spawn(SpawnRequest(str(path), on_ground=True), name="base")
    world.step(300)
    return world


def test_a_drive_wheel_touches_the_ground_once_on_its_mid_plane(tmp_path: Path) -> None:
    world = _settled(tmp_path, DIFF)
    for wheel in ("wheel_left", "wheel_right"):
        points = _ground_contacts(world, wheel)
        assert len(points) == 1, f"{wheel}: {len(points)} ground contacts, expected 1"
        # the wheel's collision is turned 90° about x: its axis (local y) is the body's y
        assert abs(points[0][1]) <= MID_PLANE, f"{wheel}: contact {points[0][1]:.5f} m off"
        assert abs(points[0][2] + dm.R) <= 1e-3, f"{wheel}: contact {points[0][2]:.4f} m below"


def test_a_cylinder_no_drive_rolls_keeps_touching_at_its_rims(tmp_path: Path) -> None:
    world = _settled(tmp_path, "")
    offsets = [abs(float(p[1])) for p in _ground_contacts(world, "wheel_left")]
    assert offsets, "the passive wheel rests on the ground"
    assert all(abs(o - WIDTH / 2) <= MID_PLANE for o in offsets), f"contacts at ±{offsets} m"


def test_the_conversion_reports_each_wheel_and_keeps_its_mass(tmp_path: Path) -> None:
    path = tmp_path / "base.urdf"
    path.write_text(dm.two_wheel_base(DIFF, width=WIDTH))
    done = convert_full(path)
    notes = [
        e
        for e in done.report.of(Outcome.APPROXIMATED)
        if "mid-plane" in e.detail and e.tag == "collision"
    ]
    assert sorted(e.subject for e in notes) == [
        "joint 'wheel_left_joint'",
        "joint 'wheel_right_joint'",
    ]
    assert all("width 0.03 m" in e.detail and "'dd'" in e.detail for e in notes)
    model = done.spec.compile()
    wheel = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "wheel_left")
    assert abs(model.body_mass[wheel] - 0.3) < 1e-12, "the link's own inertial decides the mass"
