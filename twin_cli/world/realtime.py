"""Pure real-time rules: the sync-point pacer, batch sizing, lateness and the gz-stats RTF meter.

Nothing here sleeps, reads a clock or holds a lock: the stepping loop (`twin_cli.world.loop`) passes
wall-clock readings in and gets decisions out, so every rule is testable without threads.

The pacer is timed from a sync point, not from wake-up: step k is due at
`anchor_wall + (k - anchor_step) / rate`, whatever happened before, so oversleeping one wake-up
is paid back by the next batch instead of accumulating (a pacer timed from wake-up held only
RTF 0.89 at 1 kHz). When the loop falls more than `max_backlog` steps behind (a slow model, a
long spawn holding the lock), it drops the backlog and re-anchors instead of bursting to catch
up forever; dropped steps are counted.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

SAMPLE_INTERVAL = 0.2  # [s] gz stats receives world statistics at about 5 Hz
SAMPLE_WINDOW = 20  # gz stats averages the factor over the last 20 samples (about 4 s)
MAX_BACKLOG_S = 0.05  # [s] of wall time the loop may run behind before it drops the backlog
# [s] target wall time of one unthrottled batch (the lock is held that long, so a request waits
# at most one batch; 16 ms is one frame of a 60 Hz viewer). Python between batches runs with cold
# caches after mj_step (~25-80 µs per call path instead of ~5 µs), so the batch length sets the
# loop's overhead. Measured on the humanoid (fraction of loop wall time inside mj_step, no reader /
# with a 5 Hz stats reader): 4 ms 0.95 / 0.94, 8 ms 0.97 / 0.97, 12 ms 0.99 / 0.96-0.98,
# 16 ms 0.99 / 0.97-0.98.
BATCH_WALL_S = 0.016
MAX_BATCH = 1000  # steps in one batch, whatever the model's speed


@dataclass(frozen=True)
class Pacer:
    """Sync point of the real-time schedule.

    Attributes:
        period: wall time per step [s] (1 / update rate); 0 means as fast as possible.
        anchor_wall: wall-clock time [s] at which step number `anchor_step` is due.
        anchor_step: step count the anchor refers to.
        max_backlog: steps the loop may be behind before it re-anchors.
        dropped: steps skipped by re-anchoring so far (sim time lost against wall time).
    """

    period: float
    anchor_wall: float
    anchor_step: int
    max_backlog: int
    dropped: int = 0


def start_pacer(rate: float, now: float, done: int, max_backlog_s: float = MAX_BACKLOG_S) -> Pacer:
    """A pacer anchored at `now` for a loop that has done `done` steps.

    Args:
        rate: update rate [Hz] (steps per wall second); 0 = unthrottled.
        now: wall-clock reading [s].
        done: steps done so far.
        max_backlog_s: wall time [s] the loop may lag before dropping the backlog.
    """
    period = 1.0 / rate if rate > 0 else 0.0
    backlog = max(1, math.ceil(max_backlog_s * rate)) if rate > 0 else 0
    return Pacer(period, now, done, backlog)


def due_time(pacer: Pacer, step: int) -> float:
    """Wall-clock time [s] at which step number `step` is due."""
    return pacer.anchor_wall + (step - pacer.anchor_step) * pacer.period


def steps_due(pacer: Pacer, now: float, done: int, max_batch: int) -> tuple[int, Pacer]:
    """How many steps to run now, and the (possibly re-anchored) pacer.

    Args:
        pacer: the current schedule.
        now: wall-clock reading [s].
        done: steps done so far.
        max_batch: most steps to run in one batch.

    Returns:
        (n, pacer): n ≥ 0 steps to run now. Unthrottled, n = max_batch.
    """
    if pacer.period <= 0:
        return max_batch, pacer
    due = math.floor((now - pacer.anchor_wall) / pacer.period) + pacer.anchor_step - done
    if due <= pacer.max_backlog:
        return max(0, min(due, max_batch)), pacer
    n = min(pacer.max_backlog, max_batch)
    dropped = pacer.dropped + due - n
    return n, replace(pacer, anchor_wall=now, anchor_step=done + n, dropped=dropped)


def next_wake(pacer: Pacer, done: int, min_batch: int = 1) -> float:
    """Wall-clock time [s] at which `min_batch` more steps will be due."""
    return due_time(pacer, done + min_batch)


def batch_limit(last_steps: int, last_seconds: float, target_s: float = BATCH_WALL_S) -> int:
    """Steps per batch so that one batch takes about `target_s` of wall time.

    Args:
        last_steps: steps in the previous batch (0 if none yet).
        last_seconds: wall time [s] the previous batch took.
        target_s: wall time [s] wanted per batch; bounds how long requests wait for the lock.

    Returns:
        A batch size in [1, MAX_BATCH].
    """
    if last_steps <= 0 or last_seconds <= 0:
        return 1
    per_step = last_seconds / last_steps
    return max(1, min(MAX_BATCH, int(target_s / per_step)))


@dataclass(frozen=True)
class Lateness:
    """How late the loop woke for its sync points [s].

    Attributes:
        count: batches recorded.
        total: sum of lateness [s].
        worst: largest lateness [s].
        over_period: batches that started more than one step period late.
    """

    count: int = 0
    total: float = 0.0
    worst: float = 0.0
    over_period: int = 0

    @property
    def mean(self) -> float:
        """Mean lateness [s] (0 before the first batch)."""
        return self.total / self.count if self.count else 0.0


def record_lateness(log: Lateness, late_s: float, period: float) -> Lateness:
    """Adds one batch that started `late_s` [s] after its first step was due."""
    late = max(0.0, late_s)
    return Lateness(
        log.count + 1,
        log.total + late,
        max(log.worst, late),
        log.over_period + (1 if period > 0 and late > period else 0),
    )


@dataclass(frozen=True)
class RtfMeter:
    """The `gz stats` real-time factor: (Σ Δsim) / (Σ Δreal) over the last SAMPLE_WINDOW samples.

    Attributes:
        samples: (real [s], sim [s]) points, oldest first; at most SAMPLE_WINDOW + 1 of them,
            which bound SAMPLE_WINDOW intervals.
    """

    samples: tuple[tuple[float, float], ...] = ()


def observe(
    meter: RtfMeter, real: float, sim: float, interval: float = SAMPLE_INTERVAL
) -> RtfMeter:
    """Records a sample if `interval` [s] of real time passed since the last one.

    Args:
        meter: the meter so far.
        real: real (wall) time [s] since the world started or was reset.
        sim: simulation time [s].
        interval: sampling period [s] (gz stats: about 0.2 s).
    """
    if meter.samples and real - meter.samples[-1][0] < interval:
        return meter
    return RtfMeter((*meter.samples, (real, sim))[-(SAMPLE_WINDOW + 1) :])


def observe_running(
    meter: RtfMeter, real: float, sim: float, paused: bool, interval: float = SAMPLE_INTERVAL
) -> RtfMeter:
    """`observe` while the world runs; a pause empties the window, so the factor after a
    resume is measured over running time only, as Gazebo's real time stands still while
    paused (kept, the paused seconds read as sim time that did not advance: 0.37-0.44 right
    after a resume against 0.52 in the next window)."""
    return RtfMeter() if paused else observe(meter, real, sim, interval)


def factor(meter: RtfMeter) -> float:
    """The real-time factor over the recorded window (0 with fewer than two samples)."""
    if len(meter.samples) < 2:
        return 0.0
    (real0, sim0), (real1, sim1) = meter.samples[0], meter.samples[-1]
    return (sim1 - sim0) / (real1 - real0) if real1 > real0 else 0.0
