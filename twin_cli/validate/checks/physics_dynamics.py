"""Physics checks on dynamics: joint limits hold, inertia answers torque, stability.

Inertia oracle: with every joint locked, the robot is one rigid body; a torque τ at rest gives
α = I⁻¹τ (Euler's equations, ω = 0), where I is the composite inertia about the centre of mass,
summed in numpy from each link's mass, COM and inertia (parallel-axis theorem).
"""

from __future__ import annotations

import math

import numpy as np

from twin_cli.validate.checks.base import (
    CannotApply,
    RobotUnderTest,
    Series,
    Status,
    bars,
    judged,
    not_applicable,
    result,
)
from twin_cli.validate.checks.model_joints import SLIDE, limited_range
from twin_cli.validate.checks.sim import NO_BODY, ScenarioRun
from twin_cli.validate.scenario import Scenario

FREE = 0  # mjtJoint mjJNT_FREE
TINY_RAD_S = 1e-9  # [rad/s] the floor of the spin plot's log axis (a link that never turned)
REACHED_RAD = 0.01
"""A drive reached its stop when the joint came within this of it [rad or m]; a joint whose
velocity limit keeps it from crossing its range within the drive reaches neither stop."""


def _holding(run: ScenarioRun, settle: float) -> bool:
    """True while a drive action is active and past its first `settle` fraction (the impact)."""
    return any(
        a.kind == "drive" and a.at + settle * a.duration <= run.time <= a.at + a.duration
        for a in run.scenario.actions
    )


def _violations(run: ScenarioRun, settle: float) -> tuple[dict[int, float], dict[int, float]]:
    """Run the scenario; per joint (index into run.joints), max q above/below its range while
    a drive holds it against the limit (the impact transient before `settle` is left out)."""
    ranges = {i: limited_range(run.world.model, j.joint) for i, j in enumerate(run.joints)}
    ranges = {i: r for i, r in ranges.items() if r is not None and run.joints[i].effort}
    over = {i: -math.inf for i in ranges}
    under = {i: -math.inf for i in ranges}

    def sample(r: ScenarioRun) -> None:
        if not _holding(r, settle):
            return
        q = r.qpos()
        for i, (lo, hi) in ranges.items():
            value = float(q[r.joints[i].qpos])
            over[i] = max(over[i], value - hi)
            under[i] = max(under[i], lo - value)

    run.run(run.scenario.duration, sample, every=1)
    return over, under


def check_joint_limits(robot: RobotUnderTest, scenario: Scenario, th: dict[str, float]):
    """Each joint driven past its limit with its full effort stays within it."""
    run = ScenarioRun(robot, scenario)
    over, under = _violations(run, th["settle_fraction"])
    hints, worst, reached = [], 0.0, 0
    ratios: dict[str, float] = {}  # "joint upper" → violation over its tolerance
    model = run.world.model
    for i in over:
        joint = run.joints[i]
        slide = int(model.jnt_type[joint.joint]) == SLIDE
        tol = th["max_violation_m"] if slide else th["max_violation_rad"]
        unit = "m" if slide else "rad"
        lo, hi = limited_range(model, joint.joint)
        for side, amount, bound in (("upper", over[i], hi), ("lower", under[i], lo)):
            reached += amount > -REACHED_RAD
            worst = max(worst, amount / tol)
            ratios[f"{joint.name} {side}"] = max(amount / tol, 0.0)
            if amount > tol:
                enforced = "soft" if model.jnt_limited[joint.joint] else "not enforced"
                hints.append(
                    f"joint '{joint.name}' goes {amount:.3g} {unit} past its {side} limit "
                    f"{bound:.3g} {unit} under {joint.effort:.3g} N m: the limit is {enforced}; "
                    "check <limit> and the joint's stopErp/stopCfm"
                )
    if not over:
        return not_applicable(
            "joint_limits",
            "physics",
            "no joint to drive",
            "no joint has both a range and an effort limit to drive it against its stops "
            "(continuous joints, or <limit effort='0'>)",
        )
    return result(
        "joint_limits",
        "physics",
        Status.FAIL if hints else Status.PASS,
        f"{len(over)} joint(s) driven, {reached}/{2 * len(over)} stops reached, "
        f"worst {worst:.2f}× tolerance",
        f"≤ {th['max_violation_rad']:g} rad / {th['max_violation_m']:g} m past a limit",
        hints=hints,
        value=worst,
        series=[bars("past the limit", "× tolerance", ratios, 1.0, x_label="joint and stop")]
        if ratios
        else [],
    )


def rigid_copy(spec):
    """A copy of the robot with every joint but the root's free joint removed (one rigid body)."""
    import mujoco

    rigid = spec.copy()
    for group in (rigid.actuators, rigid.equalities, rigid.sensors, rigid.tendons, rigid.keys):
        for element in list(group):
            rigid.delete(element)
    for joint in list(rigid.joints):
        if joint.type != mujoco.mjtJoint.mjJNT_FREE:
            rigid.delete(joint)
    root = rigid.worldbody.first_body()
    if root is None:
        raise CannotApply(NO_BODY)
    if not any(j.type == mujoco.mjtJoint.mjJNT_FREE for j in rigid.joints):
        root.add_freejoint(name="rigid_free")
    rigid.option.gravity = [0.0, 0.0, 0.0]
    return rigid


def composite_inertia(model, data) -> np.ndarray:
    """Inertia [kg m²] (3×3, world frame) of all bodies about their common centre of mass."""
    masses = np.array(model.body_mass[1:])
    centres = np.array(data.xipos[1:])
    com = masses @ centres / masses.sum()
    total = np.zeros((3, 3))
    for b in range(1, model.nbody):
        rot = np.array(data.ximat[b]).reshape(3, 3)
        r = np.array(data.xipos[b]) - com
        total += rot @ np.diag(model.body_inertia[b]) @ rot.T
        total += model.body_mass[b] * (r @ r * np.eye(3) - np.outer(r, r))
    return total


def check_inertia(robot: RobotUnderTest, scenario: Scenario, th: dict[str, float]):
    """A known torque on the locked robot gives the angular acceleration its inertia predicts."""
    import mujoco

    model = rigid_copy(robot.spec).compile()
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    torque = np.array(th["torque_n_m"] * np.array([1.0, 2.0, 3.0]) / math.sqrt(14.0))
    root = 1
    data.xfrc_applied[root, 3:] = torque
    mujoco.mj_forward(model, data)
    free = next(j for j in range(model.njnt) if int(model.jnt_type[j]) == FREE)
    local = np.array(data.qacc[int(model.jnt_dofadr[free]) + 3 : int(model.jnt_dofadr[free]) + 6])
    measured = np.array(data.xmat[int(model.jnt_bodyid[free])]).reshape(3, 3) @ local
    predicted = np.linalg.solve(composite_inertia(model, data), torque)
    error = float(np.linalg.norm(measured - predicted) / np.linalg.norm(predicted))
    hints = []
    if error > th["rel_tol"]:
        hints.append(
            f"angular acceleration {np.round(measured, 4).tolist()} rad/s² under "
            f"{np.round(torque, 3).tolist()} N m, I⁻¹τ predicts {np.round(predicted, 4).tolist()}:"
            " the simulated inertia is not the declared one (armature on the free joint, or "
            "inertial frames lost in conversion)"
        )
    return judged(
        "inertia",
        "physics",
        f"|α − I⁻¹τ| / |I⁻¹τ| = {error:.2e}",
        f"≤ {th['rel_tol']:g}",
        hints,
        value=error,
        series=[
            bars(
                "angular acceleration error",
                "1",
                {"|α − I⁻¹τ| / |I⁻¹τ|": max(error, 1e-16)},  # a log axis cannot show 0
                th["rel_tol"],
                x_label="locked robot under a known torque τ",
                log=True,
            )
        ],
    )


def check_stability(robot: RobotUnderTest, scenario: Scenario, th: dict[str, float]):
    """No control for the scenario's time: no NaN, no MuJoCo warning, bounded energy and spin."""

    run = ScenarioRun(robot, scenario)
    start_energy = run.world.energy()  # and MuJoCo computes it at every step from now
    low, high = run.extent()
    scale = run.mass * 9.81 * max(float(high[2] - low[2]), 0.1)  # [J]
    peak, spin, finite = [start_energy], {b: 0.0 for b in run.bodies}, [True]
    times, gains = [0.0], [0.0]  # energy above the start, over m·g·h, per sample

    def sample(r: ScenarioRun) -> None:
        with r.world.lock:
            data = r.world.data
            finite[0] = finite[0] and bool(np.all(np.isfinite(data.qpos)))
            energy = float(np.sum(data.energy))
            peak[0] = max(peak[0], energy)
            times.append(r.time)
            gains.append((energy - start_energy) / scale)
            for b in r.bodies:
                spin[b] = max(spin[b], float(np.linalg.norm(data.cvel[b][:3])))

    run.run(scenario.duration, sample, every=10)
    gain = (peak[0] - start_energy) / scale
    hints = _stability_hints(run, finite[0], gain, spin, th)
    return judged(
        "stability",
        "physics",
        f"energy gain {gain:.2%} of m·g·h, max spin {max(spin.values()):.3g} rad/s",
        f"≤ {th['max_energy_gain']:.0%}, ≤ {th['max_spin_rad_s']:g} rad/s, 0 warnings",
        hints,
        value=gain,
        series=[
            Series(
                "energy gain over m·g·h",
                "1",
                tuple(times),
                {"E(t) − E(0)": tuple(gains)},
                threshold=th["max_energy_gain"],
            ),
            bars(
                "peak spin",
                "rad/s",
                {_link(run, b): max(w, TINY_RAD_S) for b, w in spin.items()},  # log: no 0
                th["max_spin_rad_s"],
                x_label="link (peak angular speed, no control)",
                log=True,
            ),
        ],
    )


def _link(run: ScenarioRun, body: int) -> str:
    return run.world.model.body(body).name.removeprefix(f"{run.entity}/")


def _stability_hints(run: ScenarioRun, finite: bool, gain: float, spin: dict, th: dict) -> list:
    hints = []
    warnings = run.warnings()
    divergences = int(getattr(run.world, "divergences", 0))
    if not finite or divergences:
        hints.append(
            "the state became NaN (the world reset the robot): look for tiny masses or "
            "inertias and overlapping collisions"
        )
    if warnings:
        hints.append(f"MuJoCo raised {warnings} warning(s) (instability or contact overflow)")
    if gain > th["max_energy_gain"]:
        hints.append(
            f"mechanical energy grew by {gain:.1%} of m·g·h with no control: contacts "
            "or joint limits inject energy; soften kp or lower the timestep"
        )
    model = run.world.model
    for b, w in sorted(spin.items(), key=lambda kv: -kv[1]):
        if w <= th["max_spin_rad_s"]:
            break
        hints.append(
            f"link '{_link(run, b)}' spins at {w:.3g} rad/s with no control: its inertia "
            f"{float(np.sum(model.body_inertia[b])):.3g} kg m² (trace) is too small for "
            f"{float(model.body_mass[b]):.3g} kg"
        )
    return hints
