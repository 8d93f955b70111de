"""The world's elliptic friction cone against MuJoCo's pyramidal one: the step cost it adds.

twin's worlds use the elliptic cone (`converters/mjcf/world_options.py`, `CONE`), which keeps a
contact's stiffness along its normal the one its kp asks for at every μ. Every corpus robot (and
the bundled humanoid, the only robot without ../shared) is spawned on the ground in a `World`,
settled SETTLE_S, then stepped through SEGMENTS × SEGMENT_S of random ctrl within CTRL_SCALE of
each actuator's range around its initial ctrl (`default_rng(0)`; ±UNLIMITED_CTRL without a
range), and the state after each segment is kept. The world's model and a copy of it with the
pyramidal cone then step WINDOW_STEPS-step windows from those states in turn, alternated
(`step_compare.step_ratio`, thread CPU time), island sleeping off in both. Per robot: the
ratio (elliptic over pyramidal) and the mean solver iterations of each; the mean over robots
against MEAN_RATIO_GOAL.
"""

from __future__ import annotations

import copy

from benchmarks.bench_rest import corpus_request, corpus_robots
from benchmarks.step_compare import constraint_counts, step_ratio

SETTLE_S, SEGMENTS, SEGMENT_S = 1.0, 8, 0.25  # [s], count, [s]
CTRL_SCALE, UNLIMITED_CTRL = 0.1, 10.0  # share of each ctrlrange; half-range without one
MEAN_RATIO_GOAL = 1.5  # elliptic over pyramidal, mean over the robots


def _requests() -> dict:
    """Robot id → SpawnRequest: the corpus robots, then the bundled humanoid."""
    from scenarios import HUMANOID
    from twin_cli.spawn_request import SpawnRequest

    requests = {rid: corpus_request(robot) for rid, robot in corpus_robots().items()}
    requests["humanoid"] = SpawnRequest(str(HUMANOID), on_ground=True)
    return requests


def _states(model, data) -> list:  # noqa: ANN001
    """mjSTATE_INTEGRATION vectors along random ctrl segments from `data`."""
    import mujoco
    import numpy as np

    spec = mujoco.mjtState.mjSTATE_INTEGRATION
    low, high = model.actuator_ctrlrange.T.copy()
    unlimited = ~model.actuator_ctrllimited.astype(bool)
    low[unlimited], high[unlimited] = -UNLIMITED_CTRL, UNLIMITED_CTRL
    centre, half = data.ctrl.copy(), (high - low) / 2 * CTRL_SCALE
    rng, states = np.random.default_rng(0), []
    for _ in range(SEGMENTS):
        data.ctrl[:] = np.clip(rng.uniform(centre - half, centre + half), low, high)
        mujoco.mj_step(model, data, nstep=round(SEGMENT_S / model.opt.timestep))
        state = np.empty(mujoco.mj_stateSize(model, spec))
        mujoco.mj_getState(model, data, state, spec)
        states.append(state)
    return states


def _robot(request) -> dict:  # noqa: ANN001
    import mujoco

    from twin_cli.world import World

    world = World()
    world.spawn(request, name="r")
    world.step(round(SETTLE_S / world.model.opt.timestep))
    sleep = int(mujoco.mjtEnableBit.mjENBL_SLEEP)
    elliptic = copy.deepcopy(world.model)
    elliptic.opt.enableflags = int(elliptic.opt.enableflags) & ~sleep
    pyramidal = copy.deepcopy(elliptic)
    pyramidal.opt.cone = mujoco.mjtCone.mjCONE_PYRAMIDAL
    states = _states(elliptic, copy.copy(world.data))
    arms = [(m, mujoco.MjData(m)) for m in (elliptic, pyramidal)]
    row = step_ratio(arms[0], arms[1], states, states)
    row["elliptic_us"], row["pyramidal_us"] = row.pop("twin_us"), row.pop("menagerie_us")
    for name, (model, data) in zip(("elliptic", "pyramidal"), arms, strict=True):
        row[f"{name}_iterations"] = constraint_counts(model, data, states)["solver_iter"]
    return row


def run() -> dict:
    rows = {rid: _robot(request) for rid, request in _requests().items()}
    ratios = [r["ratio"] for r in rows.values()]
    mean = round(sum(ratios) / len(ratios), 3)
    return {
        "robots": rows,
        "mean_ratio": mean,
        "goal": MEAN_RATIO_GOAL,
        "met": mean <= MEAN_RATIO_GOAL,
    }
