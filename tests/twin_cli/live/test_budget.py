"""An echo's wall-clock budget: everything up to its rate, evenly thinned past it."""

from __future__ import annotations

from twin_cli.live.budget import WallBudget


class Clock:
    def __init__(self) -> None:
        self.now = 0.0

    def __call__(self) -> float:
        return self.now


def test_a_world_within_the_budget_loses_nothing():
    clock = Clock()
    budget = WallBudget(200.0, clock)
    sent = []
    for tick in range(300):  # 3 s of 10 ms looks, 2 items each: 200 per second
        clock.now = tick * 0.01
        sent += budget.take([2 * tick, 2 * tick + 1])
    assert sent == list(range(600)), "every item, in order"


def test_a_faster_world_is_thinned_to_the_budget_with_even_gaps():
    clock = Clock()
    budget = WallBudget(200.0, clock)
    budget.take(list(range(200)))  # the first second's burst is spent
    sent = []
    for tick in range(1, 101):  # 1 s of 10 ms looks, 16 items each: 1600 per second
        clock.now = tick * 0.01
        sent += budget.take(list(range(16 * tick, 16 * tick + 16)))
    assert 190 <= len(sent) <= 200, f"{len(sent)} items in 1 s for a budget of 200"
    gaps = {b - a for a, b in zip(sent, sent[1:], strict=False)}
    assert gaps == {8}, f"every 8th item: gaps {sorted(gaps)}"
