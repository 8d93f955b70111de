"""`SpawnRequest(fixed_base=True)` in the in-process World: a URDF arm and an MJCF body are
welded at the spawn pose, the MJCF's `home` key keeps its joint values, and a save file keeps
the weld."""

from __future__ import annotations

from pathlib import Path

import pytest
from arm_models import floating_arm
from models import mjcf_with_home, write_urdf

from twin_cli.spawn_request import SpawnRequest
from twin_cli.world import Pose, World, savefile

STEPS = 1000  # 1 s at the world's 1 ms step
ROOT_TOL = 1e-12  # [m] a welded root does not move
MOVED = 0.05  # [rad] the least swing of the arm's shoulder under gravity that counts as moving


def _root_drift(world: World, name: str, at: tuple[float, float, float]) -> float:
    """The largest distance [m] per axis of the entity's root from `at` over 1 s, sampled
    every 10 ms."""
    drift = 0.0
    for _ in range(STEPS // 10):
        world.step(10)
        pose = world.get_pose(name)
        drift = max(drift, *(abs(v - a) for v, a in zip((pose.x, pose.y, pose.z), at, strict=True)))
    return drift


@pytest.mark.parametrize("at", [(0.5, 0.0, 0.2), (-1.0, 2.0, 1.5)])
def test_a_fixed_base_urdf_arm_stays_at_its_spawn_pose(tmp_path: Path, at: tuple) -> None:
    urdf = write_urdf(tmp_path, floating_arm())
    world = World()
    world.spawn(SpawnRequest(urdf, fixed_base=True), name="arm", pose=Pose(*at))
    world.spawn(SpawnRequest(urdf), name="loose", pose=Pose(at[0] + 1, at[1], at[2]))
    drift = _root_drift(world, "arm", at)
    assert drift <= ROOT_TOL, f"welded root moved {drift:.3g} m in 1 s from {at}"
    swing = abs(world.joint_states("arm")[0].position)
    assert swing > MOVED, f"the shoulder swung only {swing:.3g} rad from 0 in 1 s"
    assert world.get_pose("loose").z < at[2] - 0.05, "the floating spawn of the file fell"


def test_an_mjcf_free_body_is_welded_and_keeps_its_home_joint(tmp_path: Path) -> None:
    path = tmp_path / "homed.xml"
    path.write_text(mjcf_with_home(hinge=0.7, z=0.5))
    world = World()
    result = world.spawn(SpawnRequest(str(path), fixed_base=True), pose=Pose(x=1.0, z=0.3))
    assert "root 'base' welded to the world (--fixed-base)" in result.warnings, result.warnings
    index = world.index_of("homed")
    assert index.free_qpos == -1, "no free joint left"
    assert world.joint_states("homed")[0].position == pytest.approx(0.7, abs=1e-12), "home"
    drift = _root_drift(world, "homed", (1.0, 0.0, 0.3))
    assert drift <= ROOT_TOL, f"welded MJCF root moved {drift:.3g} m in 1 s"


def test_an_mjcf_without_a_free_joint_is_unchanged_and_says_so(tmp_path: Path) -> None:
    path = tmp_path / "homed.xml"
    path.write_text(mjcf_with_home().replace('<freejoint name="root"/>', ""))
    path.write_text(path.read_text().replace('qpos="0 0 0.5 1 0 0 0 0.7"', 'qpos="0.7"'))
    world = World()
    result = world.spawn(SpawnRequest(str(path), fixed_base=True))
    assert any("already fixed" in w for w in result.warnings), result.warnings
    assert world.joint_states("homed")[0].position == pytest.approx(0.7, abs=1e-12), "home"


def test_save_and_load_keep_an_in_process_fixed_base(tmp_path: Path) -> None:
    urdf = write_urdf(tmp_path, floating_arm())
    world = World()
    world.spawn(SpawnRequest(urdf, fixed_base=True), name="arm", pose=Pose(0.5, 0.0, 0.2))
    world.step(500)
    saved = tmp_path / "world.json"
    savefile.save(world, saved)
    loaded = savefile.load(saved)
    assert loaded.entity("arm").request.fixed_base, "the loaded entity's request"
    positions = [[j.position for j in w.joint_states("arm")] for w in (world, loaded)]
    assert positions[0] == positions[1], f"joint positions [rad] saved, loaded: {positions}"
    loaded.reset()  # back to the spawn state: the arm swings from 0 again
    drift = _root_drift(loaded, "arm", (0.5, 0.0, 0.2))
    assert drift <= ROOT_TOL, f"loaded welded root moved {drift:.3g} m in 1 s"
    swing = abs(loaded.joint_states("arm")[0].position)
    assert swing > MOVED, f"the loaded arm's shoulder swung only {swing:.3g} rad in 1 s"
