"""gz-sim's MulticopterMotorModel (and Gazebo Classic's motor model) as MuJoCo actuators per rotor.

Per rotor, with ω the rotor speed [rad/s] and k = motorConstant [N s²/rad²]:

- thrust k·ω|ω| along the rotor link's z and the yaw moment −dir·momentConstant·thrust about it
  (dir = +1 ccw, −1 cw) are one site actuator `<joint>:thrust`, gear (0, 0, 1, 0, 0,
  −dir·momentConstant), on a site `rotor:<joint>` fixed to the rotor's parent body at the rotor
  link's origin and orientation: the moment goes to the parent as gz-sim applies it, and the
  spinning joint does not carry it;
- rotor drag −|ω|·rotorDragCoefficient·v⊥ is two site actuators `<joint>:drag_x`/`:drag_y`
  along the site's x and y: their length velocity is the rotor's velocity perpendicular to its
  axis, and an affine gain (gain = −C·velocity) times the activation |ω| gives the drag;
- the motor lag is MuJoCo's `filterexact` on every one of them (the thrust filters ω|ω|, the drag
  |ω|), dynprm[0] the time constant in force; dynprm[1] and dynprm[2] keep timeConstantUp and
  timeConstantDown (MuJoCo's filter reads only dynprm[0]), and each command picks one, as the
  plugin's filter does by the sign of the change;
- the rotor joint gets a joint actuator named after it, gear dir·rotorVelocitySlowdownSim, so its
  length velocity is the rotor speed the plugin reads (joint speed × slowdown): the world's
  velocity servo spins the joint at dir·ω/slowdown, lagged by the same filter, as gz-sim shows it.

The rolling moment −|ω|·rollingMomentCoefficient·v⊥ is a torque driven by a linear velocity; a
MuJoCo actuator's force and its velocity share one gear, so that coupling would need code at every
step and is not applied (reported).
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from converters.control_text import set_control_record
from converters.description.gazebo import Blob
from converters.errors import GazeboTagError
from converters.report import Report

if TYPE_CHECKING:
    import mujoco

MOTOR_MODEL_FILES = (
    "gz-sim-multicopter-motor-model-system",
    "libgz-sim-multicopter-motor-model-system.so",
    "ignition-gazebo-multicopter-motor-model-system",
    "libignition-gazebo-multicopter-motor-model-system.so",
    "libgazebo_motor_model.so",
)
MOTOR_MODEL_NAMES = ("gz::sim::systems::MulticopterMotorModel",)
SOURCE = "multicopter_motor_model"
THRUST, DRAG = ":thrust", (":drag_x", ":drag_y")
# The plugin's defaults (gz-sim MulticopterMotorModelPrivate).
DEFAULTS = {
    "timeConstantUp": 1.0 / 80.0,  # [s]
    "timeConstantDown": 1.0 / 40.0,  # [s]
    "maxRotVelocity": 838.0,  # [rad/s]
    "motorConstant": 8.54858e-06,  # [N s²/rad²]
    "momentConstant": 0.016,  # [m]
    "rotorDragCoefficient": 1.0e-4,  # [N s²/rad/m]
    "rollingMomentCoefficient": 1.0e-6,  # [N s²/rad]
    "rotorVelocitySlowdownSim": 10.0,
}


@dataclass(frozen=True)
class Rotor:
    """One MulticopterMotorModel plugin, typed (SI units).

    Attributes:
        joint, link: the rotor joint and link; direction: +1 ccw, −1 cw; motor_number: its index
        in the actuator command; time_constant_up/down [s]; max_rot_velocity [rad/s];
        motor_constant [N s²/rad²]; moment_constant [m]; rotor_drag [N s²/rad/m];
        rolling_moment [N s²/rad]; slowdown: rotorVelocitySlowdownSim; motor_type; where.
    """

    joint: str
    link: str
    direction: int
    motor_number: int
    time_constant_up: float
    time_constant_down: float
    max_rot_velocity: float
    motor_constant: float
    moment_constant: float
    rotor_drag: float
    rolling_moment: float
    slowdown: float
    motor_type: str
    where: str

    def to_dict(self) -> dict[str, Any]:
        """Plain values for JSON."""
        return dict(self.__dict__)


def is_motor_model(blob: Blob) -> bool:
    """Whether the plugin is the multicopter motor model (by filename or system name)."""
    filename = (blob.kind or "").rsplit("/", 1)[-1]
    return filename in MOTOR_MODEL_FILES or (blob.name or "") in MOTOR_MODEL_NAMES


def missing_names(blob: Blob) -> str | None:
    """Why gz-sim would not start this motor model (no jointName or linkName), or None."""
    root = ET.fromstring(blob.xml)
    missing = [tag for tag in ("jointName", "linkName") if not _text(root, tag)]
    return f"no <{'>, <'.join(missing)}>, so gz-sim does not start it" if missing else None


def read_rotor(blob: Blob, source: str) -> Rotor | None:
    """The motor model's parameters from its verbatim XML, with the plugin's defaults; None
    when it names no joint or link (gz-sim then fails to start it; reported by `plugins`).

    Raises:
        GazeboTagError: a turningDirection other than cw/ccw, a motorType other than velocity,
            or a parameter that is not a finite number >= 0.
    """
    if missing_names(blob):
        return None
    root = ET.fromstring(blob.xml)
    joint, link = _text(root, "jointName"), _text(root, "linkName")
    turning = _text(root, "turningDirection") or "cw"  # the plugin's default
    if turning not in ("cw", "ccw"):
        raise GazeboTagError(source, "", "plugin/turningDirection", turning, "cw or ccw")
    motor_type = _text(root, "motorType") or "velocity"
    if motor_type != "velocity":
        raise GazeboTagError(source, "", "plugin/motorType", motor_type, "velocity (the only one)")
    number = _number(root, source, "motorNumber", 0.0)
    values = {tag: _number(root, source, tag, default) for tag, default in DEFAULTS.items()}
    return Rotor(
        joint=joint,
        link=link,
        direction=1 if turning == "ccw" else -1,
        motor_number=int(_number(root, source, "actuator_number", number)),
        time_constant_up=values["timeConstantUp"],
        time_constant_down=values["timeConstantDown"],
        max_rot_velocity=values["maxRotVelocity"],
        motor_constant=values["motorConstant"],
        moment_constant=values["momentConstant"],
        rotor_drag=values["rotorDragCoefficient"],
        rolling_moment=values["rollingMomentCoefficient"],
        slowdown=values["rotorVelocitySlowdownSim"] or 1.0,
        motor_type=motor_type,
        where=blob.where,
    )


def _text(root: ET.Element, tag: str) -> str:
    el = root.find(tag)
    return (el.text or "").strip() if el is not None else ""


def _number(root: ET.Element, source: str, tag: str, default: float) -> float:
    text = _text(root, tag)
    if not text:
        return default
    try:
        value = float(text)
    except ValueError as exc:
        raise GazeboTagError(source, "", f"plugin/{tag}", text, "a number") from exc
    if not math.isfinite(value) or value < 0:
        raise GazeboTagError(source, "", f"plugin/{tag}", text, "a finite number >= 0")
    return value


def add_rotors(spec: mujoco.MjSpec, rotors: tuple[Rotor, ...], report: Report) -> None:
    """Gives each rotor its site, thrust, drag and spin actuators (see the module docstring).

    Raises:
        GazeboTagError: the plugin's joint is not a joint of the model, or its link is not the
            joint's child body.
    """
    for rotor in rotors:
        joint, body = _rotor_parts(spec, rotor)
        body.parent.add_site(name=f"rotor:{rotor.joint}", pos=body.pos, quat=body.quat)
        _thrust(spec, rotor)
        if rotor.rotor_drag > 0:
            _drag(spec, rotor)
        _spin(spec, rotor, joint.name)
        report.mapped(
            "model",
            f"rotor '{rotor.joint}' ({'ccw' if rotor.direction > 0 else 'cw'}, motor "
            f"{rotor.motor_number}): thrust, yaw moment, rotor drag and motor lag as actuators"
            f"{'; rolling moment not applied' if rotor.rolling_moment > 0 else ''}",
            tag="plugin",
        )


def _rotor_parts(spec: mujoco.MjSpec, rotor: Rotor) -> tuple[Any, Any]:
    model = spec.modelname or "model"
    joint = spec.joint(rotor.joint)
    if joint is None:
        raise GazeboTagError(model, "", "plugin/jointName", rotor.joint, "a joint of the model")
    body = spec.body(rotor.link)
    if body is None or joint.parent.name != body.name:
        raise GazeboTagError(model, "", "plugin/linkName", rotor.link, "the rotor joint's child")
    return joint, body


def _filtered(spec: mujoco.MjSpec, name: str, rotor: Rotor, gear: Sequence[float]) -> Any:
    """A site actuator whose activation follows ctrl with the motor's lag (filterexact)."""
    import mujoco

    actuator = spec.add_actuator(name=name, target=f"rotor:{rotor.joint}")
    actuator.trntype = mujoco.mjtTrn.mjTRN_SITE
    actuator.gear = np.array(gear)
    _lag(actuator, rotor)
    return actuator


def _lag(actuator: Any, rotor: Rotor) -> None:
    import mujoco

    actuator.dyntype = mujoco.mjtDyn.mjDYN_FILTEREXACT
    prm = np.zeros(10)
    prm[:3] = (rotor.time_constant_up, rotor.time_constant_up, rotor.time_constant_down)
    actuator.dynprm = prm


def _thrust(spec: mujoco.MjSpec, rotor: Rotor) -> None:
    moment = -rotor.direction * rotor.moment_constant
    actuator = _filtered(spec, rotor.joint + THRUST, rotor, [0, 0, 1, 0, 0, moment])
    gain = np.zeros(10)
    gain[0] = rotor.motor_constant  # ctrl ω|ω| [rad²/s²] → thrust [N]
    actuator.gainprm = gain


def _drag(spec: mujoco.MjSpec, rotor: Rotor) -> None:
    import mujoco

    for suffix, gear in zip(DRAG, ([1, 0, 0, 0, 0, 0], [0, 1, 0, 0, 0, 0]), strict=True):
        actuator = _filtered(spec, rotor.joint + suffix, rotor, gear)
        actuator.gaintype = mujoco.mjtGain.mjGAIN_AFFINE
        gain = np.zeros(10)
        gain[2] = -rotor.rotor_drag  # × site velocity [m/s] × activation |ω| [rad/s] → [N]
        actuator.gainprm = gain


def _spin(spec: mujoco.MjSpec, rotor: Rotor, joint: str) -> None:
    """The rotor joint's actuator (replacing any motor on it), driven by rotor speed commands."""
    import mujoco

    for old in [a for a in spec.actuators if a.target == joint]:
        spec.delete(old)
    actuator = spec.add_actuator(name=joint, target=joint)
    actuator.trntype = mujoco.mjtTrn.mjTRN_JOINT
    gear = np.zeros(6)
    gear[0] = rotor.direction * rotor.slowdown
    actuator.gear = gear
    _lag(actuator, rotor)
    record = {
        "modes": ["velocity"],
        "source": SOURCE,
        "where": rotor.where,
        "bounds": {},
        "pid": {},
        "velocity_limit": rotor.max_rot_velocity,
        "plugin": None,
        "rotor": rotor.to_dict(),
    }
    set_control_record(spec, joint, record)
