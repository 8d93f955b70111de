"""A world file saved before tagged position joints ran their own servos still loads: written by
twin at commit 7c98c0c (a Panda-like arm, joint 2 commanded to 0.3 rad, its other joints limp
motors with a servo reference each, `na` 7). Oracle: the file's own state and command."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from twin_cli.world.savefile import load

SAVE = Path(__file__).parent / "saves" / "arm_saved_before_own_servos.json"
HELD_RAD = 0.03  # [rad] the uncommanded joints' drift in 1 s, held by their servos (limp: 1.5)


def test_it_loads_commands_joint_2_and_holds_the_others_where_they_were_saved() -> None:
    doc = json.loads(SAVE.read_text())
    saved = doc["state"][1 : 1 + doc["layout"]["nq"]]  # time, then qpos
    world = load(SAVE)
    commands = world.commands()
    assert commands["a/panda_joint2"].target == pytest.approx(0.3), commands
    assert all(c.native for c in commands.values()), "run by the joints' own servos"
    world.step(2000)
    now = [s.position for s in world.joint_states("a")]
    assert now[1] == pytest.approx(0.3, abs=1e-3), f"joint 2 at {now[1]:.4f} rad"
    others = [abs(q - q0) for k, (q, q0) in enumerate(zip(now, saved, strict=True)) if k != 1]
    assert max(others) < HELD_RAD, f"the held joints moved {max(others):.4f} rad"
