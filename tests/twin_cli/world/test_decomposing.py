"""The swap of a decomposition into a world keeps every entity's state exactly.

A World whose conversions are bounded as in a server (`bounded.enable`), not stepping, so that
nothing but the swap can change its state between two reads. Real CoACD on the concave bin
(`bin_models`); oracles: the state before the swap (bit for bit), the bin's geoms (its hull,
then CoACD's parts), and the report rows.
"""

from __future__ import annotations

import time

import numpy as np
import pytest
from bin_models import bin_urdf

from converters.isolated import bounded
from twin_cli.spawn_request import SpawnRequest
from twin_cli.world import World
from twin_cli.world.pose import Pose

WAIT_S = 180.0  # [s] for the bin's decomposition on a loaded 2-core machine (3 CPU s idle)
BOX = """<robot name="box"><link name="box">
  <inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/>
  </inertial><collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>
</link></robot>"""


@pytest.fixture
def served(tmp_path, monkeypatch):
    """Conversions bounded in children, as in a world server, with an empty collision cache."""
    monkeypatch.setenv("TWIN_CACHE_DIR", str(tmp_path / "cache"))
    bounded.enable()
    yield
    bounded.disable()


def _bin_geoms(world: World) -> int:
    """The bin's collision geoms (its visual geom collides with nothing)."""
    with world.lock:
        model, geoms = world.model, world.index_of("bin").geoms
        return int(np.count_nonzero(model.geom_contype[geoms] | model.geom_conaffinity[geoms]))


def test_the_swap_keeps_every_state_and_replaces_the_hull_by_the_parts(served, tmp_path):
    (tmp_path / "box.urdf").write_text(BOX)
    world = World()
    world.spawn(SpawnRequest(str(tmp_path / "box.urdf")), name="box", pose=Pose(x=1, z=0.5))
    world.spawn(SpawnRequest(bin_urdf(tmp_path)), name="bin")
    world.step(300)  # the box falls: a state with speeds, contacts not yet
    hull_geoms = _bin_geoms(world)
    with world.lock:
        before = (world.data.qpos.copy(), world.data.qvel.copy(), world.data.time)
        rows = world.entity("bin").report["meshes"]
    assert [row["stopped"] for row in rows] == ["deferred"], rows
    deadline = time.monotonic() + WAIT_S
    while world.entities()[1].decomposition == "pending" and time.monotonic() < deadline:
        time.sleep(0.1)
    listed = world.entities()[1]
    assert listed.decomposition == "done" and listed.hull_stand_ins == (), listed
    with world.lock:
        after = (world.data.qpos.copy(), world.data.qvel.copy(), world.data.time)
        rows = world.entity("bin").report["meshes"]
    assert np.array_equal(before[0], after[0]) and np.array_equal(before[1], after[1])
    assert before[2] == after[2], f"sim time {before[2]} -> {after[2]}"
    assert [row["mode"] for row in rows] == ["coacd"] and rows[0]["parts"] >= 5, rows
    assert hull_geoms == 1 and _bin_geoms(world) == rows[0]["parts"], (
        f"bin geoms: {hull_geoms} as a hull, {_bin_geoms(world)} after, {rows[0]['parts']} parts"
    )
    assert [e.name for e in world.entities()] == ["box", "bin"], "spawn order kept"


def test_a_batch_shares_one_decomposition_that_outlives_a_deleted_instance(served, tmp_path):
    world = World()
    urdf = bin_urdf(tmp_path)
    world.spawn_batch(SpawnRequest(urdf), poses=[Pose(), Pose(x=1)], names=["a", "b"])
    listed = {e.name: e.decomposition for e in world.entities()}
    assert listed == {"a": "pending", "b": "pending"}, listed
    world.delete("a")  # "b" still waits: the decomposition goes on
    deadline = time.monotonic() + WAIT_S
    while world.entities()[0].decomposition == "pending" and time.monotonic() < deadline:
        time.sleep(0.1)
    (left,) = world.entities()
    assert left.name == "b" and left.decomposition == "done", left
    assert left.hull_stand_ins == (), left
