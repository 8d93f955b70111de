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

import scenarios
from twin_cli.validate import report
from twin_cli.validate.checks.base import CheckResult
from twin_cli.validate.runner import validate

# Thresholds no bundled scenario uses, so a line drawn at a default would not pass.
ZERO_GRAVITY_DRIFT_M = 0.0042
INERTIA_REL_TOL = 0.0037


@pytest.fixture(scope="module")
def results(tmp_path_factory) -> dict[str, CheckResult]:
    folder = tmp_path_factory.mktemp("plots")
    files = []
    for name, old, new in (
        ("zero_gravity", "max_com_drift_m = 0.001", f"max_com_drift_m = {ZERO_GRAVITY_DRIFT_M}"),
        ("inertia", "rel_tol = 0.01", f"rel_tol = {INERTIA_REL_TOL}"),
    ):
        text = (Path(scenarios.SCENARIO_DIR) / f"{name}.toml").read_text()
        assert old in text, f"{name}.toml changed: update this test"
        files.append(folder / f"{name}.toml")
        files[-1].write_text(text.replace(old, new))
    run = validate(
        scenarios.HUMANOID, scenarios=[str(f) for f in files], only=["zero_gravity", "inertia"]
    )
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
    (series,) = r.series
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
