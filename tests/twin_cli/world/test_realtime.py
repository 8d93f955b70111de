"""The pure real-time rules: sync-point pacing, backlog dropping, batch sizing, gz-stats factor."""

from __future__ import annotations

import math

import pytest

from twin_cli.world import realtime as rt

RATE = 1000.0  # [Hz] SDF default real_time_update_rate
PERIOD = 1.0 / RATE


def simulate(oversleep: float, seconds: float, sync_point: bool) -> float:
    """Runs a virtual 1 kHz loop whose every sleep lasts `oversleep` [s] longer than asked.

    Returns the real-time factor reached: steps done / rate / seconds of virtual wall time.
    `sync_point` uses steps_due/next_wake; otherwise one step per wake-up, timed from wake-up.
    """
    now, done = 0.0, 0
    pacer = rt.start_pacer(RATE, now, done)
    while now < seconds:
        if sync_point:
            n, pacer = rt.steps_due(pacer, now, done, max_batch=100)
            done += n
            now = max(now, rt.next_wake(pacer, done)) + oversleep
        else:
            done += 1
            now += PERIOD + oversleep
    return done / RATE / now


def test_sync_point_pacer_holds_factor_one_despite_oversleep():
    # 0.1 ms oversleep per wake-up is typical of time.sleep on a loaded Linux box.
    factor = simulate(oversleep=1e-4, seconds=10.0, sync_point=True)
    assert factor == pytest.approx(1.0, abs=0.001), f"sync-point real-time factor {factor:.4f}"


def test_wake_up_timed_pacer_loses_time_to_oversleep():
    # The counter-example: timing each step from wake-up loses the oversleep.
    factor = simulate(oversleep=1e-4, seconds=2.0, sync_point=False)
    assert factor == pytest.approx(1 / 1.1, abs=0.002), f"wake-up-timed factor {factor:.4f}"


def test_steps_due_counts_elapsed_periods_since_the_anchor():
    pacer = rt.start_pacer(RATE, now=5.0, done=7)
    assert rt.steps_due(pacer, 5.0, 7, 100)[0] == 0, "no step is due at the anchor"
    assert rt.steps_due(pacer, 5.0 + 3.5 * PERIOD, 7, 100)[0] == 3, "3.5 periods → 3 steps"
    assert rt.steps_due(pacer, 5.0 + 3.5 * PERIOD, 9, 100)[0] == 1, "2 of them done → 1 due"
    assert rt.steps_due(pacer, 5.0 + 30 * PERIOD, 7, 10)[0] == 10, "capped at max_batch"


def test_falling_far_behind_drops_backlog_instead_of_bursting():
    pacer = rt.start_pacer(RATE, now=0.0, done=0, max_backlog_s=0.05)
    n, pacer = rt.steps_due(pacer, now=2.0, done=0, max_batch=1000)  # 2 s stall: 2000 due
    assert n == pacer.max_backlog == 50, "runs at most the allowed backlog"
    assert pacer.dropped == 2000 - 50, "the rest is counted as dropped"
    assert rt.steps_due(pacer, 2.0, 50, 1000)[0] == 0, "then it is on schedule again"
    assert rt.next_wake(pacer, 50) == pytest.approx(2.0 + PERIOD), "next step due one period on"


def test_unthrottled_pacer_always_runs_a_full_batch():
    pacer = rt.start_pacer(0.0, now=1.0, done=0)
    assert rt.steps_due(pacer, 1.0, 123, 250) == (250, pacer), "rate 0 = as fast as possible"


@pytest.mark.parametrize(
    ("steps", "seconds", "expected"),
    [(0, 0.0, 1), (100, 0.004, 100), (10, 0.004, 10), (1, 1e-6, rt.MAX_BATCH), (50, 1.0, 1)],
)
def test_batch_limit_aims_at_the_target_wall_time(steps, seconds, expected):
    assert rt.batch_limit(steps, seconds, target_s=0.004) == expected, "batch size"


def test_gz_stats_factor_is_sim_over_real_across_the_last_20_samples():
    meter = rt.RtfMeter()
    for k in range(100):  # 20 s: first 10 s at factor 0.5, then 10 s at factor 1.0
        real = 0.2 * k
        sim = 0.5 * real if real <= 10.0 else 5.0 + (real - 10.0)
        meter = rt.observe(meter, real, sim)
    assert len(meter.samples) == rt.SAMPLE_WINDOW + 1, "window of 20 intervals"
    assert rt.factor(meter) == pytest.approx(1.0), "only the last 4 s count"


def test_observe_samples_at_most_every_interval():
    meter = rt.RtfMeter()
    for real in (0.0, 0.05, 0.1, 0.19, 0.2, 0.3, 0.41):
        meter = rt.observe(meter, real, real * 2)
    assert [r for r, _ in meter.samples] == [0.0, 0.2, 0.41], "samples ≥ 0.2 s apart"
    assert rt.factor(meter) == pytest.approx(2.0), "sim runs twice as fast"
    assert rt.factor(rt.RtfMeter(((1.0, 1.0),))) == 0.0, "one sample has no factor"


def test_a_pause_leaves_no_paused_seconds_in_the_factor_after_resume():
    """5 s at factor 0.5, paused 3 s, then 1 s at 0.5: the factor reads 0.5; a window that
    spans the pause reads the paused seconds as sim time that did not advance (under 0.3)."""
    meter = rt.RtfMeter()
    for k in range(46):  # 0-9 s of wall time
        real = 0.2 * k
        paused = 5.0 < real < 8.0
        sim = 0.5 * min(real, 5.0) + 0.5 * max(0.0, real - 8.0)
        meter = rt.observe_running(meter, real, sim, paused)
        if paused:
            assert rt.factor(meter) == 0.0, "no factor while paused"
    assert rt.factor(meter) == pytest.approx(0.5), [s for s in meter.samples]
    spanning = rt.RtfMeter()
    for k in range(46):
        real = 0.2 * k
        sim = 0.5 * min(real, 5.0) + 0.5 * max(0.0, real - 8.0)
        spanning = rt.observe(spanning, real, sim)
    assert rt.factor(spanning) < 0.3, "the window that spans the pause"


def test_lateness_accounts_mean_worst_and_late_batches():
    log = rt.Lateness()
    for late in (0.0, 2e-4, 5e-3, -1e-5):
        log = rt.record_lateness(log, late, PERIOD)
    assert log.count == 4, "batches"
    assert math.isclose(log.mean, (2e-4 + 5e-3) / 4), "negative lateness counts as 0"
    assert log.worst == 5e-3, "worst"
    assert log.over_period == 1, "batches later than one period"
