"""Joint trajectories (trajectory_msgs/JointTrajectory) from YAML or CSV, and their interpolation.

The interpolation is joint_trajectory_controller's "spline" method, chosen per segment by the
fields the points give: positions only → linear, positions and velocities → cubic (C¹), and
with accelerations → quintic (C²). Before the first point the controller interpolates from the
state the trajectory started in (at rest). Pure functions: no world, no MuJoCo.

Files:
- YAML: `joint_names: [...]` and `points:` each with `positions`, optional `velocities` and
  `accelerations`, and `time_from_start` as seconds or `{sec, nanosec}` (ros2 topic echo's form).
- CSV: a header `time_from_start,<joint>,...` with optional `<joint>/velocity` columns.
"""

from __future__ import annotations

import csv
import io
import math
from dataclasses import dataclass

from twin_cli.errors import InvalidRequestError


@dataclass(frozen=True)
class TrajectoryPoint:
    """A waypoint: time_from_start [s], positions [rad or m], optional velocities, accelerations."""

    time: float
    positions: tuple[float, ...]
    velocities: tuple[float, ...] | None = None
    accelerations: tuple[float, ...] | None = None


@dataclass(frozen=True)
class Trajectory:
    """joint_names and strictly increasing points (checked by `trajectory_from_dict`)."""

    joint_names: tuple[str, ...]
    points: tuple[TrajectoryPoint, ...]

    @property
    def duration(self) -> float:
        """time_from_start of the last point [s]."""
        return self.points[-1].time

    def to_dict(self) -> dict:
        """The JSON body of `POST /entities/{name}/trajectory`."""
        return {
            "joint_names": list(self.joint_names),
            "points": [
                {
                    "time_from_start": p.time,
                    "positions": list(p.positions),
                    "velocities": None if p.velocities is None else list(p.velocities),
                    "accelerations": None if p.accelerations is None else list(p.accelerations),
                }
                for p in self.points
            ],
        }


def _bad(where: str, problem: str, fix: str) -> InvalidRequestError:
    return InvalidRequestError(f"trajectory {where}", problem, fix)


def _seconds(value: object, where: str) -> float:
    if isinstance(value, dict):
        value = float(value.get("sec", 0)) + float(value.get("nanosec", 0)) * 1e-9
    if value is None or isinstance(value, bool):
        raise _bad(where, "has no time_from_start", "give each point a time_from_start [s]")
    try:
        seconds = float(value)
    except (TypeError, ValueError) as exc:
        raise _bad(where, f"time_from_start {value!r} is not a number", "give seconds") from exc
    if not math.isfinite(seconds):
        raise _bad(where, f"time_from_start {seconds} is not finite", "give seconds")
    return seconds


def _vector(values: object, n: int, field: str, where: str) -> tuple[float, ...] | None:
    if values is None or values == []:
        return None
    try:
        # any JSON value: one that is not a list of numbers raises here and is reported below
        out = tuple(float(v) for v in values)  # pyright: ignore[reportGeneralTypeIssues]
    except (TypeError, ValueError) as exc:
        raise _bad(where, f"{field} {values!r} are not numbers", "give numbers") from exc
    if len(out) != n or not all(math.isfinite(v) for v in out):
        raise _bad(where, f"{field} has {len(out)} finite values", f"give {n} (one per joint)")
    return out


def trajectory_from_dict(doc: object) -> Trajectory:
    """A checked trajectory from its message-shaped dict.

    Raises:
        InvalidRequestError: no joints or points, a point without time, times not strictly
            increasing, vectors of the wrong length.
    """
    if not isinstance(doc, dict):
        raise _bad("file", "is not a mapping", "give joint_names and points")
    names = tuple(str(n) for n in doc.get("joint_names") or ())
    raw = doc.get("points") or []
    if not names or not raw or len(set(names)) != len(names):
        raise _bad("file", "needs distinct joint_names and points", "give both")
    points, last = [], 0.0
    for i, point in enumerate(raw):
        where = f"point {i}"
        if not isinstance(point, dict):
            raise _bad(where, "is not a mapping", "give positions and time_from_start")
        time = _seconds(point.get("time_from_start"), where)
        if time <= last:
            raise _bad(
                where,
                f"time_from_start {time:g} s is not after {last:g} s",
                "make the times strictly increasing (and the first > 0)",
            )
        positions = _vector(point.get("positions"), len(names), "positions", where)
        if positions is None:
            raise _bad(where, "has no positions", "give one position per joint")
        velocities = _vector(point.get("velocities"), len(names), "velocities", where)
        accelerations = _vector(point.get("accelerations"), len(names), "accelerations", where)
        points.append(TrajectoryPoint(time, positions, velocities, accelerations))
        last = time
    return Trajectory(names, tuple(points))


def read_trajectory(text: str, name: str) -> Trajectory:
    """A trajectory from YAML or CSV text (`name` ending in .csv selects CSV)."""
    if name.lower().endswith(".csv"):
        return trajectory_from_dict(_csv_doc(text))
    import yaml

    try:
        doc = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        raise _bad(f"file {name}", f"is not YAML ({exc})", "fix the file") from exc
    return trajectory_from_dict(doc)


def _csv_doc(text: str) -> dict:
    rows = list(csv.reader(io.StringIO(text.strip())))
    if len(rows) < 2 or not rows[0] or rows[0][0].strip() != "time_from_start":
        raise _bad("CSV", "needs a header time_from_start,<joint>,... and rows", "add them")
    header = [h.strip() for h in rows[0]]
    names = [h for h in header[1:] if not h.endswith("/velocity")]
    speeds = [f"{n}/velocity" for n in names]
    has_speed = all(s in header for s in speeds)
    points = []
    for row in rows[1:]:
        cells = dict(zip(header, (c.strip() for c in row), strict=False))
        points.append(
            {
                "time_from_start": cells.get("time_from_start") or None,
                "positions": [cells.get(n) for n in names],
                "velocities": [cells.get(s) for s in speeds] if has_speed else None,
            }
        )
    return {"joint_names": names, "points": points}


def sample(
    trajectory: Trajectory, start: tuple[float, ...], t: float
) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """Reference positions and velocities at `t` [s] after the start (held after the end).

    `start` is the joints' positions when the trajectory began (at rest, time 0).
    """
    points = trajectory.points
    if t >= points[-1].time:
        last = points[-1]
        return last.positions, tuple(0.0 for _ in last.positions)
    k = next(i for i, p in enumerate(points) if p.time > t)
    before = points[k - 1] if k else TrajectoryPoint(0.0, tuple(start))
    after = points[k]
    span = after.time - before.time
    out = [segment(before, after, j, t - before.time, span) for j in range(len(start))]
    return tuple(p for p, _ in out), tuple(v for _, v in out)


def segment(a: TrajectoryPoint, b: TrajectoryPoint, j: int, s: float, T: float) -> tuple:
    """Position and velocity of joint j at s [s] into a segment of T [s] (JTC's spline rule);
    s may be a numpy array of times (the follower samples blocks of them)."""
    p0, p1 = a.positions[j], b.positions[j]
    if b.velocities is None:
        return p0 + (p1 - p0) * s / T, (p1 - p0) / T
    v0 = a.velocities[j] if a.velocities else 0.0
    v1 = b.velocities[j]
    if b.accelerations is None:
        c2 = (3 * (p1 - p0) - (2 * v0 + v1) * T) / T**2
        c3 = (2 * (p0 - p1) + (v0 + v1) * T) / T**3
        return p0 + v0 * s + c2 * s**2 + c3 * s**3, v0 + 2 * c2 * s + 3 * c3 * s**2
    a0 = a.accelerations[j] if a.accelerations else 0.0
    a1 = b.accelerations[j]
    c = _quintic(p0, v0, a0, p1, v1, a1, T)
    position = sum(ci * s**i for i, ci in enumerate(c))
    velocity = sum(i * ci * s ** (i - 1) for i, ci in enumerate(c) if i)
    return position, velocity


def _quintic(
    p0: float, v0: float, a0: float, p1: float, v1: float, a1: float, T: float
) -> list[float]:
    """Coefficients c0..c5 of the quintic matching position, velocity, acceleration at 0 and T."""
    h = p1 - p0
    c3 = (20 * h - (8 * v1 + 12 * v0) * T - (3 * a0 - a1) * T**2) / (2 * T**3)
    c4 = (-30 * h + (14 * v1 + 16 * v0) * T + (3 * a0 - 2 * a1) * T**2) / (2 * T**4)
    c5 = (12 * h - 6 * (v1 + v0) * T + (a1 - a0) * T**2) / (2 * T**5)
    return [p0, v0, a0 / 2, c3, c4, c5]
