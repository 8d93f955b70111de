"""How many messages an echo may make per wall second: a token bucket that thins evenly.

An echo of a world running faster than real time would otherwise build and send messages in
proportion to the world's speed: three echoes of a humanoid world stepping unthrottled at ~16k
steps/s (16x real time) took the loop down to ~6k steps/s, their threads holding the
interpreter the stepping thread needs between batches. An echo's budget is WALL_SPEEDUP times
its topic's rate in messages per wall second, so a world at up to that speed loses no message,
and a faster one gives evenly spaced messages (about every k-th), as a slow ROS subscriber
also sees only some of them.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from typing import TypeVar

WALL_SPEEDUP = 2.0  # a world up to this many times faster than real time loses no message
Item = TypeVar("Item")


class WallBudget:
    """At most `per_second` items per wall second, in bursts of up to one second's worth."""

    def __init__(self, per_second: float, clock: Callable[[], float] = time.monotonic) -> None:
        self.per_second = per_second
        self._clock = clock
        self._tokens = per_second
        self._last = clock()
        self._credit = 0.0  # carried across calls, so the spacing stays even between them

    def take(self, items: Sequence[Item]) -> list[Item]:
        """The items the budget allows now, in order: all of them, or an even share (a
        fraction f of them: an item each time the running sum of f passes a whole number)."""
        now = self._clock()
        elapsed, self._last = now - self._last, now
        self._tokens = min(self.per_second, self._tokens + elapsed * self.per_second)
        if len(items) <= self._tokens:
            self._tokens -= len(items)
            return list(items)
        share = max(0.0, self._tokens) / len(items)
        chosen = []
        for item in items:
            self._credit += share
            if self._credit >= 1.0 - 1e-9:  # float sums of exact fractions fall short
                self._credit -= 1.0
                chosen.append(item)
        self._tokens -= len(chosen)
        return chosen
