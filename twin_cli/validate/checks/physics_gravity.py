"""Physics checks on gravity: free fall follows ½gt², zero gravity floats, Moon gravity scales.

The oracle is Newton's second law for the whole robot: internal joint forces cancel, so the
centre of mass falls at g × (share of mass that feels gravity) whatever the joints do. Links
with gravity off (Gazebo turnGravityOff → MuJoCo gravcomp) are taken out of that share.
"""

from __future__ import annotations

import numpy as np

from twin_cli.validate.checks.base import (
    CheckResult,
    RobotUnderTest,
    Series,
    bars,
    fmt_len,
    judged,
    not_applicable,
)
from twin_cli.validate.checks.sim import ScenarioRun
from twin_cli.validate.scenario import Scenario

TINY_M = 1e-12  # [m] the floor of the link-motion plot's log axis (a link that did not move)


def _skip_fixed(check: str, run: ScenarioRun) -> CheckResult:
    reason = "the robot is fixed to the world (no floating base): it cannot fall"
    return not_applicable(check, "physics", "fixed base", reason)


def _fall(run: ScenarioRun) -> tuple[np.ndarray, np.ndarray]:
    """Run the scenario; return sample times [s] and the COM displacement [m] (N, 3)."""
    start = run.subtree_com()
    times, positions = [0.0], [np.zeros(3)]

    def sample(r: ScenarioRun) -> None:
        times.append(r.time)
        positions.append(r.subtree_com() - start)

    run.run(run.scenario.duration, sample, every=10)
    return np.array(times), np.array(positions)


def gravity_share(run: ScenarioRun) -> float:
    """Fraction of the robot's mass that feels gravity (1 − gravcomp, mass-weighted)."""
    model = run.world.model
    felt = sum(model.body_mass[b] * (1.0 - model.body_gravcomp[b]) for b in run.bodies)
    return float(felt / run.mass) if run.mass > 0 else 1.0


def _expected_drop(run: ScenarioRun, t: np.ndarray) -> np.ndarray:
    g = float(np.linalg.norm(run.scenario.world.gravity_vector()))
    return 0.5 * g * gravity_share(run) * t**2


def _gravcomp_links(run: ScenarioRun) -> list[str]:
    model = run.world.model
    return [model.body(b).name for b in run.bodies if model.body_gravcomp[b] > 0]


def check_gravity(robot: RobotUnderTest, scenario: Scenario, th: dict[str, float]):
    """Free fall: the COM drop after `duration` matches ½gt² within `rel_tol`."""
    run = ScenarioRun(robot, scenario)
    if not run.floating:
        return _skip_fixed("gravity", run)
    t, disp = _fall(run)
    drop = -disp[:, 2]
    expected = _expected_drop(run, t)
    error = abs(drop[-1] - expected[-1]) / expected[-1]
    hints = []
    if error > th["rel_tol"]:
        off = _gravcomp_links(run)
        hints.append(
            f"the robot falls {fmt_len(drop[-1])} in {t[-1]:.2f} s instead of "
            f"{fmt_len(expected[-1])} (½gt²)"
            + (f"; links with gravity off: {', '.join(off)}" if off else "")
            + ": check <gravity>/turnGravityOff tags and dampingFactor on the links"
        )
    tol = th["rel_tol"]
    series = Series(
        "free fall",
        "m",
        tuple(t),
        {"measured drop": tuple(drop), "½gt²": tuple(expected)},
        band=(tuple(e * (1 - tol) for e in expected), tuple(e * (1 + tol) for e in expected)),
    )
    return judged(
        "gravity",
        "physics",
        f"drop {fmt_len(drop[-1])} ({error:.2%} off ½gt²)",
        f"≤ {th['rel_tol']:.0%} off",
        hints,
        value=error,
        series=[series],
    )


def check_moon_gravity(robot: RobotUnderTest, scenario: Scenario, th: dict[str, float]):
    """Moon gravity: the measured acceleration over Earth's is 1.62/9.81 within `rel_tol`."""
    run = ScenarioRun(robot, scenario)
    if not run.floating:
        return _skip_fixed("moon_gravity", run)
    t, disp = _fall(run)
    accel = 2.0 * -disp[-1, 2] / (t[-1] ** 2) / gravity_share(run)
    ratio, target = accel / 9.81, th["expected_ratio"]
    error = abs(ratio - target) / target
    hints = []
    if error > th["rel_tol"]:
        hints.append(
            f"measured acceleration {accel:.3f} m/s² is {ratio:.4f} of Earth's, expected "
            f"{target:.4f}: the world's gravity preset did not reach the robot"
        )
    # the apparent acceleration 2·drop/t² so far, as the verdict computes it at the end
    late = t > 0.1 * t[-1]  # early samples divide a tiny drop by a tiny t²
    ratios = 2.0 * -disp[late, 2] / t[late] ** 2 / gravity_share(run) / 9.81
    series = Series(
        "a over g_earth",
        "1",
        tuple(t[late]),
        {"measured 2·drop/t² / 9.81": tuple(ratios)},
        band=(
            tuple(np.full(len(ratios), target * (1 - th["rel_tol"]))),
            tuple(np.full(len(ratios), target * (1 + th["rel_tol"]))),
        ),
    )
    return judged(
        "moon_gravity",
        "physics",
        f"a/g_earth = {ratio:.4f}",
        f"{target:.4f} ± {th['rel_tol']:.0%}",
        hints,
        value=ratio,
        series=[series],
    )


def _constant_pushes(run: ScenarioRun) -> str:
    """The entity's constant actuator forces, by joint ("hinge 3 N m, …"): a Gazebo PID's
    `cmd_offset` (a servo's `biasprm[0]`, or the `JOINT:offset` push beside a pid plugin),
    which moves a joint nothing else loads, in Gazebo as here."""
    import mujoco

    from converters.mjcf.export_servos import PID_OFFSET_SUFFIX

    model, prefix = run.world.model, f"{run.entity}/"
    found = []
    for a in range(model.nu):
        name = model.actuator(a).name
        force = float(model.actuator_biasprm[a, 0])
        affine = int(model.actuator_biastype[a]) == int(mujoco.mjtBias.mjBIAS_AFFINE)
        if not name.startswith(prefix) or not force or not affine:
            continue  # only an affine bias's biasprm[0] is a constant force
        joint = name.removesuffix(PID_OFFSET_SUFFIX)
        j = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, joint)
        slide = j >= 0 and int(model.jnt_type[j]) == int(mujoco.mjtJoint.mjJNT_SLIDE)
        found.append(f"'{joint.removeprefix(prefix)}' {force:g} {'N' if slide else 'N m'}")
    return ", ".join(found)


def check_zero_gravity(robot: RobotUnderTest, scenario: Scenario, th: dict[str, float]):
    """Zero gravity: the robot floats; its COM and links stay where they started."""
    run = ScenarioRun(robot, scenario)
    with run.world.lock:
        start = np.array([run.world.data.xpos[b] for b in run.bodies])
    t, disp = _fall(run)
    with run.world.lock:
        end = np.array([run.world.data.xpos[b] for b in run.bodies])
    drift = float(np.max(np.linalg.norm(disp, axis=1)))
    moved = np.linalg.norm(end - start, axis=1)
    worst = int(np.argmax(moved))
    hints = []
    if drift > th["max_com_drift_m"]:
        pushes = _constant_pushes(run)
        by = f"; its controllers push constant forces ({pushes})" if pushes else ""
        hints.append(
            f"the centre of mass drifts {fmt_len(drift)} without gravity: something pushes the "
            f"robot (springs against the world, a non-zero gravity tag, or a diverging contact)"
            f"{by}"
        )
    if moved[worst] > th["max_link_motion_m"]:
        name = run.world.model.body(run.bodies[worst]).name.removeprefix(f"{run.entity}/")
        hints.append(
            f"link '{name}' moves {fmt_len(moved[worst])} without gravity or control: check its "
            "joint springs (springStiffness/springReference) and initial overlaps"
        )
    series = Series(
        "COM drift",
        "m",
        tuple(t),
        {"|COM − start|": tuple(np.linalg.norm(disp, axis=1))},
        threshold=th["max_com_drift_m"],
    )
    names = [run.world.model.body(b).name.removeprefix(f"{run.entity}/") for b in run.bodies]
    links = bars(
        "link motion",
        "m",
        {
            n: max(float(d), TINY_M) for n, d in zip(names, moved, strict=True)
        },  # a log axis has no 0
        th["max_link_motion_m"],
        x_label="link (distance from its start, no gravity, no control)",
        log=True,
    )
    return judged(
        "zero_gravity",
        "physics",
        f"COM drift {fmt_len(drift)}, links {fmt_len(float(moved.max()))}",
        f"≤ {fmt_len(th['max_com_drift_m'])}, ≤ {fmt_len(th['max_link_motion_m'])}",
        hints,
        value=drift,
        series=[series, links],
    )
