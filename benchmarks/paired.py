"""Finely interleaved A/B throughput: many short alternating windows, summed.

On this kind of shared VM, the speed of identical `mj_step` work drifts by ±20 % over seconds
(host frequency and steal), so five long alternating windows gave medians anywhere in 0.6-1.1
for a consumer that costs 5 %. Drift that slow cancels when the two arms alternate every few
milliseconds: the ratio of the summed times of 200 pairs of short windows repeats within ±1 %.
"""

from __future__ import annotations

import time
from collections.abc import Callable

PAIRS = 200  # alternations; 500-step windows of a humanoid take ~25 ms each


def interleaved_ratio(
    plain: Callable[[], None],
    variant: Callable[[], None],
    *,
    pairs: int = PAIRS,
    clock: Callable[[], float] = time.perf_counter,
    settle: Callable[[], None] | None = None,
    prepare: Callable[[], None] | None = None,
) -> float:
    """Throughput of `variant` over that of `plain` (each call does the same work).

    Returns summed plain time / summed variant time over `pairs` alternations, so 1.0 means
    no cost and 0.95 a 5 % cost. Pass `clock=time.thread_time` for the calling thread's CPU.
    `settle`, untimed after each variant call, waits for work the variant left to another
    thread, so that the next plain window does not share the machine with it. `prepare`,
    untimed before each variant call, brings such a thread to its steady state (running
    beside the variant as it would in a long run), so the variant's window is not the quiet
    start of its work.
    """
    plain_s = variant_s = 0.0
    for _ in range(pairs):
        start = clock()
        plain()
        plain_s += clock() - start
        if prepare is not None:
            prepare()
        start = clock()
        variant()
        variant_s += clock() - start
        if settle is not None:
            settle()
    return plain_s / variant_s
