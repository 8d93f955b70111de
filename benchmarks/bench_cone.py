"""The world's elliptic friction cone against MuJoCo's pyramidal one: the step cost it adds.

twin's worlds use the elliptic cone (`converters/mjcf/world_options.py`, `CONE`), which keeps a
contact's stiffness along its normal the one its kp asks for at every μ. Every robot of
`bench_rest.spawn_requests` is spawned on the ground in a `World`; the states are those
`bench_menagerie.random_ctrl_states` takes (a settle, then random ctrl segments). The world's
model and a copy of it with the pyramidal cone then step windows from those states in turn,
alternated (`step_compare.step_ratio`, thread CPU time), island sleeping off in both. Per
robot: the ratio (elliptic over pyramidal) and the mean solver iterations of each; the mean over
robots against MEAN_RATIO_GOAL.
"""

from __future__ import annotations

import copy

from benchmarks.bench_menagerie import random_ctrl_states
from benchmarks.bench_rest import spawn_requests
from benchmarks.step_compare import constraint_counts, step_ratio

MEAN_RATIO_GOAL = 1.5  # elliptic over pyramidal, mean over the robots


def _robot(request) -> dict:  # noqa: ANN001
    import mujoco

    from twin_cli.world import World

    world = World()
    world.spawn(request, name="r")
    sleep = int(mujoco.mjtEnableBit.mjENBL_SLEEP)
    elliptic = copy.deepcopy(world.model)
    elliptic.opt.enableflags = int(elliptic.opt.enableflags) & ~sleep
    pyramidal = copy.deepcopy(elliptic)
    pyramidal.opt.cone = mujoco.mjtCone.mjCONE_PYRAMIDAL
    _, states = random_ctrl_states(elliptic, world.data)
    arms = [(m, mujoco.MjData(m)) for m in (elliptic, pyramidal)]
    row = step_ratio(arms[0], arms[1], states, states)
    row["elliptic_us"], row["pyramidal_us"] = row.pop("twin_us"), row.pop("menagerie_us")
    for name, (model, data) in zip(("elliptic", "pyramidal"), arms, strict=True):
        row[f"{name}_iterations"] = constraint_counts(model, data, states)["solver_iter"]
    return row


def run() -> dict:
    rows = {rid: _robot(request) for rid, request in spawn_requests().items()}
    ratios = [r["ratio"] for r in rows.values()]
    mean = round(sum(ratios) / len(ratios), 3)
    return {
        "robots": rows,
        "mean_ratio": mean,
        "goal": MEAN_RATIO_GOAL,
        "met": mean <= MEAN_RATIO_GOAL,
    }
