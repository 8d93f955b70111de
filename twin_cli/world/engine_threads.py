"""MuJoCo's engine thread pool and island sleeping for a World (`twin physics --threads/--sleep`).

The pool (`mujoco.mju_threadpool`, MuJoCo ≥ 3.3) parallelises collision detection and the
constraint solve across islands inside one `mj_step`; it belongs to an MjData, so it is
installed again on every new data (spawn, delete, reset, load).
It only pays with several islands to share out, so it is installed when the world has at least
`POOL_MIN_TREES` kinematic trees: a one-robot world steps as before. The pool changes no
answer (a trajectory of 8 colliding humanoids is bit-equal with and without it), only speed;
measured on a 2-core machine it did not pay (unthrottled factor with / without: 0.77-1.07 at
1-64 humanoids on a quiet machine, 0.5-0.7 at load 12-15; `benchmarks/bench_scale.py`), so a world
starts with one thread (no pool) and `twin physics --threads N` asks for one.

Sleeping (`mjENBL_SLEEP`) freezes islands whose speed stays under `sleep_tolerance` [m/s, rad/s]
for 10 steps; contacts with awake bodies and pushes wake them. Off by default: a sleeping robot's
state is held, not integrated, which is a different (if tiny) answer from the one the physics
tests check. Robots used to never sleep, not for contact creep but because MuJoCo never lets
an actuated tree sleep on its own: `twin_cli.world.sleeping` allows it and wakes a robot on
every command. Humanoids placed at rest then sleep at the default 1e-3 tolerance within 0.1 s;
dropped ones chatter on Gazebo's stiff contacts at 2-6 mm/s and need `--sleep-tolerance 0.01`.
"""

from __future__ import annotations

import mujoco
import numpy as np

from twin_cli.errors import InvalidRequestError
from twin_cli.world.sleeping import allow_actuated
from twin_cli.world.state import STATE, WorldState

POOL_MIN_TREES = 4  # kinematic trees (robots, free objects) before the pool is worth its overhead
MAX_THREADS = 64
SLEEP_BIT = int(mujoco.mjtEnableBit.mjENBL_SLEEP)


def default_threads() -> int:
    """The engine threads a new world uses: one (no pool) until a user asks for more.

    Measured on the 2-core machine twin is tested on (`python -m benchmarks scale`, load 1.9),
    MuJoCo 4.0's pool did not pay at any robot count: unthrottled factor with / without it
    1.07 (1 humanoid), 0.77 (8), 0.93 (32), 0.97 (64). `twin physics --threads N` turns it on.
    """
    return 1


def check_threads(threads: int) -> int:
    """Returns `threads` if it is a usable pool size.

    Raises:
        InvalidRequestError: not a whole number from 1 to MAX_THREADS.
    """
    if isinstance(threads, bool) or not isinstance(threads, int) or not 1 <= threads <= MAX_THREADS:
        raise InvalidRequestError(
            "engine threads", f"{threads!r}", f"give a whole number from 1 to {MAX_THREADS}"
        )
    return threads


def pool_size(threads: int, model: mujoco.MjModel) -> int:
    """Worker threads to install for `model`: none (0) when one thread or too few trees."""
    return threads if threads > 1 and model.ntree >= POOL_MIN_TREES else 0


def threads_of(state: WorldState) -> int:
    """Engine threads asked for (the pool is installed when `state.pool_threads` > 0)."""
    return state.threads or default_threads()


def sleeping(model: mujoco.MjModel) -> bool:
    """Whether island sleeping is enabled."""
    return bool(int(model.opt.enableflags) & SLEEP_BIT)


def install_pool(state: WorldState, model: mujoco.MjModel, data: mujoco.MjData) -> None:
    """Gives a new MjData the pool the world's settings ask for (caller holds the lock)."""
    allow_actuated(model)  # robots on their servos may sleep too (twin_cli.world.sleeping)
    size = pool_size(threads_of(state), model)
    if size and not data.threadpool:  # mj_recompile keeps the pool of the data it reuses
        mujoco.mju_threadpool(data, size)
    state.pool_threads = size


def set_engine(
    state: WorldState,
    *,
    threads: int | None = None,
    sleep: bool | None = None,
    sleep_tolerance: float | None = None,
) -> None:
    """Sets the engine threads, sleeping and its tolerance [m/s] (None keeps a value)."""
    if threads is not None:
        check_threads(threads)
    if sleep_tolerance is not None and not 0.0 < sleep_tolerance < 10.0:
        raise InvalidRequestError(
            "sleep tolerance", f"{sleep_tolerance!r} m/s", "give a speed above 0, e.g. 0.01"
        )
    with state.lock:
        if sleep_tolerance is not None:
            state.model.opt.sleep_tolerance = sleep_tolerance
            state.spec.option.sleep_tolerance = sleep_tolerance
        if sleep is not None:
            for option in (state.model.opt, state.spec.option):
                flags = int(option.enableflags)
                option.enableflags = flags | SLEEP_BIT if sleep else flags & ~SLEEP_BIT
        if threads is None and sleep is None:
            return
        if threads is not None:
            state.threads = threads
        # A pool cannot be removed from an MjData, and sleep state is sized at creation:
        # move the state to a fresh data (same model, same state: a bit-exact hand-over).
        renew_data(state)


def renew_data(state: WorldState) -> None:
    """Moves the whole integration state to a new MjData with the pool installed."""
    model, old = state.model, state.data
    data = mujoco.MjData(model)
    vector = np.empty(mujoco.mj_stateSize(model, STATE))
    mujoco.mj_getState(model, old, vector, STATE)
    mujoco.mj_setState(model, data, vector, STATE)
    mujoco.mj_forward(model, data)
    install_pool(state, model, data)
    state.data = data
