"""twin's step cost against MuJoCo Menagerie's hand-made models of the same robots.

Each robot a user can spawn in twin and that Menagerie models (ur5e, anymal_c, booster_t1, the
Robotiq 2F-85, and the Franka Panda when franka_description is given) is spawned in a `World` as
`twin spawn --on-ground` spawns it (`--fixed-base` for the arms and the gripper, which Menagerie
welds to the world), with the world's timestep set to Menagerie's, and stepped beside
Menagerie's `scene.xml` from its `home` keyframe (qpos0 where it has none). Island sleeping is
off in both, so every step does its full work. Per robot:
- ratio: twin's step cost over Menagerie's (goal: at most RATIO_GOAL), measured in one run by
  `step_compare.step_ratio` (short windows alternated, each from a saved state, on the calling
  thread's CPU time). `air`: a free-floating robot lifted AIR_M at rest (no contacts: the
  model's own cost); `rest`: after REST_SETTLE_S with the initial ctrl; `random`: states along
  SEGMENTS × SEGMENT_S of ctrl drawn from `default_rng(0)` within CTRL_SCALE of each actuator's
  ctrlrange around its initial ctrl (±UNLIMITED_CTRL without one), each window from the next
  state with its ctrl;
- why: contacts (ncon), constraint rows (nefc) and solver iterations, averaged over the random
  states; both models' options; MuJoCo's stage timers (mjTIMER_*) per step for both;
- variants: the random-ctrl ratio with one of twin's options set to Menagerie's value
  (integrator, solver tolerance, iteration caps, cone, impratio) or without twin's gravity
  compensation, measured the same way, so the reader sees which option costs what.
Menagerie comes from TWIN_MENAGERIE (a checkout of github.com/google-deepmind/mujoco_menagerie)
and the Panda's description from TWIN_FRANKA_DESCRIPTION (a franka_description checkout); the
bench says so and skips a robot whose files are absent (CI has no network).
"""

from __future__ import annotations

import copy
import os
import sys
import time
from pathlib import Path

from benchmarks.bench_rest import corpus_request, corpus_robots
from benchmarks.step_compare import constraint_counts, stage_timers, step_ratio

MENAGERIE_ENV, FRANKA_ENV = "TWIN_MENAGERIE", "TWIN_FRANKA_DESCRIPTION"
RATIO_GOAL = 1.1  # the project's goal for twin's step over Menagerie's at the same timestep
REST_SETTLE_S, SEGMENTS, SEGMENT_S = 1.0, 10, 0.2  # [s], count, [s]
AIR_M = 1.0  # [m] lift for the contact-free case: a 0.2 s window falls 0.2 m
CTRL_SCALE, UNLIMITED_CTRL = 0.1, 10.0  # share of each ctrlrange; half-range without one
# corpus id → (Menagerie folder, weld the base as Menagerie does)
ROBOTS = {
    "ur5e": ("universal_robots_ur5e", True),
    "anymal_c": ("anybotics_anymal_c", False),
    "booster_t1": ("booster_t1", False),
    "robotiq_2f_85": ("robotiq_2f85", True),
}
STAGES_SHOWN = ("pos_collision", "pos_make", "velocity", "constraint", "advance")


def _requests() -> dict:
    """Robot id → (Menagerie folder, SpawnRequest) for the robots whose twin side is here."""
    from dataclasses import replace

    from twin_cli.spawn_request import SpawnRequest

    corpus = corpus_robots()
    pairs = {
        rid: (folder, replace(corpus_request(corpus[rid]), fixed_base=fixed))
        for rid, (folder, fixed) in ROBOTS.items()
        if rid in corpus
    }
    franka = os.environ.get(FRANKA_ENV)
    if franka and Path(franka, "robots/fer/fer.urdf.xacro").is_file():
        # franka_description's arm with its hand and ros2_control interfaces; its link4 inertia
        # breaks the triangle inequality, so it is repaired as `twin spawn --repair-inertia` does.
        request = SpawnRequest(str(Path(franka, "robots/fer/fer.urdf.xacro")),
                               package_paths={"franka_description": franka},
                               args={"ros2_control": "true"}, on_ground=True,
                               repair_inertia=True, fixed_base=True)  # fmt: skip
        pairs["panda"] = ("franka_emika_panda", request)
    return pairs


def _no_sleep(model):  # noqa: ANN001, ANN202
    import mujoco

    model.opt.enableflags = int(model.opt.enableflags) & ~int(mujoco.mjtEnableBit.mjENBL_SLEEP)
    return model


def _menagerie(folder: Path) -> tuple:
    """(model, data at `home` or qpos0) of Menagerie's scene."""
    import mujoco

    model = _no_sleep(mujoco.MjModel.from_xml_path(str(folder / "scene.xml")))
    data = mujoco.MjData(model)
    key = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_KEY, "home")
    if key >= 0:
        mujoco.mj_resetDataKeyframe(model, data, key)
    mujoco.mj_forward(model, data)
    return model, data


def _twin(request, timestep: float) -> tuple:  # noqa: ANN001
    """(model, data) of the robot spawned in a world at `timestep` [s]."""
    from twin_cli.world import World
    from twin_cli.world.values import WorldSettings

    world = World(WorldSettings(timestep=timestep))
    world.spawn(request, name="r")
    return _no_sleep(copy.deepcopy(world.model)), copy.copy(world.data)


def random_ctrl_states(model, data) -> tuple[bytes, list]:  # noqa: ANN001
    """(the settled rest state, the states along the random ctrl sequence), as mjSTATE_INTEGRATION
    vectors (qpos, qvel, act, ctrl, ...)."""
    import mujoco
    import numpy as np

    spec = mujoco.mjtState.mjSTATE_INTEGRATION

    def grab(work):  # noqa: ANN001, ANN202
        state = np.empty(mujoco.mj_stateSize(model, spec))
        mujoco.mj_getState(model, work, state, spec)
        return state

    work, h = copy.copy(data), model.opt.timestep
    mujoco.mj_step(model, work, nstep=round(REST_SETTLE_S / h))
    rest, base = grab(work), work.ctrl.copy()
    low, high = model.actuator_ctrlrange.T.copy()
    free = ~model.actuator_ctrllimited.astype(bool)
    low[free], high[free] = base[free] - UNLIMITED_CTRL, base[free] + UNLIMITED_CTRL
    rng, states = np.random.default_rng(0), []
    for _ in range(SEGMENTS):
        half = (high - low) / 2 * CTRL_SCALE
        work.ctrl[:] = np.clip(base + rng.uniform(-half, half), low, high)
        mujoco.mj_step(model, work, nstep=round(SEGMENT_S / h))
        states.append(grab(work))
    return rest, states


def _in_the_air(model, data):  # noqa: ANN001, ANN202
    """The initial state of a free-floating robot lifted AIR_M clear of the ground at rest, as
    an mjSTATE_INTEGRATION vector; None for a robot welded to the world."""
    import mujoco
    import numpy as np

    if model.njnt == 0 or model.jnt_type[0] != mujoco.mjtJoint.mjJNT_FREE:
        return None
    spec, work = mujoco.mjtState.mjSTATE_INTEGRATION, copy.copy(data)
    work.qpos[model.jnt_qposadr[0] + 2] += AIR_M
    work.qvel[:] = 0.0
    state = np.empty(mujoco.mj_stateSize(model, spec))
    mujoco.mj_getState(model, work, state, spec)
    return state


def _options(model) -> dict:  # noqa: ANN001
    o = model.opt
    return {"integrator": int(o.integrator), "cone": int(o.cone), "solver": int(o.solver),
            "tolerance": o.tolerance, "iterations": int(o.iterations),
            "ls_iterations": int(o.ls_iterations), "impratio": o.impratio,
            "timestep": o.timestep, "nv": int(model.nv), "ngeom": int(model.ngeom)}  # fmt: skip


def _variants(twin: tuple, menagerie: tuple, twin_states: list, m_states: list) -> dict:
    """The random-ctrl ratio with one of twin's options set to Menagerie's value, and without
    twin's gravity compensation (which its servos apply through `gravcomp`)."""
    m_opt, changes = menagerie[0].opt, {}
    for name in ("integrator", "tolerance", "iterations", "ls_iterations", "cone", "impratio"):
        if getattr(twin[0].opt, name) != getattr(m_opt, name):
            changes[name] = lambda model, name=name: setattr(model.opt, name, getattr(m_opt, name))
    if twin[0].body_gravcomp.any():
        changes["no_gravcomp"] = lambda model: model.body_gravcomp.fill(0.0)
    rows = {}
    for name, change in changes.items():
        model = copy.deepcopy(twin[0])
        change(model)
        rows[name] = step_ratio((model, copy.copy(twin[1])), menagerie, twin_states, m_states)[
            "ratio"
        ]
    return rows


def _robot(folder: Path, request) -> dict:  # noqa: ANN001
    menagerie = _menagerie(folder)
    twin = _twin(request, menagerie[0].opt.timestep)
    t_rest, t_states = random_ctrl_states(*twin)
    m_rest, m_states = random_ctrl_states(*menagerie)
    t_air, m_air = _in_the_air(*twin), _in_the_air(*menagerie)
    air = step_ratio(twin, menagerie, [t_air], [m_air]) if t_air is not None else None
    t_stages, m_stages = stage_timers([(*twin, t_states), (*menagerie, m_states)])
    return {
        "air": air,
        "rest": step_ratio(twin, menagerie, [t_rest], [m_rest]),
        "random": step_ratio(twin, menagerie, t_states, m_states),
        "twin": {**_options(twin[0]), **constraint_counts(*twin, t_states), "stages_us": t_stages},
        "menagerie": {
            **_options(menagerie[0]),
            **constraint_counts(*menagerie, m_states),
            "stages_us": m_stages,
        },  # fmt: skip
        "variants": _variants(twin, menagerie, t_states, m_states),
    }


def _table(rows: dict) -> str:
    """Per robot: the three ratios, then twin/Menagerie under random ctrl (µs per step, contacts,
    constraint rows, solver iterations, stage timers) and the variants' ratios."""
    lines = [f"{'robot':14} {'air':>5} {'rest':>5} {'random':>6}  twin/Menagerie under random ctrl"]
    for rid, row in rows.items():
        if "skipped" in row:
            lines.append(f"{rid:14} skipped: {row['skipped']}")
            continue
        t, m, r = row["twin"], row["menagerie"], row["random"]
        air = f"{row['air']['ratio']:.2f}" if row["air"] else "-"
        cells = [f"µs {r['twin_us']:.1f}/{r['menagerie_us']:.1f}"]
        cells += [f"{k} {t[k]:.0f}/{m[k]:.0f}" for k in ("ncon", "nefc", "solver_iter")]
        cells += [f"{k} {t['stages_us'][k]:.1f}/{m['stages_us'][k]:.1f}" for k in STAGES_SHOWN]
        lines.append(f"{rid:14} {air:>5} {row['rest']['ratio']:5.2f} {r['ratio']:6.2f}  "
                     + ", ".join(cells))  # fmt: skip
        variants = ", ".join(f"{k} {v:.2f}" for k, v in row["variants"].items())
        lines.append(f"{'':14} with Menagerie's: {variants}")
    return "\n".join(lines)


def run() -> dict:
    root = os.environ.get(MENAGERIE_ENV)
    if not root or not Path(root).is_dir():
        note = f"set {MENAGERIE_ENV} to a MuJoCo Menagerie checkout"
        print(f"skipped: {note}", file=sys.stderr)
        return {"skipped": note}
    start, requests = time.perf_counter(), _requests()
    rows: dict[str, dict] = {rid: {"skipped": "no corpus"} for rid in ROBOTS if rid not in requests}
    if "panda" not in requests:
        rows["panda"] = {"skipped": f"set {FRANKA_ENV} to a franka_description checkout"}
    for rid, (folder, request) in requests.items():
        if not (Path(root, folder) / "scene.xml").is_file():
            rows[rid] = {"skipped": f"no {folder}/scene.xml under {root}"}
            continue
        rows[rid] = _robot(Path(root, folder), request)
    print(_table(rows), f"\ngoal: ratio ≤ {RATIO_GOAL}", file=sys.stderr)
    ratios = [row["random"]["ratio"] for row in rows.values() if "random" in row]
    return {
        "robots": rows,
        "ratio_goal": RATIO_GOAL,
        "within_goal": bool(ratios) and max(ratios) <= RATIO_GOAL,
        "wall_s": round(time.perf_counter() - start, 1),
    }
