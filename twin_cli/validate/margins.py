"""How far each check's measured value is from its threshold: the sweep records the threshold
and its report plots the margin, so both read the table here."""

from __future__ import annotations

from twin_cli.validate.checks.base import CheckResult

MARGINS: dict[str, tuple[str, str]] = {
    "friction_standing": ("max_slip_m", "max"),
    "ground_contact": ("max_penetration_m", "max"),
    "collision": ("max_intrusion_m", "max"),
    "stability": ("max_energy_gain", "max"),
    "realtime": ("min_factor", "min"),
    "gravity": ("rel_tol", "max"),
    "zero_gravity": ("max_com_drift_m", "max"),
    "inertia": ("rel_tol", "max"),
}
"""Check → (the threshold its `value` is judged against, "max" = value ≤ it, "min" = value ≥ it).
Checks not listed have no single number to compare; the plot shows them as pass (1) / fail (0)."""


def margin(r: CheckResult, limit: float | None) -> float | None:
    """Threshold minus measured (a "max" check) or measured minus threshold (a "min" check),
    in the check's own unit: positive passes, negative fails; None without a number."""
    rule = MARGINS.get(r.check)
    if rule is None or limit is None or r.value is None:
        return None
    return limit - r.value if rule[1] == "max" else r.value - limit
