"""Spawn/delete cycles keep memory bounded; a renewed world spec changes nothing in the physics.

Oracles: the process's resident memory (/proc/self/statm), and an identical world that never
renews its spec (bit-for-bit state after hundreds of steps, byte-identical MJB model).
"""

from __future__ import annotations

import os

from models import block, mjcf_arm, mjcf_ball, write_urdf
from world_helpers import full_state, spec_of

from twin_cli.spawn_request import SpawnRequest
from twin_cli.world import Pose, World
from twin_cli.world.respec import RENEW_EVERY, model_bytes

CYCLES = 300
# Measured on MuJoCo 4.0.0 with this box: without renewal the world keeps 0.07 MiB a cycle
# even after malloc_trim (21 MiB over 300 cycles), and this test saw resident memory grow
# 41 MiB with renewal switched off; with renewal every 20 deletes it stays within 1 MiB. The
# bound is a quarter of the trimmed leak, and 5x the spread measured with renewal.
GROWTH_BOUND_MIB = 5.0


def _rss_mib() -> float:
    with open("/proc/self/statm") as handle:
        return int(handle.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2**20


def test_spawn_delete_cycles_keep_resident_memory_bounded(tmp_path):
    box = str(write_urdf(tmp_path, block(name="box")))
    world = World()
    world.spawn(box, name="keep", pose=Pose(z=1.0))

    def cycles(first: int, count: int) -> None:
        for k in range(first, first + count):
            world.spawn(box, name=f"b{k}", pose=Pose(x=1.0, z=1.0))
            world.step(2)
            world.delete(f"b{k}")

    cycles(0, 2 * RENEW_EVERY)  # allocator warm-up, and past one renewal
    start = _rss_mib()
    cycles(2 * RENEW_EVERY, CYCLES)
    growth = _rss_mib() - start
    assert growth < GROWTH_BOUND_MIB, f"{growth:.1f} MiB over {CYCLES} spawn/delete cycles"
    assert world.spec_renewals >= CYCLES // RENEW_EVERY, "every renewal was accepted"
    assert world.spec_renewals_refused == 0


def _populated(tmp_path) -> World:
    """A world with a pushed ball, a commanded arm, a URDF box, changed gravity, a moved arm."""
    world = World()
    world.spawn(spec_of(mjcf_ball()), pose=Pose(z=2.0))
    world.spawn(spec_of(mjcf_arm(-2.0, 2.0, 5.0)), name="arm", pose=Pose(x=1.0))
    world.spawn(
        SpawnRequest(str(write_urdf(tmp_path, block(name="box"))), on_ground=True),
        name="box",
        pose=Pose(x=-1.0, z=0.5, yaw=0.3),
    )
    world.spawn(str(write_urdf(tmp_path, block(name="gone"), "gone.urdf")), name="gone")
    world.set_gravity((0.5, 0.0, -9.0))
    world.set_pose("arm", Pose(x=1.2, z=0.1, yaw=0.4))  # a fixed base: its attach frame moves
    world.push("ball", force=(3.0, 0.0, 0.0), duration=0.3)
    world.command("arm", "shoulder", mode="effort", value=2.0)
    world.step(50)
    world.delete("gone")
    world.step(50)
    return world


def test_a_renewed_spec_steps_and_recompiles_exactly_like_the_old_one(tmp_path):
    world, reference = _populated(tmp_path), _populated(tmp_path)
    assert world.renew_spec(), "the rebuilt spec compiles to the running model"
    world.step(300), reference.step(300)
    assert full_state(world).tobytes() == full_state(reference).tobytes()
    # The renewed spec carries on: a spawn and a delete recompile it, state moves by name.
    for w in (world, reference):
        w.spawn(spec_of(mjcf_ball()), name="late", pose=Pose(y=1.0, z=1.0))
        w.step(20)
        w.delete("box")
        w.step(200)
    assert model_bytes(world.model) == model_bytes(reference.model)
    assert full_state(world).tobytes() == full_state(reference).tobytes()
    assert world._state.spec.to_xml() == reference._state.spec.to_xml()
