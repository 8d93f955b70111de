"""Typed values shared by every validation check: the robot under test, statuses and results."""

from __future__ import annotations

import enum
import re
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    import mujoco

    from converters.report import Report


class Status(enum.Enum):
    """Outcome of one check (what each means: `STATUS_MEANING`); FAIL exits 1, ERROR exits 70.

    NOT_APPLICABLE keeps the value "skip": JSON consumers read it and JUnit calls it <skipped>.
    """

    PASS = "pass"
    WARN = "warn"
    FAIL = "fail"
    NOT_APPLICABLE = "skip"
    ERROR = "error"


STATUS_MEANING: dict[Status, str] = {
    Status.PASS: "the robot meets the check's thresholds",
    Status.WARN: "passes; a finding worth a look (or a measurement the machine could not decide)",
    Status.FAIL: "the robot breaks the check; each hint names the part and the fix (exit 1)",
    Status.NOT_APPLICABLE: "the check cannot apply to this robot; the reason is given",
    Status.ERROR: "the check itself crashed: a bug in twin, not in the robot (exit 70)",
}
"""What each status says about the robot, for reports and docs."""

EXIT_CODES: dict[Status, int] = {Status.FAIL: 1, Status.ERROR: 70}
"""`twin validate`'s exit code for a run whose worst status is this (others: 0)."""


class CannotApply(Exception):
    """Raised from inside a check (or what it builds) when the robot gives it nothing to judge;
    the runner turns it into a NOT_APPLICABLE result with `reason`, never an ERROR."""

    def __init__(self, reason: str) -> None:
        super().__init__(reason)
        self.reason = reason


@dataclass(frozen=True)
class Series:
    """A time series for a plot: `t` [s] against `values`, with an optional oracle curve and
    the check's threshold (a horizontal line, or a band around the oracle)."""

    label: str
    unit: str
    t: tuple[float, ...]
    values: dict[str, tuple[float, ...]]
    threshold: float | None = None  # a limit on the values, drawn as a line (same unit)
    band: tuple[tuple[float, ...], tuple[float, ...]] | None = None  # (low, high) allowed over t
    x_label: str = "time [s]"  # what `t` is, with its unit
    categories: tuple[str, ...] = ()  # bar names when `t` indexes items, not time (see `bars`)
    log: bool = False  # a logarithmic value axis (errors many decades below the threshold)


def bars(label: str, unit: str, values: dict[str, float], threshold: float, **extra: Any) -> Series:
    """A Series of one value per named item (joint, sensor, surface) against one threshold,
    drawn as bars: for checks that measure a number per item rather than a time series."""
    names = tuple(values)
    return Series(
        label,
        unit,
        tuple(float(i) for i in range(len(names))),
        {label: tuple(float(v) for v in values.values())},
        threshold=float(threshold),
        categories=names,
        **extra,
    )


@dataclass(frozen=True)
class CheckResult:
    """One check's verdict.

    `measured` and `threshold` are short human strings ("12.1 mm", "≤ 5 mm"); `value` is the
    headline number for JSON consumers; `hints` name the link/joint and the likely fix.
    """

    check: str
    kind: str
    status: Status
    measured: str
    threshold: str
    hints: tuple[str, ...] = ()
    details: tuple[str, ...] = ()
    value: float | None = None
    scenario: str | None = None
    seconds: float = 0.0
    series: tuple[Series, ...] = ()

    @property
    def failed(self) -> bool:
        return self.status is Status.FAIL

    @property
    def errored(self) -> bool:
        """The check crashed (a twin bug): neither a pass nor a verdict on the robot."""
        return self.status is Status.ERROR

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready view (series left out; they go to plots)."""
        return {
            "check": self.check,
            "kind": self.kind,
            "scenario": self.scenario,
            "status": self.status.value,
            "measured": self.measured,
            "threshold": self.threshold,
            "value": self.value,
            "hints": list(self.hints),
            "details": list(self.details),
            "seconds": round(self.seconds, 4),
        }


@dataclass(frozen=True)
class DeclaredJoint:
    """A joint as the URDF declares it: limits [rad] or [m], effort [N m] or [N], velocity."""

    name: str
    type: str
    lower: float | None
    upper: float | None
    effort: float | None
    velocity: float | None
    mimic: bool


@dataclass(frozen=True)
class UnplacedSensor:
    """A `<sensor>` the description attaches to a link that does not exist (`reference`)."""

    name: str
    kind: str
    link: str


@dataclass(frozen=True)
class RobotUnderTest:
    """What every check receives: the converted robot and how it was converted.

    `spec` is never mutated by a check (physics checks spawn copies); `model` is the robot
    compiled alone, in its initial pose. `repair_inertia` says whether the user asked for
    inertia repairs (then repairs are warnings, not failures). `declared_joints` are the
    URDF's own joint values (empty for MJCF input). `link_names` are the description's links,
    `geom_links` the link each named geom was declared on,
    `unplaced_sensors` its sensors on links it does not have, `ignored_parts` what Gazebo
    loads it without (tags naming a missing part, visuals whose mesh is missing; one line
    each, with the fix), `self_collide_links` the links
    with Gazebo selfCollide and `model_self_collide` the model's `<self_collide>` (all empty
    for MJCF input).
    """

    name: str
    source: str
    spec: mujoco.MjSpec
    model: mujoco.MjModel
    report: Report
    repair_inertia: bool = False
    body_links: dict[str, str] = field(default_factory=dict)
    declared_joints: tuple[DeclaredJoint, ...] = ()
    sensors: tuple = ()  # the converter's Gazebo sensors (converters.description.sensors)
    link_names: tuple[str, ...] = ()
    geom_links: dict[str, str] = field(default_factory=dict)  # geom name → the link it came from
    unplaced_sensors: tuple[UnplacedSensor, ...] = ()
    ignored_parts: tuple[str, ...] = ()
    self_collide_links: frozenset[str] = frozenset()
    model_self_collide: bool = False

    @property
    def described(self) -> bool:
        """Whether the robot came from a URDF/SDF description (not an MJCF file)."""
        return bool(self.link_names)

    def link_of_body(self, body: str) -> str:
        """The URDF link name for a body name (bodies are named after links)."""
        return self.body_links.get(body, body)

    def link_of_geom(self, geom: int) -> str:
        """The URDF link a geom of `model` was declared on (a lumped link keeps its name)."""
        name = self.model.geom(geom).name
        body = self.model.body(int(self.model.geom_bodyid[geom])).name
        return self.geom_links.get(name) or self.link_of_body(body)


def result(
    check: str,
    kind: str,
    status: Status,
    measured: str,
    threshold: str,
    **extra: Any,
) -> CheckResult:
    """Build a CheckResult, turning lists into tuples."""
    for key in ("hints", "details", "series"):
        if key in extra:
            extra[key] = tuple(extra[key])
    return CheckResult(check, kind, status, measured, threshold, **extra)


def not_applicable(check: str, kind: str, measured: str, reason: str) -> CheckResult:
    """The verdict of a check that cannot apply to this robot; `reason` says why (JUnit
    shows it as the <skipped> message), `measured` is the short form for the table."""
    return result(check, kind, Status.NOT_APPLICABLE, measured, "n/a", details=[reason])


def judged(
    check: str, kind: str, measured: str, threshold: str, hints: list[str], **extra: Any
) -> CheckResult:
    """A check's verdict by the one rule every check uses: it fails iff it has hints (each
    hint names a measured quantity past its threshold and the fix); otherwise it passes."""
    status = Status.FAIL if hints else Status.PASS
    return result(check, kind, status, measured, threshold, hints=hints, **extra)


_LINK_RE = re.compile(r"link '([^']+)'")


def link_in_subject(subject: str) -> str | None:
    """The link named in a report subject such as "link 'wheel' mass", or None."""
    match = _LINK_RE.search(subject)
    return match.group(1) if match else None


def fmt_len(metres: float) -> str:
    """A length for people: mm below 1 m."""
    return f"{metres * 1000:.3g} mm" if abs(metres) < 1.0 else f"{metres:.3g} m"
