"""`twin spawn --fixed-base` into a served world: the root stays welded at the spawn pose while
the arm's joint moves, a floating spawn of the same file falls, and `twin save` / `twin load`
keep the weld."""

from __future__ import annotations

import json

import pytest
from arm_models import floating_arm
from cli_world import twin_ok

from twin_cli.server.client import Client

WORLD_NAME = "fixed_base_cli"
STEPS, SAMPLES = 1000, 10  # 1 s at the 1 ms step, watched 10 times
ROOT_TOL = 1e-12  # [m] a welded root does not move
MOVED = 0.05  # [rad] the least swing of the loaded joint that counts as moving; 0.58 measured
FELL = 0.05  # [m] the least drop of the floating root that counts as falling; 0.15 measured


@pytest.fixture(scope="module")
def served(tmp_path_factory, serve_world):
    """A paused served world, and an arm description beside it."""
    root = tmp_path_factory.mktemp("fixed_base_cli")
    (root / "arm.urdf").write_text(floating_arm())
    with serve_world(root, WORLD_NAME, "--paused") as (client, _):
        yield root, client


def _watch(client: Client, names: tuple[str, ...]) -> dict[str, dict[str, list]]:
    """Each entity's root position [m] and joint positions [rad], before and after each of
    `SAMPLES` runs of `STEPS // SAMPLES` steps."""
    seen: dict[str, dict[str, list]] = {n: {"root": [], "joints": []} for n in names}
    for sample in range(SAMPLES + 1):
        if sample:
            client.step(STEPS // SAMPLES)
        for name in names:
            pose = client.pose(name)
            seen[name]["root"].append((pose["x"], pose["y"], pose["z"]))
            seen[name]["joints"].append([j["position"] for j in client.joints(name)])
    return seen


def _root_drift(root: list[tuple[float, float, float]], at: tuple[float, float, float]) -> float:
    """The largest distance [m] per axis of any sampled root position from `at`."""
    return max(abs(p[i] - at[i]) for p in root for i in range(3))


def _swing(joints: list[list[float]]) -> float:
    """The largest change [rad] of any joint from its first sample."""
    return max(abs(q[i] - joints[0][i]) for q in joints for i in range(len(q)))


def test_fixed_spawn_stays_at_its_pose_while_a_floating_one_falls(served) -> None:
    root, client = served
    arm = str(root / "arm.urdf")
    at = (0.5, 0.0, 0.2)
    spawned = twin_ok(root, WORLD_NAME, "spawn", arm, "--fixed-base", "-x", "0.5", "-z", "0.2")
    assert spawned.strip() == "arm", f"spawn printed {spawned!r}"
    listed = [j["name"] for j in client.joints("arm")]
    assert listed == ["shoulder"], f"joints of the welded arm: {listed}"
    twin_ok(root, WORLD_NAME, "spawn", arm, "--name", "loose", "-x", "-0.5", "-z", "0.2")
    seen = _watch(client, ("arm", "loose"))
    drift = _root_drift(seen["arm"]["root"], at)
    assert drift <= ROOT_TOL, f"welded root moved {drift:.3g} m from the spawn pose in 1 s"
    swing = _swing(seen["arm"]["joints"])
    assert swing > MOVED, f"the welded arm's shoulder swung only {swing:.3g} rad under gravity"
    fell = at[2] - seen["loose"]["root"][-1][2]
    assert fell > FELL, f"the floating spawn of the same file dropped only {fell:.3g} m in 1 s"
    client.delete("loose")


def test_save_and_load_keep_the_base_fixed(served) -> None:
    root, client = served
    names = [e["name"] for e in client.entities()]
    if "arm" not in names:
        twin_ok(root, WORLD_NAME, "spawn", str(root / "arm.urdf"), "--fixed-base", "-x", "0.5")
    at = tuple(client.pose("arm")[k] for k in ("x", "y", "z"))
    before = [j["position"] for j in client.joints("arm")]
    saved = root / "world.json"
    twin_ok(root, WORLD_NAME, "save", str(saved))
    entity = next(e for e in json.loads(saved.read_text())["entities"] if e["name"] == "arm")
    assert entity["fixed_base"] is True, f"the save file's entity: {sorted(entity)}"
    twin_ok(root, WORLD_NAME, "delete", "arm")
    twin_ok(root, WORLD_NAME, "load", str(saved))
    after = [j["position"] for j in client.joints("arm")]
    assert after == before, f"joint positions [rad] saved {before}, loaded {after}"
    twin_ok(root, WORLD_NAME, "reset")  # back to the spawn state: the arm swings again
    seen = _watch(client, ("arm",))
    drift = _root_drift(seen["arm"]["root"], at)
    assert drift <= ROOT_TOL, f"the loaded arm's root moved {drift:.3g} m in 1 s"
    assert _swing(seen["arm"]["joints"]) > MOVED, "the loaded arm's shoulder did not move"
