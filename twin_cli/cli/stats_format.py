"""Pure formatting of world statistics the way `gz stats` prints them (line, CSV, JSON)."""

from __future__ import annotations

import json
from collections.abc import Mapping

# gazebo-classic tools/gz.cc StatsCommand: printf formats, and the CSV header kept verbatim
# (it says "percent" although the value is a ratio, as Gazebo's does; scripts match it).
CSV_HEADER = "# real-time factor (percent), simtime (sec), realtime (sec), paused (T or F)"
# gz-stats messages come every 0.2 s of wall time (World.cc statPeriod), ~5 lines a second.
STATS_PERIOD_S = 0.2


def _flag(paused: bool) -> str:
    return "T" if paused else "F"


def _factor(stats: Mapping[str, object]) -> float:
    """The real-time factor, clamped at 0 as gz does for a negative value."""
    return max(0.0, float(stats["factor"]))  # type: ignore[arg-type]


def stats_line(stats: Mapping[str, object]) -> str:
    """One gz-stats line, e.g. `Factor[1.00] SimTime[12.34] RealTime[12.36] Paused[F]`.

    Args:
        stats: a mapping with `factor` [-], `sim_time` [s], `real_time` [s], `paused` [bool].
    """
    return (
        f"Factor[{_factor(stats):4.2f}] SimTime[{float(stats['sim_time']):4.2f}] "  # type: ignore[arg-type]
        f"RealTime[{float(stats['real_time']):4.2f}] Paused[{_flag(bool(stats['paused']))}]"  # type: ignore[arg-type]
    )


def stats_csv_row(stats: Mapping[str, object]) -> str:
    """One `gz stats -p` row: `%4.2f, %16.6f, %16.6f, %c`."""
    return (
        f"{_factor(stats):4.2f}, {float(stats['sim_time']):16.6f}, "  # type: ignore[arg-type]
        f"{float(stats['real_time']):16.6f}, {_flag(bool(stats['paused']))}"  # type: ignore[arg-type]
    )


def stats_json(stats: Mapping[str, object]) -> str:
    """One compact JSON object per sample (JSON lines), for `twin stats --json`."""
    return json.dumps(dict(stats), separators=(",", ":"))


def sample_times(start: float, duration: float | None, period: float = STATS_PERIOD_S):
    """Wall-clock instants [s] at which to print a sample, from `start` until `start + duration`.

    Ticks sit on a fixed grid (start + k * period) so printing never drifts; `duration`
    None yields forever (run until interrupted). The first tick is `start` itself.
    """
    k = 0
    while duration is None or k * period <= duration + 1e-9:
        yield start + k * period
        k += 1
