"""The world's integrator against MuJoCo's `implicitfast`: step cost, rest and the random-ctrl gate.

Every corpus robot (and the bundled humanoid, the only robot without ../shared) is spawned on
the ground in a `World`, as `twin spawn` spawns it. `mj_step` then runs the world's own model
(its integrator as configured) and copies of it under the other integrators of COMPARED
(`implicit`, `implicitfast`), each from a copy of the spawned state, island sleeping off in all
so every step does the full work:
- cost: from the state after COST_SETTLE_S, WINDOW_STEPS steps per window, the models
  alternating in REPEATS windows each; the best window of each gives its per-step time, and the
  ratio is the world's over implicitfast's (target: a mean of at most MEAN_RATIO_TARGET), with
  implicit's over implicitfast's beside it;
- rest: each integrator settles the robot for REST_SETTLE_S, then over REST_S: how far the root
  (free joint) moves [mm] and turns [mrad], the largest hinge or slide joint drift [mrad or mm],
  and the peak |qvel| (a light limb that its integrator keeps moving shows there);
- gate: random ctrl within 10 % of each actuator's ctrlrange around its centre (±UNLIMITED_CTRL
  without one), resampled every GATE_HOLD_S from `default_rng(0)`, for GATE_S from the spawn:
  whether the state turns non-finite or MuJoCo raises a warning (the sim time it does), and the
  peak |qvel|. The world's actuators integrate ctrl (an uncommanded motor's ctrl is its torque
  rate), so the gate drives each joint with a slowly wandering torque.
Rest and gate figures are sim-time physics, the same on any machine; the cost ratio is
measured within one run.
"""

from __future__ import annotations

import copy
import sys
import time

import numpy as np

from benchmarks.bench_rest import spawn_requests

# [s] sim time. A limp robot folds first: the bundled humanoid, symmetric, stands about 4 s on
# its feet and has fallen by 6 s.
COST_SETTLE_S, REST_SETTLE_S, REST_S = 1.0, 8.0, 5.0
# Many short windows, so that the best of each model is one no other process disturbed. On 2
# shared cores at load 2.5-4, four runs of each: the best of 4 windows of 2000 steps put
# turtlebot3's ratio anywhere in 1.08-1.39, the best of 20 of 200 steps in 0.92-1.61; the best
# of 40 of 200 repeats within 0.04 (turtlebot3 1.24-1.25, solo12 1.10-1.12, booster_t1 1.68-1.72).
# A busy spell can still move one robot (r2d2_physics 1.40 and 1.81 in two whole runs); the mean
# over the robots moved by 0.05 (1.34, 1.39).
WINDOW_STEPS, REPEATS = 200, 40
GATE_S, GATE_HOLD_S, GATE_SCALE = 10.0, 0.5, 0.1  # [s], [s], share of each ctrlrange
REST_SAMPLE_STEPS = 10  # |qvel| is sampled every 10 steps at rest
UNLIMITED_CTRL = 10.0  # half-range for an actuator without ctrlrange (10 % of it: ±1 rad/s)
COMPARED = ("implicit", "implicitfast")  # MuJoCo's integrators that treat damping implicitly
MEAN_RATIO_TARGET = 1.15  # the project's goal for the world's step cost over implicitfast's


def _models(request) -> tuple[str, dict, object]:  # noqa: ANN001
    """(the world's integrator, integrator → model, spawned data): the world's model as it is, and
    a copy of it under each other integrator of COMPARED; island sleeping off in all."""
    import mujoco

    from converters.mjcf.world_options import INTEGRATORS
    from twin_cli.world import World

    world = World()
    world.spawn(request, name="r")
    own = next(k for k, v in INTEGRATORS.items() if int(v) == int(world.model.opt.integrator))
    sleep = int(mujoco.mjtEnableBit.mjENBL_SLEEP)
    models = {}
    for name in dict.fromkeys((own, *COMPARED)):
        models[name] = model = copy.deepcopy(world.model)
        model.opt.enableflags = int(model.opt.enableflags) & ~sleep
        model.opt.integrator = INTEGRATORS[name]
    return own, models, copy.copy(world.data)


def _step_costs(models: tuple, data) -> list[float]:  # noqa: ANN001
    """Best per-step time [s] of each model over REPEATS alternating windows from `data`."""
    import mujoco

    best = [float("inf")] * len(models)
    for _ in range(REPEATS):
        for i, model in enumerate(models):
            work = copy.copy(data)
            start = time.perf_counter()
            mujoco.mj_step(model, work, nstep=WINDOW_STEPS)
            best[i] = min(best[i], (time.perf_counter() - start) / WINDOW_STEPS)
    return best


def _diverged(data) -> bool:  # noqa: ANN001
    finite = np.isfinite(data.qpos).all() and np.isfinite(data.qvel).all()
    return not finite or any(w.number for w in data.warning)


def _rest(model, data) -> dict:  # noqa: ANN001
    """Root motion, joint drift and peak |qvel| over REST_S after REST_SETTLE_S from `data`."""
    import mujoco

    work, h = copy.copy(data), model.opt.timestep
    roots = [model.jnt_qposadr[j] for j in range(model.njnt) if model.jnt_type[j] == 0]
    joints = [model.jnt_qposadr[j] for j in range(model.njnt) if model.jnt_type[j] in (2, 3)]
    mujoco.mj_step(model, work, nstep=round(REST_SETTLE_S / h))
    q0, peak = work.qpos.copy(), 0.0
    for _ in range(round(REST_S / h) // REST_SAMPLE_STEPS):
        mujoco.mj_step(model, work, nstep=REST_SAMPLE_STEPS)
        peak = max(peak, float(np.abs(work.qvel).max(initial=0.0)))
    row = {"peak_qvel": round(peak, 4), "diverged": _diverged(work)}
    if roots:
        a, turn = roots[0], np.zeros(3)
        mujoco.mju_subQuat(turn, work.qpos[a + 3 : a + 7], q0[a + 3 : a + 7])
        row["root_mm"] = round(float(np.linalg.norm(work.qpos[a : a + 3] - q0[a : a + 3])) * 1e3, 4)
        row["root_mrad"] = round(float(np.linalg.norm(turn)) * 1e3, 4)
    drift = np.abs(work.qpos[joints] - q0[joints]).max(initial=0.0)
    row["joint_drift_milli"] = round(float(drift) * 1e3, 3)
    return row


def _gate(model, data) -> dict:  # noqa: ANN001
    """Random ctrl within GATE_SCALE of each range for GATE_S: diverged at [s] and peak |qvel|."""
    import mujoco

    work = copy.copy(data)
    low, high = model.actuator_ctrlrange.T.copy()
    unlimited = ~model.actuator_ctrllimited.astype(bool)
    low[unlimited], high[unlimited] = -UNLIMITED_CTRL, UNLIMITED_CTRL
    centre, half = (low + high) / 2, (high - low) / 2 * GATE_SCALE
    rng, hold = np.random.default_rng(0), round(GATE_HOLD_S / model.opt.timestep)
    peak = 0.0
    for _ in range(round(GATE_S / GATE_HOLD_S)):
        work.ctrl[:] = rng.uniform(centre - half, centre + half)
        mujoco.mj_step(model, work, nstep=hold)
        if _diverged(work):
            return {"diverged_at_s": round(work.time, 2), "peak_qvel": round(peak, 1)}
        peak = max(peak, float(np.abs(work.qvel).max(initial=0.0)))
    return {"diverged_at_s": None, "peak_qvel": round(peak, 1)}


def _robot(request) -> dict:  # noqa: ANN001
    import mujoco

    own, models, data = _models(request)
    settled = copy.copy(data)
    mujoco.mj_step(models[own], settled, nstep=round(COST_SETTLE_S / models[own].opt.timestep))
    costs = dict(zip(models, _step_costs(tuple(models.values()), settled), strict=True))
    return {
        "integrator": own,
        "nv": int(models[own].nv),
        "step_us": {name: round(cost * 1e6, 2) for name, cost in costs.items()},
        "ratio": round(costs[own] / costs["implicitfast"], 3),
        "implicit_ratio": round(costs["implicit"] / costs["implicitfast"], 3),
        "rest": {name: _rest(model, data) for name, model in models.items()},
        "gate": {name: _gate(model, data) for name, model in models.items()},
    }


def _table(rows: dict) -> str:
    """Robot → ratio (the world's over implicitfast's step), with the two compared integrators'
    step times, rest drift and gate outcome (implicit / implicitfast)."""
    lines = [
        f"{'robot':19} {'ratio':>6} {'µs':>13} {'rest root mm':>19} {'rest joint milli':>19} "
        f"{'gate diverged s':>15}"
    ]
    for rid, row in rows.items():
        if "skipped" in row:
            lines.append(f"{rid:19} skipped: {row['skipped']}")
            continue
        rest, gate = [row["rest"][k] for k in COMPARED], [row["gate"][k] for k in COMPARED]
        cells = (
            "/".join(f"{row['step_us'][k]:.1f}" for k in COMPARED),
            "/".join(str(r.get("root_mm", "fixed")) for r in rest),
            "/".join(str(r["joint_drift_milli"]) for r in rest),
            "/".join(str(g["diverged_at_s"] or "no") for g in gate),
        )
        lines.append(
            f"{rid:19} {row['ratio']:6.3f} {cells[0]:>13} {cells[1]:>19} {cells[2]:>19} "
            f"{cells[3]:>15}"
        )
    return "\n".join(lines)


def run() -> dict:
    start = time.perf_counter()
    rows: dict[str, dict] = {}
    for rid, request in spawn_requests().items():
        try:
            rows[rid] = _robot(request)
        except Exception as exc:  # a robot that needs options the bench does not give
            rows[rid] = {"skipped": f"{type(exc).__name__}: {exc}"[:160]}
    done = [row for row in rows.values() if "ratio" in row]
    mean = round(float(np.mean([row["ratio"] for row in done])), 3) if done else None
    implicit = round(float(np.mean([row["implicit_ratio"] for row in done])), 3) if done else None
    print(
        _table(rows),
        f"\nmean ratio {mean} (target ≤ {MEAN_RATIO_TARGET}); implicit/implicitfast {implicit}",
        file=sys.stderr,
    )
    return {
        "robots": rows,
        "mean_ratio": mean,
        "mean_implicit_ratio": implicit,
        "mean_ratio_target": MEAN_RATIO_TARGET,
        "within_target": mean is not None and mean <= MEAN_RATIO_TARGET,
        "wall_s": round(time.perf_counter() - start, 1),
    }
