"""A model's own servos, run by ctrl alone: what the file gives a joint is what the World runs.

A robot's file gives some joints a MuJoCo servo bounded by its `forcerange`: a `position`
actuator (force = kp·(ctrl − q) − kv·q̇), an `intvelocity` (its activation integrates ctrl into a
position that a position servo tracks) or a `velocity` actuator (force = kv·(ctrl − q̇); a tag's
velocity PID is that law on an activation that follows ctrl within the step). twin's
export writes them for the joints a robot's tags command by position or velocity
(`converters.mjcf.export_servos`), and a World spawning a description writes the same ones, so a
Menagerie model, a `twin convert` file and the description it came from all carry their servos
in the model.

A command in a servo's own mode writes ctrl and nothing else: the served world,
`twin_cli.World` and the exported file step alike under any sequence of such commands. A command
in another mode (an arm's effort interface, a position target for a wheel) rewrites the
actuator on the model (`twin_cli.world.actuation`); the next command in the servo's own mode
writes its `Law` back, as captured from the freshly compiled model (`capture`).

From load every servo holds its joint where it spawned (`start_commands`: a position servo's
ctrl is the joint's position, a velocity servo's 0), as gz_ros2_control holds every joint it
commands before a controller claims it, and as the exported `home` keyframe's ctrl does.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import mujoco
import numpy as np

from converters.mjcf.export_servos import PID_PLUGIN
from twin_cli.world import speed_holds, velocity_motors
from twin_cli.world.servos import has_reference

FIELDS = (
    "gaintype",
    "gainprm",
    "biastype",
    "biasprm",
    "dyntype",
    "dynprm",
    "ctrllimited",
    "ctrlrange",
    "forcelimited",
    "forcerange",
    "actlimited",
    "actrange",
    "actearly",
)
BIASPRM = FIELDS.index("biasprm")
RULE = "the model's own {} servo: ctrl = target"  # what `twin joints` shows
ROTOR_THRUST = ":thrust"  # a rotor's joint motor (converters.gazebo.multicopter) is not a servo
_FIXED = int(mujoco.mjtGain.mjGAIN_FIXED)
_AFFINE = int(mujoco.mjtBias.mjBIAS_AFFINE)
_NONE = int(mujoco.mjtDyn.mjDYN_NONE)
_INTEGRATOR = int(mujoco.mjtDyn.mjDYN_INTEGRATOR)
_FOLLOW = int(mujoco.mjtDyn.mjDYN_FILTEREXACT)  # an activation that follows ctrl (actearly)
_JOINT = int(mujoco.mjtTrn.mjTRN_JOINT)


@dataclass(frozen=True)
class Law:
    """One actuator's servo as compiled.

    Attributes:
        mode: "position" or "velocity", the mode whose commands are its ctrl.
        kp, kv: its stiffness [N m/rad or N/m] (an intvelocity's integral gain; 0 for a
            velocity actuator) and damping [N m s/rad or N s/m].
        arrays: each `FIELDS` entry's row of the compiled model.
        friction: its joint's own dry friction (`frictionloss`, its solref and solimp), which
            a hold in another mode replaces (`hold`).
        ki: its integral gain [N m/(rad s) or N/(m s)] (a gz-sim PID's; 0 for the others).
    """

    mode: str
    kp: float
    kv: float
    arrays: tuple[tuple[str, np.ndarray], ...]
    friction: tuple[float, np.ndarray, np.ndarray]
    ki: float = 0.0

    @property
    def offset(self) -> float:
        """Its constant force [N m or N], `biasprm[0]` (a Gazebo PID's `cmd_offset`)."""
        return float(self.arrays[BIASPRM][1][0])

    @property
    def integrates(self) -> bool:
        """Whether its activation integrates ctrl (an `intvelocity`)."""
        return int(dict(self.arrays)["dyntype"]) == _INTEGRATOR


def mode_of(model: mujoco.MjModel, a: int) -> str | None:
    """The mode of actuator `a`'s servo law as the model has it now, or None if it is none of
    the three (a motor, a World reference servo, a filtered or geared actuator); a gz-sim PID
    with an integral, MuJoCo's pid actuator plugin, is a position servo."""
    if int(model.actuator_trntype[a]) != _JOINT or float(model.actuator_gear[a, 0]) != 1.0:
        return None
    if int(model.actuator_plugin[a]) >= 0:
        return "position" if pid_gains(model, a) is not None else None
    if int(model.actuator_gaintype[a]) != _FIXED or int(model.actuator_biastype[a]) != _AFFINE:
        return None
    gain = float(model.actuator_gainprm[a, 0])
    bias = model.actuator_biasprm[a, :3]
    dyn = int(model.actuator_dyntype[a])
    if gain <= 0.0 or has_reference(model, a):  # bias[0]: a PID's constant offset (cmd_offset)
        return None
    if bias[1] == -gain and dyn in (_NONE, _INTEGRATOR):
        return "position" if dyn == _NONE else "velocity"
    follows = dyn == _FOLLOW and bool(model.actuator_actearly[a])  # a tag's velocity PID
    if bias[1] == 0.0 and bias[2] == -gain and (dyn == _NONE or follows):
        return "velocity"
    return None


def capture(model: mujoco.MjModel) -> dict[str, Law]:
    """Every servo law of a freshly compiled `model`, by actuator name."""
    names = {model.actuator(a).name for a in range(model.nu)}
    laws = {}
    for a in range(model.nu):
        mode = mode_of(model, a)
        name = model.actuator(a).name
        if mode is None or name + ROTOR_THRUST in names or velocity_motors.is_rotor(name):
            continue
        integrates = int(model.actuator_dyntype[a]) == _INTEGRATOR
        gain = float(model.actuator_gainprm[a, 0])
        kp = gain if mode == "position" or integrates else 0.0
        kv = -float(model.actuator_biasprm[a, 2])
        pid = pid_gains(model, a)
        ki = 0.0
        if pid is not None:
            kp, ki, kv = pid
        rows = tuple((f, np.array(getattr(model, f"actuator_{f}")[a])) for f in FIELDS)
        dof = _dof(model, a)
        friction = (
            float(model.dof_frictionloss[dof]),
            model.dof_solref[dof].copy(),
            model.dof_solimp[dof].copy(),
        )
        laws[name] = Law(mode, kp, kv, rows, friction, ki)
    return laws


def pid_gains(model: mujoco.MjModel, a: int) -> tuple[float, float, float] | None:
    """(kp, ki, kd) of actuator `a` if it is a position PID run by MuJoCo's pid actuator plugin
    (a gz-sim PID, `converters.mjcf.export_servos`, or a file's own), else None: read from its
    instance's config, whose values the model stores in the plugin's attribute order."""
    instance = int(model.actuator_plugin[a])
    if instance < 0 or int(model.plugin[instance]) != _pid_slot():
        return None
    if int(model.actuator_dyntype[a]) != _NONE:
        return None  # ctrl filtered or integrated first: not a position target
    start = int(model.plugin_attradr[instance])
    end = int(model.plugin_attradr[instance + 1]) if instance + 1 < model.nplugin else None
    values = bytes(model.plugin_attr[start:end]).split(b"\0")
    kp, ki, kd = (float(v) if v else 0.0 for v in values[:3])
    return kp, ki, kd


def restore(model: mujoco.MjModel, a: int, law: Law) -> None:
    """Writes `law` back into actuator `a` of `model`, and its joint's own friction."""
    for field, row in law.arrays:
        getattr(model, f"actuator_{field}")[a] = row
    lift(model, a, law)


def lift(model: mujoco.MjModel, a: int, law: Law) -> None:
    """Gives actuator `a`'s joint its own dry friction back (a no-op when nothing held it)."""
    dof = _dof(model, a)
    model.dof_frictionloss[dof], model.dof_solref[dof], model.dof_solimp[dof] = law.friction


def hold(model: mujoco.MjModel, a: int, law: Law, effort: float) -> None:
    """A velocity of 0 on a joint whose own servo is a position servo: the joint's dry friction
    plus `effort` [N m or N] (`twin_cli.world.speed_holds`), the actuator pushing nothing."""
    restore(model, a, law)
    model.actuator_dyntype[a] = _NONE
    speed_holds.hold(model, a, law.friction[0], effort)


def _dof(model: mujoco.MjModel, a: int) -> int:
    return int(model.jnt_dofadr[model.actuator_trnid[a, 0]])


def start_value(model: mujoco.MjModel, qpos: np.ndarray, a: int, law: Law) -> float:
    """The ctrl that holds actuator `a`'s joint where `qpos` has it: its position, or speed 0."""
    if law.mode == "velocity":
        return 0.0
    joint = int(model.actuator_trnid[a, 0])
    return float(qpos[model.jnt_qposadr[joint]])


def rule(law: Law) -> str:
    """What `twin joints` shows for a command run by `law`."""
    kind = "intvelocity" if law.integrates else law.mode
    if law.ki:
        return RULE.format(f"pid (ki {law.ki:g})")
    return RULE.format(kind)


def velocity_limit(model: mujoco.MjModel, actuator: str) -> float:
    """The velocity limit [rad/s or m/s] the joint's control record gives (inf: none)."""
    from twin_cli.world.joint_control import limits_of

    entity, _, joint = actuator.rpartition("/")
    return limits_of(model, entity, joint).velocity


@functools.cache
def _pid_slot() -> int:
    """The registry slot of MuJoCo's `mujoco.pid` plugin in this process (-1 if absent): each
    model names its plugins by slot."""
    spec = mujoco.MjSpec()
    spec.activate_plugin(PID_PLUGIN)
    body = spec.worldbody.add_body()
    body.add_joint(name="j", type=mujoco.mjtJoint.mjJNT_SLIDE)
    body.add_geom(size=[0.1, 0, 0])
    instance = spec.add_plugin(name="pid", plugin_name=PID_PLUGIN)
    instance.active = True
    actuator = spec.add_actuator(target="j", trntype=mujoco.mjtTrn.mjTRN_JOINT)
    actuator.plugin = instance
    try:
        return int(spec.compile().plugin[0])
    except ValueError:
        return -1
