"""gz-sim's JointTrajectoryController read as gz-sim reads it, for twin's trajectory follower.

The system controls each joint it names (`<joint_name>`, repeatable; every 1-axis joint of the
model when none is named) with a position PID on (q − q*) and a velocity PID on (q̇ − q̇*),
summed into the joint's force; each per-joint parameter is a repeatable tag taken in the joints'
order, and a joint past the end of a list gets gz-sim's default (gains 0, `initial_position` 0,
no output limit while `cmd_max` < `cmd_min`). Before any trajectory the PIDs hold
`initial_position`. Trajectories arrive on `<topic>` (default `/model/<model>/joint_trajectory`)
and progress goes to `<topic>_progress`.

twin runs the joints as position servos with the plugin's gains: kp = position_p_gain and
kv = position_d_gain + velocity_p_gain (both terms act on the joint's speed), within the sum of
the two PIDs' output limits, with the sum of their `cmd_offset` forces as the servo's constant
force; `twin trajectory ENTITY FILE` sends a trajectory. The joints start at
their initial positions (the spawn posture) rather than being driven there from 0. A joint whose
gains are all 0 gets only its PIDs' `cmd_offset` and a trajectory's effort from gz-sim: twin
leaves it limp, in the model's own posture, on a torque motor that takes effort commands, with
the offset as a constant force beside it. The velocity PID's unbounded integral is a spring on
where the joint started (`_pid`): twin anchors it at the spawn posture, gz-sim at the posture
before its PIDs drove the joint to `initial_position`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from converters.description.gazebo import Blob
from converters.errors import GazeboTagError
from converters.gazebo.drive_records import UNBOUNDED, TrajectoryDrive
from converters.gazebo.plugin_params import Params

if TYPE_CHECKING:
    import mujoco

    from converters.gazebo.drive_readers import ReadContext

HOME_KEY = "home"  # the spawn posture (converters.mjcf.builder)
PIDS = ("position", "velocity")  # the two PIDs per joint, as their tags' prefixes

USED = {
    "joint_name",
    "initial_position",
    "position_p_gain",
    "position_d_gain",
    "position_cmd_min",
    "position_cmd_max",
    "position_cmd_offset",
    "velocity_p_gain",
    "velocity_i_gain",  # unbounded: a spring on the reference (`_pid`)
    "velocity_cmd_min",
    "velocity_cmd_max",
    "velocity_cmd_offset",
    "topic",
}
APPROXIMATED = (
    "joints as position servos with kp = position_p_gain (+ velocity_i_gain, an unbounded "
    "velocity integral being a spring on the reference) and kv = position_d_gain + "
    "velocity_p_gain, following twin trajectory's spline instead of stepping its targets from "
    "point to point; they start at initial_position instead of being driven there from 0, and "
    "hold it once commanded (twin trajectory, twin command), not from the first step",
)

BOUNDED_NOTE = (
    "velocity_i_gain within [velocity_i_min, velocity_i_max]: a bounded velocity integral is "
    "no spring MuJoCo can hold; not run"
)


def read_joint_trajectory_controller(p: Params, blob: Blob, ctx: ReadContext) -> TrajectoryDrive:
    """gz-sim JointTrajectoryController: per-joint PIDs towards a trajectory's points.

    Raises:
        GazeboTagError: a value is not a number, or no joint is named and none can be found.
    """
    joints = p.names("joint_name") or _one_axis_joints(ctx)
    if not joints:
        raise GazeboTagError(p.source, "", "plugin/joint_name", "", "a joint of the model")
    count = len(joints)
    pids = tuple(_pid(p, i) for i in range(count))
    limp = [j for j, pid in zip(joints, pids, strict=True) if pid is None]
    bounded = [
        j
        for i, j in enumerate(joints)
        if _nth(p.numbers("velocity_i_gain"), i, 0.0) and not _unbounded_velocity_integral(p, i)
    ]
    topic = p.text(f"/model/{ctx.model}/joint_trajectory", "topic")
    limp_note = (
        f"{', '.join(limp)}: gains all 0, so gz-sim pushes only cmd_offset and a trajectory's "
        "efforts: limp, on a torque motor (effort commands; twin trajectory files carry no "
        "efforts)"
    )
    return TrajectoryDrive(
        name=blob.name or "JointTrajectoryController",
        where=blob.where,
        joints=joints,
        initial_positions=_nth_all(p.numbers("initial_position", signed=True), count, 0.0),
        pids=pids,
        force_ranges=tuple(_bound(p, i) for i in range(count)),
        force_offsets=tuple(_offset(p, i) for i in range(count)),
        topic=topic,
        progress_topic=f"{topic}_progress",
        notes=((limp_note,) if limp else ())
        + ((f"{', '.join(bounded)}: {BOUNDED_NOTE}",) if bounded else ()),
    )


def _one_axis_joints(ctx: ReadContext) -> tuple[str, ...]:
    """Every hinge and slide joint of the model, in the model's order."""
    import mujoco

    if ctx.geometry is None:
        return ()
    moving = (mujoco.mjtJoint.mjJNT_HINGE, mujoco.mjtJoint.mjJNT_SLIDE)
    return tuple(j.name for j in ctx.geometry.spec.joints if j.type in moving)


def _nth(values: tuple[float, ...], i: int, default: float) -> float:
    return values[i] if i < len(values) else default


def _nth_all(values: tuple[float, ...], count: int, default: float) -> tuple[float, ...]:
    return tuple(_nth(values, i, default) for i in range(count))


def _pid(p: Params, i: int) -> tuple[float, float, float] | None:
    """(kp, 0, kv) of joint `i`'s servo, or None when its gains are all 0.

    The velocity PID's integral, i·∫(q̇ − q̇*)dt, is i·(q − q_ref) with q_ref where the joint
    started plus the trajectory's integrated speed: a spring on the position reference, as the
    position PID's p is. Unbounded (gz-sim's default, `velocity_i_max` < `velocity_i_min`) it
    adds to kp; a bounded one is left out and reported."""
    kp = _nth(p.numbers("position_p_gain"), i, 0.0)
    if _unbounded_velocity_integral(p, i):
        kp += _nth(p.numbers("velocity_i_gain"), i, 0.0)
    kv = _nth(p.numbers("position_d_gain"), i, 0.0) + _nth(p.numbers("velocity_p_gain"), i, 0.0)
    return (kp, 0.0, kv) if kp or kv else None


def _unbounded_velocity_integral(p: Params, i: int) -> bool:
    """Whether joint `i`'s velocity integral is unbounded: gz-math clamps it to [i_min, i_max]
    only when i_max ≥ i_min (defaults 0 and -1: no clamp)."""
    low = _nth(p.numbers("velocity_i_min", signed=True), i, 0.0)
    return _nth(p.numbers("velocity_i_max", signed=True), i, -1.0) < low


def _offset(p: Params, i: int) -> float:
    """Joint `i`'s constant force [N m or N]: gz-math adds each PID's `cmd_offset` to its output
    whatever its gains, and the system sums the two outputs."""
    return sum(_nth(p.numbers(f"{pid}_cmd_offset", signed=True), i, 0.0) for pid in PIDS)


def _bound(p: Params, i: int) -> tuple[float, float]:
    """Joint `i`'s force range [N m or N]: the sums of the two PIDs' output limits, each PID
    clamped to its own [cmd_min, cmd_max] (gz-sim's ignition::math::PID leaves the output free
    while cmd_max < cmd_min)."""
    total_low, total_high = 0.0, 0.0
    for pid in PIDS:
        low = _nth(p.numbers(f"{pid}_cmd_min", signed=True), i, 0.0)
        high = _nth(p.numbers(f"{pid}_cmd_max", signed=True), i, -1.0)
        gains = [_nth(p.numbers(f"{pid}_{g}_gain"), i, 0.0) for g in ("p", "i", "d")]
        if not any(gains) and not _nth(p.numbers(f"{pid}_cmd_offset", signed=True), i, 0.0):
            continue  # a PID without gains or offset adds no force
        if high < low:
            return UNBOUNDED
        total_low, total_high = total_low + low, total_high + high
    return (total_low, total_high) if total_high > total_low else UNBOUNDED


def start_at_initial_positions(spec: mujoco.MjSpec, record: TrajectoryDrive) -> None:
    """Puts the record's initial positions (clamped into each joint's range) in the spec's
    spawn posture, the `home` key, so the robot starts where the plugin's PIDs would hold it."""
    import mujoco

    key = next((k for k in spec.keys if k.name == HOME_KEY), None)
    if key is None:
        return
    model = spec.copy().compile()
    qpos = np.array(key.qpos, dtype=float)
    rows = zip(record.joints, record.initial_positions, record.pids, strict=True)
    for joint, value, pid in rows:
        j = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, joint)
        if j < 0 or pid is None:  # a limp joint: gz-sim never drives it to its initial position
            continue
        if model.jnt_limited[j]:
            value = float(np.clip(value, *model.jnt_range[j]))
        qpos[model.jnt_qposadr[j]] = value
    key.qpos = qpos
