"""Validation plots draw each check's own threshold: real checks on the bundled humanoid, with
user scenarios whose thresholds differ from the defaults, rendered by `report.figure`.

Oracle: the threshold a scenario file sets (a value no default uses) must be where the red
dotted line is, and the bars/curves must be the values the check measured (its `value`).
"""

from __future__ import annotations

from pathlib import Path

import matplotlib.image
import numpy as np
import pytest
from validate_robots import crate, write

import scenarios
from twin_cli.validate import report
from twin_cli.validate.checks.base import CheckResult, fmt_len
from twin_cli.validate.runner import validate

# Thresholds no bundled scenario uses, so a line drawn at a default would not pass.
ZERO_GRAVITY_DRIFT_M = 0.0042
LINK_MOTION_M = 0.0123
INERTIA_REL_TOL = 0.0037
SPIN_RAD_S = 77.7
SLIDE_RATIO = 0.4321
EDITS = {
    "zero_gravity": [
        ("max_com_drift_m = 0.001", f"max_com_drift_m = {ZERO_GRAVITY_DRIFT_M}"),
        ("max_link_motion_m = 0.01", f"max_link_motion_m = {LINK_MOTION_M}"),
    ],
    "inertia": [("rel_tol = 0.01", f"rel_tol = {INERTIA_REL_TOL}")],
    "stability": [("max_spin_rad_s = 100.0", f"max_spin_rad_s = {SPIN_RAD_S}")],
    "friction_incline": [("min_slide_ratio = 0.5", f"min_slide_ratio = {SLIDE_RATIO}")],
}


@pytest.fixture(scope="module")
def results(tmp_path_factory) -> dict[str, CheckResult]:
    folder = tmp_path_factory.mktemp("plots")
    files = []
    for name, edits in EDITS.items():
        text = (Path(scenarios.SCENARIO_DIR) / f"{name}.toml").read_text()
        for old, new in edits:
            assert old in text, f"{name}.toml changed: update this test"
            text = text.replace(old, new)
        files.append(folder / f"{name}.toml")
        files[-1].write_text(text)
    run = validate(scenarios.HUMANOID, scenarios=[str(f) for f in files], only=list(EDITS))
    return {r.check: r for r in run.results}


def threshold_lines(ax) -> list[float]:
    """The y values of the red dotted horizontal lines (the threshold) in an axes."""
    found = []
    for line in ax.get_lines():
        y = np.asarray(line.get_ydata(), dtype=float)
        if line.get_linestyle() == ":" and line.get_color() == "red" and np.ptp(y) == 0:
            found.append(float(y[0]))
    return found


def test_zero_gravity_plot_draws_the_scenario_threshold_over_the_measured_drift(results):
    r = results["zero_gravity"]
    series = r.series[0]
    fig = report.figure("humanoid", r, series)
    ax = fig.axes[0]
    assert threshold_lines(ax) == [pytest.approx(ZERO_GRAVITY_DRIFT_M, rel=1e-12)]
    low, high = ax.get_ylim()
    assert low <= ZERO_GRAVITY_DRIFT_M <= high, "the threshold is inside the view"
    curve = next(line for line in ax.get_lines() if line.get_label() == "|COM − start|")
    assert max(curve.get_ydata()) == pytest.approx(r.value, abs=1e-12), "peak drift = verdict"
    assert ax.get_xlabel() == "time [s]" and ax.get_ylabel() == "COM drift [m]"


def test_inertia_plot_draws_the_scenario_tolerance_over_the_measured_error(results, tmp_path):
    r = results["inertia"]
    (series,) = r.series
    fig = report.figure("humanoid", r, series)
    ax = fig.axes[0]
    assert threshold_lines(ax) == [pytest.approx(INERTIA_REL_TOL, rel=1e-12)]
    (bar,) = ax.patches
    assert bar.get_height() == pytest.approx(max(r.value, 1e-16), rel=1e-12)
    assert ax.get_yscale() == "log", "an error near 1e-16 is visible beside 1e-3 only on a log axis"
    fig.savefig(tmp_path / "inertia.png")
    assert matplotlib.image.imread(tmp_path / "inertia.png").shape == (400, 600, 4)


def bars_of(ax) -> list[float]:
    return [bar.get_height() for bar in ax.patches]


def test_zero_gravity_link_motion_bars_stand_under_the_scenarios_link_threshold(results):
    """The second zero-g limit: how far each link moved (no gravity, no control) on a log axis;
    the humanoid's links do not move at all (their bars sit on the axis floor)."""
    r = results["zero_gravity"]
    series = r.series[1]
    fig = report.figure("humanoid", r, series)
    ax = fig.axes[0]
    assert threshold_lines(ax) == [pytest.approx(LINK_MOTION_M, rel=1e-12)]
    assert ax.get_yscale() == "log" and len(ax.patches) == len(series.categories) > 5
    assert "torso" in series.categories, "bars are named by link"
    assert max(bars_of(ax)) < LINK_MOTION_M


def test_links_pushed_apart_in_zero_g_stand_above_the_line(tmp_path):
    """A flap overlapping the arm by 2 cm with self-collision on: in zero g the two links push
    each other apart, so their bars rise above the threshold and the tallest is the verdict's
    "links" figure. (`twin validate` holds the check back from that posture, naming
    `initial_overlap`; the check itself is run here.)"""
    from twin_cli.validate.robot import load_robot
    from twin_cli.validate.runner import run_check
    from twin_cli.validate.scenario import load_builtin

    robot = write(tmp_path, crate(flap_overlaps_arm=True, arm_self_collide=True))
    scenario = next(s for s in load_builtin() if s.check == "zero_gravity")
    r = run_check(load_robot(robot), scenario)
    series = r.series[1]
    ax = report.figure("crate", r, series).axes[0]
    heights = dict(zip(series.categories, bars_of(ax), strict=True))
    assert set(heights) == {"crate", "arm", "flap"}
    assert heights["arm"] > 0.01 and heights["flap"] > 0.01, heights
    assert r.status.value == "fail" and f"links {fmt_len(max(heights.values()))}" in r.measured


def test_stability_spin_bars_stand_under_the_scenarios_spin_limit(results):
    """The stability check's second limit: each link's peak angular speed [rad/s]; the worst is
    the verdict's "max spin", and every bar is a real speed (positive, finite)."""
    r = results["stability"]
    series = next(s for s in r.series if s.label == "peak spin")
    fig = report.figure("humanoid", r, series)
    ax = fig.axes[0]
    assert threshold_lines(ax) == [pytest.approx(SPIN_RAD_S, rel=1e-12)]
    heights = bars_of(ax)
    assert all(0.0 < h < SPIN_RAD_S for h in heights), heights
    assert f"max spin {max(heights):.3g} rad/s" in r.measured


def test_friction_incline_slide_probe_is_plotted_against_coulombs_distance(results):
    """The slide probe (tan θ = 1.25 μ): the block slides ½ g (sin θ − μ cos θ) t² by Coulomb;
    the bar is the measured slide over that, and the scenario's minimum ratio is the line."""
    r = results["friction_incline"]
    series = next(s for s in r.series if s.label == "slide over Coulomb's")
    fig = report.figure("humanoid", r, series)
    ax = fig.axes[0]
    assert threshold_lines(ax) == [pytest.approx(SLIDE_RATIO, rel=1e-12)]
    (ratio,) = bars_of(ax)
    assert ratio == pytest.approx(1.0, abs=0.05), "Coulomb sliding, measured independently"
