"""Two models' step cost compared within one run: paired windows, constraint counts, stage timers.

Each arm is (model, data, states): `states` are mjSTATE_INTEGRATION vectors (qpos, qvel, act,
ctrl, ...) from which its windows start in turn, so both arms step comparable work however their
trajectories differ.
"""

from __future__ import annotations

import time

from benchmarks.paired import interleaved_ratio

# 100-step windows (0.5-5 ms) alternated 150 times: on 2 shared cores two whole runs gave the
# same ratios within 0.04 (ur5e 1.143 and 1.139, anymal_c 1.272 and 1.231).
WINDOW_STEPS, PAIRS = 100, 150
TIMER_ROUNDS, TIMER_STEPS = 15, 20  # per state in each round
STAGES = ("STEP", "POS_KINEMATICS", "POS_INERTIA", "POS_COLLISION", "POS_MAKE", "POS_PROJECT",
          "VELOCITY", "ACTUATION", "CONSTRAINT", "ADVANCE")  # fmt: skip


def _window(model, data, states: list, spent: list):  # noqa: ANN001, ANN202
    """A callable stepping WINDOW_STEPS from the next state in turn; adds its CPU time to spent."""
    import mujoco

    spec, turn = mujoco.mjtState.mjSTATE_INTEGRATION, [0]

    def run() -> None:
        mujoco.mj_setState(model, data, states[turn[0] % len(states)], spec)
        turn[0] += 1
        start = time.thread_time()
        mujoco.mj_step(model, data, nstep=WINDOW_STEPS)
        spent[0] += time.thread_time() - start

    return run


def step_ratio(twin: tuple, menagerie: tuple, twin_states: list, menagerie_states: list) -> dict:
    """The first arm's (twin's) per-step CPU time over the second's (the reference model's), in
    PAIRS alternations of WINDOW_STEPS-step windows, with both per-step times [µs]."""
    t_spent, m_spent = [0.0], [0.0]
    ratio = interleaved_ratio(
        _window(*twin, twin_states, t_spent),
        _window(*menagerie, menagerie_states, m_spent),
        pairs=PAIRS,
        clock=time.thread_time,
    )
    steps = PAIRS * WINDOW_STEPS
    return {
        "ratio": round(ratio, 3),
        "twin_us": round(t_spent[0] / steps * 1e6, 2),
        "menagerie_us": round(m_spent[0] / steps * 1e6, 2),
    }


def constraint_counts(model, data, states: list) -> dict:  # noqa: ANN001
    """Mean contacts, constraint rows and solver iterations (all islands) over `states`."""
    import mujoco
    import numpy as np

    counts = []
    for state in states:
        mujoco.mj_setState(model, data, state, mujoco.mjtState.mjSTATE_INTEGRATION)
        mujoco.mj_step(model, data)
        islands = max(1, int(data.nisland))
        counts.append((data.ncon, data.nefc, int(np.sum(data.solver_niter[:islands]))))
    ncon, nefc, niter = np.mean(counts, axis=0)
    return {"ncon": round(ncon, 1), "nefc": round(nefc, 1), "solver_iter": round(niter, 1)}


def stage_timers(arms: list) -> list[dict]:
    """MuJoCo's stage timers [µs per step] of each (model, data, states) arm: TIMER_ROUNDS rounds
    alternating the arms, each stepping TIMER_STEPS from every state; per stage the fastest
    round, the one other processes disturbed least (under load 6 the median round put one
    model's constraint stage at 24 and at 44 µs in two runs). The timer callback adds its own
    small cost to every stage."""
    import mujoco
    import numpy as np

    ids = [int(getattr(mujoco.mjtTimer, f"mjTIMER_{name}")) for name in STAGES]
    rounds: list[list] = [[] for _ in arms]
    mujoco.set_mjcb_time(time.perf_counter)
    try:
        for _ in range(TIMER_ROUNDS):
            for arm, (model, data, states) in enumerate(arms):
                before = [data.timer[i].duration for i in ids]
                for state in states:
                    mujoco.mj_setState(model, data, state, mujoco.mjtState.mjSTATE_INTEGRATION)
                    mujoco.mj_step(model, data, nstep=TIMER_STEPS)
                spent = [data.timer[i].duration - b for i, b in zip(ids, before, strict=True)]
                rounds[arm].append(np.array(spent) / (TIMER_STEPS * len(states)) * 1e6)
    finally:
        mujoco.set_mjcb_time(None)
    best = [np.min(r, axis=0) for r in rounds]
    return [{n.lower(): round(float(v), 2) for n, v in zip(STAGES, m, strict=True)} for m in best]
