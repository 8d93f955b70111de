"""The trajectory follower: joint_trajectory_controller as a consumer of the world, in sim time.

It runs at the controller manager's update rate (UPDATE_RATE, 100 Hz by default) as a world
observer (twin_cli.world.observers): the stepping splits its batches there, so there is no Python
per physics step. Each update samples the trajectory (twin_cli.control.trajectory), measures the
tracking error of the joints against the reference of that instant, and writes the next
reference into the joints' position servos: target position and the velocity their damping
tracks (the feed-forward a position+velocity interface gets). After the last point the joints
keep holding it and the follower reports its errors.
"""

from __future__ import annotations

import math
import threading
import weakref
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING

from twin_cli.control.trajectory import Trajectory, TrajectoryPoint, sample, segment
from twin_cli.errors import InvalidRequestError, PartNotFoundError

if TYPE_CHECKING:
    from collections.abc import Mapping

    import mujoco
    import numpy as np

    from twin_cli.world.actuation import JointCommand
    from twin_cli.world.engine import World

UPDATE_RATE = 100.0  # [Hz] controller_manager's usual update_rate
BLOCK = 100  # updates whose references are sampled at once (1 s at 100 Hz)


@dataclass
class TrackingReport:
    """Tracking errors [rad or m] by joint: the largest over the run and the one at the end;
    `clamped`: the largest move [rad or m] of a waypoint onto the joint's limit, by joint."""

    entity: str
    joint_names: tuple[str, ...]
    duration: float
    active: bool = True
    elapsed: float = 0.0
    max_error: dict[str, float] = field(default_factory=dict)
    final_error: dict[str, float] = field(default_factory=dict)
    clamped: dict[str, float] = field(default_factory=dict)  # largest move onto a limit

    def to_dict(self) -> dict:
        return {
            "entity": self.entity,
            "joint_names": list(self.joint_names),
            "duration": self.duration,
            "active": self.active,
            "elapsed": self.elapsed,
            "max_error": dict(self.max_error),
            "final_error": dict(self.final_error),
            "clamped": dict(self.clamped),
        }


class TrajectoryFollower:
    """Follows one trajectory on one entity of a World (see module docstring)."""

    def __init__(self, world: World, entity: str, trajectory: Trajectory, rate: float) -> None:
        self.world, self.entity = world, entity
        with world.lock:
            self.trajectory, clamped = _check_points(world, entity, trajectory)
            self.report = TrackingReport(
                entity, trajectory.joint_names, trajectory.duration, clamped=clamped
            )
            states = {s.name: s.position for s in world.joint_states(entity)}
            for joint in trajectory.joint_names:
                if joint not in states:
                    raise PartNotFoundError(entity, "joint", joint, list(states))
            # the start state is never refused (an arm may rest just past a limit, as the
            # controller takes it): the hold is clamped into the range, and so is the start
            start = {j: states[j] for j in trajectory.joint_names}
            commands = world.command_joints(entity, start, mode="position", clip=True)
            self.start = tuple(c.target for c in commands)
            self.keys = [c.actuator for c in commands]
            self._held = commands  # the servos it claimed, as the world holds them
            self._qpos_model, self.qpos = world.model, self._addresses(world.model)
            self.t0 = float(world.data.time)
            self._model, self._ids, self._last = None, None, None
            self._block = _References(self.trajectory, self.start, rate)
            self._period = 1.0 / UPDATE_RATE  # [s] ahead of the reference each target is
            self._max: np.ndarray | None = None  # the largest error so far, per joint
            self.handle = world.add_observer(self._update, rate)

    def _addresses(self, model: mujoco.MjModel) -> list[int]:
        """The followed joints' qpos addresses in `model`."""
        return [int(model.joint(f"{self.entity}/{j}").qposadr[0]) for j in self.start_names]

    @property
    def start_names(self) -> tuple[str, ...]:
        return self.trajectory.joint_names

    def _update(self) -> None:
        """One controller update (the world's lock is held): measure, then command.

        Runs at `rate` in sim time inside the stepping: the references come from a block
        sampled ahead (`_References`), and the errors are one numpy expression per update.
        """
        import numpy as np

        world = self.world
        t = float(world.data.time) - self.t0
        if t < -1e-9 or not self._holds_its_joints(world.commands()):
            self.stop()  # the world was reset, or a command released a joint's position servo
            return
        reference, nxt, speed = self._block.at(t)
        if world.model is not self._qpos_model:  # a spawn or delete moved the joints' addresses
            self._qpos_model, self.qpos = world.model, self._addresses(world.model)
        errors = np.abs(world.data.qpos[self.qpos] - reference)
        # fmax: a diverged step's NaN (the world resets that entity) does not stick in the report
        self._max = errors if self._max is None else np.fmax(self._max, errors)
        names = self.start_names
        self.report.max_error = dict(zip(names, self._max.tolist(), strict=True))
        done = t >= self.trajectory.duration - 1e-9
        if done:
            self.report.final_error = dict(zip(names, errors.tolist(), strict=True))
        self.report.elapsed = t
        self._write(reference, nxt, speed)
        if done:
            self.stop()

    def _holds_its_joints(self, commands: Mapping[str, JointCommand]) -> bool:
        """Whether every followed joint still has the position servo the follower claimed.

        Another command on one of them (`twin command`, in any mode) claims the joint's
        interface, as a ros2_control controller switch does, and the controller that held it
        stops: writing its targets into a velocity or effort servo would drive the joint in
        the wrong mode, and into a new position servo would undo the new target.
        """
        return all(commands.get(c.actuator) is c for c in self._held)

    def _write(self, reference: np.ndarray, positions: np.ndarray, speeds: np.ndarray) -> None:
        """Moves each position servo's target and damping reference: ctrl and the bias constant.

        Only those numbers change (see twin_cli.world.servos.follow), written as arrays; actuator
        ids and gains are looked up again after a recompile. The world's command records get the
        last reference when the follower stops.
        """
        import numpy as np

        world = self.world
        if self._model is not world.model:
            self._model = world.model
            self._ids = np.array([world.model.actuator(k).id for k in self.keys])
            commands = [world.commands()[k] for k in self.keys]
            gear = np.abs(world.model.actuator_gear[self._ids, 0])
            gear[gear == 0] = 1.0
            self._kv = np.array([c.kv for c in commands]) / gear
        bias = self._kv * speeds
        world.follow_references(self._ids, (reference, positions, self._period), bias)
        self._last = (positions, speeds)

    def _halt(self) -> dict[str, tuple[float, float]]:
        """Stops the servos it still holds where their references are now: a reference that
        ramps (ctrl) would otherwise run on with nothing updating it. Returns their targets
        (actuator → (position, feedforward 0)) for the world's command records."""
        from twin_cli.world import servos

        world, (positions, _) = self.world, self._last
        commands = world.commands()
        targets = {}
        for i, (key, held) in enumerate(zip(self.keys, self._held, strict=True)):
            if commands.get(key) is not held or self._model is not world.model:
                continue  # claimed by another command, or a recompile renumbered the servos
            a = int(self._ids[i])
            target = float(positions[i])
            if servos.has_reference(world.model, a):
                target = float(world.data.act[world.model.actuator_actadr[a]])
            world.hold_servo(a, 0.0 if servos.has_reference(world.model, a) else target)
            targets[key] = (target, 0.0)
        return targets

    def stop(self) -> None:
        """Stops updating; the joints it still holds stay at their last reference."""
        self.report.active = False
        self.world.remove_observer(self.handle)
        if self._last is not None:
            held = dict(zip(self.keys, self._held, strict=True))
            self.world.record_targets(self._halt(), held=held)


def _check_points(
    world: World, entity: str, trajectory: Trajectory
) -> tuple[Trajectory, dict[str, float]]:
    """The trajectory as it will be followed: a position at most `LIMIT_TOLERANCE` past its
    joint's range is clamped onto it, as ros2_control's joint limiters clamp a controller's
    commands; with, by joint, the largest such move [rad or m]. Refuses positions further out
    and velocities past the joint's limit (world unchanged)."""
    from twin_cli.world.joint_control import onto_range

    world.index_of(entity)  # raises EntityNotFoundError
    columns, clamped = [], {}
    for i, joint in enumerate(trajectory.joint_names):
        low, high, velocity = _joint_bounds(world.model, entity, joint)
        column = []
        for k, point in enumerate(trajectory.points):
            where = f"trajectory point {k} joint [{joint}] of [{entity}]"
            value = point.positions[i]
            near = onto_range(value, low, high)
            if near is None:
                raise InvalidRequestError(
                    where,
                    f"position {value:g} is outside [{low:g}, {high:g}]",
                    "keep positions inside the joint's range",
                )
            if near != value:
                clamped[joint] = max(clamped.get(joint, 0.0), abs(near - value))
            column.append(near)
            speed = point.velocities[i] if point.velocities else 0.0
            if abs(speed) > velocity:
                raise InvalidRequestError(
                    where, f"velocity {speed:g} exceeds the limit {velocity:g}",
                    "slow the trajectory down",
                )  # fmt: skip
        columns.append(column)
    points = tuple(
        replace(p, positions=tuple(column[k] for column in columns))
        for k, p in enumerate(trajectory.points)
    )
    return replace(trajectory, points=points), clamped


def _joint_bounds(model: mujoco.MjModel, entity: str, joint: str) -> tuple[float, float, float]:
    """A trajectory joint's position range [rad or m] and velocity limit (unbounded for a joint
    the model lacks: command_joints names it with the known ones).

    Raises: InvalidRequestError: the joint offers no position interface."""
    from twin_cli.world.joint_control import allowed_range, limits_of

    if f"{entity}/{joint}" not in _names(model):
        return -math.inf, math.inf, math.inf
    limits = limits_of(model, entity, joint)
    if "position" not in limits.modes:
        raise InvalidRequestError(
            f"trajectory joint [{joint}] of [{entity}]",
            f"its tags offer only {', '.join(limits.modes)}, and a trajectory drives "
            "position interfaces",
            f"leave it out of joint_names, or drive it with twin command --mode {limits.modes[0]}",
        )
    j = model.joint(f"{entity}/{joint}").id
    low, high = allowed_range(model, j, "position", limits, math.inf)
    return low, high, limits.velocity


def _names(model: mujoco.MjModel) -> set[str]:
    return {model.joint(j).name for j in range(model.njnt)}


_FOLLOWERS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()
_LOCK = threading.Lock()


def follow_trajectory(
    world: World, entity: str, trajectory: Trajectory, rate: float = UPDATE_RATE
) -> TrajectoryFollower:
    """Starts following `trajectory` on `entity` (replacing its running one); returns at once.

    Raises:
        EntityNotFoundError, PartNotFoundError, InvalidRequestError: the world is unchanged.
    """
    if not (math.isfinite(rate) and rate > 0):
        raise InvalidRequestError("trajectory rate", f"{rate} Hz", "give a rate > 0 Hz")
    with _LOCK:
        running = _FOLLOWERS.setdefault(world, {})
        follower = TrajectoryFollower(world, entity, trajectory, rate)
        old = running.get(entity)
        if old is not None and old.report.active:
            with world.lock:
                old.stop()
        running[entity] = follower
        return follower


def tracking_report(world: World, entity: str) -> dict | None:
    """The entity's last trajectory report, or None when it never followed one."""
    with _LOCK:
        follower = _FOLLOWERS.get(world, {}).get(entity)
    if follower is None:
        return None
    with world.lock:
        return follower.report.to_dict()


class _References:
    """The follower's references, sampled BLOCK updates at a time: at each update time k/rate
    [s] after the start, and 1/UPDATE_RATE later (the target it writes, as before: the servo
    tracks it until the next update)."""

    def __init__(self, trajectory: Trajectory, start: tuple[float, ...], rate: float) -> None:
        self.trajectory, self.start, self.rate = trajectory, start, rate
        self.first = 0  # update index of the block's first row
        self.rows: tuple = ()

    def at(self, t: float) -> tuple:
        """(reference, next target, its speed) at `t` [s]: rows of numpy arrays."""
        k = round(t * self.rate)
        if abs(t * self.rate - k) > 1e-6:  # off the update grid (not seen): sample it now
            import numpy as np

            now, _ = sample(self.trajectory, self.start, t)
            nxt, speed = sample(self.trajectory, self.start, t + 1.0 / UPDATE_RATE)
            return np.asarray(now), np.asarray(nxt), np.asarray(speed)
        if not self.rows or not self.first <= k < self.first + BLOCK:
            self._fill(k)
        reference, targets, speeds = self.rows
        row = k - self.first
        return reference[row], targets[row], speeds[row]

    def _fill(self, k: int) -> None:
        import numpy as np

        times = (k + np.arange(BLOCK)) / self.rate
        reference, _ = sample_block(self.trajectory, self.start, times)
        targets, speeds = sample_block(self.trajectory, self.start, times + 1.0 / UPDATE_RATE)
        self.first, self.rows = k, (reference, targets, speeds)


def sample_block(trajectory: Trajectory, start: tuple[float, ...], times: object) -> tuple:
    """`sample` at many increasing times [s] at once: (positions, velocities) as arrays of
    len(times) × joints. The follower takes its references a block at a time, so each of its
    updates only looks a row up."""
    import bisect

    import numpy as np

    t = np.asarray(times, dtype=float)
    points = trajectory.points
    positions = np.tile(np.asarray(points[-1].positions, dtype=float), (len(t), 1))
    velocities = np.zeros_like(positions)  # held after the end, at rest
    first = bisect.bisect_right([p.time for p in points], float(t[0])) if len(t) else len(points)
    for k in range(first, len(points)):
        before = points[k - 1] if k else TrajectoryPoint(0.0, tuple(start))
        after = points[k]
        rows = (t >= before.time) & (t < after.time) if k else t < after.time
        if rows.any():
            s, span = t[rows] - before.time, after.time - before.time
            for j in range(len(start)):
                p, v = segment(before, after, j, s, span)
                positions[rows, j], velocities[rows, j] = p, v
        if after.time > t[-1]:
            break
    return positions, velocities
