"""`twin spawn --at` as a user types it: the lesson's five humanoids in one command, a bad pose
that spawns none, a second spawn served from the conversion cache, threads and sleep in
`twin physics`. Oracles: the poses typed (read back with `twin list`), the entity list before a
refused command, and the server's own cache flag (the converter did not run)."""

from __future__ import annotations

import json

import pytest
from test_cli_world import Twin

import scenarios

LESSON = ["0,0,1.3", "1,1,1.3", "2,0,1.3", "1,2,1.3", "0,2,1.3"]  # X,Y,Z [m]
DRIFT = 0.01  # [m] horizontal drift of a falling humanoid in the time `twin list` takes


@pytest.fixture
def twin(tmp_path):
    t = Twin(tmp_path / "rt")
    yield t
    t("stop", check=False, timeout=60)


def _listed(twin: Twin) -> dict[str, list[float]]:
    return {e["name"]: e["position"] for e in json.loads(twin("list", "--json").stdout)}


def test_five_humanoids_in_one_command_then_refusals_and_the_cache(twin):
    at = [arg for pose in LESSON for arg in ("--at", pose)]
    out = twin("spawn", str(scenarios.HUMANOID), "--name", "r", *at, "--json")
    results = json.loads(out.stdout)
    assert [r["name"] for r in results] == [f"r_{i}" for i in range(5)]
    assert results[0]["cached"] is False  # a fresh server converted the file once
    listed = _listed(twin)
    assert sorted(listed) == [f"r_{i}" for i in range(5)]
    for i, pose in enumerate(LESSON):
        x, y, _ = (float(v) for v in pose.split(","))
        assert listed[f"r_{i}"][:2] == pytest.approx([x, y], abs=DRIFT), listed

    bad = twin("spawn", str(scenarios.HUMANOID), "--name", "q", "--at", "3,3", "--at", "4,abc",
               check=False)  # fmt: skip
    assert bad.returncode == 2 and "4,abc" in bad.stderr, bad.stderr
    taken = twin("spawn", str(scenarios.HUMANOID), "--names", "a,r_1", "--at", "5,5", "--at",
                 "6,6", check=False)  # fmt: skip
    assert taken.returncode == 2 and "r_1" in taken.stderr and "Traceback" not in taken.stderr
    assert sorted(_listed(twin)) == [f"r_{i}" for i in range(5)]  # neither spawned any

    again = json.loads(twin("spawn", str(scenarios.HUMANOID), "-x", "4", "--json").stdout)
    assert again["cached"] is True, again  # served without converting

    physics = json.loads(twin("physics", "--json").stdout)
    assert physics["threads"] >= 1 and physics["sleep"] is False, physics
    changed = json.loads(twin("physics", "--threads", "2", "--sleep", "--json").stdout)
    assert (changed["threads"], changed["pool_threads"], changed["sleep"]) == (2, 2, True)


def test_a_bad_name_in_names_is_refused_before_any_world_starts(twin):
    bad = twin("spawn", str(scenarios.HUMANOID), "--names", "a/b,c", "--at", "0,0", "--at", "1,1",
               check=False)  # fmt: skip
    assert bad.returncode == 2 and "a/b" in bad.stderr and "Traceback" not in bad.stderr
    listed = twin("list", check=False)  # gz's line: no world was started for the refusal
    assert listed.returncode == 2 and "not running" in listed.stderr, listed.stderr


def test_video_and_record_with_a_sweep_are_refused_not_ignored(tmp_path):
    twin = Twin(tmp_path / "rt")
    for flag in ("--video", "--record"):
        out = twin("validate", str(scenarios.HUMANOID), "--sweep", "foot_mu=0.5:1:2", flag,
                   str(tmp_path / "out"), check=False)  # fmt: skip
        assert out.returncode == 2 and "--sweep" in out.stderr, (flag, out.stderr)
        assert not (tmp_path / "out").exists(), f"{flag} wrote files it was not asked to"
