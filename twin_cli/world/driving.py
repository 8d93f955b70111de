"""Driving a world's entities: world-frame pushes on links and joint targets for motors.

Functions of a world's state (`twin_cli.world.state`); the servo and push arithmetic lives in
`twin_cli.world.actuation`.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import replace

import mujoco

from converters.mjcf.export_servos import INTEGRAL_MARGIN
from twin_cli.errors import InvalidRequestError, ModeNotOfferedError, PartNotFoundError
from twin_cli.world import actuation as control
from twin_cli.world import (
    gravity_comp,
    joint_control,
    native_servos,
    servos,
    sleeping,
    velocity_motors,
)
from twin_cli.world.entities import EntityIndex, element_names
from twin_cli.world.state import WorldState
from twin_cli.world.values import finite_vector


def push(
    state: WorldState,
    name: str,
    force: tuple[float, float, float] = (0.0, 0.0, 0.0),
    torque: tuple[float, float, float] = (0.0, 0.0, 0.0),
    *,
    link: str | None = None,
    duration: float = 0.1,
) -> None:
    """Applies a world-frame force [N] and torque [N m] at a link's centre of mass.

    Lasts `duration` [s] of sim time, rounded to whole steps (at least one); pushes on the
    same link add up. `link` defaults to the entity's root body.
    """
    wrench = finite_vector("push force and torque", [*force, *torque], 6)
    if not (math.isfinite(duration) and duration > 0):
        raise InvalidRequestError(
            "push duration", f"{duration} s is not positive", "give a duration > 0 s"
        )
    with state.lock:
        ix = state.require(name)
        body = _link_name(state, name, ix, link)
        steps = max(1, round(duration / state.model.opt.timestep))
        state.pushes.append(control.Push(body, tuple(wrench), state.iterations + steps))
        control.apply_pushes(state.model, state.data, state.pushes, {body}, state.perturbation)


def perturb(state: WorldState, wrenches: dict[str, Sequence[float]]) -> None:
    """Sets a viewer's mouse perturbation: world-frame wrench [N, N m] per full body name.

    Replaces the previous perturbation (a drag is re-sent every frame; `{}` ends it) and is
    added to the pushes of `push` on the same body, never written over them. Unknown bodies
    are ignored (the viewer may still show a model from before a spawn or delete).
    """
    wrench = {b: tuple(finite_vector("perturbation", w, 6)) for b, w in wrenches.items()}
    with state.lock:
        touched = set(state.perturbation) | set(wrench)
        state.perturbation = wrench
        control.apply_pushes(state.model, state.data, state.pushes, touched, wrench)


def _link_name(state: WorldState, name: str, ix: EntityIndex, link: str | None) -> str:
    links = [
        n.removeprefix(f"{name}/")
        for n in element_names(state.model, state.model.name_bodyadr[ix.bodies])
        if not velocity_motors.is_rotor(n)  # a motor's reference, not a link to push
    ]
    if link is None and links:
        return f"{name}/{links[0]}"
    if link not in links:
        raise PartNotFoundError(name, "link", str(link), links)
    return f"{name}/{link}"


def command(state: WorldState, name: str, joint: str, *, mode: str, value: float) -> None:
    """Sets a joint's target: "position" [rad|m], "velocity" [rad/s|m/s] or "effort" [N m|N].

    Targets are clipped to what the joint allows (its range, velocity and effort limits);
    `command_joints` refuses them instead. The position and
    velocity servos never exceed the effort limit (see twin_cli.world.actuation).

    Raises:
        InvalidRequestError: unknown mode, or one the joint's control tags do not offer.
    """
    command_joints(state, name, {joint: value}, mode=mode, clip=True)


def command_joints(
    state: WorldState, name: str, targets: dict[str, float], *, mode: str, clip: bool = False
) -> list[control.JointCommand]:
    """Sets several joints' targets at once, all or none (`twin command`).

    Raises:
        EntityNotFoundError, PartNotFoundError: unknown entity or actuated joint.
        InvalidRequestError: unknown mode, a mode the joint does not offer, or (unless
            `clip`) a value outside the joint's limits (a position at most
            `joint_control.LIMIT_TOLERANCE` past its range is clamped onto it). On any
            error no command changes.
    """
    for joint, value in targets.items():
        _check_command(joint, mode, value)
    with state.lock:
        ix = state.require(name)
        checked = [_checked(state, name, ix, j, mode, v, clip) for j, v in targets.items()]
        positions = {
            int(state.model.jnt_qposadr[c[2]]): c[4] for c in checked if c[3] == "position"
        }
        loads = None  # tuning loads, looked up only for a command that tunes a servo
        if not all(
            _native(state, c) or _continues_speed(state, c) or _rotor(state, c) for c in checked
        ):
            dofs = state.model.jnt_dofadr[[c[2] for c in checked]]
            rolling = dofs if mode == "velocity" else dofs[:0]
            loads = joint_control.posture_loads(state.model, state.data, positions, dofs, rolling)
        commands = [_set_command(state, c, loads) for c in checked]
        gravity_comp.switch(state.model, state.commands)
        servos.keep_awake(state.model, state.commands)
        return commands


def _checked(
    state: WorldState, name: str, ix: EntityIndex, joint: str, mode: str, value: float, clip: bool
) -> tuple:
    a, j = _motor_of(state, name, ix, joint)
    limits = _offered(state, a, joint_control.limits_of(state.model, name, joint))
    if mode not in limits.modes:
        raise ModeNotOfferedError(name, joint, mode, limits.modes, limits.source)
    key = element_names(state.model, state.model.name_actuatoradr[[a]])[0]
    old = state.commands.get(key)
    effort = old.effort if old else control.effort_limit(state.model, a)
    low, high = joint_control.allowed_range(state.model, j, mode, limits, effort)
    near = joint_control.onto_range(value, low, high) if mode == "position" else None
    if clip:
        value = min(max(value, low), high)
    elif near is not None:  # on or just past a limit: clamped onto it, as ros2_control does
        value = near
    elif not low <= value <= high:
        raise InvalidRequestError(
            f"{mode} command for joint [{joint}] of [{name}]",
            f"{value:g} is outside [{low:g}, {high:g}] (the joint's limits)",
            "give a value inside that range",
        )
    return key, a, j, mode, float(value), effort, limits


def _native(state: WorldState, checked: tuple) -> bool:
    """Whether a checked command is in the mode of the model's own servo law."""
    law = state.native.get(checked[0])
    return law is not None and law.mode == checked[3]


def _rotor(state: WorldState, checked: tuple) -> bool:
    """Whether a checked command is a velocity that the joint's velocity motor runs."""
    _, a, _, mode, _, _, _ = checked
    return mode == "velocity" and velocity_motors.rotor_of(state.model, a) is not None


def _set_rotor(state: WorldState, checked: tuple) -> control.JointCommand:
    """Writes a velocity command into the joint's velocity motor (`twin_cli.world.velocity_motors`):
    the rotor's speed and the tendon's bound; no gains to tune."""
    key, a, _, _, value, effort, limits = checked
    cmd = control.JointCommand(
        key, "velocity", value, 0.0, 0.0, effort, limits.velocity, 0.0, velocity_motors.RULE
    )
    control.apply_command(state.model, state.data, a, cmd, state.native.get(key))
    state.commands[key] = cmd
    return cmd


def _set_command(state: WorldState, checked: tuple, loads: tuple | None) -> control.JointCommand:
    """Writes one checked command (`loads`: `joint_control.posture_loads`, None when no command
    tunes a servo)."""
    key, a, j, mode, value, effort, limits = checked
    previous = state.commands.get(key)
    law = state.native.get(key)
    if _rotor(state, checked):
        return _set_rotor(state, checked)
    if law is not None and law.mode == mode:
        return _set_native(state, (key, a, j, value, effort, limits), law, previous)
    if loads is None:
        return _set_speed(state, checked)
    inertia, _, carried = loads
    dof = int(state.model.jnt_dofadr[j])
    here = float(state.data.qpos[state.model.jnt_qposadr[j]])
    qvel = float(state.data.qvel[dof])
    step = abs(value - here) if mode == "position" else abs(value)
    reference = servos.has_reference(state.model, a)
    kp, kv, rule = joint_control.servo_rule(
        mode,
        limits,
        effort,
        float(inertia[dof]),
        state.model.opt.timestep,
        step,
        reference=reference,
        carried=float(carried[dof]),
    )
    was = servos.kind(previous) if previous else ""
    cmd = control.JointCommand(key, mode, value, kp, kv, effort, limits.velocity, 0.0, rule)
    if reference and previous and was == servos.kind(cmd) == "velocity":
        cmd = replace(cmd, kp=previous.kp, kv=previous.kv, rule=previous.rule)  # same integral
    elif (reference or law is not None) and servos.kind(cmd) == servos.HOLD:
        cmd = replace(cmd, kp=0.0, kv=0.0, rule=servos.HOLD_RULE)  # no servo: the joint's friction
    if reference:
        lead = 0.0
        if mode == "velocity" and cmd.kv > 0:
            before = previous.target if previous and previous.mode == mode else qvel
            lead = float(carried[dof]) * (value - before) / cmd.kv
        servos.start(state.model, state.data, a, cmd, was, lead)
    control.apply_command(state.model, state.data, a, cmd, law)
    state.commands[key] = cmd
    return cmd


def _continues_speed(state: WorldState, checked: tuple) -> bool:
    """Whether a checked command only changes the speed of a servo already running a non-zero
    speed: it keeps its gains, so the loads they were tuned on need no new look (a drive that
    steers by speed writes one at every step)."""
    key, a, _, mode, value, _, _ = checked
    previous = state.commands.get(key)
    return (
        mode == "velocity"
        and value != 0.0
        and previous is not None
        and previous.mode == "velocity"
        and previous.target != 0.0
        and previous.kp > 0.0
        and previous.kv > 0.0
        and key not in state.native
        and servos.has_reference(state.model, a)
    )


def _set_speed(state: WorldState, checked: tuple) -> control.JointCommand:
    """Writes a new speed into a running velocity servo (`_continues_speed`): its gains stay,
    and its reference steps back by the lag the change builds, on the inertia its integral gain
    was tuned for (`servos.gains` inverted)."""
    key, a, _, _, value, _, _ = checked
    previous = state.commands[key]
    carried = previous.kv**2 / (4.0 * INTEGRAL_MARGIN * previous.kp)
    cmd = replace(previous, target=value)
    lead = carried * (value - previous.target) / cmd.kv
    servos.start(state.model, state.data, a, cmd, "velocity", lead)
    control.apply_command(state.model, state.data, a, cmd, None)
    state.commands[key] = cmd
    return cmd


def _set_native(
    state: WorldState,
    target: tuple,
    law: native_servos.Law,
    previous: control.JointCommand | None,
) -> control.JointCommand:
    """Writes a command in the mode of the model's own servo: its law and ctrl, nothing else.
    An intvelocity taking over from another mode starts its integral at the joint, so the joint
    is not pulled back to where the integral was left."""
    key, a, j, value, effort, limits = target
    model, data = state.model, state.data
    if law.integrates and not (previous is not None and previous.native):
        data.act[model.actuator_actadr[a]] = data.qpos[model.jnt_qposadr[j]]
    cmd = control.JointCommand(
        key,
        law.mode,
        value,
        law.kp,
        law.kv,
        effort,
        limits.velocity,
        0.0,
        native_servos.rule(law),
        native=True,
    )
    control.apply_command(model, data, a, cmd, law)
    state.commands[key] = cmd
    return cmd


def start_commands(state: WorldState, names: Iterable[str]) -> None:
    """Holds the joints of each entity's own servos where they are, as from load (the lock is
    held): a position servo's target is its joint's position, a velocity servo's 0
    (`native_servos`). Gains come from the model: no posture is solved."""
    model, data = state.model, state.data
    for name in names:
        for a in state.require(name).actuators:
            key = model.actuator(int(a)).name
            law = state.native.get(key)
            if law is None and model.actuator_trntype[a] != mujoco.mjtTrn.mjTRN_JOINT:
                continue
            j = int(model.actuator_trnid[a, 0])
            joint = model.joint(j).name.removeprefix(f"{name}/")
            if law is None:
                _start_rotor(state, name, (key, int(a), j, joint))
                continue
            limits = joint_control.limits_of(model, name, joint)
            value = native_servos.start_value(model, data.qpos, int(a), law)
            effort = control.effort_limit(model, int(a))
            _set_native(state, (key, int(a), j, value, effort, limits), law, None)
    gravity_comp.switch(model, state.commands)
    servos.keep_awake(model, state.commands)


def _start_rotor(state: WorldState, name: str, motor: tuple) -> None:
    """Holds a joint whose velocity motor is on from load (`velocity_motors.engaged_at_load`) at
    speed 0, as the exported file does: a velocity command of 0."""
    key, a, j, joint = motor
    if key in state.commands or velocity_motors.rotor_of(state.model, a) is None:
        return
    effort = velocity_motors.engaged_at_load(joint_control.record_of(state.model, name, joint))
    if effort is not None:
        limits = joint_control.limits_of(state.model, name, joint)
        _set_rotor(state, (key, a, j, "velocity", 0.0, effort, limits))


def _actuated(m: mujoco.MjModel, ix: EntityIndex) -> dict[int, int]:
    """Joint id → id of the joint motor that drives it, for one entity (velocity motors'
    rotors are no joints of the entity's)."""
    names = element_names(m, m.name_actuatoradr[ix.actuators])
    return {
        int(m.actuator_trnid[a][0]): int(a)
        for a, n in zip(ix.actuators, names, strict=True)
        if m.actuator_trntype[a] == mujoco.mjtTrn.mjTRN_JOINT and not velocity_motors.is_rotor(n)
    }


def motor_joints(state: WorldState, name: str) -> set[str]:
    """The entity's joints that a joint motor drives (names without the entity prefix)."""
    m = state.model
    return {m.joint(j).name.removeprefix(f"{name}/") for j in _actuated(m, state.require(name))}


def _motor_of(state: WorldState, name: str, ix: EntityIndex, joint: str) -> tuple[int, int]:
    m = state.model
    j = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, f"{name}/{joint}")
    actuated = _actuated(m, ix)
    if j < 0 or j not in actuated:
        known = [
            n.removeprefix(f"{name}/") for n in element_names(m, m.name_jntadr[list(actuated)])
        ]
        raise PartNotFoundError(name, "actuated joint", joint, known)
    return actuated[j], j


def release_commands(
    state: WorldState,
    model: mujoco.MjModel,
    data: mujoco.MjData,
    dropped: Iterable[control.JointCommand],
) -> None:
    """Turns the motors of commands that no longer hold (a restore to a state without them) into
    motors at zero effort within their joints' effort limits, as an uncommanded motor is: a
    servo written for a command stays in the model until something else is written over it.
    An actuator with a servo law of its own gets that law back (its ctrl is the state's)."""
    for old in dropped:
        a = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, old.actuator)
        law = state.native.get(old.actuator)
        if a >= 0 and law is not None:
            native_servos.restore(model, a, law)
        elif a >= 0:
            limp = control.JointCommand(old.actuator, "effort", 0.0, 0.0, 0.0, old.effort)
            control.apply_command(model, data, a, limp)
            sleeping.hold_awake(model, sleeping.actuator_trees(model, (a,)), False)
        rotor = velocity_motors.rotor_of(model, a) if a >= 0 else None
        entity, _, joint = old.actuator.partition("/")
        held = velocity_motors.engaged_at_load(joint_control.record_of(model, entity, joint))
        if rotor is not None and held is not None:
            velocity_motors.engage(model, data, rotor, 0.0, held)  # as compiled: holding at speed 0
        elif rotor is not None:
            velocity_motors.disengage(model, data, rotor)


def reapply_commands(
    state: WorldState, model: mujoco.MjModel, data: mujoco.MjData, *, fresh: bool
) -> None:
    """Writes every joint command into a (re)compiled model, by actuator name, and switches
    fixed-base robots' gravity compensation and moving robots' sleep policy to match. A `fresh`
    model (just compiled) first gives the world its actuators' own servo laws. A command of a
    joint's own servo keeps the ctrl `data` carries: a trajectory moves that ctrl between its
    updates, and writing the command's first target back threw a Panda joint halfway along a
    1.5 rad move back towards its start at 6.3 rad/s when another entity was spawned."""
    if fresh:
        state.native = native_servos.capture(model)
    for actuator, cmd in state.commands.items():
        a = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, actuator)
        law = state.native.get(actuator)
        if a >= 0 and cmd.native and law is not None and law.mode == cmd.mode:
            native_servos.restore(model, a, law)
        elif a >= 0:
            control.apply_command(model, data, a, cmd, law)
    gravity_comp.switch(model, state.commands)
    servos.keep_awake(model, state.commands)


def record_targets(
    state: WorldState,
    targets: Mapping[str, tuple[float, float]],
    held: Mapping[str, control.JointCommand] | None = None,
) -> None:
    """Records where a controller left position servos (actuator → target, feedforward), so
    `twin joints` and a save show them. Skipped: commands that no longer exist, were switched
    to another mode since (whose targets are not positions), or, given `held` (the command
    objects the controller claimed), were replaced since, by a new command or controller."""
    with state.lock:
        for key, (target, feedforward) in targets.items():
            cmd = state.commands.get(key)
            if cmd is None or cmd.mode != "position":
                continue
            if held is not None and cmd is not held.get(key):
                continue
            state.commands[key] = replace(cmd, target=target, feedforward=feedforward)


def _check_command(joint: str, mode: str, value: float) -> None:
    if mode not in control.MODES:
        raise InvalidRequestError(
            f"command mode [{mode}]", "unknown", f"use one of {', '.join(control.MODES)}"
        )
    if not math.isfinite(value):
        raise InvalidRequestError(
            f"command value for joint [{joint}]", f"{value} is not finite", "give a finite number"
        )


def joint_commands(state: WorldState, name: str) -> dict[str, dict]:
    """Each actuated joint's mode, target, gains and limits (`twin joints`); lock held by caller.

    Joints without a command report mode "none" (zero effort), with the modes they offer.
    """
    model, ix = state.model, state.require(name)
    out = {}
    for a in ix.actuators:
        if model.actuator_trntype[a] != mujoco.mjtTrn.mjTRN_JOINT:
            continue  # a site actuator (a rotor's thrust or drag) drives no joint of its own
        key = element_names(model, model.name_actuatoradr[[a]])[0]
        if velocity_motors.is_rotor(key):
            continue  # a velocity motor's rotor: its joint's command shows it
        j = int(model.actuator_trnid[a][0])
        joint = element_names(model, model.name_jntadr[[j]])[0].removeprefix(f"{name}/")
        limits = _offered(state, int(a), joint_control.limits_of(model, name, joint))
        cmd = state.commands.get(key)
        out[joint] = {
            "mode": cmd.mode if cmd else "none",
            "target": cmd.target if cmd else None,
            "modes": list(limits.modes),
            "source": limits.source,
            "kp": cmd.kp if cmd else None,
            "kv": cmd.kv if cmd else None,
            "rule": cmd.rule if cmd else "",
            "velocity_limit": _finite(limits.velocity),
            "effort_limit": _finite(cmd.effort if cmd else control.effort_limit(model, int(a))),
            "effort_range": _effort_range(model, int(a), cmd),
        }
    return out


def _offered(
    state: WorldState, a: int, limits: joint_control.JointLimits
) -> joint_control.JointLimits:
    """`limits` with the modes actuator `a` can run: a plugin actuator reads ctrl its own way,
    so it takes its own servo's mode only (none when twin does not know the plugin)."""
    if state.model.actuator_plugin[a] < 0:
        return limits
    law = state.native.get(state.model.actuator(a).name)
    source = limits.source if limits.source != "model" else "MuJoCo"
    return replace(limits, modes=(law.mode,) if law is not None else (), source=source)


def _finite(value: float) -> float | None:
    return value if math.isfinite(value) else None


def _effort_range(
    model: mujoco.MjModel, actuator: int, cmd: control.JointCommand | None
) -> list[float | None]:
    """[low, high] force [N m or N] the joint's motor applies now (None where unbounded): the
    World's own servo's symmetric bound, else the actuator's range as the model states it."""
    if cmd is not None and not cmd.native:
        low, high = -cmd.effort, cmd.effort
    else:
        low, high = control.effort_range(model, actuator)
    return [_finite(float(low)), _finite(float(high))]


def set_controls(state: WorldState, actuators: Sequence[int], values: Sequence[float]) -> None:
    """Writes actuators' ctrl (a plugin's update: a planar drive's twist), waking the trees
    they move."""
    with state.lock:
        sleeping.wake_actuated(state.model, state.data, actuators)
        for a, value in zip(actuators, values, strict=True):
            state.data.ctrl[a] = value


def set_joint_forces(state: WorldState, dofs: Sequence[int], forces: Sequence[float]) -> None:
    """Applies generalised forces [N or N m] on dofs until changed (`qfrc_applied`)."""
    with state.lock:
        for dof, force in zip(dofs, forces, strict=True):
            state.data.qfrc_applied[dof] = force


def follow_references(
    state: WorldState,
    actuators: Sequence[int],
    references: tuple,
    bias: Sequence[float],
) -> None:
    """One trajectory controller update of position servos (`servos.follow`), waking them."""
    import numpy as np

    ids = np.asarray(actuators)
    with state.lock:
        own = np.array([_own_force(state, int(a)) for a in ids])
        servos.follow(state.model, state.data, ids, references, np.asarray(bias) + own)
        sleeping.wake_actuated(state.model, state.data, ids)


def hold_servo(state: WorldState, actuator: int, ctrl: float) -> None:
    """Stops a position servo where it is: `ctrl` and no speed feed-forward (the bias constant
    back to the servo's own, a Gazebo PID's `cmd_offset`)."""
    with state.lock:
        state.data.ctrl[actuator] = ctrl
        state.model.actuator_biasprm[actuator, 0] = _own_force(state, actuator)


def _own_force(state: WorldState, actuator: int) -> float:
    """The constant force [N m or N] actuator's own servo law adds (its `biasprm[0]`: a Gazebo
    PID's `cmd_offset`), which a trajectory's speed feed-forward goes on top of; 0 for others."""
    law = state.native.get(state.model.actuator(actuator).name)
    return law.offset if law is not None else 0.0
