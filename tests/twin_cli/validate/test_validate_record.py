"""`twin validate --record DIR` end to end: one bag per physics scenario, read back by rosbags."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
from record_helpers import read_bag, seconds

import scenarios

HUMANOID = Path(scenarios.HUMANOID)
STEP = 0.001  # [s] the scenario world's timestep (twin's default)
RATE = 100.0  # [Hz] twin_cli.validate.recording.RATE
G = 9.81  # [m/s²] the scenario's "earth"
Z0 = 2.0  # [m] free_fall.toml's drop height


def test_validate_record_keeps_a_bag_per_scenario_that_replays_the_fall(tmp_path):
    folder = tmp_path / "bags"
    done = subprocess.run(
        [sys.executable, "-m", "twin_cli.cli.app", "validate", str(HUMANOID)]
        + ["--only", "gravity", "--only", "collision", "--record", str(folder)],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    bags = sorted(p.name for p in folder.iterdir())
    assert bags == ["collision.mcap", "free_fall.mcap"], "one per scenario of the two checks"
    assert f"recording: {folder / 'free_fall.mcap'}" in done.stdout
    for name in bags:
        bag = read_bag(folder / name)  # every message deserializes (rosbags' AnyReader)
        clock = np.array([seconds(m.clock) for _, m in bag["/clock"]])
        assert len(clock) > 10 and np.allclose(np.diff(clock), 1 / RATE, atol=1e-9), name
    fall = read_bag(folder / "free_fall.mcap")
    ((entity,),) = [{t.split("/")[1] for t in fall if t.endswith("/odom")}]
    for _, odom in fall[f"/{entity}/odom"]:
        # Nothing but gravity acts, uniformly: no joint moves, and the root falls as MuJoCo's
        # semi-implicit Euler integrates it, z_n = z0 - g h² n(n+1)/2 after n steps of h.
        n = round(seconds(odom.header.stamp) / STEP)
        expected = Z0 - G * STEP**2 * n * (n + 1) / 2
        assert abs(odom.pose.pose.position.z - expected) < 1e-6, f"root height after {n} steps"
    _, last = fall[f"/{entity}/odom"][-1]
    assert seconds(last.header.stamp) >= 0.5 - 1e-9, "the whole 0.5 s scenario"
